// tethash_ccd_bench: time per continuous query (tethash/ccd.hpp) on one thread, on the CCD benchmark files of
// ../shared/ccd (handcrafted degenerate motions, ground truth) and on random queries that a broad phase would pass
// on (the swept boxes overlap), with small and large motions. Times are CPU time of the thread, the median of
// --repeat runs over the same queries.
// --sweep MESH times continuous detection of one mesh over a small step (a substep of a drop) instead: the one-shot
// detect_continuous (boundary found at each call, box trees) against the kept ContinuousDetector (boundary once, grid
// of boxes), in interleaved rounds.
#include "machine.hpp"
#include "tethash/ccd.hpp"
#include "tethash/continuous.hpp"
#include "tethash/detect.hpp"
#include "tethash/io/ccd_queries.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/mesh.hpp"

#include "tethash/error.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace {

using V = Eigen::Vector3d;
using Query = std::array<V, 8>;

double thread_ns()
{
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return 1e9 * static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec);
}

struct Timing {
    double ns_per_query = 0;
    std::vector<char> hits;
    std::int64_t iterations = 0;
};

Timing run(const std::vector<Query>& queries, bool edge_edge, int repeat)
{
    Timing t;
    std::vector<double> runs;
    for (int r = 0; r < repeat; ++r) {
        t.hits.assign(queries.size(), 0);
        t.iterations = 0;
        const double start = thread_ns();
        for (std::size_t i = 0; i < queries.size(); ++i) {
            const Query& x = queries[i];
            const tethash::ccd::CcdResult res =
                edge_edge ? tethash::ccd::edge_edge_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7])
                          : tethash::ccd::vertex_face_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]);
            t.hits[i] = res.hit;
            t.iterations += res.iterations;
        }
        runs.push_back((thread_ns() - start) / static_cast<double>(std::max<std::size_t>(queries.size(), 1)));
    }
    std::sort(runs.begin(), runs.end());
    t.ns_per_query = runs[runs.size() / 2];
    return t;
}

/// Random queries whose swept boxes overlap: each primitive's corners within a unit cube around a common centre
/// jittered by `spread`, each corner moving by up to `motion` per axis.
std::vector<Query> random_candidates(std::mt19937_64& rng, bool edge_edge, int count, double motion, double spread)
{
    std::uniform_real_distribution<double> half(-0.5, 0.5), move(-motion, motion), shift(-spread, spread);
    const int na = edge_edge ? 2 : 1;
    std::vector<Query> out;
    while (static_cast<int>(out.size()) < count) {
        Query q;
        const V centre(shift(rng), shift(rng), shift(rng));
        for (int i = 0; i < 4; ++i) {
            q[i] = (i < na ? centre : V::Zero()) + V(half(rng), half(rng), half(rng));
            q[4 + i] = q[i] + V(move(rng), move(rng), move(rng));
        }
        bool apart = false;
        for (int k = 0; k < 3 && !apart; ++k) {
            double alo = 1e300, ahi = -1e300, blo = 1e300, bhi = -1e300;
            for (int i = 0; i < 8; ++i) {
                const double c = q[i](k);
                if (i % 4 < na) {
                    alo = std::min(alo, c);
                    ahi = std::max(ahi, c);
                } else {
                    blo = std::min(blo, c);
                    bhi = std::max(bhi, c);
                }
            }
            apart = ahi < blo || bhi < alo;
        }
        if (!apart) out.push_back(q);
    }
    return out;
}

/// Axis-aligned box of some rows of x0 and x1.
struct Box {
    V lo, hi;
};
Box swept(const tethash::Positions& x0, const tethash::Positions& x1, std::initializer_list<tethash::Index> ids)
{
    Box b{x0.row(*ids.begin()).transpose(), x0.row(*ids.begin()).transpose()};
    for (const tethash::Index v : ids) {
        b.lo = b.lo.cwiseMin(x0.row(v).transpose()).cwiseMin(x1.row(v).transpose());
        b.hi = b.hi.cwiseMax(x0.row(v).transpose()).cwiseMax(x1.row(v).transpose());
    }
    return b;
}
bool overlap(const Box& a, const Box& b)
{
    return !((a.lo.array() > b.hi.array()).any() || (b.lo.array() > a.hi.array()).any());
}

/// The queries of a step between two frames of the same meshes: boundary vertex-face and edge-edge pairs whose
/// swept boxes overlap and that share no vertex (what a broad phase hands the narrow phase).
void step_queries(const std::string& frame0, const std::string& frame1, std::vector<Query>& vertex_face,
                  std::vector<Query>& edge_edge)
{
    const tethash::TetMesh m0 = tethash::io::read_tet_mesh(frame0), m1 = tethash::io::read_tet_mesh(frame1);
    if (m0.tets != m1.tets) throw tethash::Error(frame1 + ": not the meshes of " + frame0);
    const tethash::Positions &x0 = m0.positions, &x1 = m1.positions;
    const tethash::Triangles faces = tethash::boundary_faces(m0.tets);
    std::vector<std::array<tethash::Index, 2>> edges;
    std::vector<tethash::Index> vertices;
    for (Eigen::Index f = 0; f < faces.rows(); ++f)
        for (int c = 0; c < 3; ++c) {
            const tethash::Index i = faces(f, c), j = faces(f, (c + 1) % 3);
            edges.push_back({std::min(i, j), std::max(i, j)});
            vertices.push_back(i);
        }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    std::vector<Box> face_box, edge_box;
    for (Eigen::Index f = 0; f < faces.rows(); ++f)
        face_box.push_back(swept(x0, x1, {faces(f, 0), faces(f, 1), faces(f, 2)}));
    for (const auto& e : edges)
        edge_box.push_back(swept(x0, x1, {e[0], e[1]}));
    const auto row = [](const tethash::Positions& x, tethash::Index v) { return V(x.row(v).transpose()); };
    for (const tethash::Index v : vertices) {
        const Box vb = swept(x0, x1, {v});
        for (Eigen::Index f = 0; f < faces.rows(); ++f) {
            const tethash::Index a = faces(f, 0), b = faces(f, 1), c = faces(f, 2);
            if (v == a || v == b || v == c || !overlap(vb, face_box[static_cast<std::size_t>(f)])) continue;
            vertex_face.push_back(
                {row(x0, v), row(x0, a), row(x0, b), row(x0, c), row(x1, v), row(x1, a), row(x1, b), row(x1, c)});
        }
    }
    for (std::size_t e = 0; e < edges.size(); ++e)
        for (std::size_t g = e + 1; g < edges.size(); ++g) {
            const auto &a = edges[e], &b = edges[g];
            if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1] || !overlap(edge_box[e], edge_box[g]))
                continue;
            edge_edge.push_back({row(x0, a[0]), row(x0, a[1]), row(x0, b[0]), row(x0, b[1]), row(x1, a[0]),
                                 row(x1, a[1]), row(x1, b[0]), row(x1, b[1])});
        }
}

/// --sweep: MESH scaled to 1 m, a substep of a drop at 2 m/s at dt 1/240 (a uniform move of 8.3 mm) with every
/// vertex jittered by up to 1 % of the mean edge (seeded): detect_continuous against ContinuousDetector::detect,
/// `repeat` interleaved rounds at one thread, CPU time; prints each and the median of the rounds' ratios.
int sweep(const std::string& path, int repeat)
{
    tethash::TetMesh mesh = tethash::io::read_tet_mesh(path);
    tethash::Positions& x0 = mesh.positions;
    const Eigen::RowVector3d lo = x0.colwise().minCoeff(), hi = x0.colwise().maxCoeff();
    x0 *= 1.0 / (hi - lo).maxCoeff();
    const double edge = tethash::mean_edge_length(x0, mesh.tets);
    tethash::Positions x1 = x0;
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> jitter(-0.01 * edge, 0.01 * edge);
    for (Eigen::Index i = 0; i < x1.rows(); ++i) {
        x1(i, 2) -= 2.0 / 240;
        for (int k = 0; k < 3; ++k)
            x1(i, k) += jitter(rng);
    }
    double t = thread_ns();
    tethash::ccd::ContinuousDetector kept;
    kept.set_topology(mesh.tets, static_cast<tethash::Index>(x0.rows()));
    const double setup_ms = (thread_ns() - t) * 1e-6;
    std::vector<double> one_shot, kept_ms, ratio;
    std::int64_t candidates = 0, contacts = 0;
    for (int r = 0; r < repeat; ++r) {
        t = thread_ns();
        const auto a = tethash::ccd::detect_continuous(mesh.tets, x0, x1);
        one_shot.push_back((thread_ns() - t) * 1e-6);
        t = thread_ns();
        const auto& b = kept.detect(x0, x1);
        kept_ms.push_back((thread_ns() - t) * 1e-6);
        ratio.push_back(kept_ms.back() / one_shot.back());
        if (a.contacts.size() != b.contacts.size() || a.vertex_face_candidates != b.vertex_face_candidates ||
            a.edge_edge_candidates != b.edge_edge_candidates) {
            std::fprintf(stderr, "tethash_ccd_bench: the kept detector differs from detect_continuous\n");
            return 1;
        }
        candidates = b.vertex_face_candidates + b.edge_edge_candidates;
        contacts = static_cast<std::int64_t>(b.contacts.size());
        std::printf("round %d: detect_continuous %.2f ms, kept %.2f ms (%.3fx)\n", r + 1, one_shot.back(),
                    kept_ms.back(), ratio.back());
    }
    // The simulator's use: a few vertices moving (those of the top 5 % in x) and a filter that refuses every pair
    // (what is left is the broad phase's cost).
    std::vector<double> xs(static_cast<std::size_t>(x0.rows()));
    for (Eigen::Index i = 0; i < x0.rows(); ++i)
        xs[static_cast<std::size_t>(i)] = x0(i, 0);
    std::vector<double> sorted = xs;
    std::sort(sorted.begin(), sorted.end());
    const double cut = sorted[sorted.size() * 95 / 100];
    std::vector<unsigned char> moving(xs.size());
    for (std::size_t i = 0; i < xs.size(); ++i)
        moving[i] = xs[i] >= cut;
    std::vector<double> masked_ms;
    for (int r = 0; r < repeat; ++r) {
        t = thread_ns();
        for (int k = 0; k < 10; ++k)
            kept.detect(x0, x1, {}, moving,
                        [](tethash::ccd::ContinuousKind, tethash::Index, tethash::Index) { return false; });
        masked_ms.push_back((thread_ns() - t) * 1e-7);
    }
    auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
    };
    std::printf("%s: %lld tets, %lld boundary faces; kept set-up %.1f ms; per call detect_continuous %.2f ms, kept "
                "%.2f ms (median ratio %.3f); %lld candidates, %lld contacts\n",
                path.c_str(), static_cast<long long>(mesh.tets.rows()), static_cast<long long>(kept.faces().rows()),
                setup_ms, median(one_shot), median(kept_ms), median(ratio), static_cast<long long>(candidates),
                static_cast<long long>(contacts));
    std::printf("kept, 5 %% of the vertices moving, every pair refused: %.3f ms per call\n", median(masked_ms));
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"tethash_ccd_bench: time per continuous query on the shared CCD files and on random candidates"};
    int count = 200000, repeat = 5;
    std::string shared = TETHASH_SHARED_CCD;
    app.add_option("--random", count, "Random queries per scenario")->capture_default_str();
    app.add_option("--repeat", repeat, "Runs per set (the median is printed)")->capture_default_str();
    app.add_option("--shared", shared, "Folder of the CCD benchmark files (unit-tests/<type>/*.csv)")
        ->capture_default_str();
    std::vector<std::string> frames;
    app.add_option("--frames", frames,
                   "Pairs of frames of the same meshes (FRAME0 FRAME1 ...; e.g. simulation output): the step's "
                   "boundary pairs whose swept boxes overlap are timed as one more set");
    std::string sweep_mesh;
    app.add_option("--sweep", sweep_mesh,
                   "A tet mesh: time continuous detection of its boundary over a substep of a drop, one-shot "
                   "(detect_continuous) against kept (ContinuousDetector), instead of the query sets");
    CLI11_PARSE(app, argc, argv);
    if (!sweep_mesh.empty()) {
        try {
            return sweep(sweep_mesh, std::max(repeat, 1));
        } catch (const std::exception& e) {
            std::fprintf(stderr, "tethash_ccd_bench: %s\n", e.what());
            return 2;
        }
    }
    if (frames.size() % 2 != 0) {
        std::fprintf(stderr, "tethash_ccd_bench: --frames takes pairs of files\n");
        return 2;
    }
    repeat = std::max(repeat, 1);

    double load[3] = {0, 0, 0};
    if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
        if (std::fscanf(f, "%lf %lf %lf", &load[0], &load[1], &load[2]) != 3) load[0] = -1;
        std::fclose(f);
    }
    std::printf("tethash_ccd_bench: %s, flags '%s', %u hardware threads, 1 thread, load %.2f %.2f %.2f\n",
                TETHASH_BENCH_COMPILER, TETHASH_BENCH_FLAGS, std::thread::hardware_concurrency(), load[0], load[1],
                load[2]);
    std::printf("machine: %s\n", tethash::bench::machine_name().c_str());
    const tethash::ccd::CcdParams defaults;
    std::printf("tolerance %g, at most %lld boxes per query; CPU time of one thread, median of %d runs\n\n",
                defaults.tolerance, static_cast<long long>(defaults.max_iterations), repeat);

    std::printf("%-44s %8s %9s %6s %6s %12s %10s\n", "set", "queries", "colliding", "FN", "FP", "ns/query", "boxes/q");
    namespace fs = std::filesystem;
    for (const std::string type : {"vertex-face", "edge-edge"}) {
        const fs::path dir = fs::path(shared) / "unit-tests" / type;
        if (!fs::is_directory(dir)) {
            std::printf("%-44s (no %s)\n", type.c_str(), dir.string().c_str());
            continue;
        }
        std::vector<fs::path> files;
        for (const auto& e : fs::directory_iterator(dir))
            if (e.path().extension() == ".csv") files.push_back(e.path());
        std::sort(files.begin(), files.end());
        for (const auto& file : files) {
            const auto read = tethash::io::read_ccd_queries(file.string());
            std::vector<Query> queries;
            for (const auto& q : read)
                queries.push_back(q.points);
            const Timing t = run(queries, type == "edge-edge", repeat);
            int colliding = 0, fn = 0, fp = 0;
            for (std::size_t i = 0; i < read.size(); ++i) {
                colliding += read[i].collides;
                fn += read[i].collides && !t.hits[i];
                fp += !read[i].collides && t.hits[i];
            }
            const std::string name = type + "/" + file.filename().string();
            std::printf("%-44s %8zu %9d %6d %6d %12.0f %10.1f\n", name.c_str(), queries.size(), colliding, fn, fp,
                        t.ns_per_query, static_cast<double>(t.iterations) / static_cast<double>(queries.size()));
        }
    }
    std::mt19937_64 rng(2021);
    for (const bool edge_edge : {false, true})
        for (const double motion : {0.01, 0.1, 0.3}) {
            const auto queries = random_candidates(rng, edge_edge, count, motion, 0.5);
            const Timing t = run(queries, edge_edge, repeat);
            const auto hits = std::count(t.hits.begin(), t.hits.end(), 1);
            char name[64];
            std::snprintf(name, sizeof name, "random %s, boxes overlap, motion %g", edge_edge ? "ee" : "vf", motion);
            std::printf("%-44s %8zu %9s %6s %6s %12.0f %10.2f   (%lld reported colliding)\n", name, queries.size(), "-",
                        "-", "-", t.ns_per_query,
                        static_cast<double>(t.iterations) / static_cast<double>(queries.size()),
                        static_cast<long long>(hits));
        }
    if (!frames.empty()) {
        std::vector<Query> vertex_face, edge_edge;
        try {
            for (std::size_t k = 0; k < frames.size(); k += 2)
                step_queries(frames[k], frames[k + 1], vertex_face, edge_edge);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "tethash_ccd_bench: %s\n", e.what());
            return 2;
        }
        for (const bool ee : {false, true}) {
            const auto& queries = ee ? edge_edge : vertex_face;
            const Timing t = run(queries, ee, repeat);
            const auto hits = std::count(t.hits.begin(), t.hits.end(), 1);
            const std::string name = std::string("frames (") + std::to_string(frames.size() / 2) + " steps), " +
                                     (ee ? "edge-edge" : "vertex-face");
            std::printf("%-44s %8zu %9s %6s %6s %12.0f %10.2f   (%lld reported colliding)\n", name.c_str(),
                        queries.size(), "-", "-", "-", t.ns_per_query,
                        static_cast<double>(t.iterations) /
                            static_cast<double>(std::max<std::size_t>(queries.size(), 1)),
                        static_cast<long long>(hits));
        }
    }
    return 0;
}
