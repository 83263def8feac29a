// Benchmark driver (not part of cnem): CGAL's 3-D Laplace coordinates at many query points.
//
// Built and run by benchmarks/laplace_3d.py and tests/test_cgal_reference.py when CGAL's
// headers and g++ are present (Debian: apt-get install libcgal-dev); never installed with
// the package.
//
// usage: cgal_laplace3 NODES.bin QUERIES.bin REPEAT OUT_PREFIX
//   NODES.bin, QUERIES.bin: raw little-endian float64, (n, 3) and (q, 3) row-major.
// The Delaunay tetrahedrisation of the nodes (vertex info = node index) is built and timed
// apart.  Each of REPEAT timed runs sorts the query indices along a Hilbert curve
// (CGAL::hilbert_sort, counted) and evaluates laplace_natural_neighbor_coordinates_3 at
// every query in that order, single-threaded, each location starting from the cell the
// previous query was found in; the coordinates are normalised to sum 1 and gathered into
// a CSR matrix in the input order of the queries (inside the timed run).  A query whose
// conflict zone reaches the hull (CGAL returns false: its Voronoi cell is unbounded) gets
// an empty row and is counted as "outside".
// The last run's matrix is written to OUT_PREFIX.indptr (int64, q + 1), OUT_PREFIX.indices
// (int32, node index) and OUT_PREFIX.data (float64).
// stdout, one "key value..." per line: build seconds, run seconds (wall), run CPU seconds,
// points CGAL declined, peak resident set (VmHWM, kB).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <CGAL/natural_neighbor_coordinates_3.h>
#include <CGAL/hilbert_sort.h>
#include <CGAL/Spatial_sort_traits_adapter_3.h>
#include <CGAL/property_map.h>

#include "cgal_driver.h"

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef CGAL::Triangulation_vertex_base_with_info_3<std::uint32_t, K> Vb;
typedef CGAL::Delaunay_triangulation_cell_base_3<K> Cb;
typedef CGAL::Triangulation_data_structure_3<Vb, Cb> Tds;
typedef CGAL::Delaunay_triangulation_3<K, Tds> Dt;
typedef K::Point_3 Point;
typedef std::pair<Dt::Vertex_handle, double> Coordinate;

int main(int argc, char** argv)
{
    const Arguments args = read_arguments(argc, argv, "cgal_laplace3");
    const std::vector<Point> nodes = read_points<Point, 3>(args.nodes);
    const std::vector<Point> queries = read_points<Point, 3>(args.queries);
    const int repeat = args.repeat;
    const std::string prefix = args.prefix;
    const auto with_index = with_indices(nodes);
    auto t0 = std::chrono::steady_clock::now();
    Dt dt(with_index.begin(), with_index.end());       // spatially sorted insertion
    std::cout << "build " << seconds_since(t0) << "\n";
    std::cout << "vertices " << dt.number_of_vertices() << "\n";

    typedef CGAL::Spatial_sort_traits_adapter_3<
        K, CGAL::Pointer_property_map<Point>::const_type> Sort_traits;
    Dt::Cell_handle hint;
    std::vector<Coordinate> coords;
    auto row = [&](const Point& p, std::vector<Entry>& flat) {
        const std::size_t from = flat.size();
        hint = dt.locate(p, hint);
        coords.clear();
        double norm = 0.0;
        auto res = CGAL::laplace_natural_neighbor_coordinates_3(
            dt, p, std::back_inserter(coords), norm, hint);
        if (!res.third) return false;       // the point's Voronoi cell is unbounded
        for (const Coordinate& c : coords) flat.emplace_back(c.first->info(), c.second);
        normalise(flat, from, norm);         // CGAL's coordinates are not normalised
        return true;
    };
    timed_runs(queries, repeat, Sort_traits(CGAL::make_property_map(queries)), row, prefix);
    return 0;
}
