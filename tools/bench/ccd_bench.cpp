// tethash_ccd_bench: time per continuous query (tethash/ccd.hpp) on one thread, on the CCD benchmark files of
// ../shared/ccd (handcrafted degenerate motions, ground truth) and on random queries that a broad phase would pass
// on (the swept boxes overlap), with small and large motions. Times are CPU time of the thread, the median of
// --repeat runs over the same queries.
#include "tethash/ccd.hpp"
#include "tethash/io/ccd_queries.hpp"

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
    CLI11_PARSE(app, argc, argv);
    repeat = std::max(repeat, 1);

    double load[3] = {0, 0, 0};
    if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
        if (std::fscanf(f, "%lf %lf %lf", &load[0], &load[1], &load[2]) != 3) load[0] = -1;
        std::fclose(f);
    }
    std::printf("tethash_ccd_bench: %s, flags '%s', %u hardware threads, 1 thread, load %.2f %.2f %.2f\n",
                TETHASH_BENCH_COMPILER, TETHASH_BENCH_FLAGS, std::thread::hardware_concurrency(), load[0], load[1],
                load[2]);
    {
        std::ifstream cpu("/proc/cpuinfo");
        std::string line;
        while (std::getline(cpu, line))
            if (line.rfind("model name", 0) == 0) {
                std::printf("machine: %s\n", line.substr(line.find(':') + 2).c_str());
                break;
            }
    }
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
    return 0;
}
