// tethash_bench: ms per detection (median), ns per tet, stage split and contacts at 1 and all threads for the
// five scenarios of Teschner et al. 2003 rebuilt with io::generate (objects overlapping heavily), plus the
// meshes of ../shared/meshes; and, in the same run, a plain implementation of the 2003 algorithm (per-bucket
// vertex lists with timestamps, xor-prime hash mod a prime, plain barycentric test) as the baseline.
//
//   tethash_bench [--repeat K] [--threads N] [--scenario I] [--sweep] [--no-meshes] [--no-baseline] [--cell-factor F]
//                 [--hash column|teschner] [--table-factor F]
//   tethash_bench --moving [--scenario I] [--steps N] [--speed F] [--threads N]: a moving scene (candidate reuse)
#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/hash_grid.hpp"
#include "tethash/io/generate.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/study/scenarios.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
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

// ---- scenes ------------------------------------------------------------------------------------

/// The flatness sweep's scenes: `objects` copies of the scenario-5 object (io::generate "blob", resolution 6, as
/// study/scenarios.hpp chooses it) on a k × k × k lattice with centre spacing 0.6 × the object size, randomly
/// rotated: every object overlaps its lattice neighbours as in scenario 5, whatever the count.
TetMesh lattice_scene(int objects, std::uint32_t seed)
{
    io::GenerateParams g;
    g.shape = "blob";
    g.resolution = 6;
    TetMesh obj = io::generate(g);
    obj.vertex_object.clear();
    obj.tet_object.clear();
    obj.rest_positions.resize(0, 3);
    const Eigen::RowVector3d lo = obj.positions.colwise().minCoeff(), hi = obj.positions.colwise().maxCoeff();
    const double size = (hi - lo).maxCoeff();
    for (Eigen::Index v = 0; v < obj.positions.rows(); ++v)
        obj.positions.row(v) -= 0.5 * (lo + hi);
    int k = 1;
    while (k * k * k < objects)
        ++k;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    Positions p(static_cast<Eigen::Index>(objects) * obj.positions.rows(), 3);
    Tets t(static_cast<Eigen::Index>(objects) * obj.tets.rows(), 4);
    TetMesh scene;
    for (int o = 0; o < objects; ++o) {
        const Eigen::Matrix3d rot =
            Eigen::AngleAxisd(3.14159 * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized())
                .toRotationMatrix();
        const Eigen::RowVector3d c(0.6 * size * (o % k), 0.6 * size * ((o / k) % k), 0.6 * size * (o / (k * k)));
        const Eigen::Index vb = o * obj.positions.rows(), tb = o * obj.tets.rows();
        for (Eigen::Index v = 0; v < obj.positions.rows(); ++v)
            p.row(vb + v) = (rot * obj.positions.row(v).transpose()).transpose() + c;
        t.middleRows(tb, obj.tets.rows()) = (obj.tets.array() + static_cast<Index>(vb)).matrix();
        scene.vertex_object.insert(scene.vertex_object.end(), obj.positions.rows(), o);
        scene.tet_object.insert(scene.tet_object.end(), obj.tets.rows(), o);
    }
    scene.positions = std::move(p);
    scene.tets = std::move(t);
    return scene;
}

// ---- the plain 2003 baseline -------------------------------------------------------------------------

/// Teschner et al. 2003 as written: hash table of per-bucket vertex lists, stamped with the step instead of
/// cleared; each tet looks up every cell its box touches (xor-prime hash mod a prime), checks box and own
/// vertices, and computes barycentric coordinates in double (no exactness). Pairs found through several
/// cells sharing a bucket are filtered by comparing the vertex's cell with the visited cell.
class Baseline {
  public:
    void run(const TetMesh& m, double l, std::vector<std::pair<Index, Index>>& out)
    {
        const Index n = m.num_vertices();
        if (m_table == 0) {
            m_table = static_cast<std::size_t>(next_prime(2 * n));
            m_buckets.assign(m_table, {});
            m_stamp.assign(m_table, 0);
        }
        ++m_step;
        m_cell.resize(3 * static_cast<std::size_t>(n));
        const double inv = 1.0 / l;
        for (Index v = 0; v < n; ++v) {
            const std::int32_t c[3] = {static_cast<std::int32_t>(std::floor(m.positions(v, 0) * inv)),
                                       static_cast<std::int32_t>(std::floor(m.positions(v, 1) * inv)),
                                       static_cast<std::int32_t>(std::floor(m.positions(v, 2) * inv))};
            for (int k = 0; k < 3; ++k)
                m_cell[3 * v + k] = c[k];
            const std::size_t b = teschner_hash(c[0], c[1], c[2]) % m_table;
            if (m_stamp[b] != m_step) {
                m_stamp[b] = m_step;
                m_buckets[b].clear();
            }
            m_buckets[b].push_back(v);
        }
        out.clear();
        for (Index t = 0; t < m.num_tets(); ++t) {
            const Index id[4] = {m.tets(t, 0), m.tets(t, 1), m.tets(t, 2), m.tets(t, 3)};
            Eigen::Vector3d p[4];
            for (int k = 0; k < 4; ++k)
                p[k] = m.positions.row(id[k]).transpose();
            const Eigen::Vector3d lo = p[0].cwiseMin(p[1]).cwiseMin(p[2]).cwiseMin(p[3]);
            const Eigen::Vector3d hi = p[0].cwiseMax(p[1]).cwiseMax(p[2]).cwiseMax(p[3]);
            const Eigen::Vector3d e1 = p[1] - p[0], e2 = p[2] - p[0], e3 = p[3] - p[0];
            const double vol = e1.dot(e2.cross(e3));
            if (vol == 0) continue;
            std::int32_t c0[3], c1[3];
            for (int k = 0; k < 3; ++k) {
                c0[k] = static_cast<std::int32_t>(std::floor(lo[k] * inv));
                c1[k] = static_cast<std::int32_t>(std::floor(hi[k] * inv));
            }
            for (std::int32_t x = c0[0]; x <= c1[0]; ++x)
                for (std::int32_t y = c0[1]; y <= c1[1]; ++y)
                    for (std::int32_t z = c0[2]; z <= c1[2]; ++z) {
                        const std::size_t b = teschner_hash(x, y, z) % m_table;
                        if (m_stamp[b] != m_step) continue;
                        for (Index v : m_buckets[b]) {
                            if (v == id[0] || v == id[1] || v == id[2] || v == id[3]) continue;
                            if (m_cell[3 * v] != x || m_cell[3 * v + 1] != y || m_cell[3 * v + 2] != z) continue;
                            const Eigen::Vector3d q = m.positions.row(v).transpose();
                            if ((q.array() < lo.array()).any() || (q.array() > hi.array()).any()) continue;
                            const Eigen::Vector3d d = q - p[0];
                            const double b1 = d.dot(e2.cross(e3)) / vol, b2 = e1.dot(d.cross(e3)) / vol,
                                         b3 = e1.dot(e2.cross(d)) / vol;
                            if (b1 >= 0 && b2 >= 0 && b3 >= 0 && b1 + b2 + b3 <= 1) out.emplace_back(v, t);
                        }
                    }
        }
    }

  private:
    std::size_t m_table = 0;
    std::vector<std::vector<Index>> m_buckets;
    std::vector<std::uint32_t> m_stamp;
    std::uint32_t m_step = 0;
    std::vector<std::int32_t> m_cell;
};

// ---- measuring -------------------------------------------------------------------------------------

struct Measured {
    double ms = 0;
    double cpu_ms = 0;         ///< CPU time of the calling thread (meaningful at 1 thread)
    double process_cpu_ms = 0; ///< CPU time of all threads (includes OpenMP spin-waiting)
    DetectStats stats;
};

Measured measure(const TetMesh& m, DetectParams p, int repeat)
{
    Detector det(p);
    det.set_topology(m);
    DetectStats st;
    det.detect(m.positions); // warm-up (auto cell size, buffers)
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
    return {median(ms), median(cpu), median(pcpu), st};
}

double measure_baseline(const TetMesh& m, double l, int repeat, std::size_t& contacts, double& cpu_ms)
{
    Baseline b;
    std::vector<std::pair<Index, Index>> out;
    b.run(m, l, out);
    std::vector<double> ms, cpu;
    for (int r = 0; r < repeat; ++r) {
        const double c0 = thread_cpu_ms();
        const auto t0 = Clock::now();
        b.run(m, l, out);
        ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
        cpu.push_back(thread_cpu_ms() - c0);
    }
    contacts = out.size();
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

double g_table_factor = 0; ///< --table-factor F (0: automatic table size)

void report(const char* name, const TetMesh& m, const DetectParams& base, int threads_all, int repeat, bool baseline)
{
    DetectParams p1 = base;
    if (g_table_factor > 0) { // --table-factor: the power of two nearest to F × vertices
        const double want = g_table_factor * m.num_vertices();
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
    std::printf("  cell %.4g  table %lld  cells %lld  scanned %lld  collisions %lld  box-rejected %lld  own %lld  "
                "inside tests %lld  exact %lld  degenerate %lld  memory %.1f B/tet\n",
                s.cell_size, static_cast<long long>(s.table_size), static_cast<long long>(s.cells_visited),
                static_cast<long long>(s.entries_scanned), static_cast<long long>(s.hash_collisions),
                static_cast<long long>(s.box_rejections), static_cast<long long>(s.own_vertex_skips),
                static_cast<long long>(s.inside_tests), static_cast<long long>(s.exact_fallbacks),
                static_cast<long long>(s.degenerate_tets), double(s.memory_bytes) / std::max(1, m.num_tets()));
    if (all.stats.contacts != one.stats.contacts) std::printf("  ERROR: contact counts differ between thread counts\n");
    if (baseline) {
        std::size_t bc = 0;
        double bcpu = 0;
        const double bms = measure_baseline(m, s.cell_size, std::max(3, repeat / 3), bc, bcpu);
        std::printf("  baseline 2003  %8.3f ms (1 thread, cpu %.3f ms, %zu contacts)   ratio: %.1fx at 1 thread "
                    "(cpu %.1fx), %.1fx at %d threads\n",
                    bms, bcpu, bc, bms / one.ms, bcpu / one.cpu_ms, bms / all.ms, all.stats.threads);
    }
    std::fflush(stdout);
}

// ---- moving scenes (candidate reuse with a skin) --------------------------------------------------

/// The objects of `m` moving rigidly, each by its own small rotation about its centroid and translation per step
/// (random axis and direction per object; the fastest vertex moves about `speed` × mean edge per step), plus a
/// random perturbation of both per step (a quarter of that); the translations reverse every 40 steps, so objects
/// move apart and together again.
class MovingScene {
  public:
    MovingScene(const TetMesh& m, double mean_edge, double speed, std::uint32_t seed)
        : m_mesh(m), m_positions(m.positions), m_rng(seed), m_step_length(speed * mean_edge)
    {
        const int objects = m.num_objects();
        m_members.assign(static_cast<std::size_t>(objects), {});
        for (Eigen::Index v = 0; v < m.positions.rows(); ++v)
            m_members[static_cast<std::size_t>(m.vertex_object[static_cast<std::size_t>(v)])].push_back(
                static_cast<Index>(v));
        std::normal_distribution<double> g;
        for (int o = 0; o < objects; ++o) {
            Eigen::Vector3d dir(g(m_rng), g(m_rng), g(m_rng)), axis(g(m_rng), g(m_rng), g(m_rng));
            m_velocity.push_back(0.5 * m_step_length * dir.normalized());
            m_axis.push_back(axis.normalized());
            double radius = 1e-12;
            const Eigen::RowVector3d c = centroid(o);
            for (Index v : m_members[static_cast<std::size_t>(o)])
                radius = std::max(radius, (m_positions.row(v) - c).norm());
            m_omega.push_back(0.5 * m_step_length / radius); // rim speed: half a step length
        }
    }
    const Positions& positions() const { return m_positions; }
    void step()
    {
        ++m_step;
        std::normal_distribution<double> g;
        const double sign = (m_step / 40) % 2 ? -1.0 : 1.0;
        for (std::size_t o = 0; o < m_members.size(); ++o) {
            const Eigen::RowVector3d c = centroid(static_cast<int>(o));
            const Eigen::Vector3d jitter_axis = Eigen::Vector3d(g(m_rng), g(m_rng), g(m_rng)).normalized();
            const Eigen::Matrix3d R = (Eigen::AngleAxisd(m_omega[o], m_axis[o]) *
                                       Eigen::AngleAxisd(0.25 * m_omega[o] * g(m_rng), jitter_axis))
                                          .toRotationMatrix();
            const Eigen::Vector3d shift =
                sign * m_velocity[o] +
                0.25 * 0.5 * m_step_length * Eigen::Vector3d(g(m_rng), g(m_rng), g(m_rng)).normalized();
            for (Index v : m_members[o]) {
                const Eigen::Vector3d p = (m_positions.row(v) - c).transpose();
                m_positions.row(v) = (R * p + c.transpose() + shift).transpose();
            }
        }
    }

  private:
    Eigen::RowVector3d centroid(int o) const
    {
        Eigen::RowVector3d c = Eigen::RowVector3d::Zero();
        for (Index v : m_members[static_cast<std::size_t>(o)])
            c += m_positions.row(v);
        return c / std::max<double>(1.0, static_cast<double>(m_members[static_cast<std::size_t>(o)].size()));
    }
    const TetMesh& m_mesh;
    Positions m_positions;
    std::mt19937 m_rng;
    double m_step_length;
    int m_step = 0;
    std::vector<std::vector<Index>> m_members;
    std::vector<Eigen::Vector3d> m_velocity, m_axis;
    std::vector<double> m_omega;
};

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
            MovingScene scene(m, edge, speed, 11);
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
        MovingScene scene(m, edge, speed, 11);
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

} // namespace

int main(int argc, char** argv)
{
    int repeat = 21, threads = 0, only = -1, profile = 0, steps = 100;
    bool sweep = false, meshes = true, baseline = true, moving = false;
    double speed = 0.01;
    double cell_factor = 1.0;
    std::string hash = "column";
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "tethash_bench: %s needs a value\n", a.c_str());
                std::exit(2);
            }
            return argv[++i];
        };
        if (a == "--repeat")
            repeat = std::max(1, std::stoi(next()));
        else if (a == "--threads")
            threads = std::stoi(next());
        else if (a == "--scenario")
            only = std::stoi(next());
        else if (a == "--sweep")
            sweep = true;
        else if (a == "--no-meshes")
            meshes = false;
        else if (a == "--no-baseline")
            baseline = false;
        else if (a == "--profile")
            profile = std::stoi(next());
        else if (a == "--table-factor")
            g_table_factor = std::stod(next());
        else if (a == "--cell-factor")
            cell_factor = std::stod(next());
        else if (a == "--hash")
            hash = next();
        else if (a == "--moving")
            moving = true;
        else if (a == "--steps")
            steps = std::max(2, std::stoi(next()));
        else if (a == "--speed")
            speed = std::stod(next());
        else {
            std::fprintf(stderr,
                         "usage: tethash_bench [--repeat K] [--threads N] [--scenario 1..5] [--sweep] [--no-meshes] "
                         "[--no-baseline] [--profile N] [--table-factor F] [--cell-factor F] [--hash column|teschner]\n"
                         "       tethash_bench --moving [--scenario 1..5] [--steps N] [--speed F] [--threads N]\n");
            return 2;
        }
    }
#ifdef _OPENMP
    const int threads_all = threads > 0 ? threads : omp_get_max_threads();
#else
    const int threads_all = 1;
#endif
    DetectParams base;
    base.cell_size_mode = DetectParams::CellSizeMode::factor_of_mean_edge;
    base.cell_size = cell_factor;
    base.hash = parse_hash_function(hash);
    std::printf("tethash_bench: %s, flags '%s', %d hardware threads, repeat %d (median), cell %.3g x mean edge, "
                "table auto, hash %s\n",
                TETHASH_BENCH_COMPILER, TETHASH_BENCH_FLAGS, threads_all, repeat, cell_factor, hash.c_str());
    {
        std::ifstream cpu("/proc/cpuinfo");
        std::string line;
        while (std::getline(cpu, line))
            if (line.rfind("model name", 0) == 0) {
                std::printf("machine: %s\n", line.substr(line.find(':') + 2).c_str());
                break;
            }
    }
    const char* simd = std::getenv("TETHASH_SIMD");
    std::printf("scan kernel: %s\n\n",
                simd && std::strcmp(simd, "scalar") == 0 ? "scalar (TETHASH_SIMD)" : "avx2 if supported");

    if (sweep) {
        std::printf("flatness sweep: copies of the scenario-5 object (551 tets) packed as in scenario 5, 1 thread\n");
        for (int tets : {1000, 3000, 10000, 30000, 100000, 300000, 1000000}) {
            const TetMesh m = lattice_scene(std::max(2, (tets + 275) / 551), 7);
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
        return 0;
    }

    if (moving) {
        report_moving(study::teschner_scenario(only > 0 ? only - 1 : 4), base, threads_all, steps, speed);
        return 0;
    }

    if (profile > 0) { // one scenario (default 5) at --threads (default 1), N detections, no statistics
        const study::Scenario sc = study::teschner_scenario(only > 0 ? only - 1 : 4);
        DetectParams p = base;
        p.threads = threads > 0 ? threads : 1;
        Detector det(p);
        det.set_topology(sc.mesh);
        det.detect(sc.mesh.positions);
        const std::size_t n = profile_detects(det, sc.mesh, profile);
        std::printf("profile: scenario %d, %d detections, %zu contacts in all\n", only > 0 ? only : 5, profile, n);
        return 0;
    }
    // The five scenarios exactly as `tethash study --teschner-scenarios` builds them (study/scenarios.hpp),
    // so that the benchmark and the study measure the same scenes.
    for (int k = 0; k < 5; ++k) {
        if (only > 0 && only != k + 1) continue;
        const study::Scenario sc = study::teschner_scenario(k);
        char name[96];
        std::snprintf(name, sizeof name, "scenario %d (%s r%d; paper %d/%d/%d)", k + 1, sc.shape.c_str(), sc.resolution,
                      sc.spec.objects, sc.spec.tets, sc.spec.vertices);
        report(name, sc.mesh, base, threads_all, repeat, baseline);
    }
    if (meshes && only < 0) {
        const std::filesystem::path dir = TETHASH_SHARED_MESHES;
        if (std::filesystem::exists(dir)) {
            std::vector<std::filesystem::path> files;
            for (const auto& e : std::filesystem::directory_iterator(dir))
                files.push_back(e.path());
            std::sort(files.begin(), files.end());
            for (const auto& f : files) {
                if (!io::is_tet_mesh_path(f.string()) || f.extension() == ".node") continue;
                try {
                    TetMesh one = io::read_mesh(f.string());
                    // Two copies, the second shifted by a fraction of the size: overlapping objects.
                    const Eigen::RowVector3d lo = one.positions.colwise().minCoeff(),
                                             hi = one.positions.colwise().maxCoeff();
                    one.vertex_object.clear();
                    one.tet_object.clear();
                    one.ensure_object_ids();
                    TetMesh two = one;
                    two.positions.rowwise() += 0.2 * (hi - lo);
                    one.append(two);
                    report(f.filename().string().c_str(), one, base, threads_all, std::max(3, repeat / 3), baseline);
                } catch (const std::exception& e) {
                    std::printf("%-28s skipped: %s\n", f.filename().string().c_str(), e.what());
                }
            }
        }
    }
    return 0;
}
