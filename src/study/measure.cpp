// Measuring a study (measure.hpp): one point of a detection sweep (its repeats, the oracle comparison and the
// penetration-depth error), and the run of a plan point by point.
#include "measure.hpp"

#include "report.hpp"

#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/oracle.hpp"
#include "tethash/penetration.hpp"
#include "tethash/study/stats_table.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <new>

namespace tethash::study {

namespace fs = std::filesystem;

std::int64_t now_ns()
{
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

double elapsed_ms(std::int64_t start_ns)
{
    return static_cast<double>(now_ns() - start_ns) * 1e-6;
}

std::vector<std::string> detect_columns()
{
    std::vector<std::string> c = {"point",         "repeat",     "scene", "sweep",           "objects", "cell_factor",
                                  "table_request", "table_kind", "hash",  "threads_request", "method"};
    for (const auto& [name, option] : partition_columns())
        c.push_back(name);
    for (const StatField& f : k_detect_stats)
        if ((f.use & in_study) && f.kind != StatKind::timing) c.emplace_back(f.name);
    for (const char* name :
         {"oracle_contacts", "missed", "extra", "pen_pairs", "depth_err_rms", "depth_err_max", "depth_exact_max"})
        c.emplace_back(name);
    for (const StatField& f : k_detect_stats)
        if ((f.use & in_study) && f.kind == StatKind::timing) c.emplace_back(f.name);
    c.emplace_back("ms_wall");
    c.emplace_back("ms_penetration");
    c.emplace_back("error"); // a method that could not run (not built, refused its memory): its message
    return c;
}

namespace {

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

} // namespace

std::vector<Row> run_detect_point(StudyPlan& plan, std::int64_t index, const RunHooks& hooks)
{
    std::vector<std::string>& notes = plan.notes;
    const StudyOptions& o = plan.options;
    const DetectPoint& p = plan.detect_points[static_cast<std::size_t>(index)];
    SceneData& scene = plan.scenes[p.scene];
    const TetMesh& mesh = scene.mesh;

    // The oracle, once per scene.
    if (o.oracle && !scene.oracle) {
        const auto t0 = now_ns();
        scene.oracle = brute_force_contacts(mesh.positions, mesh.tets, mesh.vertex_object, mesh.tet_object,
                                            std::span<const ObjectOptions>{});
        const std::string note = "oracle for " + scene.name + ": " + std::to_string(scene.oracle->size()) +
                                 " contacts in " + fmt_double(elapsed_ms(t0) / 1000.0) + " s";
        notes.push_back(note);
        if (hooks.on_note) hooks.on_note(note);
    }

    DetectParams dp{.cell_size_mode = DetectParams::CellSizeMode::factor_of_mean_edge,
                    .cell_size = p.cell_factor,
                    .table_size = p.table_size,
                    .hash = p.hash,
                    .threads = p.threads,
                    .method = p.method,
                    .partition = p.partition};
    if (p.method == Method::portals) dp.partition.cells = scene.cells;
    Detector det(dp);
    det.set_topology(mesh);
    Row head = {std::to_string(index),
                "",
                scene.name,
                to_string(o.sweep),
                std::to_string(mesh.num_objects()),
                fmt_double(p.cell_factor),
                p.table_request,
                p.table_kind,
                to_string(p.hash),
                std::to_string(p.threads),
                to_string(p.method)};
    for (const std::string& v : p.partition_text)
        head.push_back(v);
    try {
        for (int w = 0; w < o.warmup; ++w)
            det.detect(mesh.positions);

        // Penetration depth error (Heidelberger et al. 2004 against the exact distance), once per point.
        PenetrationResult pen;
        if (o.penetration) {
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
            Row row = head;
            row[1] = std::to_string(r);
            for (const StatField& f : k_detect_stats)
                if ((f.use & in_study) && f.kind != StatKind::timing) row.push_back(stat_text(f, st));
            for (std::string v : {oc, missed, extra})
                row.push_back(std::move(v));
            row.push_back(pen.available ? std::to_string(pen.pairs) : "");
            for (double v : {pen.err_rms, pen.err_max, pen.exact_max})
                row.push_back(pen.available ? fmt_double(v) : "");
            for (const StatField& f : k_detect_stats)
                if ((f.use & in_study) && f.kind == StatKind::timing) row.push_back(stat_text(f, st));
            row.push_back(fmt_double(wall));
            row.push_back(pen.available ? fmt_double(pen.ms) : "");
            row.emplace_back(); // no error
            rows.push_back(std::move(row));
        }
        return rows;
    } catch (const std::exception& e) { // Error, or bad_alloc: the method cannot run on this scene
        const std::string what = dynamic_cast<const std::bad_alloc*>(&e) ? "out of memory" : e.what();
        const std::string note = scene.name + " " + to_string(p.method) + ": " + what;
        notes.push_back(note);
        if (hooks.on_note) hooks.on_note(note);
        std::vector<Row> rows;
        for (int r = 0; r < o.repeat; ++r) {
            Row row = head;
            row[1] = std::to_string(r);
            const std::vector<std::string> cols = detect_columns();
            row.resize(cols.size());
            row.back() = what;
            for (std::size_t c = 0; c < cols.size(); ++c) // the scene's size, as the rows of the methods that ran
                if (cols[c] == "vertices" || cols[c] == "tets")
                    row[c] = std::to_string(cols[c] == "vertices" ? mesh.num_vertices() : mesh.num_tets());
            rows.push_back(std::move(row));
        }
        return rows;
    }
}

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

    write_study_json(plan, res, table, elapsed_ms(t_start) / 1000.0);
    res.notes = plan.notes;
    return res;
}

} // namespace tethash::study
