// tethash simulate: runs a scene (TOML, or the built-in default) and writes VTU frames + a .pvd series.
#include "command.hpp"

#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/io/pvd.hpp"
#include "tethash/io/vtu.hpp"
#include "tethash/sim/simulation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>

namespace tethash::cli {
namespace {

volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void on_interrupt(int)
{
    g_interrupted = 1;
}

/// "1/240", "0.004", "4e-3": seconds; false when the text is not a number or a fraction of two numbers.
bool parse_seconds(const std::string& text, double& out)
{
    const auto number = [](const std::string& t, double& v) {
        if (t.empty() || std::isspace(static_cast<unsigned char>(t[0]))) return false;
        char* end = nullptr;
        v = std::strtod(t.c_str(), &end);
        return end == t.c_str() + t.size();
    };
    const std::size_t slash = text.find('/');
    if (slash == std::string::npos) return number(text, out);
    double a = 0, b = 0;
    if (!number(text.substr(0, slash), a) || !number(text.substr(slash + 1), b) || !(b != 0)) return false;
    out = a / b;
    return true;
}

/// Removes frame_NNNNN.vtu and scene.pvd from `dir`; returns how many files it removed.
int remove_previous_frames(const std::string& dir)
{
    int removed = 0;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
        const std::string name = entry.path().filename().string();
        const bool frame =
            name.size() == 15 && name.compare(0, 6, "frame_") == 0 && name.compare(11, 4, ".vtu") == 0 &&
            std::all_of(name.begin() + 6, name.begin() + 11, [](char c) { return c >= '0' && c <= '9'; });
        if ((frame || name == "scene.pvd") && entry.is_regular_file()) {
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
    std::string threads; ///< "" = the scene's
    std::string out = "out";
};

void run_simulate(const SimulateOptions& o)
{
    sim::Scene scene = o.scene.empty() ? sim::default_scene() : sim::load_scene(o.scene);
    if (o.steps != SimulateOptions::unset) {
        if (o.steps < 0) throw Error(fmt::format("--steps must be ≥ 0, found {}", o.steps));
        scene.steps = o.steps;
    }
    if (!o.dt.empty()) {
        // One grammar with the scene file and the studies: seconds, or a fraction such as 1/240.
        double dt = 0;
        if (!parse_seconds(o.dt, dt) || !(dt > 0) || !std::isfinite(dt))
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
    if (!o.threads.empty())
        scene.detect.threads = parse_threads(o.threads);
    else
        check_threads(scene.detect.threads, scene.source + ": [detector] threads");
    // Detector threads: the scene's (1 unless [detector] threads says otherwise), --threads overrides; 0 = all.
    const int all = set_threads(scene.detect.threads);
    const int threads = scene.detect.threads > 0 ? scene.detect.threads : all;

    sim::Simulation sim(scene);
    for (const std::string& w : sim.warnings())
        std::fprintf(stderr, "tethash: warning: %s\n", w.c_str());

    std::error_code ec;
    std::filesystem::create_directories(o.out, ec);
    if (ec) throw Error("--out: cannot create folder '" + o.out + "': " + ec.message());
    // A previous run's frames would join this run's in ParaView's file group: they go first (only the files this
    // command writes: frame_NNNNN.vtu and scene.pvd), and the run says so.
    const int removed = remove_previous_frames(o.out);
    if (removed > 0)
        std::fprintf(stderr, "tethash: note: removed %d file%s of a previous run from %s\n", removed,
                     removed == 1 ? "" : "s", o.out.c_str());
    std::vector<std::pair<double, std::string>> series;
    const std::string pvd = (std::filesystem::path(o.out) / "scene.pvd").string();
    auto write_frame = [&]() {
        const std::string name = fmt::format("frame_{:05d}.vtu", sim.step_index());
        io::write_vtu((std::filesystem::path(o.out) / name).string(), sim.mesh(), sim.output_fields());
        series.emplace_back(sim.time(), name);
        io::write_pvd(pvd, series);
    };
    const int every = scene.output.every;
    if (every > 0) write_frame();

    const sim::Energy e0 = sim.energy();
    std::fprintf(stdout, "scene: %s\n", scene.source.c_str());
    std::fprintf(
        stdout,
        "%d objects, %d vertices, %d tets, %d springs; integrator %s, dt %g s x %d substeps, %d steps, %d threads\n",
        static_cast<int>(scene.objects.size()), sim.mesh().num_vertices(), sim.mesh().num_tets(),
        static_cast<int>(sim.model().springs.edges.rows()), sim::to_string(scene.integrator), scene.dt, scene.substeps,
        scene.steps, threads);
    std::fprintf(stdout, "explicit stability limit ~ %.3g s\n", sim.explicit_dt_limit());
    std::fflush(stdout);

    const bool tty = stderr_is_terminal();
    double ms_detect = 0, ms_depth = 0, ms_response = 0, ms_integrate = 0, max_depth = 0, depth_sum = 0;
    std::int64_t contacts = 0, iterations = 0, ignored = 0, refined = 0, refined_substeps = 0;
    const auto start = std::chrono::steady_clock::now();
    auto last_print = start;
    const int plain_every = std::max(1, scene.steps / 10);
    // Ctrl-C ends the run after the current step with a note of where it stopped; the frames written so far and
    // scene.pvd stay a valid series.
    g_interrupted = 0;
    const auto old_handler = std::signal(SIGINT, on_interrupt);
    if (old_handler == SIG_IGN) std::signal(SIGINT, SIG_IGN); // ignored stays ignored (nohup, &)
    struct Restore {
        decltype(old_handler) h;
        ~Restore() { std::signal(SIGINT, h); }
    } restore{old_handler};
    int done = 0;
    try {
        for (int s = 0; s < scene.steps; ++s) {
            if (g_interrupted) break;
            sim.step();
            done = s + 1;
            const sim::StepStats& st = sim.last_stats();
            ms_detect += st.ms_detect;
            ms_depth += st.ms_depth;
            ms_response += st.ms_response;
            ignored += st.ignored_local;
            ms_integrate += st.ms_integrate;
            contacts += st.contacts;
            iterations += st.solver_iterations;
            if (st.substeps > scene.substeps) {
                ++refined;
                refined_substeps = std::max<std::int64_t>(refined_substeps, st.substeps);
            }
            max_depth = std::max(max_depth, st.max_depth);
            depth_sum += st.mean_depth * static_cast<double>(st.contacts);
            if (every > 0 && sim.step_index() % every == 0) write_frame();
            const auto now = std::chrono::steady_clock::now();
            const double secs = std::chrono::duration<double>(now - start).count();
            const double rate = secs > 0 ? (s + 1) / secs : 0.0;
            if (tty) {
                if (std::chrono::duration<double>(now - last_print).count() > 0.1 || s + 1 == scene.steps) {
                    const int width = 30, filled = static_cast<int>(width * (s + 1) / std::max(1, scene.steps));
                    std::fprintf(stderr, "\r[%s%s] step %d/%d  %.1f steps/s  contacts %lld  max pen %.3g   ",
                                 std::string(static_cast<size_t>(filled), '#').c_str(),
                                 std::string(static_cast<size_t>(width - filled), '.').c_str(), s + 1, scene.steps,
                                 rate, static_cast<long long>(st.contacts), st.max_depth);
                    last_print = now;
                }
            } else if ((s + 1) % plain_every == 0 || s + 1 == scene.steps) {
                std::fprintf(stderr, "step %d/%d  %.1f steps/s  contacts %lld  max pen %.3g\n", s + 1, scene.steps,
                             rate, static_cast<long long>(st.contacts), st.max_depth);
            }
        }
    } catch (const RunFailure&) {
        if (tty) std::fprintf(stderr, "\n");
        throw;
    }
    if (tty) std::fprintf(stderr, "\n");
    if (g_interrupted) {
        std::fprintf(stderr,
                     "tethash: interrupted after step %d of %d (t = %g s); the %zu frame%s written so far form a valid "
                     "series: %s\n",
                     done, scene.steps, sim.time(), series.size(), series.size() == 1 ? "" : "s", pvd.c_str());
        std::fflush(stderr);
        std::signal(SIGINT, SIG_DFL);
        std::raise(SIGINT); // the conventional status of a run ended by Ctrl-C (130 from a shell)
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const int n = std::max(1, scene.steps);
    const sim::Energy e1 = sim.energy();
    std::fprintf(stdout,
                 "steps: %d in %.3f s (%.2f ms/step: detection %.3f, depth %.3f, response %.3f, integration %.3f)\n",
                 scene.steps, wall, 1e3 * wall / n, ms_detect / n, ms_depth / n, ms_response / n, ms_integrate / n);
    std::fprintf(stdout, "contacts per step: %.1f (plus %.1f local self-contacts left to the elastic terms)\n",
                 static_cast<double>(contacts) / n, static_cast<double>(ignored) / n);
    if (iterations)
        std::fprintf(stdout, "solver: %.1f %s per step\n", static_cast<double>(iterations) / n,
                     scene.integrator == sim::Integrator::vbd ? "sweeps" : "CG iterations");
    if (refined)
        std::fprintf(stdout,
                     "refined steps: %lld of %d taken in up to %lld substeps (tets inverted or a blow-up at "
                     "%d; max_substeps bounds it)\n",
                     static_cast<long long>(refined), n, static_cast<long long>(refined_substeps), scene.substeps);
    std::fprintf(stdout, "penetration depth: max %.4g, mean %.4g\n", max_depth,
                 contacts ? depth_sum / static_cast<double>(contacts) : 0.0);
    std::fprintf(stdout,
                 "energy: start %.6g, end %.6g (kinetic %.4g, spring %.4g, volume %.4g, gravity %.4g, ground %.4g, "
                 "contact %.4g)\n",
                 e0.total(), e1.total(), e1.kinetic, e1.spring, e1.volume, e1.gravity, e1.ground, e1.contact);
    if (every > 0)
        std::fprintf(stdout, "frames: %zu in %s (open scene.pvd in ParaView)\n", series.size(), o.out.c_str());
}

Registrar reg{
    {"simulate", "Simulate a scene of deformable tet meshes (mass-spring) and write VTU frames", [](CLI::App& sub) {
         auto o = std::make_shared<SimulateOptions>();
         sub.add_option("scene", o->scene, "Scene file (TOML); without it the built-in default scene runs");
         sub.add_option("--steps", o->steps, "Number of steps (overrides the scene)");
         sub.add_option("--dt", o->dt, "Time step in s, or a fraction such as 1/240 (overrides the scene)");
         sub.add_option("--substeps", o->substeps, "Substeps per step (overrides the scene)");
         sub.add_option("--integrator", o->integrator, "vbd (default), implicit_euler or symplectic_euler");
         sub.add_option("--threads", o->threads,
                        "Detector threads: 0 = every hardware thread, or 1..256 (default: the scene's [detector] "
                        "threads, 1 if absent)");
         sub.add_option("-o,--out", o->out,
                        "Output folder for frame_NNNNN.vtu and scene.pvd (those of a previous run there are removed)")
             ->capture_default_str();
         sub.callback([o] { run_simulate(*o); });
     }}};

} // namespace
} // namespace tethash::cli
