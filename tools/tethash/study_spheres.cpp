// tethash study spheres: the spheres experiment of the octree / k-d / BSP comparison (study_spheres.hpp).
#include "study_spheres.hpp"

#include "command.hpp"

#include "tethash/error.hpp"

#include <atomic>
#include <csignal>
#include <cstdio>

namespace tethash::cli {
namespace {

std::atomic<bool> g_stop_spheres{false};
extern "C" void on_sigint_spheres(int)
{
    g_stop_spheres.store(true);
}

} // namespace

void add_spheres_options(CLI::App& sub, SpheresArgs& a)
{
    study::SpheresOptions& o = a.o;
    a.options = {
        sub.add_option("--spheres", o.spheres, "spheres: spheres dropped, one per frame")->capture_default_str(),
        sub.add_option("--frames", o.frames, "spheres: frames simulated")->capture_default_str(),
        sub.add_option("--depths", o.depths, "spheres: maximum tree depths (default 3,7)")->delimiter(','),
        sub.add_option("--methods", o.methods,
                       "spheres: brute, octree, octree-point, kd, kd-point, bsp, bsp-balanced "
                       "(default: all but bsp-balanced); detection sweeps: broad phases (detect --method names, or "
                       "all; default: all in the method sweep, else hash)")
            ->delimiter(','),
        sub.add_option("--radius", o.radius, "spheres: sphere radius (the box is the unit cube)")
            ->capture_default_str(),
        sub.add_option("--seed", o.seed, "spheres: seed of the drop positions")->capture_default_str(),
        sub.add_option("--leaf-size", o.leaf_size,
                       "spheres: nodes with at most this many spheres are leaves; detection sweeps: the trees' leaf "
                       "size (one value; default: the method's)")
            ->capture_default_str(),
    };
}

void reject_spheres_options(const SpheresArgs& a, const std::string& what)
{
    for (const CLI::Option* opt : a.options)
        if (opt->count() > 0)
            throw Error(opt->get_name() + ": only for 'tethash study spheres', not for the " + what + " study");
}

void run_spheres_command(SpheresArgs& a, const std::string& out, bool quiet, const std::string& command_line)
{
    study::SpheresOptions& o = a.o;
    if (!out.empty()) o.out_dir = out;
    o.command_line = command_line;
#ifdef TETHASH_CXX_FLAGS
    o.compiler_flags = TETHASH_CXX_FLAGS;
#endif
    study::check_spheres_options(o); // before any output
    g_stop_spheres.store(false);
    auto old_handler = std::signal(SIGINT, on_sigint_spheres);
    study::SpheresHooks hooks;
    hooks.stop = &g_stop_spheres;
    const int every = std::max(1, o.frames / 20);
    hooks.on_frame = [quiet, every](int frame, int frames) {
        if (quiet || ((frame + 1) % every != 0 && frame + 1 != frames)) return;
        std::fprintf(stderr, "%sspheres: frame %d/%d%s", stderr_is_terminal() ? "\r\033[K" : "", frame + 1, frames,
                     stderr_is_terminal() ? "" : "\n");
        std::fflush(stderr);
    };
    study::SpheresResult res;
    try {
        res = study::run_spheres(o, hooks);
    } catch (...) {
        std::signal(SIGINT, old_handler);
        throw;
    }
    std::signal(SIGINT, old_handler);
    if (!quiet && stderr_is_terminal()) std::fprintf(stderr, "\r\033[K");
    std::printf("study spheres: %d of %d frames, %lld rows -> %s, %s\n", res.frames_done, o.frames,
                static_cast<long long>(res.rows), res.csv_path.c_str(), res.json_path.c_str());
    std::printf("%-14s %5s %12s %10s %14s %12s\n", "method", "depth", "total_ms", "ms/frame", "tests", "collisions");
    for (const auto& s : res.summary)
        std::printf("%-14s %5d %12.1f %10.3f %14lld %12lld\n", s.method.c_str(), s.depth, s.total_ms,
                    res.frames_done ? s.total_ms / res.frames_done : 0.0, static_cast<long long>(s.tests),
                    static_cast<long long>(s.collisions));
    if (res.interrupted)
        throw RunFailure("interrupted after " + std::to_string(res.frames_done) + " frames; " + res.csv_path +
                         " keeps the rows measured");
}

} // namespace tethash::cli
