// Benchmark driver (not part of cnem): CGAL's Sibson coordinates at many query points.
//
// Built and run by benchmarks/shape_functions.py when CGAL's headers and g++ are present
// (Debian: apt-get install libcgal-dev); never installed with the package.
//
// usage: cgal_sibson NODES.bin QUERIES.bin REPEAT OUT_PREFIX
//   NODES.bin, QUERIES.bin: raw little-endian float64, (n, 2) and (q, 2) row-major.
// The Delaunay triangulation of the nodes (vertex info = node index) is built and timed
// apart.  Each of REPEAT timed runs sorts the query indices along a Hilbert curve
// (CGAL::hilbert_sort, counted) and evaluates natural_neighbor_coordinates_2 at every
// query in that order, single-threaded, each location starting from the face the
// previous query was found in; the coordinates are normalised to sum 1 and gathered into
// a CSR matrix in the input order of the queries (inside the timed run: cnem returns one).
// The last run's matrix is written to OUT_PREFIX.indptr (int64, q + 1), OUT_PREFIX.indices
// (int32, node index) and OUT_PREFIX.data (float64).
// stdout, one "key value..." per line: build seconds, run seconds (wall), run CPU seconds
// (std::clock: less sensitive to a busy machine), points outside the hull, peak resident
// set (VmHWM, kB).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/natural_neighbor_coordinates_2.h>
#include <CGAL/hilbert_sort.h>
#include <CGAL/Spatial_sort_traits_adapter_2.h>
#include <CGAL/property_map.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef CGAL::Triangulation_vertex_base_with_info_2<std::uint32_t, K> Vb;
typedef CGAL::Triangulation_data_structure_2<Vb> Tds;
typedef CGAL::Delaunay_triangulation_2<K, Tds> Dt;
typedef K::Point_2 Point;
typedef std::pair<std::uint32_t, double> Entry;

static std::vector<Point> read_points(const char* path)
{
    std::ifstream f(path, std::ios::binary | std::ios::ate);
    if (!f) { std::cerr << "cannot open " << path << "\n"; std::exit(2); }
    std::streamsize bytes = f.tellg();
    f.seekg(0);
    std::vector<double> xy(static_cast<std::size_t>(bytes) / sizeof(double));
    f.read(reinterpret_cast<char*>(xy.data()), bytes);
    std::vector<Point> pts;
    pts.reserve(xy.size() / 2);
    for (std::size_t i = 0; i + 1 < xy.size(); i += 2) pts.emplace_back(xy[i], xy[i + 1]);
    return pts;
}

template <class T>
static void write_array(const std::string& path, const std::vector<T>& a)
{
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(a.data()), a.size() * sizeof(T));
}

static long peak_rss_kb()
{
    std::ifstream f("/proc/self/status");
    std::string key;
    while (f >> key) {
        if (key == "VmHWM:") { long kb; f >> kb; return kb; }
    }
    return -1;
}

static double seconds_since(std::chrono::steady_clock::time_point t0)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int main(int argc, char** argv)
{
    if (argc != 5) {
        std::cerr << "usage: cgal_sibson NODES.bin QUERIES.bin REPEAT OUT_PREFIX\n";
        return 2;
    }
    const std::vector<Point> nodes = read_points(argv[1]);
    const std::vector<Point> queries = read_points(argv[2]);
    const int repeat = std::atoi(argv[3]);
    const std::string prefix = argv[4];

    std::vector<std::pair<Point, std::uint32_t>> with_index;
    with_index.reserve(nodes.size());
    for (std::size_t i = 0; i < nodes.size(); ++i)
        with_index.emplace_back(nodes[i], static_cast<std::uint32_t>(i));
    auto t0 = std::chrono::steady_clock::now();
    Dt dt;
    dt.insert(with_index.begin(), with_index.end());   // spatially sorted insertion
    std::cout << "build " << seconds_since(t0) << "\n";
    std::cout << "vertices " << dt.number_of_vertices() << "\n";

    const std::size_t q = queries.size();
    std::vector<std::size_t> order(q), start(q + 1);
    std::vector<Entry> flat;                 // rows in the sorted order
    flat.reserve(8 * q);
    std::vector<std::int64_t> indptr(q + 1);
    std::vector<std::int32_t> indices;
    std::vector<double> data;
    auto to_entry = [](const std::pair<Dt::Vertex_handle, double>& vc) {
        return Entry(vc.first->info(), vc.second);
    };
    typedef CGAL::Spatial_sort_traits_adapter_2<
        K, CGAL::Pointer_property_map<Point>::const_type> Sort_traits;
    long outside = 0;
    std::vector<double> cpu;
    std::cout << "runs";
    for (int run = 0; run < repeat; ++run) {
        flat.clear();
        indices.clear();
        data.clear();
        outside = 0;
        t0 = std::chrono::steady_clock::now();
        const std::clock_t c0 = std::clock();
        for (std::size_t i = 0; i < q; ++i) order[i] = i;
        CGAL::hilbert_sort(order.begin(), order.end(),
                           Sort_traits(CGAL::make_property_map(queries)));
        Dt::Face_handle hint;
        Dt::Locate_type lt;
        int li;
        for (std::size_t k = 0; k < q; ++k) {
            const std::size_t i = order[k];
            start[k] = flat.size();
            hint = dt.locate(queries[i], lt, li, hint);
            auto res = CGAL::natural_neighbor_coordinates_2(
                dt, queries[i], std::back_inserter(flat), to_entry, hint);
            if (!res.third) { ++outside; flat.resize(start[k]); continue; }
            const double inv = 1.0 / res.second;   // CGAL's coordinates are not normalised
            for (std::size_t j = start[k]; j < flat.size(); ++j) flat[j].second *= inv;
        }
        start[q] = flat.size();
        // the CSR matrix in the input order of the queries, like Model.shape_functions
        indptr[0] = 0;
        for (std::size_t k = 0; k < q; ++k) indptr[order[k] + 1] = start[k + 1] - start[k];
        for (std::size_t i = 0; i < q; ++i) indptr[i + 1] += indptr[i];
        indices.resize(flat.size());
        data.resize(flat.size());
        for (std::size_t k = 0; k < q; ++k) {
            std::int64_t to = indptr[order[k]];
            for (std::size_t j = start[k]; j < start[k + 1]; ++j, ++to) {
                indices[to] = static_cast<std::int32_t>(flat[j].first);
                data[to] = flat[j].second;
            }
        }
        std::cout << " " << seconds_since(t0) << std::flush;
        cpu.push_back(double(std::clock() - c0) / CLOCKS_PER_SEC);
    }
    std::cout << "\ncpu_runs";
    for (double c : cpu) std::cout << " " << c;
    std::cout << "\noutside " << outside << "\n";
    std::cout << "peak_kb " << peak_rss_kb() << "\n";
    write_array(prefix + ".indptr", indptr);
    write_array(prefix + ".indices", indices);
    write_array(prefix + ".data", data);
    return 0;
}
