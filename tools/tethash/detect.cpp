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
    std::string hash = "column";
    int threads = 0;
    int repeat = 1;
    std::string contacts_path, stats_path;
    bool no_self = false;
    std::vector<int> static_objects;
};

/// "auto" | "xF" (factor of the mean edge length) | L (absolute, > 0).
void parse_cell_size(const std::string& s, DetectParams& p)
{
    auto bad = [&] {
        return Error("--cell-size: expected a positive length, 'auto' or 'xF' (F > 0, a factor of the mean edge length), got '" + s + "'");
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
    params.hash = parse_hash_function(o.hash);
    if (o.threads < 0) throw Error("--threads: expected ≥ 0 (0 = all), got " + std::to_string(o.threads));
    if (o.repeat < 1) throw Error("--repeat: expected ≥ 1, got " + std::to_string(o.repeat));
    params.threads = set_threads(o.threads);

    // The scene: each file one object; ids global in argument order.
    TetMesh scene;
    std::vector<Index> vobj, tobj;
    std::vector<Positions> parts;
    Index nv = 0, nt = 0;
    std::vector<TetMesh> meshes;
    for (const std::string& path : o.meshes) {
        meshes.push_back(io::read_mesh(path));
        nv += meshes.back().num_vertices();
        nt += meshes.back().num_tets();
    }
    scene.positions.resize(nv, 3);
    scene.tets.resize(nt, 4);
    Index v0 = 0, t0 = 0;
    for (std::size_t k = 0; k < meshes.size(); ++k) {
        const TetMesh& m = meshes[k];
        scene.positions.middleRows(v0, m.num_vertices()) = m.positions;
        scene.tets.middleRows(t0, m.num_tets()) = m.tets.array() + v0;
        vobj.insert(vobj.end(), static_cast<std::size_t>(m.num_vertices()), static_cast<Index>(k));
        tobj.insert(tobj.end(), static_cast<std::size_t>(m.num_tets()), static_cast<Index>(k));
        v0 += m.num_vertices();
        t0 += m.num_tets();
    }
    std::vector<ObjectOptions> objects(meshes.size());
    for (auto& ob : objects) ob.self_collision = !o.no_self;
    for (int s : o.static_objects) {
        if (s < 0 || s >= static_cast<int>(meshes.size()))
            throw Error("--static: object " + std::to_string(s) + " out of range [0, " + std::to_string(meshes.size()) +
                        ") (objects are the mesh files, in order)");
        objects[static_cast<std::size_t>(s)].is_static = true;
    }

    Detector det(params);
    det.set_topology(scene.tets, nv, vobj, tobj, objects);
    DetectStats stats;
    std::vector<double> ms;
    if (o.repeat > 1) det.detect(scene.positions);   // warm-up
    for (int r = 0; r < o.repeat; ++r) {
        const auto start = std::chrono::steady_clock::now();
        det.detect(scene.positions, &stats);
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    }
    std::vector<double> sorted = ms;
    std::sort(sorted.begin(), sorted.end());
    const double median_ms = sorted[sorted.size() / 2];
    const std::vector<Contact>& contacts = det.contacts();

    fmt::print("scene: {} objects, {} vertices, {} tets\n", meshes.size(), nv, nt);
    fmt::print("grid: cell size {:.6g}, table size {}, hash {}, threads {}\n", stats.cell_size, stats.table_size,
               to_string(params.hash), stats.threads);
    fmt::print("time: {:.3f} ms per detection (median of {}): vertices {:.3f}, tets {:.3f}, inside {:.3f}, sort {:.3f}\n",
               median_ms, o.repeat, stats.ms_vertices, stats.ms_tets, stats.ms_inside, stats.ms_sort);
    fmt::print("work: {} cells, {} entries scanned ({} hash collisions, {} box rejections, {} own vertices), "
               "{} inside tests, {} exact fallbacks, {} degenerate tets\n",
               stats.cells_visited, stats.entries_scanned, stats.hash_collisions, stats.box_rejections,
               stats.own_vertex_skips, stats.inside_tests, stats.exact_fallbacks, stats.degenerate_tets);
    fmt::print("contacts: {}\n", contacts.size());

    if (!o.contacts_path.empty())
        io::write_atomically(o.contacts_path, [&](const std::string& tmp) {
            std::FILE* f = std::fopen(tmp.c_str(), "wb");
            if (!f) throw RunFailure("cannot write " + tmp);
            std::fputs("vertex,tet,b0,b1,b2,b3\n", f);
            for (const Contact& c : contacts)
                std::fprintf(f, "%d,%d,%.17g,%.17g,%.17g,%.17g\n", c.vertex, c.tet, c.bary[0], c.bary[1], c.bary[2],
                             c.bary[3]);
            const bool ok = std::fflush(f) == 0;
            std::fclose(f);
            if (!ok) throw RunFailure("cannot write " + tmp);
        });
    if (!o.stats_path.empty())
        io::write_atomically(o.stats_path, [&](const std::string& tmp) {
            std::ofstream f(tmp);
            std::string msl;
            for (std::size_t i = 0; i < ms.size(); ++i) msl += fmt::format("{}{:.6f}", i ? ", " : "", ms[i]);
            f << "{\n"
              << fmt::format("  \"objects\": {},\n  \"vertices\": {},\n  \"tets\": {},\n  \"contacts\": {},\n",
                             meshes.size(), nv, nt, contacts.size())
              << fmt::format("  \"threads\": {},\n  \"cell_size\": {:.17g},\n  \"table_size\": {},\n  \"hash\": \"{}\",\n",
                             stats.threads, stats.cell_size, stats.table_size, to_string(params.hash))
              << fmt::format("  \"repeat\": {},\n  \"median_ms\": {:.6f},\n  \"run_ms\": [{}],\n", o.repeat, median_ms, msl)
              << fmt::format("  \"ms_vertices\": {:.6f},\n  \"ms_tets\": {:.6f},\n  \"ms_inside\": {:.6f},\n  \"ms_sort\": {:.6f},\n",
                             stats.ms_vertices, stats.ms_tets, stats.ms_inside, stats.ms_sort)
              << fmt::format("  \"cells_visited\": {},\n  \"entries_scanned\": {},\n  \"hash_collisions\": {},\n",
                             stats.cells_visited, stats.entries_scanned, stats.hash_collisions)
              << fmt::format("  \"box_rejections\": {},\n  \"own_vertex_skips\": {},\n  \"inside_tests\": {},\n",
                             stats.box_rejections, stats.own_vertex_skips, stats.inside_tests)
              << fmt::format("  \"exact_fallbacks\": {},\n  \"degenerate_tets\": {},\n  \"table_load\": {:.6f},\n",
                             stats.exact_fallbacks, stats.degenerate_tets, stats.table_load)
              << fmt::format("  \"memory_bytes\": {}\n}}\n", stats.memory_bytes);
            if (!f) throw RunFailure("cannot write " + tmp);
        });
}

Registrar reg{{"detect", "Find every vertex inside a tet of another object or of its own (spatial hashing, exact)",
               [](CLI::App& sub) {
                   auto o = std::make_shared<DetectOptions>();
                   sub.add_option("meshes", o->meshes, "Tet meshes; together one scene, each file an object")
                       ->required()
                       ->check(CLI::ExistingFile);
                   sub.add_option("--cell-size", o->cell_size, "Cell edge length: L, auto (mean edge) or xF (F × mean edge)");
                   sub.add_option("--table-size", o->table_size, "Hash table size: N ≥ 1 or auto");
                   sub.add_option("--hash", o->hash, "Hash function: column (default) or teschner");
                   sub.add_option("--threads", o->threads, "Threads (0 = all)");
                   sub.add_option("--repeat", o->repeat, "Run K times after a warm-up; report the median");
                   sub.add_option("--contacts", o->contacts_path, "Write contacts CSV (vertex,tet,b0,b1,b2,b3)");
                   sub.add_option("--stats", o->stats_path, "Write statistics JSON");
                   sub.add_flag("--no-self", o->no_self, "No self-collisions (only between objects)");
                   sub.add_option("--static", o->static_objects, "Object index (file order, from 0) that never moves; repeatable");
                   sub.callback([o] { run(*o); });
               }}};

} // namespace
} // namespace tethash::cli
