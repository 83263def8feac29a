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

#include "cgal_driver.h"

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef CGAL::Triangulation_vertex_base_with_info_2<std::uint32_t, K> Vb;
typedef CGAL::Triangulation_data_structure_2<Vb> Tds;
typedef CGAL::Delaunay_triangulation_2<K, Tds> Dt;
typedef K::Point_2 Point;

int main(int argc, char** argv)
{
    const Arguments args = read_arguments(argc, argv, "cgal_sibson");
    const std::vector<Point> nodes = read_points<Point, 2>(args.nodes);
    const std::vector<Point> queries = read_points<Point, 2>(args.queries);
    const int repeat = args.repeat;
    const std::string prefix = args.prefix;
    const auto with_index = with_indices(nodes);
    auto t0 = std::chrono::steady_clock::now();
    Dt dt;
    dt.insert(with_index.begin(), with_index.end());   // spatially sorted insertion
    std::cout << "build " << seconds_since(t0) << "\n";
    std::cout << "vertices " << dt.number_of_vertices() << "\n";

    auto to_entry = [](const std::pair<Dt::Vertex_handle, double>& vc) {
        return Entry(vc.first->info(), vc.second);
    };
    typedef CGAL::Spatial_sort_traits_adapter_2<
        K, CGAL::Pointer_property_map<Point>::const_type> Sort_traits;
    Dt::Face_handle hint;
    Dt::Locate_type lt;
    int li;
    auto row = [&](const Point& p, std::vector<Entry>& flat) {
        const std::size_t from = flat.size();
        hint = dt.locate(p, lt, li, hint);
        auto res = CGAL::natural_neighbor_coordinates_2(dt, p, std::back_inserter(flat),
                                                        to_entry, hint);
        if (!res.third) return false;
        normalise(flat, from, res.second);   // CGAL's coordinates are not normalised
        return true;
    };
    timed_runs(queries, repeat, Sort_traits(CGAL::make_property_map(queries)), row, prefix);
    return 0;
}
