// What the CGAL benchmark drivers (cgal_sibson.cpp, cgal_laplace3.cpp) share: reading the
// raw float64 inputs, timing, gathering the rows into a CSR matrix in the queries' order,
// and writing the results.  Not part of cnem.
#pragma once

#include <CGAL/hilbert_sort.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

typedef std::pair<std::uint32_t, double> Entry;     // (node index, coordinate)

// The raw little-endian float64 values of a file (row-major points).
static std::vector<double> read_doubles(const char* path)
{
    std::ifstream f(path, std::ios::binary | std::ios::ate);
    if (!f) { std::cerr << "cannot open " << path << "\n"; std::exit(2); }
    std::streamsize bytes = f.tellg();
    f.seekg(0);
    std::vector<double> values(static_cast<std::size_t>(bytes) / sizeof(double));
    f.read(reinterpret_cast<char*>(values.data()), bytes);
    return values;
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

// Rows computed in the order order[0], order[1], ... (row k is flat[start[k]:start[k+1]])
// as a CSR matrix in the input order of the queries, like cnem's shape functions.
struct Csr {
    std::vector<std::int64_t> indptr;
    std::vector<std::int32_t> indices;
    std::vector<double> data;

    void gather(const std::vector<std::size_t>& order, const std::vector<std::size_t>& start,
                const std::vector<Entry>& flat)
    {
        const std::size_t q = order.size();
        indptr.assign(q + 1, 0);
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
    }
};

// The lines after the runs' wall times, and the last run's matrix at OUT_PREFIX.*.
static void report_and_write(const std::vector<double>& cpu, long outside, const Csr& csr,
                             const std::string& prefix)
{
    std::cout << "\ncpu_runs";
    for (double c : cpu) std::cout << " " << c;
    std::cout << "\noutside " << outside << "\n";
    std::cout << "peak_kb " << peak_rss_kb() << "\n";
    write_array(prefix + ".indptr", csr.indptr);
    write_array(prefix + ".indices", csr.indices);
    write_array(prefix + ".data", csr.data);
}

// The points with their indices, for a triangulation whose vertex info is the node index.
template <class Point>
static std::vector<std::pair<Point, std::uint32_t>> with_indices(const std::vector<Point>& pts)
{
    std::vector<std::pair<Point, std::uint32_t>> out;
    out.reserve(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i)
        out.emplace_back(pts[i], static_cast<std::uint32_t>(i));
    return out;
}

// The command line every driver takes: NODES.bin QUERIES.bin REPEAT OUT_PREFIX.
struct Arguments {
    const char* nodes;
    const char* queries;
    int repeat;
    std::string prefix;
};

static Arguments read_arguments(int argc, char** argv, const char* name)
{
    if (argc != 5) {
        std::cerr << "usage: " << name << " NODES.bin QUERIES.bin REPEAT OUT_PREFIX\n";
        std::exit(2);
    }
    return Arguments{argv[1], argv[2], std::atoi(argv[3]), argv[4]};
}

// REPEAT timed runs over the queries: each sorts the query indices along a Hilbert curve
// (counted), computes every row in that order with row(point, flat) (which appends the
// row's normalised entries to flat and returns false for a point it cannot answer: its row
// is left empty and counted as outside) and gathers the CSR matrix; prints the runs' wall
// times, then `report_and_write`.
template <class Point, class SortTraits, class Row>
static void timed_runs(const std::vector<Point>& queries, int repeat, const SortTraits& traits,
                       Row row, const std::string& prefix)
{
    const std::size_t q = queries.size();
    std::vector<std::size_t> order(q), start(q + 1);
    std::vector<Entry> flat;                 // rows in the sorted order
    flat.reserve(16 * q);
    Csr csr;
    long outside = 0;
    std::vector<double> cpu;
    std::cout << "runs";
    for (int run = 0; run < repeat; ++run) {
        flat.clear();
        outside = 0;
        const auto t0 = std::chrono::steady_clock::now();
        const std::clock_t c0 = std::clock();
        for (std::size_t i = 0; i < q; ++i) order[i] = i;
        CGAL::hilbert_sort(order.begin(), order.end(), traits);
        for (std::size_t k = 0; k < q; ++k) {
            start[k] = flat.size();
            if (!row(queries[order[k]], flat)) { ++outside; flat.resize(start[k]); }
        }
        start[q] = flat.size();
        csr.gather(order, start, flat);
        std::cout << " " << seconds_since(t0) << std::flush;
        cpu.push_back(double(std::clock() - c0) / CLOCKS_PER_SEC);
    }
    report_and_write(cpu, outside, csr, prefix);
}

// Divide the entries flat[from:] by their sum's given normaliser.
static void normalise(std::vector<Entry>& flat, std::size_t from, double norm)
{
    const double inv = 1.0 / norm;
    for (std::size_t j = from; j < flat.size(); ++j) flat[j].second *= inv;
}

// The D-dimensional points of a raw float64 file (row-major).
template <class Point, int D>
static std::vector<Point> read_points(const char* path)
{
    const std::vector<double> v = read_doubles(path);
    std::vector<Point> pts;
    pts.reserve(v.size() / D);
    for (std::size_t i = 0; i + D <= v.size(); i += D) {
        if constexpr (D == 2) pts.emplace_back(v[i], v[i + 1]);
        else pts.emplace_back(v[i], v[i + 1], v[i + 2]);
    }
    return pts;
}
