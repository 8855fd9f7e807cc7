// tethash_bench: ms per detection (median), ns per tet, stage split and contacts at 1 and all threads for the
// five scenarios of Teschner et al. 2003 rebuilt with meshing::generate (objects overlapping heavily), plus the
// meshes of ../shared/meshes; and, in the same run, a plain implementation of the 2003 algorithm
// (baseline_2003.hpp) as the baseline. Scenes of its own: bench_scenes.hpp. `tethash_bench --help` lists options.
//
//   tethash_bench [--repeat K] [--threads N] [--scenario I] [--sweep] [--no-meshes] [--no-baseline] [--cell-factor F]
//                 [--hash column|teschner] [--table-factor F]
//   tethash_bench --moving [--scenario I] [--steps N] [--speed F] [--threads N]: a moving scene (candidate reuse)
//   tethash_bench --edges [--scenario I] [--no-meshes]: the edge-face contacts (edge_contacts.hpp) beside the
//                 vertex-in-tet detection on the same scenes
//   tethash_bench --methods hash,bvh,kd [--partition-scenes bars,sizes]: the other broad phases on every scene, in the
//                 same run as the hash and the baseline (medians at 1 thread)
//   tethash_bench --walk [--steps N] [--walk-speed L] [--rooms N] [--methods ...]: the building, the building with
//                 cells made from its walls and the hall with every object walking: CPU ms per step of each method,
//                 the portals' segment tests and overlaps per step; every wall against the walls of the cell
#include "machine.hpp"
#include "tethash/detect.hpp"
#include "tethash/detect_grammar.hpp"
#include "tethash/edge_contacts.hpp"
#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/portals.hpp"
#include "tethash/study/methods.hpp"
#include "tethash/study/scenarios.hpp"
#include "tethash/study/stats_table.hpp"

#include "baseline_2003.hpp"
#include "bench_scenes.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <time.h>

#ifdef _OPENMP
#include <omp.h>
#endif

using namespace tethash;
using Clock = std::chrono::steady_clock;

namespace {

/// CPU time of the calling thread in ms (robust against other load on the machine for 1-thread runs).
double thread_cpu_ms()
{
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

/// CPU time of the whole process in ms (all threads).
double process_cpu_ms()
{
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

// ---- measuring -------------------------------------------------------------------------------------

struct Measured {
    double ms = 0;
    double cpu_ms = 0;         ///< CPU time of the calling thread (meaningful at 1 thread)
    double process_cpu_ms = 0; ///< CPU time of all threads (includes OpenMP spin-waiting)
    DetectStats stats;
    std::vector<Contact> contacts; ///< of the warm-up call (the oracle's, as the tests hold)
};

Measured measure(const TetMesh& m, const DetectParams& p, int repeat)
{
    Detector det(p);
    det.set_topology(m);
    DetectStats st;
    std::vector<Contact> contacts = det.detect(m.positions); // warm-up (auto cell size, buffers)
    std::vector<double> ms, cpu, pcpu, s1, s2, s3, s4;
    for (int r = 0; r < repeat; ++r) {
        const double c0 = thread_cpu_ms(), p0 = process_cpu_ms();
        const auto t0 = Clock::now();
        det.detect(m.positions);
        ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
        cpu.push_back(thread_cpu_ms() - c0);
        pcpu.push_back(process_cpu_ms() - p0);
    }
    // Stage split from separate runs with statistics on (they count degenerate tets too).
    for (int r = 0; r < std::max(3, repeat / 3); ++r) {
        det.detect(m.positions, &st);
        s1.push_back(st.ms_vertices);
        s2.push_back(st.ms_tets);
        s3.push_back(st.ms_inside);
        s4.push_back(st.ms_sort);
    }
    st.ms_vertices = median(s1);
    st.ms_tets = median(s2);
    st.ms_inside = median(s3);
    st.ms_sort = median(s4);
    return {median(ms), median(cpu), median(pcpu), st, std::move(contacts)};
}

double measure_baseline(const TetMesh& m, double l, int repeat, std::vector<std::pair<Index, Index>>& out,
                        double& cpu_ms)
{
    bench::Baseline2003 b;
    b.run(m, l, out);
    std::vector<double> ms, cpu;
    for (int r = 0; r < repeat; ++r) {
        const double c0 = thread_cpu_ms();
        const auto t0 = Clock::now();
        b.run(m, l, out);
        ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
        cpu.push_back(thread_cpu_ms() - c0);
    }
    cpu_ms = median(cpu);
    return median(ms);
}

/// --profile N: N detections without statistics and nothing else, for
/// `valgrind --tool=callgrind --toggle-collect='*profile_detects*'` (instruction counts independent of load).
__attribute__((noinline)) std::size_t profile_detects(Detector& det, const TetMesh& m, int calls)
{
    std::size_t n = 0;
    for (int r = 0; r < calls; ++r)
        n += det.detect(m.positions).size();
    return n;
}

/// One scene: tethash at 1 and all threads, its statistics, and the baseline. `table_factor` > 0: the table size
/// is the power of two nearest to table_factor × vertices (0: automatic).
void report(const char* name, const TetMesh& m, const DetectParams& base, int threads_all, int repeat, bool baseline,
            double table_factor, const std::vector<Method>& methods)
{
    DetectParams p1 = base;
    if (table_factor > 0) {
        const double want = table_factor * m.num_vertices();
        std::int64_t n = 1;
        while (static_cast<double>(n) * 1.41421356 < want)
            n <<= 1;
        p1.table_size = n;
    }
    p1.threads = 1;
    DetectParams pn = p1;
    pn.threads = threads_all;
    const Measured one = measure(m, p1, repeat);
    const Measured all = measure(m, pn, repeat);
    std::printf("%-28s objects %4d  tets %8d  vertices %8d  contacts %8lld\n", name, m.num_objects(), m.num_tets(),
                m.num_vertices(), static_cast<long long>(one.stats.contacts));
    auto line = [&](const char* label, const Measured& r) {
        std::printf("  %-14s %8.3f ms (cpu %.3f, all threads %.3f)  %7.1f ns/tet  [vertices %.3f  tets+scan %.3f  "
                    "inside %.3f  sort %.3f]\n",
                    label, r.ms, r.cpu_ms, r.process_cpu_ms, 1e6 * r.ms / m.num_tets(), r.stats.ms_vertices,
                    r.stats.ms_tets, r.stats.ms_inside, r.stats.ms_sort);
    };
    line("1 thread", one);
    char label[32];
    std::snprintf(label, sizeof label, "%d threads", all.stats.threads);
    line(label, all);
    const DetectStats& s = one.stats;
    std::printf(" ");
    for (const study::StatField& f : study::k_detect_stats)
        if (f.use & study::in_bench) {
            if (f.kind == study::StatKind::count)
                std::printf(" %s %lld ", f.bench_label, static_cast<long long>(f.get(s)));
            else
                std::printf(" %s %.4g ", f.bench_label, f.get(s));
        }
    std::printf(" memory %.1f B/tet\n", double(s.memory_bytes) / std::max(1, m.num_tets()));
    if (all.stats.contacts != one.stats.contacts) std::printf("  ERROR: contact counts differ between thread counts\n");
    double baseline_cpu = 0;
    if (baseline) {
        std::vector<std::pair<Index, Index>> pairs;
        const double bms = measure_baseline(m, s.cell_size, std::max(3, repeat / 3), pairs, baseline_cpu);
        std::printf("  baseline 2003  %8.3f ms (1 thread, cpu %.3f ms, %zu contacts)   ratio: %.1fx at 1 thread "
                    "(cpu %.1fx), %.1fx at %d threads%s\n",
                    bms, baseline_cpu, pairs.size(), bms / one.ms, baseline_cpu / one.cpu_ms, bms / all.ms,
                    all.stats.threads,
                    bench::same_pairs(pairs, one.contacts) ? "" : "  ERROR: contacts differ from the hash");
    }
    // The other broad phases at 1 thread, same scene and parameters (DetectStats::candidates: the pairs handed to
    // the exact test; nodes: cells, nodes or levels of the structure; the stage split: build + query of the broad
    // phase, the exact stage, the sort, medians of the runs with statistics).
    for (Method method : methods) {
        DetectParams pm = p1;
        pm.method = method;
        try {
            const Measured r = measure(m, pm, std::max(3, repeat / 3));
            std::printf("  %-14s %8.3f ms (cpu %.3f)  %7.1f ns/tet  [broad %.3f  exact %.3f  sort %.3f]  candidates "
                        "%lld  nodes %lld  memory %.1f B/tet  contacts %lld%s",
                        to_string(method), r.ms, r.cpu_ms, 1e6 * r.cpu_ms / std::max(1, m.num_tets()),
                        r.stats.ms_vertices + r.stats.ms_tets, r.stats.ms_inside, r.stats.ms_sort,
                        static_cast<long long>(r.stats.candidates), static_cast<long long>(r.stats.nodes),
                        double(r.stats.memory_bytes) / std::max(1, m.num_tets()),
                        static_cast<long long>(r.stats.contacts),
                        r.stats.contacts == s.contacts ? "" : "  ERROR: contacts differ from the hash");
            if (baseline) std::printf("  baseline/this %.2fx (cpu)", baseline_cpu / r.cpu_ms);
            std::printf("\n");
        } catch (const std::exception& e) {
            std::printf("  %-14s error: %s\n", to_string(method), e.what());
        }
        std::fflush(stdout);
    }
    std::fflush(stdout);
}

/// --moving: ms per step over `steps` steps of a moving scenario at skin off and several skins (factors of the cell
/// size), 1 thread (CPU time) and all threads (wall); then, in a second pass over the same steps with statistics,
/// the rebuild rate, kept candidates and memory; contacts summed over the steps must not depend on the skin.
void report_moving(const study::Scenario& sc, const DetectParams& base, int threads_all, int steps, double speed)
{
    const TetMesh& m = sc.mesh;
    const double edge = mean_edge_length(m.positions, m.tets);
    std::printf(
        "moving scene: scenario %s r%d, %d objects, %d tets, %d vertices, %d steps, fastest vertex ~%.3g x mean "
        "edge per step\n",
        sc.shape.c_str(), sc.resolution, m.num_objects(), m.num_tets(), m.num_vertices(), steps, speed);
    long long reference_contacts = -1;
    for (double skin : {0.0, 0.05, 0.1, 0.2, 0.3, 0.5}) {
        double times[2] = {0, 0};
        int thread_counts[2] = {1, threads_all};
        for (int k = 0; k < 2; ++k) {
            DetectParams p = base;
            p.threads = thread_counts[k];
            p.skin_mode = DetectParams::SkinMode::factor_of_cell_size;
            p.skin = skin;
            Detector det(p);
            det.set_topology(m);
            bench::MovingScene scene(m, edge, speed, 11);
            det.detect(scene.positions()); // warm-up (auto cell size, buffers): the first step
            std::vector<double> t;
            for (int s = 1; s < steps; ++s) {
                scene.step();
                const double c0 = thread_cpu_ms();
                const auto t0 = Clock::now();
                det.detect(scene.positions());
                t.push_back(k == 0 ? thread_cpu_ms() - c0
                                   : std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
            }
            double sum = 0;
            for (double x : t)
                sum += x;
            times[k] = sum / static_cast<double>(t.size());
            if (threads_all == 1) {
                times[1] = times[0];
                break;
            }
        }
        // Statistics pass (slower scan kernel): rebuilds, kept candidates, contacts.
        DetectParams p = base;
        p.threads = 1;
        p.skin_mode = DetectParams::SkinMode::factor_of_cell_size;
        p.skin = skin;
        Detector det(p);
        det.set_topology(m);
        bench::MovingScene scene(m, edge, speed, 11);
        DetectStats st;
        det.detect(scene.positions(), &st);
        int rebuilds = 0;
        long long contacts = 0, cached = 0, tests = 0;
        std::int64_t memory = 0;
        for (int s = 1; s < steps; ++s) {
            scene.step();
            det.detect(scene.positions(), &st);
            rebuilds += !st.reused;
            contacts += st.contacts;
            cached += st.cached_candidates;
            tests += st.inside_tests;
            memory = std::max(memory, st.memory_bytes);
        }
        if (reference_contacts < 0) reference_contacts = contacts;
        std::printf("  skin %.2f x cell (%.4g)  %8.3f ms/step at 1 thread (cpu)  %8.3f ms/step at %d threads (wall)  "
                    "rebuilds %3d/%d (%4.1f%%)  inside tests/step %lld  kept candidates/step %lld  memory %.1f B/tet  "
                    "contacts/step %.0f%s\n",
                    skin, skin * st.cell_size, times[0], times[1], threads_all, rebuilds, steps - 1,
                    100.0 * rebuilds / std::max(1, steps - 1), tests / std::max(1, steps - 1),
                    cached / std::max(1, steps - 1), double(memory) / m.num_tets(),
                    double(contacts) / std::max(1, steps - 1),
                    contacts == reference_contacts ? "" : "  ERROR: contacts differ from skin off");
        std::fflush(stdout);
    }
}

/// --walk, the object-world part: every vertex against every wall (ObstacleSet::query), then against the walls of
/// its cell only (CellWalls), the two interleaved step by step at 1 thread; CPU ms per step (medians), the
/// vertex-obstacle pairs looked at, and the contacts, which must agree.
void report_walls(const ObstacleSet& walls, const CellLayout& cells, const std::vector<Positions>& frames)
{
    const CellWalls by_cell(cells, walls);
    std::vector<double> all_ms, cell_ms;
    std::int64_t contacts = 0, tests = 0, every = 0;
    bool same = true;
    for (std::size_t k = 1; k < frames.size(); ++k) {
        double c0 = thread_cpu_ms();
        const std::vector<ObstacleContact> a = walls.query(frames[k]);
        all_ms.push_back(thread_cpu_ms() - c0);
        WallStats ws;
        c0 = thread_cpu_ms();
        const std::vector<ObstacleContact> b = by_cell.query(frames[k], &ws);
        cell_ms.push_back(thread_cpu_ms() - c0);
        same = same && a.size() == b.size() &&
               std::equal(a.begin(), a.end(), b.begin(), [](const ObstacleContact& x, const ObstacleContact& y) {
                   return x.vertex == y.vertex && x.obstacle == y.obstacle && x.depth == y.depth;
               });
        contacts += static_cast<std::int64_t>(a.size());
        tests += ws.tests;
        every += ws.all;
    }
    const double per = 1.0 / static_cast<double>(std::max<std::size_t>(1, frames.size() - 1));
    std::printf("  walls (%d obstacles, %zu cells)  every wall %7.3f ms/step  walls of the cell %7.3f ms/step  "
                "pairs %.0f of %.0f/step  wall contacts %lld%s\n",
                static_cast<int>(walls.size()), cells.cells.size(), median(all_ms), median(cell_ms),
                static_cast<double>(tests) * per, static_cast<double>(every) * per, static_cast<long long>(contacts),
                same ? "" : "  ERROR: the walls of the cells give other contacts");
    std::fflush(stdout);
}

/// --walk: the partition scenes "building", "walled" (its cells made from its walls) and "hall" with every object
/// moving rigidly at `speed` (length per step) in a random direction of the floor, turned back at the building's outer
/// walls (objects go through inner walls and doors alike: nothing stops them). Per method at 1 thread: CPU ms per step
/// (median), the build and query of the broad phase, and for portals the segment tests and boxes entered beyond their
/// cell per step; the contacts summed over the steps must agree.
void report_walk(const std::vector<Method>& methods, const DetectParams& base, int steps, double speed, int rooms)
{
    for (const char* name : {"building", "walled", "hall"}) {
        study::NamedScene ps = study::partition_scene(name);
        if (rooms > 0) { // rooms × rooms rooms, the hall one cell over them all
            ps = study::building_scene(rooms, rooms);
            if (std::string(name) == "walled")
                ps.cells = std::make_shared<const CellLayout>(cells_from_obstacles(*ps.walls));
            if (std::string(name) == "hall") {
                auto one = std::make_shared<CellLayout>();
                PortalCell c;
                c.name = "hall";
                c.hi[0] = c.hi[1] = 4.0 * rooms;
                c.hi[2] = 3;
                one->cells.push_back(c);
                ps.cells = one;
                ps.walls = nullptr; // an open hall
            }
        }
        const double side = rooms > 0 ? 4.0 * rooms : 16.0;
        const TetMesh& m = ps.mesh;
        // Frames: each object's velocity from a fixed sequence of directions.
        std::vector<Eigen::Vector2d> velocity(static_cast<std::size_t>(m.num_objects()));
        for (std::size_t o = 0; o < velocity.size(); ++o) {
            const double a = 2.399963229728653 * static_cast<double>(o); // golden angle: directions spread evenly
            velocity[o] = speed * Eigen::Vector2d(std::cos(a), std::sin(a));
        }
        std::vector<Eigen::Vector2d> centre(velocity.size(), Eigen::Vector2d::Zero());
        std::vector<int> count(velocity.size(), 0);
        for (Index v = 0; v < m.num_vertices(); ++v) {
            const auto o = static_cast<std::size_t>(m.vertex_object[static_cast<std::size_t>(v)]);
            centre[o] += Eigen::Vector2d(m.positions(v, 0), m.positions(v, 1));
            ++count[o];
        }
        for (std::size_t o = 0; o < centre.size(); ++o)
            centre[o] /= count[o];
        std::vector<Positions> frames(static_cast<std::size_t>(steps), m.positions);
        for (int k = 1; k < steps; ++k) {
            frames[static_cast<std::size_t>(k)] = frames[static_cast<std::size_t>(k) - 1];
            for (std::size_t o = 0; o < centre.size(); ++o) {
                for (int a = 0; a < 2; ++a)
                    if (centre[o][a] + velocity[o][a] < 0.3 || centre[o][a] + velocity[o][a] > side - 0.3)
                        velocity[o][a] = -velocity[o][a];
                centre[o] += velocity[o];
            }
            Positions& f = frames[static_cast<std::size_t>(k)];
            for (Index v = 0; v < m.num_vertices(); ++v) {
                const auto o = static_cast<std::size_t>(m.vertex_object[static_cast<std::size_t>(v)]);
                f(v, 0) += velocity[o][0];
                f(v, 1) += velocity[o][1];
            }
        }
        std::printf("walk: %s, %d objects, %d tets, %d vertices, %d steps of %.3g per step\n", name, m.num_objects(),
                    m.num_tets(), m.num_vertices(), steps, speed);
        for (Method method : methods) {
            DetectParams p = base;
            p.threads = 1;
            p.method = method;
            p.partition.cells = ps.cells;
            Detector det(p);
            det.set_topology(m);
            std::vector<double> cpu, build, query;
            std::int64_t contacts = 0, rays = 0, overlaps = 0;
            DetectStats st;
            for (int k = 0; k < steps; ++k) {
                const double c0 = thread_cpu_ms();
                det.detect(frames[static_cast<std::size_t>(k)], &st);
                if (k == 0) continue; // the first call builds what is kept
                cpu.push_back(thread_cpu_ms() - c0);
                build.push_back(st.ms_vertices);
                query.push_back(st.ms_tets);
                contacts += st.contacts;
                rays += st.ray_tests;
                overlaps += st.portal_overlaps;
            }
            const double per = 1.0 / std::max(1, steps - 1);
            std::printf("  %-13s cpu %8.3f ms/step  build %7.3f  query %7.3f  contacts %lld", to_string(method),
                        median(cpu), median(build), median(query), static_cast<long long>(contacts));
            if (method == Method::portals)
                std::printf("  segment tests %.0f/step  overlaps %.0f/step", static_cast<double>(rays) * per,
                            static_cast<double>(overlaps) * per);
            std::printf("\n");
            std::fflush(stdout);
        }
        if (ps.walls) report_walls(*ps.walls, *ps.cells, frames);
    }
}

} // namespace

/// Each tet mesh of ../shared/meshes (sorted; a TetGen pair once) as two overlapping copies, the
/// second shifted by a fifth of the size, each copy its own object; a file that does not read is reported skipped.
void for_each_shared_mesh_pair(const std::function<void(const char* name, const TetMesh& two)>& run)
{
    const std::filesystem::path dir = TETHASH_SHARED_MESHES;
    if (!std::filesystem::exists(dir)) return;
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
        if (!io::is_tet_mesh_path(f.string()) || f.extension() == ".node") continue;
        try {
            TetMesh one = io::read_mesh(f.string());
            const Eigen::RowVector3d lo = one.positions.colwise().minCoeff(), hi = one.positions.colwise().maxCoeff();
            one.vertex_object.clear();
            one.tet_object.clear();
            one.ensure_object_ids();
            TetMesh two = one;
            two.positions.rowwise() += 0.2 * (hi - lo);
            one.append(two);
            run(f.filename().string().c_str(), one);
        } catch (const std::exception& e) {
            std::printf("%-28s skipped: %s\n", f.filename().string().c_str(), e.what());
        }
    }
}

/// --edges: the edge-face contacts of one scene: set-up (boundary, neighbours; once per topology), find() at 1 thread
/// (CPU time of the thread, median) and at `threads_all` (wall, median), beside the vertex-in-tet detection at 1
/// thread.
void report_edges(const char* name, const TetMesh& m, const DetectParams& base, int threads_all, int repeat)
{
    EdgeFaceDetector det;
    const auto t0 = Clock::now();
    det.set_topology(m.tets, m.num_vertices(), m.vertex_object, m.tet_object);
    const double setup_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    det.find(m.positions, 1); // warm-up
    std::vector<double> one, all;
    for (int r = 0; r < repeat; ++r) {
        const double c0 = thread_cpu_ms();
        det.find(m.positions, 1);
        one.push_back(thread_cpu_ms() - c0);
        const auto w0 = Clock::now();
        det.find(m.positions, threads_all);
        all.push_back(std::chrono::duration<double, std::milli>(Clock::now() - w0).count());
    }
    const EdgeFaceResult& r = det.find(m.positions, 1);
    DetectParams p = base;
    p.threads = 1;
    const Measured v = measure(m, p, repeat);
    std::printf("%-28s %6lld edges %6lld faces  set-up %7.3f ms  find %7.3f ms (1 thread, cpu) %7.3f ms (%d threads)  "
                "%7lld candidates %6zu edge-face contacts | vertex-in-tet %7.3f ms (1 thread, cpu) %6lld contacts\n",
                name, static_cast<long long>(r.edges.rows()), static_cast<long long>(r.faces.rows()), setup_ms,
                median(one), median(all), threads_all, static_cast<long long>(r.candidates), r.contacts.size(),
                v.cpu_ms, static_cast<long long>(v.stats.contacts));
    std::fflush(stdout);
}

namespace {

/// The benchmark's options (tethash_bench --help).
struct BenchOptions {
    int repeat = 21, threads = 0, only = -1, profile = 0, steps = 100, rooms = 0, leaf_size = 0;
    bool sweep = false, no_meshes = false, no_baseline = false, moving = false, walk = false, edges = false;
    double speed = 0.01, cell_factor = 1.0, table_factor = 0, walk_speed = 0.05;
    std::string hash = "column", methods_text, partition_scenes = "all";
};

void add_options(CLI::App& app, BenchOptions& o)
{
    app.add_option("--repeat", o.repeat, "measured detections per scene (median; at least 1)")->capture_default_str();
    app.add_option("--threads", o.threads, "threads of the 'all threads' runs; 0 = every hardware thread")
        ->capture_default_str();
    app.add_option("--scenario", o.only, "only this scenario (1..5); with --moving or --profile: which one")
        ->check(CLI::Range(1, 5));
    app.add_flag("--sweep", o.sweep, "flatness sweep: ns per tet from 1,000 to 1,000,000 tets at 1 thread");
    app.add_flag("--no-meshes", o.no_meshes, "skip the meshes of ../shared/meshes");
    app.add_flag("--no-baseline", o.no_baseline, "skip the 2003 baseline");
    app.add_option("--profile", o.profile,
                   "N detections of one scenario without statistics, for callgrind "
                   "(--toggle-collect='*profile_detects*')");
    app.add_option("--table-factor", o.table_factor,
                   "table size: the power of two nearest to F × vertices (default: automatic)");
    app.add_option("--cell-factor", o.cell_factor, "cell size as a factor of the mean edge length")
        ->capture_default_str();
    app.add_option("--hash", o.hash, "hash function: column or teschner")->capture_default_str();
    app.add_option("--methods", o.methods_text,
                   "other broad phases to measure on every scene at 1 thread (detect --method names, or all)");
    app.add_option("--partition-scenes", o.partition_scenes,
                   "scenes of the space-partition comparison after the scenarios: bars, sizes, corner, thin, "
                   "building, walled, hall, all or none")
        ->capture_default_str();
    app.add_flag("--edges", o.edges,
                 "the edge-face contacts (set-up, find at 1 and all threads) beside vertex-in-tet detection, on the "
                 "scenarios (--scenario I: one) and the shared meshes (two copies overlapping; --no-meshes: none)");
    app.add_flag("--moving", o.moving, "a moving scene (scenario 5 by default): candidate reuse at several skins");
    app.add_option("--steps", o.steps, "--moving: steps (at least 2)")->capture_default_str();
    app.add_option("--speed", o.speed, "--moving: fastest vertex per step, as a factor of the mean edge")
        ->capture_default_str();
    app.add_flag("--walk", o.walk,
                 "the building and the hall with every object walking (--steps, --walk-speed; --methods, default "
                 "hash, grid, sort-sweep, bvh-refit, portals)");
    app.add_option("--walk-speed", o.walk_speed, "--walk: distance each object moves per step")->capture_default_str();
    app.add_option("--leaf-size", o.leaf_size,
                   "trees: items per leaf; portals: vertices per slab of a cell (0: the method's default)")
        ->check(CLI::Range(0, 1 << 30));
    app.add_option("--rooms", o.rooms, "--walk: a building of N x N rooms instead of the partition scene's 4 x 4")
        ->capture_default_str();
}

/// The scenes of --partition-scenes (a comma-separated list, all or none); throws Error naming an unknown one.
std::vector<std::string> partition_scene_list(const std::string& text)
{
    const auto& known = study::partition_scene_names();
    if (text == "all") return known;
    std::vector<std::string> names;
    if (text == "none") return names;
    std::string item;
    for (std::size_t i = 0; i <= text.size(); ++i) {
        if (i < text.size() && text[i] != ',') {
            item += text[i];
            continue;
        }
        if (std::find(known.begin(), known.end(), item) == known.end())
            throw Error("--partition-scenes: unknown scene '" + item +
                        "' (expected bars, sizes, corner, thin, building, walled, hall, all or none)");
        names.push_back(item);
        item.clear();
    }
    return names;
}

/// What the run measures on: compiler, flags, threads, the machine and the scan kernel.
void print_header(const BenchOptions& o, int threads_all)
{
    std::printf("tethash_bench: %s, flags '%s', %d hardware threads, repeat %d (median), cell %.3g x mean edge, "
                "table auto, hash %s\n",
                TETHASH_BENCH_COMPILER, TETHASH_BENCH_FLAGS, threads_all, o.repeat, o.cell_factor, o.hash.c_str());
    std::printf("machine: %s\n", bench::machine_name().c_str());
    const char* simd = std::getenv("TETHASH_SIMD");
    std::printf("scan kernel: %s\n\n",
                simd && std::strcmp(simd, "scalar") == 0 ? "scalar (TETHASH_SIMD)" : "avx2 if supported");
}

/// --sweep: ns per tet from 1,000 to 1,000,000 tets at one thread.
void report_sweep(const DetectParams& base, int repeat)
{
    std::printf("flatness sweep: copies of the scenario-5 object (551 tets) packed as in scenario 5, 1 thread\n");
    for (int tets : {1000, 3000, 10000, 30000, 100000, 300000, 1000000}) {
        const TetMesh m = bench::lattice_scene(std::max(2, (tets + 275) / 551), 7);
        DetectParams p = base;
        p.threads = 1;
        const Measured r = measure(m, p, std::max(3, repeat / (tets >= 300000 ? 4 : 1)));
        std::printf("  tets %8d  vertices %8d  %9.3f ms (cpu %.3f)  %6.1f ns/tet (cpu)  %6.1f B/tet  contacts %lld "
                    "(%.2f per tet)\n",
                    m.num_tets(), m.num_vertices(), r.ms, r.cpu_ms, 1e6 * r.cpu_ms / m.num_tets(),
                    double(r.stats.memory_bytes) / m.num_tets(), static_cast<long long>(r.stats.contacts),
                    double(r.stats.contacts) / m.num_tets());
        std::fflush(stdout);
    }
}

/// --profile N: one scenario (default 5) at --threads (default 1), N detections, no statistics.
void run_profile(const BenchOptions& o, const DetectParams& base)
{
    const study::Scenario sc = study::teschner_scenario(o.only > 0 ? o.only - 1 : 4);
    DetectParams p = base;
    p.threads = o.threads > 0 ? o.threads : 1;
    Detector det(p);
    det.set_topology(sc.mesh);
    det.detect(sc.mesh.positions);
    const std::size_t n = profile_detects(det, sc.mesh, o.profile);
    std::printf("profile: scenario %d, %d detections, %zu contacts in all\n", o.only > 0 ? o.only : 5, o.profile, n);
}

/// The default run: the five scenarios, the partition scenes and the shared meshes, each against the baseline and
/// the other methods asked for.
void report_scenes(const BenchOptions& o, const DetectParams& base, int threads_all,
                   const std::vector<std::string>& scene_names, const std::vector<Method>& methods)
{
    const bool baseline = !o.no_baseline;
    // The five scenarios exactly as `tethash study --teschner-scenarios` builds them (study/scenarios.hpp),
    // so that the benchmark and the study measure the same scenes.
    for (int k = 0; k < 5; ++k) {
        if (o.only > 0 && o.only != k + 1) continue;
        const study::Scenario sc = study::teschner_scenario(k);
        char name[96];
        std::snprintf(name, sizeof name, "scenario %d (%s r%d; paper %d/%d/%d)", k + 1, sc.shape.c_str(), sc.resolution,
                      sc.spec.objects, sc.spec.tets, sc.spec.vertices);
        report(name, sc.mesh, base, threads_all, o.repeat, baseline, o.table_factor, methods);
    }
    if (o.only >= 0) return;
    // Scenes unlike scenario 5 (study/scenarios.hpp: partition_scene): many objects each touching several at
    // V/T 0.5, and the scenes where the hash is at its worst.
    for (const std::string& n : scene_names) {
        const study::NamedScene ps = study::partition_scene(n);
        std::printf("%s: %s\n", n.c_str(), ps.description.c_str());
        DetectParams with_cells = base; // the scene's cells and portals, for --method portals
        with_cells.partition.cells = ps.cells;
        report(n.c_str(), ps.mesh, with_cells, threads_all, std::max(3, o.repeat / 3), baseline, o.table_factor,
               methods);
    }
    if (!o.no_meshes)
        for_each_shared_mesh_pair([&](const char* name, const TetMesh& two) {
            report(name, two, base, threads_all, std::max(3, o.repeat / 3), baseline, o.table_factor, methods);
        });
}

} // namespace

int main(int argc, char** argv)
{
    BenchOptions o;
    CLI::App app{"tethash_bench: ms per detection (median), ns per tet, stage split and contacts at 1 and all "
                 "threads for the five scenarios of Teschner et al. 2003 and ../shared/meshes, against a plain "
                 "implementation of the 2003 algorithm"};
    add_options(app, o);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }
    o.repeat = std::max(1, o.repeat);
    std::vector<Method> methods;
    std::vector<std::string> scene_names;
    try {
        if (!o.methods_text.empty()) methods = study::parse_method_list(o.methods_text, "--methods");
        scene_names = partition_scene_list(o.partition_scenes);
    } catch (const Error& e) {
        std::fprintf(stderr, "tethash_bench: error: %s\n", e.what());
        return 2;
    }
    o.steps = std::max(2, o.steps);
#ifdef _OPENMP
    const int threads_all = o.threads > 0 ? o.threads : omp_get_max_threads();
#else
    const int threads_all = 1;
#endif
    DetectParams base;
    base.cell_size_mode = DetectParams::CellSizeMode::factor_of_mean_edge;
    base.cell_size = o.cell_factor;
    base.hash = parse_hash_function(o.hash);
    base.partition.leaf_size = o.leaf_size;
    print_header(o, threads_all);

    if (o.sweep) {
        report_sweep(base, o.repeat);
    } else if (o.walk) {
        if (methods.empty())
            methods = {Method::hash, Method::uniform_grid, Method::sort_sweep, Method::bvh_refit, Method::portals};
        report_walk(methods, base, std::max(2, o.steps), o.walk_speed, o.rooms);
    } else if (o.edges) {
        for (int k = 0; k < 5; ++k) {
            if (o.only > 0 && o.only != k + 1) continue;
            const study::Scenario sc = study::teschner_scenario(k);
            const std::string name = "scenario " + std::to_string(k + 1);
            report_edges(name.c_str(), sc.mesh, base, threads_all, o.repeat);
        }
        if (!o.no_meshes && o.only < 0)
            for_each_shared_mesh_pair([&](const char* name, const TetMesh& two) {
                report_edges(name, two, base, threads_all, std::max(3, o.repeat / 3));
            });
    } else if (o.moving) {
        report_moving(study::teschner_scenario(o.only > 0 ? o.only - 1 : 4), base, threads_all, o.steps, o.speed);
    } else if (o.profile > 0) {
        run_profile(o, base);
    } else {
        report_scenes(o, base, threads_all, scene_names, methods);
    }
    return 0;
}
