// tethash_sim_bench: the simulator on the meshes people load. Drops every mesh of ../shared/meshes (scaled to
// 1 m, 0.2 m above the ground, density 1000, young 1e5) and throws two armadillo_4k into each other at 2 m/s (--throw),
// for each integrator and time step asked; prints per scene the median ms per step split into detection / depth /
// response / integration, solver iterations, contacts, inverted tets, far self-penetrations and vertices inside
// another object (each at the end and the most at any frame of 1/60 s), the steps taken again (with tighter tolerances
// for energy they gained, in more substeps for a far part entered unseen), and the measure of Teschner et al. 2004:
// largest stable dt (of those run) divided by the cost per step. When built with Bullet (libbullet-dev found), each
// scene and dt also runs with Bullet's soft bodies in the same process (rows "bullet"), so the ratio to the peer comes
// from one run. With --bodies, generated spheres of about that many tets instead, each at one thread and at --threads:
// ms per step, ns per tet, bytes per tet and the speed-up of the threads (how the step scales from 10 k to 1 M tets).
#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/meshing/generate.hpp"
#include "tethash/sim/quality.hpp"
#include "tethash/sim/simulation.hpp"

#ifdef TETHASH_HAVE_BULLET
#include "bullet_peer.hpp"
#endif

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <malloc.h>
#include <map>
#include <thread>

using namespace tethash;

namespace {

struct Row {
    std::string scene, integrator;
    double dt = 0;
    Index vertices = 0, tets = 0;
    double ms = 0, detect = 0, depth = 0, proximity = 0, response = 0, integrate = 0, sweeps = 0, contacts = 0;
    double other = 0;         ///< median over the steps of the step less its stages: checks, copies of retaken steps
    double threads = 1;       ///< mean threads per step (--threads 0: chosen step by step)
    double bytes_per_tet = 0; ///< resident memory the run added (set-up, state, detector), per tet
    double ms_mean = 0;       ///< mean ms per step: the cost that counts where some steps were refined
    /// Processor time of the process per step (ms; median, mean): at one thread the step's own work, which the time
    /// slices other processes take on a loaded machine leave out (the wall-clock `ms` counts them).
    double cpu_ms = 0, cpu_ms_mean = 0;
    double sweeps_mean = 0; ///< mean solver iterations per step (the landing's steps need more than the fall's)
    double setup_ms = 0;    ///< constructing the simulation (processor time, ms), apart from the steps
    int threads_asked = 1;  ///< the run's --threads (the --bodies table pairs one thread with more)
    double substeps = 1;    ///< mean substeps per step (more than the scene's where steps were refined)
    std::int64_t inverted = 0, far_self = 0;
    std::int64_t unconverged = 0;       ///< substeps whose sweeps reached their cap
    std::int64_t retaken = 0;           ///< steps taken again with tighter tolerances for energy they gained
    std::int64_t crossed = 0;           ///< steps taken again in more substeps for a far part entered unseen
    std::int64_t far_self_max = 0;      ///< most far self-penetrations at any frame (every 1/60 s), not only the end
    std::int64_t inside = 0;            ///< vertices inside a tet of another object at the end
    std::int64_t inside_max = 0;        ///< the most at any frame (every 1/60 s)
    std::int64_t unresolved = 0;        ///< steps whose continuous check left an impact past its retakes
    std::int64_t edge_contacts_max = 0; ///< most edge contacts (contact.edges) at any step (CSV only)
    double mean_z = 0;                  ///< mean height of the vertices at the end (how far the body sagged or sank)
    double energy_ratio = 0;            ///< total energy at the end / at the start (a passive drop must stay ≤ 1)
    double volume_ratio = 0;            ///< volume of the dynamic tets at the end / at the start
    bool stable = false;
    std::string failure;
};

double mean(const std::vector<double>& v)
{
    double sum = 0;
    for (double x : v)
        sum += x;
    return v.empty() ? 0 : sum / static_cast<double>(v.size());
}

double median(std::vector<double> v)
{
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

/// The mesh scaled to `size` (its longest extent, m), centred over the origin, its lowest point `lift` × size above
/// the ground.
sim::ObjectSpec placed(const TetMesh& mesh, double lift, double size)
{
    const auto [lo, hi] = bounding_box(mesh.positions);
    sim::ObjectSpec o;
    const double s = size / (hi - lo).maxCoeff();
    o.scale = Eigen::Vector3d::Constant(s);
    o.translate = Eigen::Vector3d(-s * 0.5 * (lo.x() + hi.x()), -s * 0.5 * (lo.y() + hi.y()), lift * size - s * lo.z());
    o.data = mesh;
    o.material.density = 1000;
    o.material.young = 1e5;
    return o;
}

/// Processor time the process has used (ms): every thread's, so at one thread the work of the step alone, whatever
/// else the machine runs.
double process_cpu_ms()
{
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

/// Resident memory of the process (bytes), after giving freed memory back.
double resident_bytes()
{
    malloc_trim(0);
    std::ifstream statm("/proc/self/statm");
    double pages = 0, resident = 0;
    statm >> pages >> resident;
    return resident * 4096.0;
}

/// `cpu_time`: a step's ms are its processor time (--cpu-time, one thread), else the wall clock's.
Row run(const std::string& name, const sim::Scene& scene, int steps, bool cpu_time)
{
    Row r;
    r.scene = name;
    r.integrator = sim::to_string(scene.integrator);
    r.dt = scene.dt;
    r.threads_asked = scene.detect.threads;
    const double rss0 = resident_bytes();
    const double setup0 = process_cpu_ms();
    sim::Simulation s(scene);
    r.setup_ms = process_cpu_ms() - setup0;
    r.vertices = s.mesh().num_vertices();
    r.tets = s.mesh().num_tets();
    const Positions start = s.positions();
    sim::FarSelfPenetrations far(s.mesh(), start);
    sim::InsideOtherObjects inside(s.mesh());
    const double energy0 = s.energy().total(), volume0 = sim::total_volume(s.model(), start);
    std::vector<double> ms, cpu, det, dep, prox, resp, integ, other, threads, sw, con, sub;
    // Frames as a viewer would see them: every 1/60 s (every step at larger steps), counted outside the timing.
    const int frame_every = std::max(1, static_cast<int>(std::lround(1.0 / (60.0 * scene.dt))));
    try {
        for (int i = 0; i < steps; ++i) {
            const double cpu0 = process_cpu_ms();
            const auto t0 = std::chrono::steady_clock::now();
            s.step();
            cpu.push_back(process_cpu_ms() - cpu0);
            ms.push_back(
                cpu_time ? cpu.back()
                         : std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            if ((i + 1) % frame_every == 0) {
                r.far_self_max = std::max(r.far_self_max, far.count(s.positions()));
                r.inside_max = std::max(r.inside_max, inside.count(s.positions()));
            }
            const sim::StepStats& st = s.last_stats();
            det.push_back(st.ms_detect);
            dep.push_back(st.ms_depth);
            prox.push_back(st.ms_proximity);
            resp.push_back(st.ms_response);
            integ.push_back(st.ms_integrate);
            other.push_back(st.ms_checks());
            threads.push_back(st.threads);
            sw.push_back(st.solver_iterations);
            con.push_back(static_cast<double>(st.contacts));
            sub.push_back(st.substeps);
            r.unconverged += st.unconverged;
            if (st.tightened > 0) ++r.retaken;
            if (st.crossings > 0) ++r.crossed;
            if (st.continuous_unresolved > 0) ++r.unresolved;
            r.edge_contacts_max = std::max(r.edge_contacts_max, st.edge_contacts);
        }
    } catch (const RunFailure& e) {
        r.failure = e.what();
        r.failure = r.failure.substr(0, r.failure.find(':'));
    }
    r.ms = median(ms);
    r.detect = median(det);
    r.depth = median(dep);
    r.proximity = median(prox);
    r.response = median(resp);
    r.integrate = median(integ);
    r.other = median(other);
    r.threads = mean(threads);
    r.sweeps = median(sw);
    r.ms_mean = mean(ms);
    r.cpu_ms = median(cpu);
    r.cpu_ms_mean = mean(cpu);
    r.sweeps_mean = mean(sw);
    r.substeps = sub.empty() ? 1 : mean(sub);
    r.contacts = mean(con);
    r.inverted = sim::count_inverted(s.mesh(), start);
    r.far_self = far.count(s.positions());
    r.far_self_max = std::max(r.far_self_max, r.far_self);
    r.inside = inside.count(s.positions());
    r.inside_max = std::max(r.inside_max, r.inside);
    r.mean_z = s.mesh().positions.col(2).mean();
    r.energy_ratio = s.energy().total() / energy0;
    r.volume_ratio = sim::total_volume(s.model(), s.positions()) / volume0;
    r.stable = r.failure.empty() && r.inverted <= r.tets / 100;
    r.bytes_per_tet = std::max(0.0, resident_bytes() - rss0) / static_cast<double>(std::max<Index>(1, r.tets));
    return r;
}

#ifdef TETHASH_HAVE_BULLET
/// The same scene with Bullet's soft bodies: each object placed as tethash places it, same density, velocity,
/// dt and duration; inverted tets and far self-penetrations measured on its end state the same way.
Row run_peer(const std::string& name, const sim::Scene& scene, int steps, int iterations, bool cpu_time)
{
    Row r;
    r.scene = name;
    r.integrator = "bullet";
    r.dt = scene.dt;
    std::vector<TetMesh> placed_meshes;
    for (const sim::ObjectSpec& o : scene.objects) {
        TetMesh m = *o.data;
        for (Index i = 0; i < m.num_vertices(); ++i)
            m.positions.row(i) = (o.scale.cwiseProduct(m.positions.row(i).transpose()) + o.translate).transpose();
        placed_meshes.push_back(std::move(m));
    }
    std::vector<bench::PeerBody> bodies;
    for (size_t k = 0; k < placed_meshes.size(); ++k)
        bodies.push_back({&placed_meshes[k], scene.objects[k].material.density, scene.objects[k].velocity});
    const bench::PeerResult p = bench::run_bullet(bodies, scene.dt, steps, iterations);
    const std::vector<double>& ms = cpu_time ? p.cpu_ms : p.ms;
    r.ms = median(ms);
    r.ms_mean = mean(ms);
    r.integrate = r.ms;
    r.sweeps = iterations;
    r.failure = p.failure;
    for (size_t k = 0; k < placed_meshes.size(); ++k) {
        TetMesh end = placed_meshes[k];
        end.positions = p.final[k];
        r.vertices += end.num_vertices();
        r.tets += end.num_tets();
        r.inverted += sim::count_inverted(end, placed_meshes[k].positions);
        r.far_self += sim::count_far_self_penetrations(end, placed_meshes[k].positions);
        r.mean_z += end.positions.col(2).sum();
    }
    r.mean_z /= static_cast<double>(std::max<Index>(1, r.vertices));
    r.far_self_max = r.far_self; // the peer's frames are not looked at: its end state only
    r.stable = r.failure.empty() && r.inverted <= r.tets / 100;
    return r;
}
#endif

void print(const Row& r)
{
    std::printf(
        "%-36s %-16s %8.5f %7d %7d %8.2f %7.2f %7.2f %7.2f %7.2f %7.2f %7.2f %7.2f %4.2g %6.1f %5.2f %8.1f %7lld %5lld "
        "%5lld %5lld %5lld %8.4g %7.3g %6.3f %6lld %7lld %7lld %5lld %10.3g  %s\n",
        r.scene.c_str(), r.integrator.c_str(), r.dt, r.vertices, r.tets, r.ms, r.ms_mean, r.detect, r.depth,
        r.proximity, r.response, r.integrate, r.other, r.threads, r.sweeps, r.substeps, r.contacts,
        static_cast<long long>(r.inverted), static_cast<long long>(r.far_self), static_cast<long long>(r.far_self_max),
        static_cast<long long>(r.inside), static_cast<long long>(r.inside_max), r.mean_z, r.energy_ratio,
        r.volume_ratio, static_cast<long long>(r.unconverged), static_cast<long long>(r.retaken),
        static_cast<long long>(r.crossed), static_cast<long long>(r.unresolved), r.stable ? r.dt / r.ms_mean : 0.0,
        r.failure.c_str());
    std::fflush(stdout);
}

double parse_dt(const std::string& v)
{
    const auto slash = v.find('/');
    try {
        if (slash != std::string::npos) return std::stod(v.substr(0, slash)) / std::stod(v.substr(slash + 1));
        return std::stod(v);
    } catch (const std::exception&) {
        throw Error("--dt: '" + v + "' is not a time step (seconds, or a fraction such as 1/240)");
    }
}

/// The benchmark's options (tethash_sim_bench --help).
struct SimBenchOptions {
    std::string meshes_dir = TETHASH_SHARED_MESHES, filter, csv;
    std::vector<std::string> integrators{"vbd"}, dts{"1/240"};
    std::vector<double> sizes{1.0}, youngs, bodies;
    double seconds = 0; ///< 0: automatic (run_seconds)
    int threads = 1, rounds = 1, peer_iterations = 10, iterations = 0, max_substeps = 0, max_iterations = 0;
    double convergence = -1;
    bool no_coarse = false;
    double skin = -1, sweep_tolerance = -1, rho = -1, margin = -1;
    bool no_speculative = false, inversion_guard = false;
    std::string crossing_check, continuous_check, contact_edges;
    bool no_peer = false;
    bool cpu_time = false;
    double throw_speed = 2; ///< m/s at which the two armadillos close on each other
};

void add_options(CLI::App& app, SimBenchOptions& o)
{
    // Three sections in --help: what runs, what each scene is made to do differently, and the peer.
    CLI::Option_group* runs = app.add_option_group("Runs");
    runs->add_option("--meshes", o.meshes_dir, "folder of the shared meshes")->capture_default_str();
    runs->add_option("--scenes", o.filter, "only scenes whose name contains this");
    runs->add_option("--integrator", o.integrators, "integrators (vbd, implicit_euler, symplectic_euler)")
        ->delimiter(',');
    runs->add_option("--dt", o.dts, "time steps (seconds or fractions like 1/240), comma-separated")->delimiter(',');
    runs->add_option("--size", o.sizes,
                     "body sizes (longest extent, m), comma-separated; drops start 0.2 sizes above the ground, the "
                     "two armadillos 1.4 sizes apart")
        ->delimiter(',')
        ->check(CLI::PositiveNumber);
    runs->add_option("--young", o.youngs,
                     "Young's moduli (Pa), comma-separated; each scene runs at each (default: the scenes' 1e5)")
        ->delimiter(',')
        ->check(CLI::PositiveNumber);
    runs->add_option("--seconds", o.seconds,
                     "simulated time per run (default: 0.5 s, or 2.5 times the fall for a drop whose fall takes more "
                     "than 0.25 s, so that large bodies land and settle: 1.1 s at 5 m, 1.6 s at 10 m)");
    runs->add_option("--threads", o.threads,
                     "detector and solver threads; 0: every core, fewer in the steps where they do not pay (chosen "
                     "as the run goes, as `tethash simulate` does)")
        ->capture_default_str();
    runs->add_option("--rounds", o.rounds,
                     "run each scene this many times; with --bodies one thread and --threads alternate, and the "
                     "table gives the medians over the rounds and the median of the rounds' speed-ups (interleaved "
                     "rounds for a loaded machine)")
        ->check(CLI::Range(1, 100))
        ->capture_default_str();
    runs->add_option("--throw", o.throw_speed,
                     "speed (m/s) at which the two armadillos close on each other (each moves at half of it)")
        ->capture_default_str();
    runs->add_option("--csv", o.csv, "write the rows as CSV to this file");
    runs->add_flag("--cpu-time", o.cpu_time,
                   "a step's ms (ms/step, mean) are its processor time, not the wall clock's (on a machine shared "
                   "with other work; one thread only, the stages stay wall-clock), the peer's too");
    runs->add_option("--bodies", o.bodies,
                     "instead of the shared meshes: generated spheres of about these many tets (comma-separated, "
                     "e.g. 1e4,1e5,1e6; 1 m, dropped 0.2 m), each at one thread and at --threads, with a table of "
                     "ms per step, ns per tet, bytes per tet and the threads' speed-up")
        ->delimiter(',')
        ->check(CLI::Range(1e3, 2e7));
    CLI::Option_group* overrides = app.add_option_group("Scene overrides", "each defaults to the scene's own value");
    overrides->add_option("--iterations", o.iterations, "solver iterations (sweeps) per step; 0 = the scene default");
    overrides->add_option("--max-substeps", o.max_substeps,
                          "refine a step that inverts tets or blows up into up to this many substeps; 1 = never; "
                          "0 = the scene default");
    overrides->add_option("--convergence", o.convergence, "vbd automatic sweeps: relative tolerance in [0, 1)");
    overrides->add_option("--max-iterations", o.max_iterations, "vbd automatic sweeps: the cap per substep");
    overrides->add_flag("--no-coarse", o.no_coarse, "vbd: sweeps alone, without the coarse space's corrections");
    overrides->add_option("--sweep-tolerance", o.sweep_tolerance, "vbd early stop (fraction of the mean edge)");
    overrides->add_option("--acceleration", o.rho, "vbd Chebyshev acceleration ρ in [0, 1)");
    overrides->add_option("--skin", o.skin, "detector candidate reuse, as a factor of the cell size");
    overrides->add_option("--margin", o.margin, "contact margin, as a fraction of the mean edge (0: off)")
        ->check(CLI::NonNegativeNumber);
    overrides->add_flag("--no-speculative", o.no_speculative, "no speculative contacts (proximity.hpp)");
    overrides->add_flag("--inversion-guard", o.inversion_guard, "vbd: keep tets the right way out (inversion_guard)");
    overrides
        ->add_option("--crossing-check", o.crossing_check,
                     "on or off: retake a step in more substeps where a far part was entered unseen (crossing_check)")
        ->check(CLI::IsMember({"on", "off"}));
    overrides
        ->add_option("--continuous-check", o.continuous_check,
                     "on or off: also sweep each substep by continuous detection and retake a step where a far pair "
                     "met unseen (continuous_check)")
        ->check(CLI::IsMember({"on", "off"}));
    overrides
        ->add_option("--contact-edges", o.contact_edges,
                     "on or off: push boundary edges out of the far boundary faces they pass through (contact.edges)")
        ->check(CLI::IsMember({"on", "off"}));
    CLI::Option_group* peer = app.add_option_group("Peer", "Bullet's soft bodies, when built with libbullet-dev");
    peer->add_flag("--no-peer", o.no_peer, "do not run the peer even when built with it");
    peer->add_option("--peer-iterations", o.peer_iterations, "the peer's position iterations")->capture_default_str();
}

/// What the run measures on: compiler, flags, threads, the machine's load, the peer.
void print_header(SimBenchOptions& o)
{
    double load[3] = {0, 0, 0};
    if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
        if (std::fscanf(f, "%lf %lf %lf", &load[0], &load[1], &load[2]) != 3) load[0] = -1;
        std::fclose(f);
    }
    std::printf("tethash_sim_bench: %s, flags '%s', %u hardware threads, %d thread(s), load %.2f %.2f %.2f\n",
                TETHASH_BENCH_COMPILER, TETHASH_BENCH_FLAGS, std::thread::hardware_concurrency(), o.threads, load[0],
                load[1], load[2]);
    std::printf("%s simulated per run; ms are medians over the steps%s\n",
                o.seconds > 0 ? fmt::format("{} s", o.seconds).c_str()
                              : "0.5 s (2.5 times the fall where it takes more than 0.25 s)",
                o.cpu_time ? " (ms/step and mean: processor time, --cpu-time)" : "");
#ifdef TETHASH_HAVE_BULLET
    std::printf("peer: Bullet %d.%02d soft bodies, %d position iterations, links on the tet edges%s\n",
                bench::bullet_version() / 100, bench::bullet_version() % 100, o.peer_iterations,
                o.no_peer ? " (off: --no-peer)" : "");
#else
    std::printf("peer: Bullet not found at build time (install libbullet-dev and rebuild to compare)\n");
    o.no_peer = true;
#endif
}

/// The scenes: each shared mesh dropped at each size and modulus, and the two armadillos thrown at each other.
/// Simulated time of a run: --seconds, or 0.5 s, or for a drop whose fall to the ground takes longer than 0.25 s
/// (bodies above about 1.5 m) 2.5 times the fall, so that it lands and settles (a 10 m body falls 2 m, 0.64 s).
double run_seconds(const SimBenchOptions& o, const sim::Scene& scene)
{
    if (o.seconds > 0) return o.seconds;
    double low = INFINITY;
    for (const sim::ObjectSpec& obj : scene.objects)
        if (obj.data && obj.data->num_vertices() > 0)
            low = std::min(low, obj.translate.z() + obj.scale.z() * obj.data->positions.col(2).minCoeff());
    const double g = scene.gravity.norm();
    if (!std::isfinite(low) || !(low > 0) || !(g > 0)) return 0.5;
    const double fall = std::sqrt(2 * low / g);
    return fall > 0.25 ? 2.5 * fall : 0.5;
}

/// --bodies: a sphere of about `tets` tets (the lattice's 6.5 tets per cell cubed), 1 m, dropped 0.2 m.
std::pair<std::string, sim::Scene> body_scene(double tets)
{
    meshing::GenerateParams g;
    g.shape = "sphere";
    g.resolution = std::max(2, static_cast<int>(std::lround(std::cbrt(tets / 6.5))));
    const TetMesh mesh = meshing::generate(g);
    sim::Scene s;
    s.objects.push_back(placed(mesh, 0.2, 1.0));
    s.ground.enabled = true;
    s.output.every = 0;
    return {fmt::format("drop sphere {}k", (mesh.num_tets() + 500) / 1000), s};
}

std::vector<std::pair<std::string, sim::Scene>> make_scenes(const SimBenchOptions& o)
{
    std::vector<std::pair<std::string, sim::Scene>> scenes;
    if (!o.bodies.empty()) {
        for (double tets : o.bodies)
            scenes.push_back(body_scene(tets));
        return scenes;
    }
    const std::vector<std::string> files = {"octopus-low.mesh", "armadillo_4k.node",    "screw.msh",
                                            "P1.msh",           "raptorTetra_8418.vtu", "32770_octocat.msh",
                                            "hand.mesh",        "mat100x100t40.msh",    "quintupleTorus.veg"};
    // A size's scenes are named with it ("drop hand 5cm") unless only 1 m is run (the rows' historic names).
    auto size_name = [&](double size) {
        if (o.sizes.size() == 1 && size == 1.0) return std::string();
        return size < 1 ? fmt::format(" {:g}cm", 100 * size) : fmt::format(" {:g}m", size);
    };
    // With --young, each scene runs at each modulus and is named with it ("drop hand 5cm E1e+09").
    const std::vector<double> moduli = o.youngs.empty() ? std::vector<double>{0.0} : o.youngs;
    auto with_young = [&](const sim::ObjectSpec& base, double young) {
        sim::ObjectSpec obj = base;
        if (young > 0) obj.material.young = young;
        return obj;
    };
    auto young_name = [](double young) { return young > 0 ? fmt::format(" E{:.0e}", young) : std::string(); };
    for (const std::string& file : files) {
        const std::filesystem::path p = std::filesystem::path(o.meshes_dir) / file;
        if (!std::filesystem::exists(p)) continue;
        const TetMesh mesh = io::read_mesh(p.string());
        for (double size : o.sizes)
            for (double young : moduli) {
                sim::Scene s;
                s.objects.push_back(with_young(placed(mesh, 0.2, size), young));
                s.ground.enabled = true;
                s.output.every = 0;
                scenes.emplace_back("drop " + p.stem().string() + size_name(size) + young_name(young), s);
                if (file == "armadillo_4k.node") {
                    sim::Scene two;
                    for (int k = 0; k < 2; ++k) {
                        sim::ObjectSpec obj = with_young(placed(mesh, 0.3, size), young);
                        obj.translate.x() += (k == 0 ? -0.7 : 0.7) * size;
                        obj.velocity = Eigen::Vector3d((k == 0 ? 0.5 : -0.5) * o.throw_speed, 0, 0);
                        two.objects.push_back(obj);
                    }
                    two.ground.enabled = true;
                    two.output.every = 0;
                    scenes.emplace_back(fmt::format("two armadillos at {:g} m/s", o.throw_speed) + size_name(size) +
                                            young_name(young),
                                        two);
                }
            }
    }
    return scenes;
}

/// The options' scene overrides, and the integrator and time step of one run.
void apply_overrides(sim::Scene& scene, const SimBenchOptions& o, sim::Integrator integrator, double dt)
{
    scene.integrator = integrator;
    scene.dt = dt;
    scene.detect.threads = o.threads;
    if (o.iterations > 0) scene.iterations = o.iterations;
    if (o.max_substeps > 0) scene.max_substeps = o.max_substeps;
    if (o.sweep_tolerance >= 0) scene.sweep_tolerance = o.sweep_tolerance;
    if (o.convergence >= 0) scene.convergence = o.convergence;
    if (o.max_iterations > 0) scene.max_iterations = o.max_iterations;
    if (o.no_coarse) scene.coarse_space = false;
    if (o.rho >= 0) scene.acceleration = o.rho;
    if (o.margin >= 0) scene.contact.margin = o.margin;
    if (o.no_speculative) scene.contact.speculative = false;
    if (o.inversion_guard) scene.inversion_guard = true;
    if (!o.crossing_check.empty()) scene.crossing_check = o.crossing_check == "on";
    if (!o.continuous_check.empty()) scene.continuous_check = o.continuous_check == "on";
    if (!o.contact_edges.empty()) scene.contact.edges = o.contact_edges == "on";
    if (o.skin >= 0) {
        scene.detect.skin_mode = DetectParams::SkinMode::factor_of_cell_size;
        scene.detect.skin = o.skin;
    }
}

/// Teschner et al. 2004: the largest stable dt of those run, divided by the cost per step at that dt.
void print_stable_dt(const std::vector<Row>& rows)
{
    std::map<std::pair<std::string, std::string>, std::pair<double, double>> best;
    for (const Row& r : rows)
        if (r.stable) {
            auto& b = best[{r.scene, r.integrator}];
            if (r.dt > b.first) b = {r.dt, r.ms_mean};
        }
    std::printf("\nlargest stable dt / ms per step (Teschner et al. 2004), over the dt run:\n");
    for (const auto& [key, v] : best)
        std::printf("  %-34s %-16s dt %.5f s at %.2f ms/step: %.3g s/ms\n", key.first.c_str(), key.second.c_str(),
                    v.first, v.second, v.first / v.second);
}

/// --csv FILE: the rows, written whole or not at all.
void write_csv(const std::string& csv, const std::vector<Row>& rows)
{
    const std::string tmp = csv + ".partial";
    {
        std::ofstream out(tmp);
        if (!out) throw Error("--csv: cannot write '" + tmp + "'");
        out << "scene,integrator,dt,vertices,tets,ms_step,ms_step_mean,ms_detect,ms_depth,ms_proximity,"
               "ms_response,ms_integrate,ms_other,threads,iterations,substeps,contacts,inverted,far_self,"
               "far_self_max,mean_z,energy_ratio,volume_ratio,unconverged,stable,bytes_per_tet,cpu_ms_step,"
               "cpu_ms_step_mean,iterations_mean,setup_cpu_ms,failure,retaken,crossed,inside,inside_max,unresolved,"
               "edge_contacts_max\n";
        for (const Row& r : rows)
            out << fmt::format("{},{},{:.6g},{},{},{:.4g},{:.4g},{:.4g},{:.4g},{:.4g},{:.4g},{:.4g},{:.4g},{:.3g},"
                               "{:.3g},{:.3g},{:.4g},{},{},{},{:.5g},{:.4g},{:.4g},{},{},{:.4g},{:.4g},{:.4g},{:.3g},{:"
                               ".4g},\"{}\",{},{},{},{},{},{}\n",
                               r.scene, r.integrator, r.dt, r.vertices, r.tets, r.ms, r.ms_mean, r.detect, r.depth,
                               r.proximity, r.response, r.integrate, r.other, r.threads, r.sweeps, r.substeps,
                               r.contacts, r.inverted, r.far_self, r.far_self_max, r.mean_z, r.energy_ratio,
                               r.volume_ratio, r.unconverged, r.stable ? 1 : 0, r.bytes_per_tet, r.cpu_ms,
                               r.cpu_ms_mean, r.sweeps_mean, r.setup_ms, r.failure, r.retaken, r.crossed, r.inside,
                               r.inside_max, r.unresolved, r.edge_contacts_max);
    }
    std::filesystem::rename(tmp, csv);
}

/// --bodies: per body and time step, the cost per step and per tet, the memory per tet and the threads' speed-up,
/// each the median over the --rounds (rows as run: one thread, then --threads, round after round). The cost per tet
/// is the processor time at one thread, which other processes on a loaded machine do not inflate (a long step loses
/// more of its wall-clock time to their time slices than a short one); the median is mostly the fall's steps, the
/// mean carries the landing's. The speed-up is wall-clock (one round's median over median, mean over mean; the
/// median over the rounds), the set-up's processor time is apart.
void print_bodies(const std::vector<Row>& rows, int threads, int rounds)
{
    const bool more = threads != 1;
    std::printf("\nbodies (one thread: wall-clock ms, processor ms and ns/tet per step as median and mean, mean sweeps "
                "per step;\n%sset-up processor s; B/tet: resident memory the run added%s):\n",
                more ? fmt::format("{} threads: wall-clock ms and the speed-up over one thread; ", threads).c_str()
                     : "",
                rounds > 1 ? fmt::format("; medians over {} rounds", rounds).c_str() : "");
    std::printf("%-18s %8s %8s | %8s %8s %8s %7s %7s %6s | %8s %8s %6s %6s | %6s %6s\n", "body", "dt", "tets", "ms",
                "cpu ms", "cpu mean", "ns/tet", "ns mean", "sweeps", "ms more", "mean", "speed", "mean", "set-up",
                "B/tet");
    auto over = [](const std::vector<const Row*>& rs, auto field) {
        std::vector<double> v;
        for (const Row* r : rs)
            v.push_back(field(*r));
        return median(v);
    };
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {0, 0};
    int bodies = 0;
    for (size_t i = 0; i < rows.size();) {
        // One body at one integrator and dt: its rounds' rows.
        size_t end = i;
        while (end < rows.size() && rows[end].scene == rows[i].scene && rows[end].integrator == rows[i].integrator &&
               rows[end].dt == rows[i].dt)
            ++end;
        std::vector<const Row*> ones, mores;
        for (size_t k = i; k < end; ++k)
            (more && rows[k].threads_asked != 1 ? mores : ones).push_back(&rows[k]);
        std::vector<double> speed, speed_mean;
        for (size_t k = 0; k < std::min(ones.size(), mores.size()); ++k) {
            speed.push_back(mores[k]->ms > 0 ? ones[k]->ms / mores[k]->ms : 0.0);
            speed_mean.push_back(mores[k]->ms_mean > 0 ? ones[k]->ms_mean / mores[k]->ms_mean : 0.0);
        }
        const Row& one = rows[i];
        const double tets = static_cast<double>(std::max<Index>(1, one.tets));
        const double per_tet[2] = {1e6 * over(ones, [](const Row& r) { return r.cpu_ms; }) / tets,
                                   1e6 * over(ones, [](const Row& r) { return r.cpu_ms_mean; }) / tets};
        for (int k = 0; k < 2; ++k) {
            lo[k] = std::min(lo[k], per_tet[k]);
            hi[k] = std::max(hi[k], per_tet[k]);
        }
        std::printf("%-18s %8.5f %8lld | %8.2f %8.2f %8.2f %7.1f %7.1f %6.2f | %8.2f %8.2f %6.2f %6.2f | %6.2f %6.0f\n",
                    one.scene.c_str(), one.dt, static_cast<long long>(one.tets),
                    over(ones, [](const Row& r) { return r.ms; }), over(ones, [](const Row& r) { return r.cpu_ms; }),
                    over(ones, [](const Row& r) { return r.cpu_ms_mean; }), per_tet[0], per_tet[1],
                    over(ones, [](const Row& r) { return r.sweeps_mean; }),
                    over(mores, [](const Row& r) { return r.ms; }), over(mores, [](const Row& r) { return r.ms_mean; }),
                    speed.empty() ? 1.0 : median(speed), speed_mean.empty() ? 1.0 : median(speed_mean),
                    1e-3 * over(ones, [](const Row& r) { return r.setup_ms; }),
                    over(ones, [](const Row& r) { return r.bytes_per_tet; }));
        ++bodies;
        i = end;
    }
    if (bodies > 1)
        std::printf("ns/tet, largest over smallest body: %.2f (median), %.2f (mean)\n", hi[0] / lo[0], hi[1] / lo[1]);
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"tethash_sim_bench: the simulator on the shared real meshes (drops and a collision)"};
    SimBenchOptions o;
    add_options(app, o);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }
    try {
        std::vector<double> steps_dt;
        for (const std::string& d : o.dts) {
            const double v = parse_dt(d);
            if (!(v > 0)) throw Error("--dt must be positive, found '" + d + "'");
            steps_dt.push_back(v);
        }
        std::vector<sim::Integrator> integ;
        for (const std::string& i : o.integrators)
            integ.push_back(sim::parse_integrator(i));
        if (!(o.seconds >= 0) || !std::isfinite(o.seconds))
            throw Error("--seconds must be positive (or 0: automatic), found " + fmt::format("{}", o.seconds));
        if (!(o.throw_speed >= 0) || !std::isfinite(o.throw_speed))
            throw Error("--throw must be a speed (m/s, 0 or more), found " + fmt::format("{}", o.throw_speed));
        if (o.threads < 0 || o.threads > 256) throw Error("--threads must be in 0..256 (0: chosen step by step)");
        if (o.cpu_time && o.threads != 1)
            throw Error("--cpu-time measures one thread's work: it needs --threads 1 (found " +
                        std::to_string(o.threads) + ")");
        if (o.bodies.empty() && !std::filesystem::is_directory(o.meshes_dir)) {
            std::printf("shared meshes not found at %s: nothing to run\n", o.meshes_dir.c_str());
            return 0;
        }
        print_header(o);
        std::vector<std::pair<std::string, sim::Scene>> scenes = make_scenes(o);
        std::printf(
            "%-36s %-16s %8s %7s %7s %8s %7s %7s %7s %7s %7s %7s %7s %4s %6s %5s %8s %7s %5s %5s %5s %5s %8s %7s "
            "%6s %6s %7s %7s %5s %10s  %s\n",
            "scene", "integrator", "dt", "verts", "tets", "ms/step", "mean", "detect", "depth", "near", "resp",
            "integr", "other", "thr", "iters", "subst", "contacts", "invert", "far", "fmax", "in", "inmax", "mean_z",
            "E1/E0", "V1/V0", "unconv", "retaken", "crossed", "unres", "dt/ms", "failure");
        std::vector<Row> rows;
        for (auto& [name, scene] : scenes) {
            if (!o.filter.empty() && name.find(o.filter) == std::string::npos) continue;
            // --bodies: one thread, then --threads (the speed-up of the summary).
            std::vector<int> thread_counts{o.threads};
            if (!o.bodies.empty() && o.threads != 1) thread_counts.insert(thread_counts.begin(), 1);
            for (sim::Integrator i : integ)
                for (double dt : steps_dt)
                    for (int round = 0; round < o.rounds; ++round)
                        for (int threads : thread_counts) {
                            apply_overrides(scene, o, i, dt);
                            scene.detect.threads = threads;
                            const int steps = std::max(1, static_cast<int>(std::lround(run_seconds(o, scene) / dt)));
                            const Row r = run(name, scene, steps, o.cpu_time);
                            print(r);
                            rows.push_back(r);
                        }
#ifdef TETHASH_HAVE_BULLET
            if (!o.no_peer && o.bodies.empty())
                for (double dt : steps_dt) {
                    scene.dt = dt;
                    const Row r =
                        run_peer(name, scene, std::max(1, static_cast<int>(std::lround(run_seconds(o, scene) / dt))),
                                 o.peer_iterations, o.cpu_time);
                    print(r);
                    rows.push_back(r);
                }
#endif
        }
        print_stable_dt(rows);
        if (!o.bodies.empty()) print_bodies(rows, o.threads, o.rounds);
        if (!o.csv.empty()) write_csv(o.csv, rows);
    } catch (const Error& e) {
        std::fprintf(stderr, "tethash_sim_bench: %s\n", e.what());
        return 2;
    }
    return 0;
}
