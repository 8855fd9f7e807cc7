// tethash study SWEEP ... : parameter studies (detection sweeps, integrator work-precision), and
// tethash study merge DIR... --out DIR : joining the shards of a study.
#include "command.hpp"
#include "study_spheres.hpp"

#include "tethash/error.hpp"
#include "tethash/study/study.hpp"

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace tethash::cli {
namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_sigint(int)
{
    g_stop.store(true);
}

std::string shell_quote(const std::string& s)
{
    if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_./=:,+%@") ==
                          std::string::npos)
        return s;
    std::string q = "'";
    for (char c : s)
        q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

/// This process's command line (from /proc/self/cmdline), shell-quoted.
std::string own_command_line()
{
    std::ifstream in("/proc/self/cmdline", std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string raw = ss.str();
    std::string out, arg;
    bool first = true;
    for (char c : raw) {
        if (c == '\0') {
            if (first) arg = std::filesystem::path(arg).filename().string();
            out += (out.empty() ? "" : " ") + shell_quote(arg);
            arg.clear();
            first = false;
        } else {
            arg += c;
        }
    }
    return out;
}

/// First of /usr/bin/python3, python3 that imports matplotlib, or "".
std::string python_with_matplotlib()
{
    for (const char* py : {"/usr/bin/python3", "python3"}) {
        const std::string cmd = std::string(py) + " -c 'import matplotlib' >/dev/null 2>&1";
        if (std::system(cmd.c_str()) == 0) return py;
    }
    return "";
}

/// Runs tools/`script` (plot_study.py, plot_spheres.py) on `dir`; prints what happened.
void make_figures(const std::string& dir, const std::string& script_name = "plot_study.py")
{
    const std::string py = python_with_matplotlib();
    if (py.empty()) {
        std::printf("figures: skipped (no python3 with matplotlib found; the CSV and JSON are complete)\n");
        return;
    }
    const std::string script = std::string(TETHASH_SOURCE_DIR) + "/tools/" + script_name;
    if (!std::filesystem::exists(script)) {
        std::printf("figures: skipped (%s not found)\n", script.c_str());
        return;
    }
    const std::string cmd = py + " " + shell_quote(script) + " " + shell_quote(dir);
    std::fflush(stdout);
    if (std::system(cmd.c_str()) != 0)
        std::printf("figures: the plot script failed (%s); the CSV and JSON are complete\n", cmd.c_str());
}

struct Args {
    std::vector<std::string> positional;
    study::StudyOptions o;
    std::string shard;
    std::string out;
    double from = 0, to = 0;
    int points = 0;
    bool no_plot = false, no_oracle = false, no_penetration = false, quiet = false;
    static constexpr int kUnset = std::numeric_limits<int>::min(); ///< option not given
    int repeat = kUnset, warmup = kUnset;
    SpheresArgs spheres;
};

void progress(std::int64_t k, std::int64_t of, const study::PointInfo& p, bool quiet)
{
    if (quiet) return;
    if (stderr_is_terminal()) {
        const int width = 30;
        const int filled = of ? static_cast<int>(width * k / of) : width;
        std::string bar(static_cast<std::size_t>(filled), '#');
        bar.resize(width, ' ');
        std::string label = p.label();
        if (label.size() > 60) label = label.substr(0, 57) + "...";
        std::fprintf(stderr, "\r\033[K[%s] %lld/%lld %s", bar.c_str(), static_cast<long long>(k + 1),
                     static_cast<long long>(of), label.c_str());
    } else {
        std::fprintf(stderr, "study: point %lld/%lld: %s\n", static_cast<long long>(k + 1), static_cast<long long>(of),
                     p.label().c_str());
    }
    std::fflush(stderr);
}

void run(Args& a)
{
    if (a.positional.empty())
        throw Error("study: missing SWEEP (cell-size, table-size, hash, threads, grid, method, integrator, stability, "
                    "spheres) or merge");
    const std::string what = a.positional.front();
    if (what == "spheres") {
        if (a.positional.size() > 1) throw Error("study: unexpected argument '" + a.positional[1] + "'");
        run_spheres_command(a.spheres, a.out, a.quiet, own_command_line());
        if (!a.no_plot) make_figures(a.spheres.o.out_dir, "plot_spheres.py");
        return;
    }
    // The options the spheres study shares with the detection sweeps: the broad phases and the leaf size.
    SpheresArgs spheres_only = a.spheres;
    std::erase_if(spheres_only.options, [&](const CLI::Option* opt) {
        const bool shared = opt->get_name() == "--methods" || opt->get_name() == "--leaf-size";
        if (shared && opt->count() > 0) {
            if (opt->get_name() == "--methods")
                a.o.methods = a.spheres.o.methods;
            else
                a.o.leaf_size = {std::to_string(a.spheres.o.leaf_size)};
        }
        return shared;
    });
    reject_spheres_options(spheres_only, what);
    if (what == "merge") {
        std::vector<std::string> dirs(a.positional.begin() + 1, a.positional.end());
        if (dirs.empty()) throw Error("study merge: give the shard folders: tethash study merge DIR... --out DIR");
        if (a.out.empty()) throw Error("study merge: --out DIR is required");
        const auto missing = study::merge_studies(dirs, a.out, own_command_line());
        std::printf("merged %zu folders into %s/study.csv\n", dirs.size(), a.out.c_str());
        if (!missing.empty())
            std::printf("warning: %zu points are missing (first: %lld); run the missing shards and merge again\n",
                        missing.size(), static_cast<long long>(missing.front()));
        if (!a.no_plot) make_figures(a.out);
        return;
    }
    if (a.positional.size() > 1) throw Error("study: unexpected argument '" + a.positional[1] + "'");
    study::StudyOptions& o = a.o;
    o.sweep = study::parse_sweep(what);
    if (!a.out.empty()) o.out_dir = a.out;
    if (!a.shard.empty()) study::parse_shard(a.shard, o.shard_index, o.shard_count);
    const bool simulates = o.sweep == study::Sweep::integrator || o.sweep == study::Sweep::stability;
    o.repeat = a.repeat != Args::kUnset ? a.repeat : (simulates ? 1 : 3);
    o.warmup = a.warmup != Args::kUnset ? a.warmup : (simulates ? 0 : 1);
    if (o.repeat < 1) throw Error("--repeat: must be >= 1, found " + std::to_string(o.repeat));
    if (o.warmup < 0) throw Error("--warmup: must be >= 0, found " + std::to_string(o.warmup));
    o.oracle = !a.no_oracle;
    o.penetration = !a.no_penetration;
    if (a.points != 0 || a.from != 0 || a.to != 0) {
        if (a.points < 1) throw Error("--points: must be >= 1 with --from/--to, found " + std::to_string(a.points));
        if (!(a.from > 0) || !(a.to > 0)) throw Error("--from/--to: must be > 0");
        if (a.from > a.to || (a.points == 1 && a.from != a.to))
            throw Error("--from/--to/--points: empty range (need FROM <= TO)");
        char buf[128];
        switch (o.sweep) {
        case study::Sweep::cell_size: // factors of the mean edge
            std::snprintf(buf, sizeof buf, "x%.10g:x%.10g:%d", a.from, a.to, a.points);
            o.cell_size = {buf};
            break;
        case study::Sweep::table_size: // factors of the vertex count
            std::snprintf(buf, sizeof buf, "x%.10g:x%.10g:%d", a.from, a.to, a.points);
            o.table_size = {buf};
            break;
        case study::Sweep::integrator: // time steps in seconds
            std::snprintf(buf, sizeof buf, "%.10g:%.10g:%d", a.from, a.to, a.points);
            o.dt = {buf};
            break;
        default:
            throw Error("--from/--to/--points: only for the cell-size, table-size and integrator sweeps");
        }
    }
    o.command_line = own_command_line();
#ifdef TETHASH_CXX_FLAGS
    o.compiler_flags = TETHASH_CXX_FLAGS;
#endif
    auto plan = study::plan_study(o); // every check happens here, before any measurement

    g_stop.store(false);
    auto old_handler = std::signal(SIGINT, on_sigint);
    study::RunHooks hooks;
    const bool quiet = a.quiet;
    hooks.on_point = [quiet](std::int64_t k, std::int64_t of, const study::PointInfo& p) { progress(k, of, p, quiet); };
    hooks.on_note = [quiet](const std::string& n) {
        if (quiet) return;
        std::fprintf(stderr, "%sstudy: %s\n", stderr_is_terminal() ? "\r\033[K" : "", n.c_str());
    };
    hooks.stop = &g_stop;
    study::StudyResult res;
    try {
        res = study::run_study(*plan, hooks);
    } catch (...) {
        std::signal(SIGINT, old_handler);
        throw;
    }
    std::signal(SIGINT, old_handler);
    if (!quiet && stderr_is_terminal()) std::fprintf(stderr, "\r\033[K");
    std::printf("study %s: %lld of %lld points (%lld in all shards), %lld rows -> %s, %s\n", what.c_str(),
                static_cast<long long>(res.points_done), static_cast<long long>(res.points_planned),
                static_cast<long long>(study::points_total(*plan)), static_cast<long long>(res.rows),
                res.csv_path.c_str(), res.json_path.c_str());
    if (res.interrupted)
        throw RunFailure("interrupted after " + std::to_string(res.points_done) + " points; " + res.csv_path +
                         " keeps the " + std::to_string(res.rows) + " rows measured");
    if (!a.no_plot) make_figures(o.out_dir);
}

Registrar reg{
    {"study",
     "Parameter studies: sweeps of cell size, table size, hash, threads, a grid of two, the broad-phase method, or "
     "the simulator's integrator x dt x substeps, or its stability matrix, or the spheres experiment of the octree / "
     "k-d / BSP comparison; CSV, JSON and figures",
     [](CLI::App& sub) {
         auto a = std::make_shared<Args>();
         sub.add_option("sweep", a->positional,
                        "cell-size | table-size | hash | threads | grid | method | integrator | stability | spheres, "
                        "or: merge DIR...")
             ->required();
         sub.add_option("--mesh", a->o.meshes,
                        "tet mesh files, one scene each ('a.vtu+b.vtu' joins files into one scene)");
         sub.add_option("--scene", a->o.scene_file, "simulator scene (TOML) for the integrator sweep");
         sub.add_flag("--teschner-scenarios", a->o.teschner, "the five scenarios of Teschner et al. 2003");
         sub.add_option("--scenarios", a->o.scenarios,
                        "with or instead of --teschner-scenarios: which (1..5), e.g. 1,5")
             ->delimiter(',');
         sub.add_option("--cell-size", a->o.cell_size,
                        "cell sizes: xF (F x the mean edge), L (a length) or auto; a list 'x0.5,x1,x2' or a log range "
                        "xFROM:xTO:POINTS (or FROM:TO:POINTS of lengths) (default: x0.125:x8:13 when swept, "
                        "x0.25:x4:9 in a grid, else auto)");
         sub.add_option("--table-size", a->o.table_size,
                        "table sizes: N, auto, xF (F x vertices), or range xFROM:xTO:POINTS (primes and powers of two; "
                        "default: x0.01:x100:9 when swept, x0.03:x30:4 in a grid, else auto)");
         sub.add_option("--hash", a->o.hash,
                        "hash functions: teschner, column, all (default: all when swept, else column)");
         sub.add_option("--threads", a->o.threads,
                        "thread counts: list or FROM:TO (0 = every hardware thread; default 1; threads sweep: "
                        "1..cores)");
         sub.add_option("--partition-scenes", a->o.partition_scenes,
                        "scenes of the space-partition comparison: bars, sizes, corner, thin, building, walled, hall "
                        "or all (hash "
                        "at its worst; many objects each touching several; rooms and doors for portals)")
             ->delimiter(',');
         // --methods and --leaf-size are shared with the spheres study (study_spheres.cpp registers them).
         sub.add_option("--max-depth", a->o.max_depth, "trees: deepest levels, list (default: the method's)");
         sub.add_option("--looseness", a->o.looseness, "loose octree: enlargement factors 1..16, list (default 2)");
         sub.add_option("--levels", a->o.levels, "hierarchical grid: most levels, list (default: as sizes span)");
         sub.add_option("--grid", a->o.grid, "grid sweep: the two parameters (cell-size, table-size, hash, threads)")
             ->delimiter(',');
         sub.add_option("--from", a->from,
                        "range start of the swept parameter (cell factor, table factor of vertices, dt in s)");
         sub.add_option("--to", a->to, "range end");
         sub.add_option("--points", a->points, "number of log-spaced points");
         sub.add_option("--integrator", a->o.integrator,
                        "integrators: vbd, implicit_euler, symplectic_euler, all; a list 'vbd,symplectic_euler' "
                        "(default: all)")
             ->delimiter(',');
         sub.add_option("--dt", a->o.dt,
                        "time steps in s (list, FROM:TO:POINTS, xF = F x the scene's dt; default: x0.25:x4:5; "
                        "stability: 1e-3,1/240,1/60 where xF = F x 1/240)");
         sub.add_option("--substeps", a->o.substeps, "substep counts (default: 1)");
         sub.add_option("--young", a->o.young,
                        "stability sweep: Young's moduli in Pa, list or FROM:TO:POINTS (default: 1e3,1e5,1e7,1e9)");
         sub.add_option("--mass-ratio", a->o.mass_ratio,
                        "stability sweep: density of the first body over the second (default: 1,1e3,1e6)");
         sub.add_option("--size", a->o.size,
                        "stability sweep: body sizes in m (longest extent), list or FROM:TO:POINTS (default: 1; "
                        "try 0.05,0.15,1,5)");
         sub.add_option("--duration", a->o.duration, "simulated seconds (default: the scene's, at most 0.5)");
         sub.add_option("--samples", a->o.samples, "fixed times where the position error is taken")
             ->capture_default_str();
         sub.add_option("--reference-factor", a->o.reference_factor, "reference dt = smallest dt / this")
             ->capture_default_str();
         sub.add_option("--repeat", a->repeat, "measured repeats per point (default 3; integrator: 1)");
         sub.add_option("--warmup", a->warmup, "unmeasured runs before the repeats (default 1; integrator: 0)");
         sub.add_flag("--no-oracle", a->no_oracle, "do not compare with the brute-force oracle");
         sub.add_flag("--no-penetration", a->no_penetration, "do not measure the penetration-depth error");
         sub.add_option("--shard", a->shard, "I/N: run points with index % N == I (0 <= I < N)");
         sub.add_option("-o,--out", a->out, "output folder, made if missing (default: study; spheres: spheres)");
         sub.add_flag("--no-plot", a->no_plot, "do not run tools/plot_study.py");
         sub.add_flag("--quiet", a->quiet, "no progress output");
         add_spheres_options(sub, a->spheres);
         sub.callback([a]() { run(*a); });
     }}};

} // namespace
} // namespace tethash::cli
