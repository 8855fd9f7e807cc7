// tethash simulate: runs a scene (TOML, or the built-in default) and writes VTU frames + a .pvd series.
#include "command.hpp"
#include "render_options.hpp"
#include "simulate_ccd.hpp"

#include "tethash/detect.hpp"
#include "tethash/detect_grammar.hpp"
#include "tethash/error.hpp"
#include "tethash/io/file.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/io/pvd.hpp"
#include "tethash/io/surface.hpp"
#include "tethash/io/vtu.hpp"
#include "tethash/sim/simulation.hpp"
#include "tethash/study/json.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <optional>

namespace tethash::cli {
namespace {

volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void on_interrupt(int)
{
    // The first Ctrl-C ends the run after the current step (the step in progress stops at its next sweep or
    // substep and is rolled back); a second one ends the process at once.
    g_interrupted = 1;
    std::signal(SIGINT, SIG_DFL);
}

/// Removes frame_NNNNN.vtu, static.vtu, scene.pvd and run.json from `dir`; returns how many files it removed.
int remove_previous_frames(const std::string& dir)
{
    int removed = 0;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
        const std::string name = entry.path().filename().string();
        const bool frame =
            name.size() == 15 && name.compare(0, 6, "frame_") == 0 && name.compare(11, 4, ".vtu") == 0 &&
            std::all_of(name.begin() + 6, name.begin() + 11, [](char c) { return c >= '0' && c <= '9'; });
        if ((frame || name == "scene.pvd" || name == "run.json" || name == "static.vtu") && entry.is_regular_file()) {
            std::error_code rm;
            if (std::filesystem::remove(entry.path(), rm))
                ++removed;
            else if (rm)
                throw Error("--out: cannot remove '" + entry.path().string() + "' of a previous run: " + rm.message());
        }
    }
    return removed;
}

struct SimulateOptions {
    std::string scene;
    static constexpr int unset = std::numeric_limits<int>::min();
    int steps = unset;
    std::string dt; ///< "" = the scene's
    int substeps = unset;
    std::string integrator;
    std::string crossing_check;   ///< "" = the scene's; "on" or "off"
    std::string continuous_check; ///< "" = the scene's; "on" or "off"
    std::string contact_edges;    ///< "" = the scene's; "on" or "off"
    std::string threads;          ///< "" = the scene's
    std::string out = "out";
    bool strict = false; ///< a run that cannot be trusted (RunHealth::problems) exits 1
    CcdQueryOptions ccd; ///< --ccd-queries: the steps' continuous queries in the CCD benchmark's format
    // The one-line path: a mesh dropped on the ground (a scene written for it).
    std::string mesh;
    double scale = 1;
    std::string up = "z";
    double young = 1e5, density = 1000;
    bool template_scene = false;
    std::string render; ///< --render FILE: the run drawn at its end ("" none)
    RenderFlags render_flags;
};

/// A file name whose extension is a mesh's (tet mesh or surface), not a scene's.
bool looks_like_a_mesh(const std::string& path)
{
    return io::classify_path(path) != io::PathKind::unknown;
}

/// The scene `--mesh FILE` runs: the mesh scaled by `scale`, its up axis `up`, centred over the origin with its
/// lowest point a tenth of its height above the ground, 2 s at dt 1/240, 60 frames a second. Written out as TOML
/// with comments, so that the user can edit it and run it again.
std::string mesh_scene_text(const SimulateOptions& o)
{
    if (!(o.scale > 0) || !std::isfinite(o.scale))
        throw Error(fmt::format("--scale must be a positive number, found {}", o.scale));
    if (!(o.young > 0) || !std::isfinite(o.young))
        throw Error(fmt::format("--young must be a positive number (Pa), found {}", o.young));
    if (!(o.density > 0) || !std::isfinite(o.density))
        throw Error(fmt::format("--density must be a positive number (kg/m³), found {}", o.density));
    const bool minus = !o.up.empty() && o.up[0] == '-';
    const std::string axis = minus ? o.up.substr(1) : o.up;
    if (axis != "x" && axis != "y" && axis != "z")
        throw Error("--up must be x, y or z (or -x, -y, -z), found '" + o.up + "'");
    const int a = axis[0] - 'x';
    const TetMesh mesh = io::read_mesh(o.mesh);
    if (mesh.num_vertices() == 0) throw Error(o.mesh + ": the mesh has no vertices");
    const auto [lo, hi] = bounding_box(mesh.positions);
    const Eigen::Vector3d centre = 0.5 * o.scale * (lo + hi);
    const double height = o.scale * (hi[a] - lo[a]);
    Eigen::Vector3d translate = -centre;
    // Along the up axis: the lowest point (the highest with -axis) a tenth of the height above the ground at 0.
    translate[a] = minus ? -o.scale * hi[a] - 0.1 * height : -o.scale * lo[a] + 0.1 * height;
    const std::string name = std::filesystem::path(o.mesh).stem().string();
    std::string path = std::filesystem::absolute(o.mesh).string();
    for (size_t i = 0; i < path.size(); ++i)
        if (path[i] == '"' || path[i] == '\\') path.insert(i++, 1, '\\');
    return fmt::format(R"(# Written by `tethash simulate --mesh`: the scene this run ran. Edit it and run it again with
# `tethash simulate scene.toml`; `tethash simulate --template` prints every key with its meaning. Units are SI:
# metres, kilograms, seconds, pascals.
dt = "1/240"          # time step (s): a number or a fraction
steps = 480           # 2 s
up = "{}"              # gravity points against it, the ground's normal along it

[ground]
height = 0.0          # along the up axis

[output]
every = 4             # a frame every 4 steps: 60 frames a second

[[object]]
name = "{}"
mesh = "{}"
scale = {:.9g}         # the file's units to metres (a mesh in millimetres: 0.001)
translate = [{:.9g}, {:.9g}, {:.9g}]  # centred, its lowest point a tenth of its height above the ground
material = {{ young = {:.9g}, density = {:.9g} }}  # Pa, kg/m³
)",
                       o.up, name, path, o.scale, translate.x(), translate.y(), translate.z(), o.young, o.density);
}

/// Every key of a scene with its default and meaning, for `--template`.
const char* template_text()
{
    return R"(# A tethash scene (TOML). Units are SI: metres, kilograms, seconds, pascals. Keys left out take the default
# shown. Run it with `tethash simulate scene.toml`; docs/simulator.md has the whole grammar.
dt = "1/240"            # time step (s): a number or a fraction
steps = 480             # steps to run
substeps = 1            # substeps per step (each with its own detection)
integrator = "vbd"      # vbd (default), implicit_euler, symplectic_euler
# crossing_check = true   # retake a step in more substeps where a far part was entered unseen within a substep
# continuous_check = false # also sweep each substep (continuous detection): retake where a far pair met unseen
# iterations = 0        # vbd sweeps per substep; 0: until converged
# convergence = 0.1     # vbd: relative tolerance of the sweeps
# max_iterations = 100  # vbd: the most sweeps a substep takes (reaching it is reported)
up = "z"                # gravity (9.81 m/s²) points against it; "y" for meshes made y-up
# gravity = [0, 0, -9.81]

[ground]                # absent: no ground
height = 0.0
# friction = 0.5

[contact]
# margin = 0.25         # contact before penetration, in mean edges
# edges = false         # push edges out of far faces they pass through with no vertex inside
# friction = 0.0

[output]
every = 4               # a frame every N steps (0: none)
# fields = ["velocity", "contact", "depth", "object"]

[[object]]
name = "body"
mesh = "body.msh"       # .msh .vtu .vtk .mesh .node/.ele .veg, or a closed surface (.obj .stl .ply ...)
# generate = { shape = "sphere", resolution = 8, size = 0.2 }   # instead of mesh: `tethash generate --list`
scale = 1.0             # the file's units to metres (millimetres: 0.001)
# rotate = [0, 0, 0]    # degrees about x, y, z
translate = [0, 0, 0.5]
# velocity = [0, 0, 0]
material = { young = 1e5, density = 1000, damping = 0.01 }   # Pa, kg/m³, s
# self_collision = true
# static = false

# [[pin]]               # vertices held fixed
# object = 0
# box_min = [-1, -1, -1]
# box_max = [1, 1, 0.05]
)";
}

/// DIR/run.json: what the run was and how far it can be trusted (written at the end, or when interrupted).
void write_run_json(const std::string& dir, const sim::Simulation& sim, const std::string& status, double wall)
{
    const sim::RunHealth& h = sim.health();
    study::JsonWriter j;
    j.begin_object()
        .member("scene", sim.scene().source)
        .member("status", status)
        .member("integrator", sim::to_string(sim.scene().integrator))
        .member("dt", sim.scene().dt)
        .member("steps", h.steps)
        .member("substeps", h.substeps)
        .member("refined_steps", h.refined_steps)
        .member("crossing_steps", h.crossing_steps)
        .member("continuous_unresolved_steps", h.continuous_unresolved_steps)
        .member("unconverged_substeps", h.unconverged_substeps)
        .member("energy_start", h.energy_start)
        .member("energy_end", h.energy_end)
        .member("energy_scale", h.energy_scale)
        .member("energy_growth", h.energy_growth)
        .member("volume_ratio_min", h.volume_ratio)
        .member("volume_ratio_end", h.volume_end)
        .member("inverted_tets_end", h.inverted_end)
        .member("tets", h.tets)
        .member("wall_seconds", wall);
    // The scene's up axis (the ground's normal, else against gravity), for the camera of `tethash render`.
    Eigen::Vector3d up(0, 0, 1);
    if (sim.model().ground.enabled)
        up = sim.model().ground.normal.normalized();
    else if (sim.scene().gravity.norm() > 0)
        up = -sim.scene().gravity.normalized();
    j.key("up").begin_array().value(up.x()).value(up.y()).value(up.z()).end_array();
    j.key("problems").begin_array(study::JsonWriter::block_layout);
    for (const std::string& p : h.problems())
        j.value(p);
    j.end_array().end_object();
    io::write_text_file((std::filesystem::path(dir) / "run.json").string(), j.str() + "\n");
}

/// The scene the options ask for: a scene file, the mesh of --mesh (its scene text into `mesh_scene`) or the
/// built-in default, with the command line's overrides.
sim::Scene simulate_scene(SimulateOptions& o, std::string& mesh_scene)
{
    if (!o.scene.empty() && !o.mesh.empty())
        throw Error("give a scene file or --mesh FILE, not both (found '" + o.scene + "' and --mesh '" + o.mesh + "')");
    if (!o.scene.empty() && looks_like_a_mesh(o.scene)) {
        std::fprintf(stderr,
                     "tethash: note: %s is a mesh, not a scene: dropping it on the ground as `--mesh %s` does (the "
                     "scene it runs is written to %s/scene.toml)\n",
                     o.scene.c_str(), o.scene.c_str(), o.out.c_str());
        o.mesh = o.scene;
        o.scene.clear();
    }
    if (o.mesh.empty() && (o.scale != 1 || o.up != "z" || o.young != 1e5 || o.density != 1000))
        throw Error("--scale, --up, --young and --density go with --mesh FILE (a scene file says them itself)");
    if (!o.mesh.empty()) mesh_scene = mesh_scene_text(o);
    sim::Scene scene = !mesh_scene.empty() ? sim::parse_scene(mesh_scene, "--mesh " + o.mesh)
                       : o.scene.empty()   ? sim::default_scene()
                                           : sim::load_scene(o.scene);
    if (o.steps != SimulateOptions::unset) {
        if (o.steps < 0) throw Error(fmt::format("--steps must be ≥ 0, found {}", o.steps));
        scene.steps = o.steps;
    }
    if (!o.dt.empty()) {
        // One grammar with the scene file and the studies: seconds, or a fraction such as 1/240.
        double dt = 0;
        if (!sim::parse_seconds(o.dt, dt) || !(dt > 0) || !std::isfinite(dt))
            throw Error("--dt must be a positive, finite time in seconds (e.g. 0.004 or 1/240), found '" + o.dt + "'");
        scene.dt = dt;
    }
    if (o.substeps != SimulateOptions::unset) {
        if (o.substeps < 1) throw Error(fmt::format("--substeps must be ≥ 1, found {}", o.substeps));
        scene.substeps = o.substeps;
    }
    if (!o.integrator.empty()) {
        try {
            scene.integrator = sim::parse_integrator(o.integrator);
        } catch (const Error& e) {
            throw Error(std::string("--integrator: ") + e.what());
        }
    }
    if (!o.crossing_check.empty()) {
        if (o.crossing_check != "on" && o.crossing_check != "off")
            throw Error("--crossing-check must be on or off, found '" + o.crossing_check + "'");
        scene.crossing_check = o.crossing_check == "on";
    }
    if (!o.continuous_check.empty()) {
        if (o.continuous_check != "on" && o.continuous_check != "off")
            throw Error("--continuous-check must be on or off, found '" + o.continuous_check + "'");
        scene.continuous_check = o.continuous_check == "on";
    }
    if (!o.contact_edges.empty()) {
        if (o.contact_edges != "on" && o.contact_edges != "off")
            throw Error("--contact-edges must be on or off, found '" + o.contact_edges + "'");
        scene.contact.edges = o.contact_edges == "on";
    }
    if (!o.threads.empty())
        scene.detect.threads = parse_threads(o.threads);
    else
        check_threads(scene.detect.threads, scene.source + ": [detector] threads");
    return scene;
}

/// The output folder made, a previous run's files removed from it (with a note), the --mesh scene written to it.
void prepare_out_folder(const std::string& out, const std::string& mesh_scene)
{
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    if (ec) {
        // A file on the way is a bad --out; anything else is the file system refusing (exit 1).
        const std::string msg = "--out: cannot create folder '" + out + "': " + ec.message();
        if (ec == std::errc::not_a_directory || ec == std::errc::file_exists) throw Error(msg);
        throw WriteError(msg);
    }
    // A previous run's frames would join this run's in ParaView's file group: they go first (only the files this
    // command writes: frame_NNNNN.vtu and scene.pvd), and the run says so.
    const int removed = remove_previous_frames(out);
    if (removed > 0)
        std::fprintf(stderr, "tethash: note: removed %d file%s of a previous run from %s\n", removed,
                     removed == 1 ? "" : "s", out.c_str());
    if (!mesh_scene.empty()) {
        const std::string path = (std::filesystem::path(out) / "scene.toml").string();
        io::write_text_file(path, mesh_scene);
        std::fprintf(stderr, "tethash: note: the scene of this run is %s (edit it, run it again)\n", path.c_str());
    }
}

/// The frames of the run and their series, scene.pvd. What does not move (the bsp obstacles, the ground) is written
/// once, static.vtu, and listed at every time as part 1 of the series: ParaView and `tethash render` show it beside
/// the frames (part 0).
class FrameWriter {
  public:
    explicit FrameWriter(std::string out) : m_out(std::move(out)), m_pvd((m_out / "scene.pvd").string()) {}
    void write(const sim::Simulation& sim)
    {
        const std::string name = fmt::format("frame_{:05d}.vtu", sim.step_index());
        io::write_vtu((m_out / name).string(), sim.mesh(), sim.output_fields());
        // After the first frame (a folder that takes no frame gets no static surface either).
        if (m_series.empty()) {
            const sim::StaticSurface st = sim.static_surface();
            if (st.surface.triangles.rows() > 0) {
                m_static = "static.vtu";
                io::write_vtu_surface((m_out / m_static).string(), st.surface, st.triangle_object);
            }
        }
        m_series.push_back({sim.time(), name, 0});
        if (!m_static.empty()) m_series.push_back({sim.time(), m_static, 1});
        io::write_pvd_parts(m_pvd, m_series);
    }
    std::size_t frames() const
    {
        return static_cast<std::size_t>(
            std::count_if(m_series.begin(), m_series.end(), [](const io::PvdEntry& e) { return e.part == 0; }));
    }
    const std::string& pvd() const { return m_pvd; }

  private:
    std::filesystem::path m_out;
    std::string m_pvd;
    std::vector<io::PvdEntry> m_series;
    std::string m_static;
};

/// What the run is: the scene, its size, integrator and threads, each object's size.
void print_run_header(const sim::Scene& scene, const sim::Simulation& sim, int threads)
{
    std::fprintf(stdout, "scene: %s\n", scene.source.c_str());
    std::fprintf(
        stdout,
        "%d objects, %d vertices, %d tets, %d springs; integrator %s, dt %g s x %d substeps, %d steps, %s%d thread%s\n",
        static_cast<int>(scene.objects.size()), sim.mesh().num_vertices(), sim.mesh().num_tets(),
        static_cast<int>(sim.model().springs.edges.rows()), sim::to_string(scene.integrator), scene.dt, scene.substeps,
        scene.steps, scene.detect.threads == 0 && threads > 1 ? "up to " : "", threads, threads == 1 ? "" : "s");
    std::string sizes;
    const std::vector<double> size = sim.object_sizes();
    for (size_t k = 0; k < size.size(); ++k)
        sizes +=
            fmt::format("{}{} {:.4g} m", k ? ", " : "",
                        scene.objects[k].name.empty() ? fmt::format("object {}", k) : scene.objects[k].name, size[k]);
    std::fprintf(stdout, "object sizes (longest extent): %s\n", sizes.c_str());
    if (scene.integrator == sim::Integrator::symplectic_euler)
        std::fprintf(stdout, "explicit stability limit ~ %.3g s\n", sim.explicit_dt_limit());
    std::fflush(stdout);
}

/// The steps' statistics summed over the run, for its summary.
struct RunTotals {
    double ms_detect = 0, ms_depth = 0, ms_proximity = 0, ms_response = 0, ms_integrate = 0, ms_checks = 0,
           max_depth = 0, depth_sum = 0;
    std::int64_t contacts = 0, iterations = 0, ignored = 0, refined = 0, refined_substeps = 0, tightened = 0;
    std::int64_t steps = 0, one_thread_steps = 0; // threads = 0: steps taken on one thread, more not paying

    void add(const sim::StepStats& st, int scene_substeps)
    {
        ++steps;
        if (st.threads == 1) ++one_thread_steps;
        ms_checks += st.ms_checks();
        ms_detect += st.ms_detect;
        ms_depth += st.ms_depth;
        ms_proximity += st.ms_proximity;
        ms_response += st.ms_response;
        ignored += st.ignored_local;
        ms_integrate += st.ms_integrate;
        contacts += st.contacts;
        iterations += st.solver_iterations;
        tightened += st.tightened > 0 ? 1 : 0;
        if (st.substeps > scene_substeps) {
            ++refined;
            refined_substeps = std::max<std::int64_t>(refined_substeps, st.substeps);
        }
        max_depth = std::max(max_depth, st.max_depth);
        depth_sum += st.mean_depth * static_cast<double>(st.contacts);
    }
};

/// The progress line after each step: a bar redrawn at most ten times a second on a terminal, a line every tenth of
/// the run otherwise.
class Progress {
  public:
    explicit Progress(int steps)
        : m_tty(stderr_is_terminal()), m_start(std::chrono::steady_clock::now()), m_last_print(m_start),
          m_plain_every(std::max(1, steps / 10))
    {
    }
    bool tty() const { return m_tty; }
    /// Seconds since the run started.
    double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count(); }
    void step(int s, int steps, const sim::Simulation& sim)
    {
        const sim::StepStats& st = sim.last_stats();
        const auto now = std::chrono::steady_clock::now();
        const double secs = std::chrono::duration<double>(now - m_start).count();
        const double rate = secs > 0 ? (s + 1) / secs : 0.0;
        const double eta = rate > 0 ? (steps - s - 1) / rate : 0.0;
        const std::string times = fmt::format("  {:.1f} s elapsed, {:.1f} s left", secs, eta);
        // What the run should not hide, as it happens: energy gained, substeps unconverged, steps refined.
        std::string note;
        const sim::RunHealth& hl = sim.health();
        if (hl.energy_growth > sim::RunHealth::energy_slack)
            note += fmt::format("  energy +{:.3g}%", 100 * hl.energy_growth);
        if (hl.unconverged_substeps > 0) note += fmt::format("  unconverged {}", hl.unconverged_substeps);
        if (hl.refined_steps > 0) note += fmt::format("  refined {}", hl.refined_steps);
        if (hl.continuous_unresolved_steps > 0)
            note += fmt::format("  swept unresolved {}", hl.continuous_unresolved_steps);
        if (m_tty) {
            if (std::chrono::duration<double>(now - m_last_print).count() > 0.1 || s + 1 == steps) {
                const int width = 30, filled = static_cast<int>(width * (s + 1) / std::max(1, steps));
                std::fprintf(stderr, "\r[%s%s] step %d/%d  %.1f steps/s%s  contacts %lld  max pen %.3g%s   ",
                             std::string(static_cast<size_t>(filled), '#').c_str(),
                             std::string(static_cast<size_t>(width - filled), '.').c_str(), s + 1, steps, rate,
                             times.c_str(), static_cast<long long>(st.contacts), st.max_depth, note.c_str());
                m_last_print = now;
            }
        } else if ((s + 1) % m_plain_every == 0 || s + 1 == steps) {
            std::fprintf(stderr, "step %d/%d  %.1f steps/s%s  contacts %lld  max pen %.3g%s\n", s + 1, steps, rate,
                         times.c_str(), static_cast<long long>(st.contacts), st.max_depth, note.c_str());
        }
    }

  private:
    bool m_tty;
    std::chrono::steady_clock::time_point m_start, m_last_print;
    int m_plain_every;
};

/// The run's steps until the end or an interruption (Ctrl-C ends the run after the current step, which is rolled back
/// when it is in progress): frames every `every` steps, continuous queries recorded, statistics summed. A run that
/// fails writes run.json and its queries so far before the failure goes on. Returns the steps done.
int run_steps(sim::Simulation& sim, const sim::Scene& scene, const std::string& out, int every,
              CcdQueryRecorder& ccd_queries, FrameWriter& frames, RunTotals& totals, Progress& progress)
{
    int done = 0;
    Positions step_start;
    try {
        for (int s = 0; s < scene.steps; ++s) {
            if (g_interrupted) break;
            const bool record = ccd_queries.wants(s + 1);
            if (record) step_start = sim.positions();
            try {
                sim.step();
            } catch (const sim::Interrupted&) {
                break; // rolled back to the last complete step
            }
            done = s + 1;
            if (record) ccd_queries.record(s + 1, sim.mesh().tets, step_start, sim.positions());
            totals.add(sim.last_stats(), scene.substeps);
            if (every > 0 && sim.step_index() % every == 0) frames.write(sim);
            progress.step(s, scene.steps, sim);
        }
    } catch (const RunFailure&) {
        if (progress.tty()) std::fprintf(stderr, "\n");
        write_run_json(out, sim, "failed", progress.seconds());
        ccd_queries.write(); // the queries of the steps completed
        throw;
    }
    if (progress.tty()) std::fprintf(stderr, "\n");
    return done;
}

/// The run's summary on stdout: the stages' times per step, contacts, solver, refined and retaken steps, depth,
/// energy and health.
void print_summary(const sim::Scene& scene, const sim::Simulation& sim, const RunTotals& t, double wall,
                   const sim::Energy& e0, int threads)
{
    const int n = std::max(1, scene.steps);
    const sim::Energy e1 = sim.energy();
    // The stages add up to the step's wall time: the step's own checks (energy, inverted tets, blow-up, the
    // copies of steps taken again), then what the loop adds (frames written, progress lines).
    const double ms_step = 1e3 * wall / n;
    const double ms_stages =
        (t.ms_detect + t.ms_depth + t.ms_proximity + t.ms_response + t.ms_integrate + t.ms_checks) / n;
    std::fprintf(stdout,
                 "steps: %d in %.3f s (%.2f ms/step: detection %.3f, depth %.3f, proximity %.3f, response %.3f, "
                 "integration %.3f, checks %.3f, output and progress %.3f)\n",
                 scene.steps, wall, ms_step, t.ms_detect / n, t.ms_depth / n, t.ms_proximity / n, t.ms_response / n,
                 t.ms_integrate / n, t.ms_checks / n, std::max(0.0, ms_step - ms_stages));
    if (scene.detect.threads == 0 && threads > 1)
        std::fprintf(stdout,
                     "threads: %d (every core) for %lld steps, 1 for %lld steps where %d did not pay (measured as the "
                     "run went; the result is the same at any count)\n",
                     threads, static_cast<long long>(t.steps - t.one_thread_steps),
                     static_cast<long long>(t.one_thread_steps), threads);
    std::fprintf(stdout, "contacts per step: %.1f (plus %.1f local self-contacts left to the elastic terms)\n",
                 static_cast<double>(t.contacts) / n, static_cast<double>(t.ignored) / n);
    if (t.iterations)
        std::fprintf(stdout, "solver: %.1f %s per step\n", static_cast<double>(t.iterations) / n,
                     scene.integrator == sim::Integrator::vbd ? "sweeps" : "CG iterations");
    if (t.refined)
        std::fprintf(stdout,
                     "steps in more substeps: %lld of %d, up to %lld substeps (objects approaching fast, tets "
                     "inverted, iterations unconverged or a blow-up at %d; max_substeps bounds it)\n",
                     static_cast<long long>(t.refined), n, static_cast<long long>(t.refined_substeps), scene.substeps);
    if (t.tightened)
        std::fprintf(stdout, "steps taken again with tighter tolerances (they gained energy): %lld of %d\n",
                     static_cast<long long>(t.tightened), n);
    std::fprintf(stdout, "penetration depth: max %.4g, mean %.4g\n", t.max_depth,
                 t.contacts ? t.depth_sum / static_cast<double>(t.contacts) : 0.0);
    std::fprintf(stdout,
                 "energy: start %.6g, end %.6g (kinetic %.4g, spring %.4g, volume %.4g, gravity %.4g, ground %.4g, "
                 "contact %.4g)\n",
                 e0.total(), e1.total(), e1.kinetic, e1.spring, e1.volume, e1.gravity, e1.ground, e1.contact);
    const sim::RunHealth& health = sim.health();
    std::fprintf(stdout,
                 "health: energy end/start %.4g (most gained %.3g %% of what the scene had to spend), volume end/start "
                 "%.4f (least %.4f), %lld unconverged of %lld substeps, %lld refined steps, %lld tets inverted\n",
                 health.energy_start != 0 ? health.energy_end / health.energy_start : 1.0,
                 100 * std::max(0.0, health.energy_growth), health.volume_end, health.volume_ratio,
                 static_cast<long long>(health.unconverged_substeps), static_cast<long long>(health.substeps),
                 static_cast<long long>(health.refined_steps), static_cast<long long>(health.inverted_end));
}

void run_simulate(SimulateOptions o)
{
    if (o.template_scene) {
        std::fputs(template_text(), stdout);
        return;
    }
    std::string mesh_scene;
    const sim::Scene scene = simulate_scene(o, mesh_scene);
    // Threads: the scene's ([detector] threads; a scene file's default is 0), --threads overrides; 0 = every core,
    // fewer in the steps where they do not pay.
    const int all = set_threads(scene.detect.threads);
    const int threads = scene.detect.threads > 0 ? scene.detect.threads : all;

    // --render: its file and options checked before the run, not after it.
    std::optional<render::RenderOptions> render_options;
    if (!o.render.empty()) {
        render::check_render_path(o.render, "--render");
        render_options = o.render_flags.options();
        if (scene.output.every == 0)
            throw Error("--render: the scene writes no frames ([output] every = 0): nothing to draw");
    }
    CcdQueryRecorder ccd_queries(o.ccd); // its paths checked before the run
    sim::Simulation sim(scene);
    sim.set_interrupt_flag(&g_interrupted);
    for (const std::string& w : sim.warnings())
        std::fprintf(stderr, "tethash: warning: %s\n", w.c_str());

    prepare_out_folder(o.out, mesh_scene);
    FrameWriter frames(o.out);
    // 60 frames per simulated second unless the scene says (a frame every step of a 55k-tet mesh wrote 2.5 GB).
    const int every = scene.output.every >= 0 ? scene.output.every
                                              : std::max(1, static_cast<int>(std::lround(1.0 / (60.0 * scene.dt))));
    if (every > 0) frames.write(sim);

    const sim::Energy e0 = sim.energy();
    print_run_header(scene, sim, threads);

    RunTotals totals;
    Progress progress(scene.steps);
    // Ctrl-C ends the run after the current step with a note of where it stopped; the frames written so far and
    // scene.pvd stay a valid series.
    g_interrupted = 0;
    const auto old_handler = std::signal(SIGINT, on_interrupt);
    if (old_handler == SIG_IGN) std::signal(SIGINT, SIG_IGN); // ignored stays ignored (nohup, &)
    struct Restore {
        decltype(old_handler) h;
        ~Restore() { std::signal(SIGINT, h); }
    } restore{old_handler};
    const int done = run_steps(sim, scene, o.out, every, ccd_queries, frames, totals, progress);
    if (g_interrupted) {
        write_run_json(o.out, sim, "interrupted", progress.seconds());
        ccd_queries.write();
        std::fprintf(stderr,
                     "tethash: interrupted after step %d of %d (t = %g s); the %zu frame%s written so far form a valid "
                     "series: %s\n",
                     done, scene.steps, sim.time(), frames.frames(), frames.frames() == 1 ? "" : "s",
                     frames.pvd().c_str());
        std::fflush(stderr);
        std::signal(SIGINT, SIG_DFL);
        std::raise(SIGINT); // the conventional status of a run ended by Ctrl-C (130 from a shell)
    }
    const double wall = progress.seconds();
    print_summary(scene, sim, totals, wall, e0, threads);
    const std::vector<std::string> problems = sim.health().problems();
    for (const std::string& p : problems)
        std::fprintf(stderr, "tethash: warning: %s\n", p.c_str());
    write_run_json(o.out, sim, problems.empty() ? "ok" : "untrusted", wall);
    ccd_queries.write();
    if (every > 0)
        std::fprintf(stdout, "frames: %zu in %s (open scene.pvd in ParaView; run.json says how far to trust them)\n",
                     frames.frames(), o.out.c_str());
    if (render_options) render_run(render::open_series(o.out), *render_options, o.render);
    if (o.strict && !problems.empty())
        throw RunFailure("--strict: the run cannot be trusted (" + std::to_string(problems.size()) + " problem" +
                         (problems.size() == 1 ? "" : "s") + " above)");
}

Registrar reg{
    {"simulate", "Simulate a scene of deformable tet meshes (mass-spring) and write VTU frames", [](CLI::App& sub) {
         auto o = std::make_shared<SimulateOptions>();
         sub.add_option("scene", o->scene,
                        "Scene file (TOML; units SI: metres, kilograms, seconds); without it the built-in default "
                        "scene runs; a mesh file here is dropped on the ground as with --mesh");
         sub.add_option("--mesh", o->mesh,
                        "Drop this mesh on the ground: 2 s at 1/240, 60 frames a second; the scene it runs is "
                        "written to OUT/scene.toml");
         sub.add_option("--scale", o->scale, "With --mesh: the file's units to metres (a mesh in millimetres: 0.001)")
             ->capture_default_str();
         sub.add_option("--up", o->up, "With --mesh: the mesh's up axis, x, y or z (or -x, -y, -z)")
             ->capture_default_str();
         sub.add_option("--young", o->young, "With --mesh: Young's modulus (Pa)")->capture_default_str();
         sub.add_option("--density", o->density, "With --mesh: density (kg/m³)")->capture_default_str();
         sub.add_flag("--template", o->template_scene,
                      "Print a commented scene with every key and its default, and exit");
         sub.add_option("--steps", o->steps, "Number of steps (overrides the scene)");
         sub.add_option("--dt", o->dt, "Time step in s, or a fraction such as 1/240 (overrides the scene)");
         sub.add_option("--substeps", o->substeps, "Substeps per step (overrides the scene)");
         sub.add_option("--integrator", o->integrator, "vbd (default), implicit_euler or symplectic_euler");
         sub.add_option("--crossing-check", o->crossing_check,
                        "on or off (overrides the scene's crossing_check): take a step again in more substeps where a "
                        "vertex entered a far part within a substep unseen by the contacts");
         sub.add_option("--continuous-check", o->continuous_check,
                        "on or off (overrides the scene's continuous_check): sweep each substep by continuous "
                        "detection and take the step again in more substeps where a vertex-face or edge-edge pair of "
                        "different objects or far parts met unseen by the contacts (a vertex through a thin layer, an "
                        "edge through a face)");
         sub.add_option("--contact-edges", o->contact_edges,
                        "on or off (overrides the scene's contact.edges): push a boundary edge that passes through a "
                        "far boundary face, with no vertex inside, out of it");
         sub.add_option("--threads", o->threads,
                        "Threads of the detector and the solver: 0 = every hardware thread, fewer in the steps "
                        "where they do not pay (measured as the run goes), or a fixed 1..256 (default: the scene's "
                        "[detector] threads, 0 if absent); the result is the same at any count");
         sub.add_flag("--strict", o->strict,
                      "Exit 1 when the run cannot be trusted: energy gained, volume lost, iterations unconverged, "
                      "steps refined or tets inverted at the end (each is a warning otherwise)");
         sub.add_option("--ccd-queries", o->ccd.dir,
                        "Write the continuous queries of the steps (boundary vertex-face and edge-edge pairs whose "
                        "swept boxes overlap, at the step's start and end) to DIR/vertex_face.csv and "
                        "DIR/edge_edge.csv in the CCD benchmark's format (`tethash ccd` replays them); ground truth: "
                        "the narrow phase's answer");
         sub.add_option("--ccd-steps", o->ccd.steps,
                        "With --ccd-queries: only step K, or steps FIRST:LAST (1-based; step K ends at frame K)");
         sub.add_option("--ccd-max-queries", o->ccd.max_queries,
                        "With --ccd-queries: at most this many queries per file, whole steps (later steps left out, "
                        "with a note)")
             ->capture_default_str();
         sub.add_option("-o,--out", o->out,
                        "Output folder for frame_NNNNN.vtu and scene.pvd (those of a previous run there are removed)")
             ->capture_default_str();
         CLI::Option* render = sub.add_option("--render", o->render,
                                              "At the end, draw the run to this file (.gif, .mp4 or .png; without a "
                                              "value OUT/scene.gif); the options of `tethash render` apply")
                                   ->expected(0, 1);
         o->render_flags.add(sub, false);
         sub.callback([o, render] {
             if (render->count() > 0 && o->render.empty())
                 o->render = (std::filesystem::path(o->out) / "scene.gif").string();
             run_simulate(*o);
         });
     }}};

} // namespace
} // namespace tethash::cli
