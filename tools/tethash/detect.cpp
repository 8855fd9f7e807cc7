// tethash detect MESH... : one scene (each file an object), three-stage spatial-hash detection, summary,
// optional contacts CSV and statistics JSON.
#include "command.hpp"

#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

namespace tethash::cli {
namespace {

struct DetectOptions {
    std::vector<std::string> meshes;
    std::string cell_size = "auto";
    std::string table_size = "auto";
    std::string skin = "0";
    std::string hash = "column";
    int threads = 0;
    int repeat = 1;
    std::string contacts_path, stats_path;
    bool no_self = false;
    std::vector<int> static_objects;
    std::string objects_from_labels; ///< "", "separate" or "join"
};

/// "auto" | "xF" (factor of the mean edge length) | L (absolute, > 0).
void parse_cell_size(const std::string& s, DetectParams& p)
{
    auto bad = [&] {
        return Error(
            "--cell-size: expected a positive length, 'auto' or 'xF' (F > 0, a factor of the mean edge length), got '" +
            s + "'");
    };
    if (s == "auto") {
        p.cell_size_mode = DetectParams::CellSizeMode::auto_mean_edge;
        return;
    }
    const bool factor = !s.empty() && (s[0] == 'x' || s[0] == 'X');
    const std::string num = factor ? s.substr(1) : s;
    double v = 0;
    std::size_t used = 0;
    try {
        v = std::stod(num, &used);
    } catch (const std::exception&) {
        throw bad();
    }
    if (used != num.size() || !(v > 0) || !std::isfinite(v)) throw bad();
    p.cell_size_mode = factor ? DetectParams::CellSizeMode::factor_of_mean_edge : DetectParams::CellSizeMode::absolute;
    p.cell_size = v;
}

/// L (a length ≥ 0; 0 = no candidate reuse) | "xF" (F ≥ 0, a factor of the cell size).
void parse_skin(const std::string& s, DetectParams& p)
{
    const bool factor = !s.empty() && (s[0] == 'x' || s[0] == 'X');
    const std::string num = factor ? s.substr(1) : s;
    double v = 0;
    std::size_t used = 0;
    try {
        v = std::stod(num, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != num.size() || !(v >= 0) || !std::isfinite(v))
        throw Error("--skin: expected a length ≥ 0 or 'xF' (F ≥ 0, a factor of the cell size), got '" + s + "'");
    p.skin_mode = factor ? DetectParams::SkinMode::factor_of_cell_size : DetectParams::SkinMode::absolute;
    p.skin = v;
}

void parse_table_size(const std::string& s, DetectParams& p)
{
    if (s == "auto") {
        p.table_size = 0;
        return;
    }
    long long v = 0;
    std::size_t used = 0;
    try {
        v = std::stoll(s, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != s.size() || v < 1)
        throw Error("--table-size: expected a positive integer or 'auto', got '" + s + "'");
    p.table_size = v;
}

void run(const DetectOptions& o)
{
    DetectParams params;
    parse_cell_size(o.cell_size, params);
    parse_table_size(o.table_size, params);
    parse_skin(o.skin, params);
    params.hash = parse_hash_function(o.hash);
    if (o.threads < 0) throw Error("--threads: expected ≥ 0 (0 = all), got " + std::to_string(o.threads));
    if (o.repeat < 1) throw Error("--repeat: expected ≥ 1, got " + std::to_string(o.repeat));
    params.threads = set_threads(o.threads);
    check_objects_from_labels_value(o.objects_from_labels);
    // Output files are checked before the work, so that a typo does not cost a long run.
    if (!o.contacts_path.empty()) io::check_output_file(o.contacts_path, "--contacts");
    if (!o.stats_path.empty()) io::check_output_file(o.stats_path, "--stats");

    // The scene: each file one object; ids global in argument order.
    TetMesh scene;
    std::vector<Index> vobj, tobj;
    std::vector<Positions> parts;
    Index nv = 0, nt = 0;
    std::vector<TetMesh> meshes;
    Index num_objects = 0;
    for (const std::string& path : o.meshes) {
        meshes.push_back(io::read_mesh(path));
        if (!o.objects_from_labels.empty()) {
            fmt::print("{}: {}\n", path, objects_from_labels(meshes.back(), path, o.objects_from_labels));
        } else { // each file one object, whatever object ids it carries
            meshes.back().vertex_object.clear();
            meshes.back().tet_object.clear();
        }
        meshes.back().ensure_object_ids();
        num_objects += std::max<Index>(1, meshes.back().num_objects()); // an empty file is still an object
        nv += meshes.back().num_vertices();
        nt += meshes.back().num_tets();
    }
    scene.positions.resize(nv, 3);
    scene.tets.resize(nt, 4);
    Index v0 = 0, t0 = 0, o0 = 0;
    for (std::size_t k = 0; k < meshes.size(); ++k) {
        const TetMesh& m = meshes[k];
        scene.positions.middleRows(v0, m.num_vertices()) = m.positions;
        scene.tets.middleRows(t0, m.num_tets()) = m.tets.array() + v0;
        for (Index id : m.vertex_object)
            vobj.push_back(o0 + id);
        for (Index id : m.tet_object)
            tobj.push_back(o0 + id);
        v0 += m.num_vertices();
        t0 += m.num_tets();
        o0 += std::max<Index>(1, m.num_objects());
    }
    std::vector<ObjectOptions> objects(static_cast<std::size_t>(num_objects));
    for (auto& ob : objects)
        ob.self_collision = !o.no_self;
    for (int s : o.static_objects) {
        if (s < 0 || s >= num_objects)
            throw Error("--static: object " + std::to_string(s) + " out of range [0, " + std::to_string(num_objects) +
                        ") (objects are the mesh files, in order, or their labels with --objects-from-labels)");
        objects[static_cast<std::size_t>(s)].is_static = true;
    }

    Detector det(params);
    det.set_topology(scene.tets, nv, vobj, tobj, objects);
    DetectStats stats;
    std::vector<double> ms;
    if (o.repeat > 1) det.detect(scene.positions); // warm-up
    for (int r = 0; r < o.repeat; ++r) {
        const auto start = std::chrono::steady_clock::now();
        det.detect(scene.positions, &stats);
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    }
    std::vector<double> sorted = ms;
    std::sort(sorted.begin(), sorted.end());
    const double median_ms = sorted[sorted.size() / 2];
    const std::vector<Contact>& contacts = det.contacts();

    fmt::print("scene: {} objects, {} vertices, {} tets\n", num_objects, nv, nt);
    fmt::print("grid: cell size {:.6g}, table size {}, hash {}, threads {}\n", stats.cell_size, stats.table_size,
               to_string(params.hash), stats.threads);
    fmt::print(
        "time: {:.3f} ms per detection (median of {}): vertices {:.3f}, tets {:.3f}, inside {:.3f}, sort {:.3f}\n",
        median_ms, o.repeat, stats.ms_vertices, stats.ms_tets, stats.ms_inside, stats.ms_sort);
    fmt::print("work: {} cells, {} entries scanned ({} hash collisions, {} box rejections, {} own vertices), "
               "{} inside tests, {} exact fallbacks, {} degenerate tets\n",
               stats.cells_visited, stats.entries_scanned, stats.hash_collisions, stats.box_rejections,
               stats.own_vertex_skips, stats.inside_tests, stats.exact_fallbacks, stats.degenerate_tets);
    fmt::print("contacts: {}\n", contacts.size());

    if (!o.contacts_path.empty()) {
        std::string csv = "vertex,tet,b0,b1,b2,b3\n";
        for (const Contact& c : contacts)
            csv += fmt::format("{},{},{:.17g},{:.17g},{:.17g},{:.17g}\n", c.vertex, c.tet, c.bary[0], c.bary[1],
                               c.bary[2], c.bary[3]);
        io::write_text_file(o.contacts_path, csv);
    }
    if (!o.stats_path.empty()) {
        std::string msl;
        for (std::size_t i = 0; i < ms.size(); ++i)
            msl += fmt::format("{}{:.6f}", i ? ", " : "", ms[i]);
        std::string f = "{\n";
        f += fmt::format("  \"objects\": {},\n  \"vertices\": {},\n  \"tets\": {},\n  \"contacts\": {},\n", num_objects,
                         nv, nt, contacts.size());
        f += fmt::format("  \"threads\": {},\n  \"cell_size\": {:.17g},\n  \"table_size\": {},\n  \"hash\": \"{}\",\n",
                         stats.threads, stats.cell_size, stats.table_size, to_string(params.hash));
        f +=
            fmt::format("  \"repeat\": {},\n  \"median_ms\": {:.6f},\n  \"run_ms\": [{}],\n", o.repeat, median_ms, msl);
        f += fmt::format(
            "  \"ms_vertices\": {:.6f},\n  \"ms_tets\": {:.6f},\n  \"ms_inside\": {:.6f},\n  \"ms_sort\": {:.6f},\n",
            stats.ms_vertices, stats.ms_tets, stats.ms_inside, stats.ms_sort);
        f += fmt::format("  \"cells_visited\": {},\n  \"entries_scanned\": {},\n  \"hash_collisions\": {},\n",
                         stats.cells_visited, stats.entries_scanned, stats.hash_collisions);
        f += fmt::format("  \"box_rejections\": {},\n  \"own_vertex_skips\": {},\n  \"inside_tests\": {},\n",
                         stats.box_rejections, stats.own_vertex_skips, stats.inside_tests);
        f += fmt::format("  \"exact_fallbacks\": {},\n  \"degenerate_tets\": {},\n  \"table_load\": {:.6f},\n",
                         stats.exact_fallbacks, stats.degenerate_tets, stats.table_load);
        f += fmt::format("  \"skin\": {:.17g},\n  \"reused\": {},\n  \"cached_candidates\": {},\n", stats.skin,
                         stats.reused, stats.cached_candidates);
        f += fmt::format("  \"memory_bytes\": {}\n}}\n", stats.memory_bytes);
        io::write_text_file(o.stats_path, f);
    }
}

Registrar reg{
    {"detect", "Find every vertex inside a tet of another object or of its own (spatial hashing, exact)",
     [](CLI::App& sub) {
         auto o = std::make_shared<DetectOptions>();
         sub.add_option("meshes", o->meshes, "Tet meshes; together one scene, each file an object")->required();
         sub.add_option("--cell-size", o->cell_size,
                        "Cell edge length: L, auto (the mean edge length) or xF (F × mean edge)")
             ->capture_default_str();
         sub.add_option("--table-size", o->table_size, "Hash table size: N ≥ 1 or auto (chosen from the vertex count)")
             ->capture_default_str();
         sub.add_option("--skin", o->skin,
                        "Candidate reuse between calls (--repeat): L (a length, 0 = off) or xF (F × cell size)")
             ->capture_default_str();
         sub.add_option("--hash", o->hash, "Hash function: column or teschner")->capture_default_str();
         sub.add_option("--threads", o->threads, "Threads (0 = all)")->capture_default_str();
         sub.add_option("--repeat", o->repeat, "Run K times after a warm-up; report the median")->capture_default_str();
         sub.add_option("--contacts", o->contacts_path, "Write contacts CSV (vertex,tet,b0,b1,b2,b3)");
         sub.add_option("--stats", o->stats_path, "Write statistics JSON");
         sub.add_flag("--no-self", o->no_self, "No self-collisions (only between objects)");
         sub.add_option("--static", o->static_objects,
                        "Object index (file order, from 0) that never moves; repeatable");
         add_objects_from_labels_option(sub, o->objects_from_labels);
         sub.callback([o] { run(*o); });
     }}};

} // namespace
} // namespace tethash::cli
