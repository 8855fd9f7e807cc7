// Parameter studies of the detector: planning (validation, scenes, points), measuring, CSV/JSON output,
// merging shards.
#include "tethash/study/study.hpp"

#include "internal.hpp"

#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/penetration.hpp"
#include "tethash/study/scenarios.hpp"
#if __has_include("tethash/oracle.hpp")
#include "tethash/oracle.hpp"
#define TETHASH_STUDY_HAVE_ORACLE 1
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <thread>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace tethash::study {

namespace fs = std::filesystem;

// ---------------------------------------------------------------- small helpers

std::int64_t now_ns()
{
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

double elapsed_ms(std::int64_t start_ns)
{
    return static_cast<double>(now_ns() - start_ns) * 1e-6;
}

std::string json_escape(const std::string& s)
{
    std::string o = "\"";
    for (unsigned char c : s) {
        switch (c) {
        case '"':
            o += "\\\"";
            break;
        case '\\':
            o += "\\\\";
            break;
        case '\n':
            o += "\\n";
            break;
        case '\r':
            o += "\\r";
            break;
        case '\t':
            o += "\\t";
            break;
        default:
            if (c < 0x20) {
                char buf[8];
                std::snprintf(buf, sizeof buf, "\\u%04x", c);
                o += buf;
            } else {
                o += static_cast<char>(c);
            }
        }
    }
    return o + "\"";
}

namespace {

std::vector<std::string> split(const std::string& s, char sep)
{
    std::vector<std::string> out;
    std::string cur;
    for (char c : s) {
        if (c == sep) {
            out.push_back(cur);
            cur.clear();
        } else {
            cur += c;
        }
    }
    out.push_back(cur);
    return out;
}

std::string trim(const std::string& s)
{
    const auto b = s.find_first_not_of(" \t");
    if (b == std::string::npos) return "";
    const auto e = s.find_last_not_of(" \t");
    return s.substr(b, e - b + 1);
}

/// All comma-separated items of all specs, trimmed; an empty item is an error.
std::vector<std::string> items_of(const std::vector<std::string>& specs, const std::string& option)
{
    std::vector<std::string> items;
    for (const auto& spec : specs)
        for (const auto& raw : split(spec, ',')) {
            const std::string it = trim(raw);
            if (it.empty()) throw Error(option + ": empty value in '" + spec + "'");
            items.push_back(it);
        }
    if (items.empty()) throw Error(option + ": empty list");
    return items;
}

double parse_number(const std::string& text, const std::string& option)
{
    std::size_t used = 0;
    double v = 0;
    try {
        v = std::stod(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used != text.size() || !std::isfinite(v)) throw Error(option + ": expected a number, found '" + text + "'");
    return v;
}

long long parse_integer(const std::string& text, const std::string& option)
{
    std::size_t used = 0;
    long long v = 0;
    try {
        v = std::stoll(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used != text.size()) throw Error(option + ": expected an integer, found '" + text + "'");
    return v;
}

/// "xF" → F · scale (scale > 0), otherwise the number itself.
double parse_scaled(const std::string& text, const std::string& option, double scale)
{
    if (!text.empty() && text[0] == 'x') {
        if (scale <= 0) throw Error(option + ": 'x' factors are not allowed here, found '" + text + "'");
        return parse_number(text.substr(1), option) * scale;
    }
    // A fraction such as 1/240 (time steps are usually given so).
    if (const auto slash = text.find('/'); slash != std::string::npos) {
        const double den = parse_number(text.substr(slash + 1), option);
        if (!(den != 0)) throw Error(option + ": division by zero in '" + text + "'");
        return parse_number(text.substr(0, slash), option) / den;
    }
    return parse_number(text, option);
}

/// Log-spaced values from..to (points ≥ 1; one point: from, which must equal to).
std::vector<double> log_range(const std::string& item, const std::string& option, double scale)
{
    const auto parts = split(item, ':');
    if (parts.size() != 3) throw Error(option + ": expected FROM:TO:POINTS, found '" + item + "'");
    const double a = parse_scaled(trim(parts[0]), option, scale), b = parse_scaled(trim(parts[1]), option, scale);
    const long long n = parse_integer(trim(parts[2]), option);
    if (a <= 0 || b <= 0) throw Error(option + ": range '" + item + "' must have FROM > 0 and TO > 0");
    if (n < 1 || a > b || (n == 1 && a != b))
        throw Error(option + ": empty range '" + item + "' (need FROM <= TO and POINTS >= 1)");
    if (n > 100000) throw Error(option + ": range '" + item + "' has too many points");
    std::vector<double> v;
    for (long long i = 0; i < n; ++i)
        v.push_back(n == 1 ? a : a * std::pow(b / a, static_cast<double>(i) / static_cast<double>(n - 1)));
    return v;
}

bool is_prime(std::int64_t n)
{
    if (n < 2) return false;
    if (n % 2 == 0) return n == 2;
    for (std::int64_t d = 3; d * d <= n; d += 2)
        if (n % d == 0) return false;
    return true;
}

std::int64_t next_prime(std::int64_t n)
{
    if (n <= 2) return 2;
    while (!is_prime(n))
        ++n;
    return n;
}

} // namespace

std::vector<double> parse_real_list(const std::vector<std::string>& specs, const std::string& option,
                                    double scale_for_x, bool log_ranges)
{
    std::vector<double> out;
    for (const auto& it : items_of(specs, option)) {
        if (it.find(':') != std::string::npos) {
            if (!log_ranges) throw Error(option + ": ranges are not allowed here, found '" + it + "'");
            for (double v : log_range(it, option, scale_for_x))
                out.push_back(v);
        } else {
            const double v = parse_scaled(it, option, scale_for_x);
            if (!(v > 0)) throw Error(option + ": value " + it + " must be > 0");
            out.push_back(v);
        }
    }
    return out;
}

std::vector<int> parse_int_list(const std::vector<std::string>& specs, const std::string& option)
{
    std::vector<int> out;
    for (const auto& it : items_of(specs, option)) {
        const auto parts = split(it, ':');
        if (parts.size() == 1) {
            const long long v = parse_integer(it, option);
            if (v < 1 || v > 1000000) throw Error(option + ": value " + it + " must be >= 1");
            out.push_back(static_cast<int>(v));
        } else if (parts.size() == 2) {
            const long long a = parse_integer(trim(parts[0]), option), b = parse_integer(trim(parts[1]), option);
            if (a < 1 || b < a || b > 1000000)
                throw Error(option + ": empty range '" + it + "' (need 1 <= FROM <= TO)");
            for (long long v = a; v <= b; ++v)
                out.push_back(static_cast<int>(v));
        } else {
            throw Error(option + ": expected N or FROM:TO, found '" + it + "'");
        }
    }
    return out;
}

Sweep parse_sweep(const std::string& name)
{
    if (name == "cell-size") return Sweep::cell_size;
    if (name == "table-size") return Sweep::table_size;
    if (name == "hash") return Sweep::hash;
    if (name == "threads") return Sweep::threads;
    if (name == "grid") return Sweep::grid;
    if (name == "integrator") return Sweep::integrator;
    if (name == "stability") return Sweep::stability;
    throw Error("sweep: unknown sweep '" + name +
                "' (expected cell-size, table-size, hash, threads, grid, integrator or stability)");
}

const char* to_string(Sweep s)
{
    switch (s) {
    case Sweep::cell_size:
        return "cell-size";
    case Sweep::table_size:
        return "table-size";
    case Sweep::hash:
        return "hash";
    case Sweep::threads:
        return "threads";
    case Sweep::grid:
        return "grid";
    case Sweep::integrator:
        return "integrator";
    case Sweep::stability:
        return "stability";
    }
    return "?";
}

void parse_shard(const std::string& spec, int& index, int& count)
{
    const auto parts = split(spec, '/');
    if (parts.size() != 2) throw Error("--shard: expected I/N (0 <= I < N), found '" + spec + "'");
    long long i = 0, n = 0;
    try {
        i = parse_integer(trim(parts[0]), "--shard");
        n = parse_integer(trim(parts[1]), "--shard");
    } catch (const Error&) {
        throw Error("--shard: expected I/N (0 <= I < N), found '" + spec + "'");
    }
    if (n < 1 || i < 0 || i >= n || n > 1000000)
        throw Error("--shard: expected I/N (0 <= I < N), found '" + spec + "'");
    index = static_cast<int>(i);
    count = static_cast<int>(n);
}

std::string PointInfo::label() const
{
    std::string s = scene;
    for (const auto& [k, v] : params)
        s += " " + k + "=" + v;
    return s;
}

// ---------------------------------------------------------------- planning

namespace {

const std::vector<std::string> k_detect_columns = {
    "point",           "repeat",          "scene",
    "sweep",           "objects",         "cell_factor",
    "table_request",   "table_kind",      "hash",
    "threads_request", "cell_size",       "table_size",
    "threads",         "vertices",        "tets",
    "cells_visited",   "entries_scanned", "hash_collisions",
    "collision_rate",  "box_rejections",  "own_vertex_skips",
    "inside_tests",    "exact_fallbacks", "degenerate_tets",
    "contacts",        "table_load",      "memory_bytes",
    "oracle_contacts", "missed",          "extra",
    "pen_pairs",       "depth_err_rms",   "depth_err_max",
    "depth_exact_max", "ms_total",        "ms_vertices",
    "ms_tets",         "ms_inside",       "ms_sort",
    "ms_wall",         "ms_penetration",
};

std::vector<SceneData> load_scenes(const StudyOptions& o)
{
    std::vector<SceneData> scenes;
    // Check every file first: a missing mesh is reported before anything is read.
    for (const auto& entry : o.meshes)
        for (const auto& file : split(entry, '+')) {
            if (file.empty()) throw Error("--mesh: empty file name in '" + entry + "'");
            if (!fs::exists(file)) throw Error("--mesh: file not found: " + file);
            if (fs::is_directory(file)) throw Error("--mesh: " + file + ": is a directory, expected a mesh file");
            if (!io::is_tet_mesh_path(file)) throw Error("--mesh: not a tet mesh format: " + file);
        }
    for (const auto& entry : o.meshes) {
        SceneData s;
        s.source = entry;
        std::string name;
        for (const auto& file : split(entry, '+')) {
            TetMesh m = io::read_tet_mesh(file);
            if (s.mesh.num_vertices() == 0 && s.mesh.num_tets() == 0) {
                s.mesh = std::move(m);
                s.mesh.ensure_object_ids();
            } else {
                s.mesh.append(m);
            }
            if (!name.empty()) name += "+";
            name += fs::path(file).stem().string();
        }
        s.name = name;
        scenes.push_back(std::move(s));
    }
    std::vector<int> which = o.scenarios;
    if (o.teschner && which.empty()) which = {1, 2, 3, 4, 5};
    for (int k : which)
        if (k < 1 || k > static_cast<int>(teschner_specs().size()))
            throw Error("--scenarios: scenario " + std::to_string(k) + " out of range 1..5");
    for (int k : which) {
        Scenario sc = teschner_scenario(k - 1);
        {
            SceneData s;
            s.name = sc.spec.name;
            s.source = "teschner scenario: " + std::to_string(sc.spec.objects) + " × generate " + sc.shape +
                       " resolution " + std::to_string(sc.resolution);
            s.mesh = std::move(sc.mesh);
            scenes.push_back(std::move(s));
        }
    }
    for (auto& s : scenes) {
        if (s.mesh.num_tets() == 0) throw Error("--mesh: " + s.source + " has no tetrahedra");
        s.mesh.check_consistency(s.source);
        s.mesh.ensure_object_ids();
        s.mean_edge = mean_edge_length(s.mesh.positions, s.mesh.tets);
    }
    return scenes;
}

/// A cell size of the study: a factor of each scene's mean edge length, or a length.
struct CellChoice {
    double value = 1;
    bool factor = true;
};

/// The cell-size grammar of every command (detect.hpp: L a length, xF a factor of the mean edge, auto), plus
/// log ranges "xFROM:xTO:POINTS" (factors) and "FROM:TO:POINTS" (lengths).
std::vector<CellChoice> cell_choices(const std::vector<std::string>& specs)
{
    const std::string opt = "--cell-size";
    std::vector<CellChoice> out;
    for (const auto& it : items_of(specs, opt)) {
        if (it.find(':') != std::string::npos) {
            const auto parts = split(it, ':');
            const auto is_x = [](const std::string& p) { return !p.empty() && (p[0] == 'x' || p[0] == 'X'); };
            const bool factor = parts.size() == 3 && is_x(trim(parts[0])) && is_x(trim(parts[1]));
            if (parts.size() == 3 && !factor && (is_x(trim(parts[0])) || is_x(trim(parts[1]))))
                throw Error(opt + ": range '" + it +
                            "' mixes a factor and a length (write xFROM:xTO:POINTS for "
                            "factors of the mean edge, FROM:TO:POINTS for lengths)");
            std::string plain = it;
            plain.erase(std::remove_if(plain.begin(), plain.end(), [](char c) { return c == 'x' || c == 'X'; }),
                        plain.end());
            for (double v : log_range(plain, opt, -1))
                out.push_back({v, factor});
        } else {
            DetectParams p;
            parse_cell_size(it, p, opt);
            out.push_back({p.cell_size, p.cell_size_mode != DetectParams::CellSizeMode::absolute});
        }
    }
    return out;
}

struct TableChoice {
    std::int64_t size = 0;
    std::string kind, request;
};

std::vector<TableChoice> table_choices(const std::vector<std::string>& specs, std::int64_t vertices)
{
    std::vector<TableChoice> out;
    const std::string opt = "--table-size";
    const double scale = static_cast<double>(std::max<std::int64_t>(vertices, 1));
    for (const auto& it : items_of(specs, opt)) {
        if (it == "auto") {
            out.push_back({0, "auto", it});
        } else if (it.find(':') != std::string::npos) {
            for (double v : log_range(it, opt, scale)) {
                const auto target = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(v)));
                out.push_back({next_power_of_two(target), "pow2", it});
                out.push_back({next_prime(target), "prime", it});
            }
        } else { // the grammar of every command (detect.hpp)
            const bool factor = it[0] == 'x' || it[0] == 'X';
            out.push_back({parse_table_size(it, vertices, opt), factor ? "pow2" : "given", it});
        }
    }
    // Ranges can give one size twice (a power of two that is also the next prime: 2): keep the first.
    std::vector<TableChoice> unique;
    for (const auto& c : out) {
        bool dup = false;
        for (const auto& u : unique)
            dup = dup || (u.size == c.size && u.kind == c.kind);
        if (!dup) unique.push_back(c);
    }
    return unique;
}

/// Thread counts: the grammar of every command (detect.hpp: 0 = every hardware thread) and ranges FROM:TO.
std::vector<int> thread_choices(const std::vector<std::string>& specs)
{
    const std::string opt = "--threads";
    std::vector<int> out;
    for (const auto& it : items_of(specs, opt)) {
        const auto parts = split(it, ':');
        if (parts.size() == 1) {
            out.push_back(parse_threads(it, opt));
        } else if (parts.size() == 2) {
            const int a = parse_threads(trim(parts[0]), opt), b = parse_threads(trim(parts[1]), opt);
            if (a < 1 || b < a) throw Error(opt + ": empty range '" + it + "' (need 1 <= FROM <= TO)");
            for (int v = a; v <= b; ++v)
                out.push_back(v);
        } else {
            throw Error(opt + ": expected N or FROM:TO, found '" + it + "'");
        }
    }
    return out;
}

std::vector<HashFunction> hash_choices(const std::vector<std::string>& specs)
{
    std::vector<HashFunction> out;
    for (const auto& it : items_of(specs, "--hash")) {
        if (it == "all") {
            out.push_back(HashFunction::teschner);
            out.push_back(HashFunction::column);
        } else if (it == "default") {
            out.push_back(DetectParams{}.hash);
        } else {
            out.push_back(parse_hash_function(it));
        }
    }
    return out;
}

void plan_detection(StudyPlan& plan)
{
    const StudyOptions& o = plan.options;
    const bool is_grid = o.sweep == Sweep::grid;
    auto swept = [&](const std::string& param) {
        if (is_grid) return std::find(o.grid.begin(), o.grid.end(), param) != o.grid.end();
        return std::string(to_string(o.sweep)) == param;
    };
    if (is_grid) {
        if (o.grid.size() != 2 || o.grid[0] == o.grid[1])
            throw Error("--grid: expected two different parameters (cell-size, table-size, hash, threads)");
        for (const auto& g : o.grid)
            if (g != "cell-size" && g != "table-size" && g != "hash" && g != "threads")
                throw Error("--grid: unknown parameter '" + g + "' (expected cell-size, table-size, hash or threads)");
    }
    const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
    const auto cell_specs = !o.cell_size.empty() ? o.cell_size
                            : swept("cell-size") ? std::vector<std::string>{is_grid ? "x0.25:x4:9" : "x0.125:x8:13"}
                                                 : std::vector<std::string>{"auto"};
    const auto table_specs = !o.table_size.empty() ? o.table_size
                             : swept("table-size") ? std::vector<std::string>{is_grid ? "x0.03:x30:4" : "x0.01:x100:9"}
                                                   : std::vector<std::string>{"auto"};
    const auto hash_specs = !o.hash.empty() ? o.hash
                            : swept("hash") ? std::vector<std::string>{"all"}
                                            : std::vector<std::string>{"default"};
    const auto thread_specs = !o.threads.empty() ? o.threads
                              : swept("threads") ? std::vector<std::string>{"1:" + std::to_string(hw)}
                                                 : std::vector<std::string>{"1"};

    // Validate every list before loading anything.
    const auto cells = cell_choices(cell_specs);
    const auto hashes = hash_choices(hash_specs);
    const auto threads = thread_choices(thread_specs);
    (void)table_choices(table_specs, 0); // syntax and value checks

    plan.scenes = load_scenes(o);
    if (plan.scenes.empty())
        throw Error("no scene: give --mesh FILE, --teschner-scenarios (or --scene FILE for the integrator sweep)");

    plan.columns = k_detect_columns;
    for (std::size_t s = 0; s < plan.scenes.size(); ++s) {
        const auto tables = table_choices(table_specs, plan.scenes[s].mesh.num_vertices());
        for (const auto& t : tables)
            for (HashFunction h : hashes)
                for (int th : threads)
                    for (const CellChoice& cc : cells) {
                        const double mean_edge = plan.scenes[s].mean_edge;
                        const double c = cc.factor ? cc.value : cc.value / (mean_edge > 0 ? mean_edge : 1.0);
                        DetectPoint p{s, c, t.size, t.kind, t.request, h, th};
                        PointInfo info;
                        info.index = static_cast<std::int64_t>(plan.points.size());
                        info.scene = plan.scenes[s].name;
                        info.params = {{"cell_factor", fmt_double(c)},
                                       {"table_request", t.request},
                                       {"table_size", t.size ? std::to_string(t.size) : "auto"},
                                       {"hash", to_string(h)},
                                       {"threads", std::to_string(th)}};
                        plan.points.push_back(std::move(info));
                        plan.detect_points.push_back(p);
                    }
    }
}

// ---------------------------------------------------------------- measuring detection points

/// (vertex, tet) pairs of `got` missing from / extra to `want` (both sorted by vertex, then tet).
std::pair<std::int64_t, std::int64_t> compare_contacts(const std::vector<Contact>& got,
                                                       const std::vector<Contact>& want)
{
    auto key = [](const Contact& c) { return std::pair<Index, Index>(c.vertex, c.tet); };
    std::int64_t missed = 0, extra = 0;
    std::size_t i = 0, j = 0;
    while (i < got.size() || j < want.size()) {
        if (j == want.size() || (i < got.size() && key(got[i]) < key(want[j]))) {
            ++extra;
            ++i;
        } else if (i == got.size() || key(want[j]) < key(got[i])) {
            ++missed;
            ++j;
        } else {
            ++i;
            ++j;
        }
    }
    return {missed, extra};
}

struct PenetrationResult {
    bool available = false;
    std::int64_t pairs = 0;
    double err_rms = 0, err_max = 0, exact_max = 0, ms = 0;
};

std::vector<Row> run_detect_point(StudyPlan& plan, std::int64_t index, const RunHooks& hooks)
{
    std::vector<std::string>& notes = plan.notes;
    const StudyOptions& o = plan.options;
    const DetectPoint& p = plan.detect_points[static_cast<std::size_t>(index)];
    SceneData& scene = plan.scenes[p.scene];
    const TetMesh& mesh = scene.mesh;

    // The oracle, once per scene.
    if (o.oracle && !scene.oracle && !scene.oracle_failed) {
#ifdef TETHASH_STUDY_HAVE_ORACLE
        const auto t0 = now_ns();
        scene.oracle = brute_force_contacts(mesh.positions, mesh.tets, mesh.vertex_object, mesh.tet_object,
                                            std::span<const ObjectOptions>{});
        const std::string note = "oracle for " + scene.name + ": " + std::to_string(scene.oracle->size()) +
                                 " contacts in " + fmt_double(elapsed_ms(t0) / 1000.0) + " s";
        notes.push_back(note);
        if (hooks.on_note) hooks.on_note(note);
#else
        scene.oracle_failed = true;
        notes.push_back("oracle not available in this build: missed/extra left empty");
        if (hooks.on_note) hooks.on_note(notes.back());
#endif
    }

    DetectParams dp;
    dp.cell_size_mode = DetectParams::CellSizeMode::factor_of_mean_edge;
    dp.cell_size = p.cell_factor;
    dp.table_size = p.table_size;
    dp.hash = p.hash;
    dp.threads = p.threads;
    Detector det(dp);
    det.set_topology(mesh);
    for (int w = 0; w < o.warmup; ++w)
        det.detect(mesh.positions);

    // Penetration depth error (Heidelberger et al. 2004 against the exact distance), once per point.
    PenetrationResult pen;
    if (o.penetration) {
        try {
            std::vector<Contact> contacts = det.detect(mesh.positions);
            Penetration pn;
            pn.set_topology(mesh);
            PenetrationStats ps;
            const auto t0 = now_ns();
            pn.compute(mesh.positions, contacts, &ps);
            pen.ms = elapsed_ms(t0);
            const auto exact = pn.exact_depths(mesh.positions, contacts);
            double sum = 0;
            for (std::size_t i = 0; i < contacts.size(); ++i) {
                const double e = std::abs(contacts[i].depth - exact[i]);
                sum += e * e;
                pen.err_max = std::max(pen.err_max, e);
                pen.exact_max = std::max(pen.exact_max, exact[i]);
            }
            pen.err_rms = contacts.empty() ? 0 : std::sqrt(sum / static_cast<double>(contacts.size()));
            pen.pairs = ps.pairs;
            pen.available = true;
        } catch (const std::exception& e) {
            const std::string what = e.what();
            if (what.find("not implemented") == std::string::npos) throw;
            plan.options.penetration = false;
            notes.push_back(std::string("penetration depth unavailable (") + what + "): columns left empty");
            if (hooks.on_note) hooks.on_note(notes.back());
        }
    }

    std::vector<Row> rows;
    for (int r = 0; r < o.repeat; ++r) {
        if (hooks.stop && hooks.stop->load()) break;
        DetectStats st;
        const auto t0 = now_ns();
        const std::vector<Contact>& got = det.detect(mesh.positions, &st);
        const double wall = elapsed_ms(t0);
        std::string oc, missed, extra;
        if (scene.oracle) {
            const auto [m, x] = compare_contacts(got, *scene.oracle);
            oc = std::to_string(scene.oracle->size());
            missed = std::to_string(m);
            extra = std::to_string(x);
        }
        const double rate = st.entries_scanned ? static_cast<double>(st.hash_collisions) / st.entries_scanned : 0.0;
        auto i64 = [](std::int64_t v) { return std::to_string(v); };
        Row row = {std::to_string(index),
                   std::to_string(r),
                   scene.name,
                   to_string(o.sweep),
                   std::to_string(mesh.num_objects()),
                   fmt_double(p.cell_factor),
                   p.table_request,
                   p.table_kind,
                   to_string(p.hash),
                   std::to_string(p.threads),
                   fmt_double(st.cell_size),
                   i64(st.table_size),
                   std::to_string(st.threads),
                   i64(st.vertices),
                   i64(st.tets),
                   i64(st.cells_visited),
                   i64(st.entries_scanned),
                   i64(st.hash_collisions),
                   fmt_double(rate),
                   i64(st.box_rejections),
                   i64(st.own_vertex_skips),
                   i64(st.inside_tests),
                   i64(st.exact_fallbacks),
                   i64(st.degenerate_tets),
                   i64(st.contacts),
                   fmt_double(st.table_load),
                   i64(st.memory_bytes),
                   oc,
                   missed,
                   extra,
                   pen.available ? i64(pen.pairs) : "",
                   pen.available ? fmt_double(pen.err_rms) : "",
                   pen.available ? fmt_double(pen.err_max) : "",
                   pen.available ? fmt_double(pen.exact_max) : "",
                   fmt_double(st.ms_total),
                   fmt_double(st.ms_vertices),
                   fmt_double(st.ms_tets),
                   fmt_double(st.ms_inside),
                   fmt_double(st.ms_sort),
                   fmt_double(wall),
                   pen.available ? fmt_double(pen.ms) : ""};
        rows.push_back(std::move(row));
    }
    return rows;
}

std::string read_file_text(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::string utc_now()
{
    const std::time_t t = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}

/// A CSV value as JSON: a number when it parses as one, else a string ("" → null).
std::string json_value(const std::string& v)
{
    if (v.empty()) return "null";
    char* end = nullptr;
    const double d = std::strtod(v.c_str(), &end);
    if (end && *end == '\0' && std::isfinite(d) && v.find_first_of("xX") == std::string::npos) return v;
    return json_escape(v);
}

void write_json(const std::string& path, const std::string& text)
{
    io::write_text_file(path, text);
}

} // namespace

namespace {

/// Checks, without creating anything, that the folder `dir` exists or can be made (run_study makes it)
/// and accepts files: the nearest existing ancestor must be a folder where files can be created.
void check_out_dir(const std::string& dir)
{
    fs::path p(dir);
    while (!p.empty() && !fs::exists(p) && p.has_parent_path() && p.parent_path() != p)
        p = p.parent_path();
    if (p.empty() || !fs::exists(p)) p = ".";
    if (!fs::is_directory(p)) throw Error("--out: " + dir + ": '" + p.string() + "' exists and is not a folder");
    io::check_output_file((p / "study.csv").string(), "--out " + dir);
}

/// Makes the output folder (and its parents).
void make_out_dir(const std::string& dir)
{
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw Error("--out: cannot create folder '" + dir + "': " + ec.message());
}

} // namespace

std::shared_ptr<StudyPlan> plan_study(const StudyOptions& options)
{
    auto plan = std::make_shared<StudyPlan>();
    plan->options = options;
    const StudyOptions& o = plan->options;
    if (o.repeat < 1) throw Error("--repeat: must be >= 1, found " + std::to_string(o.repeat));
    if (o.warmup < 0) throw Error("--warmup: must be >= 0, found " + std::to_string(o.warmup));
    if (o.shard_count < 1 || o.shard_index < 0 || o.shard_index >= o.shard_count)
        throw Error("--shard: expected I/N (0 <= I < N), found " + std::to_string(o.shard_index) + "/" +
                    std::to_string(o.shard_count));
    if (o.out_dir.empty()) throw Error("--out: empty folder name");
    check_out_dir(o.out_dir);
    if (o.sweep == Sweep::stability) {
        plan_stability_study(*plan);
    } else if (o.sweep == Sweep::integrator) {
        if (!o.meshes.empty() || o.teschner || !o.scenarios.empty())
            throw Error(
                "integrator sweep: takes --scene FILE (or the default scene), not --mesh / --teschner-scenarios");
        plan_sim_study(*plan);
    } else {
        if (!o.scene_file.empty())
            throw Error("--scene: only the integrator sweep takes a simulator scene; use --mesh for detection sweeps");
        plan_detection(*plan);
    }
    return plan;
}

std::int64_t points_total(const StudyPlan& plan)
{
    return static_cast<std::int64_t>(plan.points.size());
}

std::int64_t points_in_shard(const StudyPlan& plan)
{
    const std::int64_t n = points_total(plan), i = plan.options.shard_index, k = plan.options.shard_count;
    return n > i ? (n - i + k - 1) / k : 0;
}

const std::vector<std::string>& columns(const StudyPlan& plan)
{
    return plan.columns;
}

// ---------------------------------------------------------------- machine, summary, JSON

std::string machine_json(const std::string& compiler_flags)
{
    std::string cpu = "unknown";
    {
        std::ifstream in("/proc/cpuinfo");
        for (std::string line; std::getline(in, line);)
            if (line.rfind("model name", 0) == 0) {
                const auto colon = line.find(':');
                if (colon != std::string::npos) cpu = trim(line.substr(colon + 1));
                break;
            }
    }
    char host[256] = "unknown";
    std::ifstream("/proc/sys/kernel/hostname") >> host;
#ifdef _OPENMP
    const int omp_threads = omp_get_max_threads();
#else
    const int omp_threads = 1;
#endif
    std::ostringstream j;
    j << "{\"cores\": " << std::thread::hardware_concurrency() << ", \"cpu\": " << json_escape(cpu)
      << ", \"host\": " << json_escape(host) << ", \"openmp_max_threads\": " << omp_threads
#if defined(__clang__)
      << ", \"compiler\": " << json_escape(std::string("clang ") + __clang_version__)
#elif defined(__GNUC__)
      << ", \"compiler\": " << json_escape(std::string("g++ ") + __VERSION__)
#else
      << ", \"compiler\": \"unknown\""
#endif
      << ", \"flags\": " << json_escape(compiler_flags) << ", \"date\": " << json_escape(utc_now()) << "}";
    return j.str();
}

std::string summary_json(const Table& t)
{
    const int ip = t.index_of("point");
    if (ip < 0) throw Error("study table: no 'point' column");
    std::map<long long, std::vector<const Row*>> groups;
    for (const Row& r : t.rows)
        groups[std::atoll(r[static_cast<std::size_t>(ip)].c_str())].push_back(&r);
    std::ostringstream j;
    j << "[";
    bool first_point = true;
    for (const auto& [point, rows] : groups) {
        j << (first_point ? "\n" : ",\n") << "    {\"point\": " << point << ", \"repeats\": " << rows.size();
        first_point = false;
        for (std::size_t c = 0; c < t.columns.size(); ++c) {
            const std::string& name = t.columns[c];
            if (name == "point" || name == "repeat") continue;
            if (!is_timing_column(name)) {
                j << ", " << json_escape(name) << ": " << json_value((*rows.front())[c]);
                continue;
            }
            std::vector<double> v;
            for (const Row* r : rows)
                if (!(*r)[c].empty()) v.push_back(std::strtod((*r)[c].c_str(), nullptr));
            if (v.empty()) {
                j << ", " << json_escape(name) << ": null";
                continue;
            }
            std::sort(v.begin(), v.end());
            const std::size_t n = v.size();
            const double median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
            j << ", " << json_escape(name) << ": {\"median\": " << fmt_double(median)
              << ", \"min\": " << fmt_double(v.front()) << ", \"max\": " << fmt_double(v.back()) << "}";
        }
        j << "}";
    }
    j << "\n  ]";
    return j.str();
}

// ---------------------------------------------------------------- running

StudyResult run_study(StudyPlan& plan, const RunHooks& hooks)
{
    const StudyOptions& o = plan.options;
    StudyResult res;
    make_out_dir(o.out_dir);
    res.csv_path = (fs::path(o.out_dir) / "study.csv").string();
    res.json_path = (fs::path(o.out_dir) / "study.json").string();
    res.points_planned = points_in_shard(plan);

    Table table;
    table.columns = plan.columns;
    CsvWriter csv;
    csv.open(res.csv_path, plan.columns);
    for (const auto& n : plan.notes)
        if (hooks.on_note) hooks.on_note(n);

    const auto t_start = now_ns();
    std::int64_t k = 0;
    for (std::int64_t i = o.shard_index; i < points_total(plan); i += o.shard_count) {
        if (hooks.stop && hooks.stop->load()) {
            res.interrupted = true;
            break;
        }
        if (hooks.on_point) hooks.on_point(k, res.points_planned, plan.points[static_cast<std::size_t>(i)]);
        std::vector<Row> rows = o.sweep == Sweep::integrator  ? run_sim_point(plan, i, hooks)
                                : o.sweep == Sweep::stability ? run_stability_point(plan, i, hooks)
                                                              : run_detect_point(plan, i, hooks);
        for (Row& r : rows) {
            csv.write(r);
            table.rows.push_back(std::move(r));
            ++res.rows;
        }
        if (hooks.stop && hooks.stop->load() && static_cast<int>(rows.size()) < o.repeat) {
            res.interrupted = true;
            break;
        }
        ++k;
        ++res.points_done;
    }
    csv.close();
    if (hooks.stop && hooks.stop->load()) res.interrupted = true;

    std::ostringstream j;
    j << "{\n  \"tethash_study\": 1,\n  \"sweep\": " << json_escape(to_string(o.sweep))
      << ",\n  \"command\": " << json_escape(o.command_line) << ",\n  \"machine\": " << machine_json(o.compiler_flags)
      << ",\n  \"points_total\": " << points_total(plan) << ",\n  \"shard\": {\"index\": " << o.shard_index
      << ", \"count\": " << o.shard_count << "},\n  \"points_planned\": " << res.points_planned
      << ",\n  \"points_done\": " << res.points_done << ",\n  \"rows\": " << res.rows << ",\n  \"repeat\": " << o.repeat
      << ",\n  \"warmup\": " << o.warmup << ",\n  \"interrupted\": " << (res.interrupted ? "true" : "false")
      << ",\n  \"seconds\": " << fmt_double(elapsed_ms(t_start) / 1000.0) << ",\n  \"scenes\": [";
    for (std::size_t s = 0; s < plan.scenes.size(); ++s) {
        const auto& sc = plan.scenes[s];
        j << (s ? ", " : "") << "{\"name\": " << json_escape(sc.name) << ", \"source\": " << json_escape(sc.source)
          << ", \"objects\": " << sc.mesh.num_objects() << ", \"vertices\": " << sc.mesh.num_vertices()
          << ", \"tets\": " << sc.mesh.num_tets() << ", \"mean_edge\": " << fmt_double(sc.mean_edge) << "}";
    }
    j << "],\n  \"notes\": [";
    for (std::size_t n = 0; n < plan.notes.size(); ++n)
        j << (n ? ", " : "") << json_escape(plan.notes[n]);
    j << "],\n  \"summary\": " << summary_json(table) << "\n}\n";
    write_json(res.json_path, j.str());
    res.notes = plan.notes;
    return res;
}

// ---------------------------------------------------------------- merging shards

std::vector<std::int64_t> merge_studies(const std::vector<std::string>& dirs, const std::string& out_dir,
                                        const std::string& command_line)
{
    if (dirs.empty()) throw Error("study merge: no input folders");
    for (const auto& d : dirs)
        if (!fs::exists(fs::path(d) / "study.csv"))
            throw Error("study merge: " + (fs::path(d) / "study.csv").string() + ": file not found");
    Table merged;
    std::vector<std::string> jsons;
    long long total = -1;
    std::string sweep = "\"?\"";
    for (const auto& d : dirs) {
        const std::string csv = (fs::path(d) / "study.csv").string();
        Table t = Table::read_csv(csv);
        if (merged.columns.empty()) {
            merged.columns = t.columns;
        } else if (t.columns != merged.columns) {
            throw Error("study merge: " + csv + ": columns differ from " +
                        (fs::path(dirs.front()) / "study.csv").string());
        }
        for (auto& r : t.rows)
            merged.rows.push_back(std::move(r));
        const auto json_path = fs::path(d) / "study.json";
        if (fs::exists(json_path)) {
            const std::string text = read_file_text(json_path.string());
            jsons.push_back(text);
            std::smatch m;
            if (std::regex_search(text, m, std::regex("\"points_total\": ([0-9]+)")))
                total = std::max(total, std::stoll(m[1]));
            if (std::regex_search(text, m, std::regex("\"sweep\": (\"[^\"]*\")"))) sweep = m[1];
        }
    }
    const int ip = merged.index_of("point"), ir = merged.index_of("repeat");
    if (ip < 0 || ir < 0) throw Error("study merge: the CSV files have no 'point' and 'repeat' columns");
    auto key = [&](const Row& r) {
        return std::pair<long long, long long>(std::atoll(r[static_cast<std::size_t>(ip)].c_str()),
                                               std::atoll(r[static_cast<std::size_t>(ir)].c_str()));
    };
    std::stable_sort(merged.rows.begin(), merged.rows.end(),
                     [&](const Row& a, const Row& b) { return key(a) < key(b); });
    for (std::size_t i = 1; i < merged.rows.size(); ++i)
        if (key(merged.rows[i]) == key(merged.rows[i - 1]))
            throw Error("study merge: point " + std::to_string(key(merged.rows[i]).first) + " repeat " +
                        std::to_string(key(merged.rows[i]).second) + " appears twice (the same shard given twice?)");
    std::vector<std::int64_t> missing;
    if (total >= 0) {
        std::vector<char> seen(static_cast<std::size_t>(total), 0);
        for (const Row& r : merged.rows) {
            const long long p = key(r).first;
            if (p >= 0 && p < total) seen[static_cast<std::size_t>(p)] = 1;
        }
        for (long long p = 0; p < total; ++p)
            if (!seen[static_cast<std::size_t>(p)]) missing.push_back(p);
    }
    check_out_dir(out_dir);
    make_out_dir(out_dir);
    merged.write_csv((fs::path(out_dir) / "study.csv").string());
    std::ostringstream j;
    j << "{\n  \"tethash_study\": 1,\n  \"sweep\": " << sweep << ",\n  \"command\": " << json_escape(command_line)
      << ",\n  \"merged_from\": [";
    for (std::size_t i = 0; i < dirs.size(); ++i)
        j << (i ? ", " : "") << json_escape(dirs[i]);
    j << "],\n  \"points_total\": " << total << ",\n  \"rows\": " << merged.rows.size() << ",\n  \"missing_points\": [";
    for (std::size_t i = 0; i < missing.size(); ++i)
        j << (i ? ", " : "") << missing[i];
    j << "],\n  \"shards\": [";
    for (std::size_t i = 0; i < jsons.size(); ++i)
        j << (i ? ",\n" : "\n") << jsons[i];
    j << "],\n  \"summary\": " << summary_json(merged) << "\n}\n";
    write_json((fs::path(out_dir) / "study.json").string(), j.str());
    return missing;
}

} // namespace tethash::study
