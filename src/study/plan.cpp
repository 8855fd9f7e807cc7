// Planning a study (plan.hpp): validating the options, loading the scenes and expanding the value lists into
// points (the detection sweeps here; sim_study.cpp and stability_study.cpp plan theirs).
#include "plan.hpp"

#include "measure.hpp"
#include "report.hpp"
#include "value_list.hpp"

#include "core/hash/table_size.hpp"

#include "tethash/detect_grammar.hpp"
#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/study/methods.hpp"
#include "tethash/study/scenarios.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <thread>

namespace tethash::study {

namespace fs = std::filesystem;

std::string PointInfo::label() const
{
    std::string s = scene;
    for (const auto& [k, v] : params)
        s += " " + k + "=" + v;
    return s;
}

namespace {

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
        s.kind = "mesh";
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
            s.kind = "teschner";
            scenes.push_back(std::move(s));
        }
    }
    std::vector<std::string> partition_names;
    for (const auto& it :
         o.partition_scenes.empty() ? std::vector<std::string>{} : items_of(o.partition_scenes, "--partition-scenes")) {
        if (it == "all") {
            for (const auto& n : partition_scene_names())
                partition_names.push_back(n);
        } else if (std::find(partition_scene_names().begin(), partition_scene_names().end(), it) ==
                   partition_scene_names().end()) {
            throw Error("--partition-scenes: unknown scene '" + it +
                        "' (expected bars, sizes, corner, thin, building, walled, hall or all)");
        } else {
            partition_names.push_back(it);
        }
    }
    for (const auto& n : partition_names) {
        NamedScene ps = partition_scene(n);
        SceneData s;
        s.name = ps.name;
        s.source = "partition scene: " + ps.description;
        s.mesh = std::move(ps.mesh);
        s.cells = std::move(ps.cells);
        s.kind = "partition";
        scenes.push_back(std::move(s));
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

/// The methods of the study and, per partition parameter, its values ("default" or a number; checked).
std::vector<Method> method_choices(const std::vector<std::string>& specs)
{
    std::vector<Method> out;
    for (const auto& it : items_of(specs, "--methods"))
        for (Method m : parse_method_list(it, "--methods"))
            if (std::find(out.begin(), out.end(), m) == out.end()) out.push_back(m);
    return out;
}

std::vector<std::string> partition_choices(const std::vector<std::string>& specs, const std::string& option)
{
    if (specs.empty()) return {"default"};
    std::vector<std::string> out;
    for (const auto& it : items_of(specs, option)) {
        DetectParams p;
        parse_partition_param(option, it, p); // throws naming the option and the text
        out.push_back(it);
    }
    return out;
}

/// Every combination of the partition values that `m` reads (one empty combination for the others).
std::vector<std::vector<std::string>> partition_combinations(Method m,
                                                             const std::vector<std::vector<std::string>>& values)
{
    std::vector<std::vector<std::string>> combos = {{}};
    const auto& cols = partition_columns();
    for (std::size_t k = 0; k < cols.size(); ++k) {
        std::vector<std::vector<std::string>> next;
        for (const auto& c : combos) {
            if (!method_uses(m, cols[k].second)) {
                next.push_back(c);
                next.back().push_back("");
                continue;
            }
            for (const auto& v : values[k]) {
                next.push_back(c);
                next.back().push_back(v);
            }
        }
        combos = std::move(next);
    }
    return combos;
}

} // namespace

const std::vector<std::pair<std::string, std::string>>& partition_columns()
{
    static const std::vector<std::pair<std::string, std::string>> c = {{"max_depth", "--max-depth"},
                                                                       {"leaf_size", "--leaf-size"},
                                                                       {"looseness", "--looseness"},
                                                                       {"levels", "--levels"}};
    return c;
}

void plan_detection_study(StudyPlan& plan)
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
    const auto method_specs = !o.methods.empty() ? o.methods
                              : swept("method")  ? std::vector<std::string>{"all"}
                                                 : std::vector<std::string>{to_string(DetectParams{}.method)};
    const auto thread_specs = !o.threads.empty() ? o.threads
                              : swept("threads") ? std::vector<std::string>{"1:" + std::to_string(hw)}
                                                 : std::vector<std::string>{"1"};

    // Validate every list before loading anything.
    const auto cells = cell_choices(cell_specs);
    const auto hashes = hash_choices(hash_specs);
    const auto threads = thread_choices(thread_specs);
    const auto methods = method_choices(method_specs);
    const std::vector<std::vector<std::string>> partition_values = {
        partition_choices(o.max_depth, "--max-depth"), partition_choices(o.leaf_size, "--leaf-size"),
        partition_choices(o.looseness, "--looseness"), partition_choices(o.levels, "--levels")};
    (void)table_choices(table_specs, 0); // syntax and value checks

    plan.scenes = load_scenes(o);
    if (plan.scenes.empty())
        throw Error("no scene: give --mesh FILE, --teschner-scenarios, --partition-scenes (or --scene FILE for the "
                    "integrator sweep)");

    plan.columns = detect_columns();
    for (std::size_t s = 0; s < plan.scenes.size(); ++s) {
        const auto tables = table_choices(table_specs, plan.scenes[s].mesh.num_vertices());
        for (const auto& t : tables)
            for (HashFunction h : hashes)
                for (int th : threads)
                    for (const CellChoice& cc : cells)
                        for (Method m : methods)
                            for (const auto& combo : partition_combinations(m, partition_values)) {
                                const double mean_edge = plan.scenes[s].mean_edge;
                                const double c = cc.factor ? cc.value : cc.value / (mean_edge > 0 ? mean_edge : 1.0);
                                DetectPoint p{s, c, t.size, t.kind, t.request, h, th, m, {}, combo};
                                PointInfo info;
                                info.index = static_cast<std::int64_t>(plan.points.size());
                                info.scene = plan.scenes[s].name;
                                info.params = {{"cell_factor", fmt_double(c)},
                                               {"table_request", t.request},
                                               {"table_size", t.size ? std::to_string(t.size) : "auto"},
                                               {"hash", to_string(h)},
                                               {"threads", std::to_string(th)},
                                               {"method", to_string(m)}};
                                const auto& cols = partition_columns();
                                for (std::size_t k = 0; k < cols.size(); ++k) {
                                    if (combo[k].empty()) continue;
                                    DetectParams dp;
                                    dp.partition = p.partition;
                                    parse_partition_param(cols[k].second, combo[k], dp);
                                    p.partition = dp.partition;
                                    info.params.emplace_back(cols[k].first, combo[k]);
                                }
                                plan.points.push_back(std::move(info));
                                plan.detect_points.push_back(p);
                            }
    }
}

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
        plan_detection_study(*plan);
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

} // namespace tethash::study
