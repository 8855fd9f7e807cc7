// tethash detect MESH... : one scene (each file an object), collision detection by the spatial hash or another
// broad phase (--method; --method all compares them), summary, optional contacts CSV and statistics JSON.
#include "command.hpp"
#include "detect_continuous.hpp"

#include "tethash/bsp.hpp"
#include "tethash/detect.hpp"
#include "tethash/detect_grammar.hpp"
#include "tethash/edge_contacts.hpp"
#include "tethash/error.hpp"
#include "tethash/io/cells.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/io/surface.hpp"
#include "tethash/penetration.hpp"
#include "tethash/study/json.hpp"
#include "tethash/study/methods.hpp"
#include "tethash/study/stats_table.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
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
    std::string threads = "0";
    std::string method = to_string(DetectParams{}.method);
    std::string max_depth = "default", leaf_size = "default", looseness = "default", levels = "default";
    int repeat = 1;
    bool repeat_given = false; ///< --repeat given (else 1, or 3 with --method all)
    std::string contacts_path, stats_path;
    bool no_self = false;
    std::vector<int> static_objects;
    std::string objects_from_labels; ///< "", "separate" or "join"
    bool linearize = false;
    std::vector<std::string> obstacles; ///< closed surfaces, each a static BSP obstacle
    bool continuous = false;            ///< the two meshes are frames: contacts over the step between them
    std::string cells_path;             ///< --cells: the cells and portals of --method portals (io/cells.hpp)
    bool edges = false;                 ///< also the edge-face contacts (edge_contacts.hpp)
    std::string edge_contacts_path;     ///< their CSV (implies edges)
};

/// One input file of the scene: where its vertices and tets start in the scene, and its own numbering.
struct InputFile {
    std::string path;
    Index first_vertex = 0, first_tet = 0;
    io::ReadNotes notes; ///< vertex_ids, tet_ids, first_id: the file's numbering
};

/// The file holding scene id `id`, given the first ids of each file (`first` increasing).
std::size_t file_of(const std::vector<InputFile>& files, Index id, Index InputFile::*first)
{
    std::size_t k = files.size() - 1;
    while (k > 0 && files[k].*first > id)
        --k;
    return k;
}

/// Id `local` (0-based in its file) in the file's own numbering.
std::int64_t file_id(const io::ReadNotes& notes, const std::vector<std::int64_t>& ids, Index local)
{
    return ids.empty() ? std::int64_t{notes.first_id} + local : ids[static_cast<std::size_t>(local)];
}

/// Contacts as CSV: a header comment saying which id is which, then one row per contact sorted by (vertex, tet).
/// With obstacles, the rows of the vertices inside them follow each vertex's tet contacts (tet columns empty), and
/// every row has the obstacle (empty for a tet contact), the depth and the direction.
std::string contacts_csv(const std::vector<Contact>& contacts, const std::vector<InputFile>& files,
                         const std::vector<std::string>& obstacle_paths = {},
                         const std::vector<ObstacleContact>& obstacle_contacts = {},
                         const std::vector<Index>& vertex_object = {})
{
    const bool obstacles = !obstacle_paths.empty();
    std::string csv = "# tethash detect: each row is a vertex lying inside a tet it does not belong to.\n"
                      "# vertex, tet: 0-based ids in the scene (the input files joined in argument order).\n"
                      "# vertex_object, tet_object: objects (each file one, in order from 0; its 'object' cell data or "
                      "labels with --objects-from-labels).\n"
                      "# vertex_file, tet_file: the input file (0-based argument position, listed below); "
                      "vertex_in_file, tet_in_file: the id in that file's own numbering (Gmsh node and element tags; "
                      "1-based in Medit and Vega; TetGen from its first index; 0-based in VTK).\n"
                      "# b0..b3: barycentric coordinates of the vertex in the tet (corners in the tet's order).\n";
    if (obstacles)
        csv += "# obstacle: the surface file (--obstacle) the vertex lies in or on (a static BSP obstacle; tet columns "
               "empty); depth: distance to the penetrated surface (tets: consistent penetration depth; obstacles: "
               "distance to the nearest face); n0..n2: unit direction out of it.\n";
    for (std::size_t k = 0; k < files.size(); ++k)
        csv += fmt::format("# file {}: {}\n", k, files[k].path);
    for (std::size_t k = 0; k < obstacle_paths.size(); ++k)
        csv += fmt::format("# obstacle {}: {}\n", k, obstacle_paths[k]);
    csv += "vertex,tet,vertex_object,tet_object,vertex_file,vertex_in_file,tet_file,tet_in_file,b0,b1,b2,b3";
    csv += obstacles ? ",obstacle,depth,n0,n1,n2\n" : "\n";
    std::size_t next = 0; // next obstacle contact
    auto obstacle_rows = [&](Index up_to) {
        for (; next < obstacle_contacts.size() && obstacle_contacts[next].vertex <= up_to; ++next) {
            const ObstacleContact& c = obstacle_contacts[next];
            const std::size_t fv = file_of(files, c.vertex, &InputFile::first_vertex);
            const io::ReadNotes& nv = files[fv].notes;
            csv += fmt::format("{},,{},,{},{},,,,,,,{},{:.17g},{:.17g},{:.17g},{:.17g}\n", c.vertex,
                               vertex_object[static_cast<std::size_t>(c.vertex)], fv,
                               file_id(nv, nv.vertex_ids, c.vertex - files[fv].first_vertex),
                               obstacle_paths[static_cast<std::size_t>(c.obstacle)], c.depth, c.direction[0],
                               c.direction[1], c.direction[2]);
        }
    };
    for (const Contact& c : contacts) {
        obstacle_rows(c.vertex - 1);
        const std::size_t fv = file_of(files, c.vertex, &InputFile::first_vertex);
        const std::size_t ft = file_of(files, c.tet, &InputFile::first_tet);
        const io::ReadNotes& nv = files[fv].notes;
        const io::ReadNotes& nt = files[ft].notes;
        csv += fmt::format(
            "{},{},{},{},{},{},{},{},{:.17g},{:.17g},{:.17g},{:.17g}\n", c.vertex, c.tet, c.vertex_object, c.tet_object,
            fv, file_id(nv, nv.vertex_ids, c.vertex - files[fv].first_vertex), ft,
            file_id(nt, nt.tet_ids, c.tet - files[ft].first_tet), c.bary[0], c.bary[1], c.bary[2], c.bary[3]);
        if (obstacles) {
            csv.pop_back();
            csv += fmt::format(",,{:.17g},{:.17g},{:.17g},{:.17g}\n", c.depth, c.direction[0], c.direction[1],
                               c.direction[2]);
        }
    }
    obstacle_rows(std::numeric_limits<Index>::max());
    return csv;
}

/// Edge-face contacts as CSV: a header comment saying which column is which, then one row per contact sorted by
/// (edge, face).
std::string edge_contacts_csv(const EdgeFaceResult& r, const std::vector<InputFile>& files)
{
    std::string csv =
        "# tethash detect --edges: each row is a boundary edge crossing a boundary triangle of another object or of a "
        "distant part of its own (no vertex of the edge and of the triangle the same or in one tet).\n"
        "# e0, e1: the edge's vertices; f0, f1, f2: the triangle's (outward order); 0-based ids in the scene (the "
        "input files joined in argument order).\n"
        "# edge_object, face_object: objects; edge_file, face_file: the input file (0-based argument position, "
        "listed below); e0_in_file .. f2_in_file: the vertex ids in that file's own numbering.\n"
        "# t: the crossing point is (1 - t) x[e0] + t x[e1]; b0..b2: its barycentric coordinates in the triangle.\n"
        "# inner_end: the end of the edge (0: e0, 1: e1) on the triangle's inner side; n0..n2: the triangle's unit "
        "normal, from its inner to its outer side (the direction that takes the inner end back out).\n";
    for (std::size_t k = 0; k < files.size(); ++k)
        csv += fmt::format("# file {}: {}\n", k, files[k].path);
    csv += "e0,e1,f0,f1,f2,edge_object,face_object,edge_file,e0_in_file,e1_in_file,face_file,f0_in_file,f1_in_file,"
           "f2_in_file,t,b0,b1,b2,inner_end,n0,n1,n2\n";
    auto in_file = [&](std::size_t file, Index v) {
        const io::ReadNotes& notes = files[file].notes;
        return file_id(notes, notes.vertex_ids, v - files[file].first_vertex);
    };
    for (const EdgeFaceContact& c : r.contacts) {
        const std::size_t fe = file_of(files, c.edge_vertices[0], &InputFile::first_vertex);
        const std::size_t ff = file_of(files, c.face_vertices[0], &InputFile::first_vertex);
        csv += fmt::format(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.17g},{:.17g},{:.17g},{:.17g},{},{:.17g},{:.17g},"
            "{:.17g}\n",
            c.edge_vertices[0], c.edge_vertices[1], c.face_vertices[0], c.face_vertices[1], c.face_vertices[2],
            c.edge_object, c.face_object, fe, in_file(fe, c.edge_vertices[0]), in_file(fe, c.edge_vertices[1]), ff,
            in_file(ff, c.face_vertices[0]), in_file(ff, c.face_vertices[1]), in_file(ff, c.face_vertices[2]), c.edge_t,
            c.face_bary[0], c.face_bary[1], c.face_bary[2], c.inner_end, c.normal[0], c.normal[1], c.normal[2]);
    }
    return csv;
}

/// Contacts as a VTU of the scene: point data contact (number of tets the vertex lies in), penetration_depth
/// (the largest over its contacts, 0 where none) and contact_tet (the scene id of the first such tet, -1 where
/// none); cell data object (written from the mesh) and contacts (vertices inside the tet).
void write_contacts_vtu(const std::string& path, const TetMesh& scene, std::vector<Contact>& contacts,
                        const std::vector<ObstacleContact>& obstacle_contacts)
{
    Penetration pen;
    pen.set_topology(scene);
    pen.compute(scene.positions, contacts);
    const auto n = static_cast<std::size_t>(scene.num_vertices()), m = static_cast<std::size_t>(scene.num_tets());
    io::Fields f;
    f.point.push_back({"contact", 1, std::vector<double>(n, 0.0)});
    f.point.push_back({"penetration_depth", 1, std::vector<double>(n, 0.0)});
    f.point.push_back({"contact_tet", 1, std::vector<double>(n, -1.0)});
    f.cell.push_back({"contacts", 1, std::vector<double>(m, 0.0)});
    for (const Contact& c : contacts) {
        const auto v = static_cast<std::size_t>(c.vertex);
        f.point[0].values[v] += 1;
        if (std::isfinite(c.depth)) f.point[1].values[v] = std::max(f.point[1].values[v], c.depth);
        if (f.point[2].values[v] < 0) f.point[2].values[v] = c.tet;
        f.cell[0].values[static_cast<std::size_t>(c.tet)] += 1;
    }
    for (const ObstacleContact& c : obstacle_contacts) {
        const auto v = static_cast<std::size_t>(c.vertex);
        f.point[0].values[v] += 1;
        f.point[1].values[v] = std::max(f.point[1].values[v], c.depth);
    }
    io::write_mesh(path, scene, f);
}

/// `--method all`: every method on the scene, the comparison table and whether they agree (exit 1 if not).
void compare_all_methods(const TetMesh& scene, Index nv, Index nt, Index num_objects, const std::vector<Index>& vobj,
                         const std::vector<Index>& tobj, const std::vector<ObjectOptions>& objects,
                         const DetectParams& params, int repeat)
{
    fmt::print("scene: {} objects, {} vertices, {} tets\n", num_objects, nv, nt);
    fmt::print("every method, threads {}, time: median of {} calls after the first\n",
               params.threads == 0 ? std::string("all") : std::to_string(params.threads), repeat);
    std::fflush(stdout);
    const auto runs =
        study::compare_methods({scene.positions, scene.tets, vobj, tobj, objects}, params, all_methods(), repeat);
    fmt::print("{}", study::method_table(runs));
    const study::Agreement a = study::check_agreement(runs);
    if (!a.same) throw RunFailure(a.message);
    fmt::print("agreement: {}\n", a.message);
}

/// `--continuous FRAME0 FRAME1`: the options that apply to it, the others refused.
void run_continuous_detection(const DetectOptions& o)
{
    if (o.meshes.size() != 2)
        throw Error(fmt::format("--continuous: expected two frames of the same meshes (FRAME0 FRAME1), got {} files",
                                o.meshes.size()));
    if (o.edges || !o.edge_contacts_path.empty())
        throw Error(std::string(o.edges ? "--edges" : "--edge-contacts") +
                    ": not with --continuous (edge-face contacts are of one instant; continuous detection reports "
                    "the edge-edge pairs that meet during the step)");
    if (o.method == "all" || !o.stats_path.empty() || !o.obstacles.empty() || o.repeat_given || o.skin != "0" ||
        !o.cells_path.empty())
        throw Error(std::string("--continuous: not with ") +
                    (o.method == "all"       ? "--method all"
                     : !o.cells_path.empty() ? "--cells"
                     : !o.stats_path.empty() ? "--stats"
                     : !o.obstacles.empty()  ? "--obstacle"
                     : o.repeat_given        ? "--repeat"
                                             : "--skin") +
                    " (continuous detection has its own broad phase over swept boxes)");
    check_objects_from_labels_value(o.objects_from_labels);
    ContinuousOptions c;
    c.frame0 = o.meshes[0];
    c.frame1 = o.meshes[1];
    c.contacts_path = o.contacts_path;
    c.threads = set_threads(parse_threads(o.threads));
    c.no_self = o.no_self;
    c.static_objects = o.static_objects;
    c.objects_from_labels = o.objects_from_labels;
    c.linearize = o.linearize;
    run_continuous(c);
}

/// The detector's parameters of the options (their grammar checked; the table size's value comes with the scene).
DetectParams params_of(const DetectOptions& o, bool side_by_side)
{
    DetectParams params;
    parse_cell_size(o.cell_size, params);
    parse_table_size(o.table_size, 0); // the syntax now; the value once the vertices are counted
    parse_skin(o.skin, params);
    params.hash = parse_hash_function(o.hash);
    if (!side_by_side) params.method = parse_method(o.method, "--method");
    for (const auto& [option, text] : {std::pair{"--max-depth", &o.max_depth}, std::pair{"--leaf-size", &o.leaf_size},
                                       std::pair{"--looseness", &o.looseness}, std::pair{"--levels", &o.levels}})
        study::parse_partition_param(option, *text, params);
    if (!o.cells_path.empty()) {
        if (!side_by_side && params.method != Method::portals)
            throw Error("--cells " + o.cells_path + ": read by --method portals (or all) only, not by --method " +
                        o.method);
        params.partition.cells = std::make_shared<CellLayout>(io::read_cells(o.cells_path));
    }
    return params;
}

/// Output files are checked before the work, so that a typo does not cost a long run.
void check_output_paths(const DetectOptions& o)
{
    if (!o.contacts_path.empty()) {
        io::check_output_file(o.contacts_path, "--contacts");
        const std::string e = io::extension_of(o.contacts_path);
        if (e != ".csv" && e != ".vtu")
            throw Error("--contacts " + o.contacts_path + ": unknown format '" + e +
                        "' (expected .csv for a table or .vtu for the meshes with contact fields)");
    }
    if (!o.stats_path.empty()) io::check_output_file(o.stats_path, "--stats");
    if (!o.edge_contacts_path.empty()) {
        io::check_output_file(o.edge_contacts_path, "--edge-contacts");
        if (io::extension_of(o.edge_contacts_path) != ".csv")
            throw Error("--edge-contacts " + o.edge_contacts_path + ": unknown format '" +
                        io::extension_of(o.edge_contacts_path) + "' (expected .csv)");
    }
}

/// The scene of the files given: each file one object (or the objects of its 'object' cell data, or of its labels);
/// ids global in argument order.
struct DetectScene {
    TetMesh mesh;
    std::vector<Index> vobj, tobj;
    Index nv = 0, nt = 0, num_objects = 0;
    std::vector<InputFile> files;
    std::vector<ObjectOptions> objects;
};

/// Reads one file of the scene (its notes printed) with its objects as the options say.
TetMesh read_scene_file(const DetectOptions& o, const std::string& path, InputFile& file)
{
    io::ReadOptions read_options;
    read_options.linearize = o.linearize;
    TetMesh mesh = io::read_tet_mesh(path, &file.notes, read_options);
    for (const std::string& m : file.notes.messages)
        if (m.rfind("--linearize", 0) == 0) fmt::print("{}: note: {}\n", path, m);
    if (!o.objects_from_labels.empty()) {
        fmt::print("{}: {}\n", path, objects_from_labels(mesh, path, o.objects_from_labels));
    } else if (!mesh.tet_object.empty() && mesh.num_objects() > 1) {
        // A simulation frame (or any file with 'object' cell data) keeps its objects.
        fmt::print("{}: {} objects from its 'object' cell data\n", path, mesh.num_objects());
    } else { // one object
        mesh.vertex_object.clear();
        mesh.tet_object.clear();
    }
    mesh.ensure_object_ids();
    std::int64_t collapsed = 0;
    for (Index t = 0; t < mesh.num_tets(); ++t) {
        const auto r = mesh.tets.row(t);
        collapsed += r(0) == r(1) || r(0) == r(2) || r(0) == r(3) || r(1) == r(2) || r(1) == r(3) || r(2) == r(3);
    }
    if (collapsed)
        fmt::print("{}: note: {} tets with a repeated vertex (collapsed, zero volume) are skipped like the other "
                   "degenerate tets ('tethash info' lists them)\n",
                   path, collapsed);
    return mesh;
}

DetectScene load_detect_scene(const DetectOptions& o)
{
    DetectScene sc;
    std::vector<TetMesh> meshes;
    for (const std::string& path : o.meshes) {
        InputFile file{path, sc.nv, sc.nt, {}};
        meshes.push_back(read_scene_file(o, path, file));
        sc.files.push_back(std::move(file));
        sc.num_objects += std::max<Index>(1, meshes.back().num_objects()); // an empty file is still an object
        sc.nv += meshes.back().num_vertices();
        sc.nt += meshes.back().num_tets();
    }
    sc.mesh.positions.resize(sc.nv, 3);
    sc.mesh.tets.resize(sc.nt, 4);
    Index v0 = 0, t0 = 0, o0 = 0;
    for (const TetMesh& m : meshes) {
        sc.mesh.positions.middleRows(v0, m.num_vertices()) = m.positions;
        sc.mesh.tets.middleRows(t0, m.num_tets()) = m.tets.array() + v0;
        for (Index id : m.vertex_object)
            sc.vobj.push_back(o0 + id);
        for (Index id : m.tet_object)
            sc.tobj.push_back(o0 + id);
        v0 += m.num_vertices();
        t0 += m.num_tets();
        o0 += std::max<Index>(1, m.num_objects());
    }
    sc.objects.resize(static_cast<std::size_t>(sc.num_objects));
    for (auto& ob : sc.objects)
        ob.self_collision = !o.no_self;
    for (int s : o.static_objects) {
        if (s < 0 || s >= sc.num_objects)
            throw Error("--static: object " + std::to_string(s) + " out of range [0, " +
                        std::to_string(sc.num_objects) +
                        ") (objects are the mesh files, in order, or their labels with --objects-from-labels)");
        sc.objects[static_cast<std::size_t>(s)].is_static = true;
    }
    return sc;
}

/// The first call (the one-off set-up) and `repeat` timed calls after it; `stats` is the median call's.
struct TimedDetection {
    DetectStats first, stats;
    std::vector<double> ms; ///< of each timed call, in order
};

TimedDetection time_detection(Detector& det, const Positions& positions, int repeat)
{
    // The first call does the one-off set-up (automatic cell size, static vertices) and warms caches: it is
    // reported apart, and the K timed calls follow it. The stages printed are those of the median call.
    TimedDetection t;
    det.detect(positions, &t.first);
    std::vector<DetectStats> runs(static_cast<std::size_t>(repeat));
    for (DetectStats& run : runs) {
        det.detect(positions, &run);
        t.ms.push_back(run.ms_total);
    }
    std::vector<std::size_t> order(runs.size());
    for (std::size_t i = 0; i < order.size(); ++i)
        order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return t.ms[a] < t.ms[b]; });
    t.stats = runs[order[order.size() / 2]];
    return t;
}

void print_detection(const DetectScene& sc, const DetectParams& params, const TimedDetection& t, int repeat,
                     std::size_t contacts)
{
    const DetectStats& stats = t.stats;
    const double median_ms = stats.ms_total;
    const double stages = stats.ms_vertices + stats.ms_tets + stats.ms_inside + stats.ms_sort;
    fmt::print("scene: {} objects, {} vertices, {} tets\n", sc.num_objects, sc.nv, sc.nt);
    fmt::print("grid: cell size {:.6g}, table size {}, hash {}, threads {}\n", stats.cell_size, stats.table_size,
               to_string(params.hash), stats.threads);
    fmt::print("first call: {:.3f} ms, of which set-up {:.3f} ms (cell size, static vertices; once per scene)\n",
               t.first.ms_total, t.first.ms_setup);
    fmt::print("time: {:.3f} ms per detection (median of {} after the first): vertices {:.3f}, tets {:.3f}, inside "
               "{:.3f}, sort {:.3f}, other {:.3f}\n",
               median_ms, repeat, stats.ms_vertices, stats.ms_tets, stats.ms_inside, stats.ms_sort,
               std::max(0.0, median_ms - stages));
    fmt::print("work: {} cells, {} entries scanned ({} hash collisions, {} box rejections, {} own vertices), "
               "{} inside tests, {} exact fallbacks, {} degenerate tets\n",
               stats.cells_visited, stats.entries_scanned, stats.hash_collisions, stats.box_rejections,
               stats.own_vertex_skips, stats.inside_tests, stats.exact_fallbacks, stats.degenerate_tets);
    fmt::print("broad phase: {}, {} candidates, {} nodes, memory {}\n", to_string(params.method), stats.candidates,
               stats.nodes, study::human_bytes(static_cast<double>(stats.memory_bytes)));
    if (params.method == Method::portals)
        fmt::print("portals: {} cells, {} segment tests, {} boxes entered beyond their own cell\n", stats.nodes,
                   stats.ray_tests, stats.portal_overlaps);
    fmt::print("contacts: {}\n", contacts);
}

/// The vertices inside the obstacles, each obstacle's count printed. With `cells` (--method portals), each vertex is
/// tested against the walls of its cell only (CellWalls: the same answer).
std::vector<ObstacleContact> query_obstacles(const ObstacleSet& obstacles, const Positions& positions,
                                             const std::vector<std::string>& paths, const CellLayout* cells)
{
    if (obstacles.size() == 0) return {};
    std::optional<CellWalls> walls;
    if (cells) walls.emplace(*cells, obstacles);
    WallStats ws;
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<ObstacleContact> inside = walls ? walls->query(positions, &ws) : obstacles.query(positions);
    const double obstacle_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (walls)
        fmt::print("walls: each vertex against the obstacles meeting its cell: {} vertex-obstacle tests of {} ({} "
                   "vertices in no cell)\n",
                   ws.tests, ws.all, ws.outside);
    for (Index k = 0; k < obstacles.size(); ++k) {
        const BspStats& b = obstacles[k].stats();
        const auto n =
            std::count_if(inside.begin(), inside.end(), [k](const ObstacleContact& c) { return c.obstacle == k; });
        fmt::print("obstacle {}: {}: {} vertices inside (bsp: {} triangles, {} planes, {} nodes, depth {})\n", k,
                   paths[static_cast<std::size_t>(k)], n, b.triangles, b.planes, b.nodes, b.depth);
    }
    fmt::print("obstacle contacts: {} ({:.3f} ms, depth and direction included)\n", inside.size(), obstacle_ms);
    return inside;
}

/// --contacts FILE: a table (.csv, with the obstacles' rows and depths where there are obstacles) or the meshes
/// (.vtu, with the contacts' depths filled in).
void write_contacts(const DetectOptions& o, DetectScene& sc, std::vector<Contact>& contacts,
                    const std::vector<ObstacleContact>& inside, bool obstacles)
{
    if (io::extension_of(o.contacts_path) == ".vtu") {
        sc.mesh.vertex_object = sc.vobj;
        sc.mesh.tet_object = sc.tobj;
        write_contacts_vtu(o.contacts_path, sc.mesh, contacts, inside);
    } else if (obstacles) {
        // Rows carry depths: the tet contacts' are computed here.
        std::vector<Contact> valued = contacts;
        sc.mesh.vertex_object = sc.vobj;
        sc.mesh.tet_object = sc.tobj;
        compute_penetration(sc.mesh, valued);
        io::write_text_file(o.contacts_path, contacts_csv(valued, sc.files, o.obstacles, inside, sc.vobj));
    } else {
        io::write_text_file(o.contacts_path, contacts_csv(contacts, sc.files));
    }
}

/// --stats FILE: the run's figures as JSON.
void write_stats(const DetectOptions& o, const DetectScene& sc, const DetectParams& params, const TimedDetection& t,
                 int repeat, std::size_t contacts, std::size_t obstacle_contacts, const EdgeFaceResult* edges,
                 double edges_ms)
{
    study::JsonWriter j;
    j.begin_object()
        .member("objects", sc.num_objects)
        .member("vertices", sc.nv)
        .member("tets", sc.nt)
        .member("contacts", contacts)
        .member("obstacle_contacts", obstacle_contacts);
    if (edges) j.member("edge_face_contacts", edges->contacts.size()).member("edge_face_ms", edges_ms);
    j.member("hash", to_string(params.hash))
        .member("method", to_string(params.method))
        .member("repeat", repeat)
        .member("median_ms", t.stats.ms_total)
        .member("first_call_ms", t.first.ms_total)
        .member("setup_ms", t.first.ms_setup);
    j.key("run_ms").begin_array();
    for (const double ms : t.ms)
        j.value(ms);
    j.end_array();
    for (const study::StatField& field : study::k_detect_stats)
        if (field.use & study::in_detect) study::write_stat(j, field, t.stats);
    j.end_object();
    const std::string f = j.str() + "\n";
    io::write_text_file(o.stats_path, f);
}

void run(const DetectOptions& o)
{
    if (o.continuous) {
        run_continuous_detection(o);
        return;
    }
    const bool side_by_side = o.method == "all"; // every method side by side
    DetectParams params = params_of(o, side_by_side);
    const int repeat = o.repeat_given ? o.repeat : side_by_side ? 3 : 1;
    if (repeat < 1) throw Error("--repeat: expected ≥ 1, got " + std::to_string(repeat));
    const bool edges = o.edges || !o.edge_contacts_path.empty();
    if (side_by_side && (!o.contacts_path.empty() || !o.stats_path.empty() || !o.obstacles.empty() || edges))
        throw Error(std::string(!o.contacts_path.empty()       ? "--contacts"
                                : !o.stats_path.empty()        ? "--stats"
                                : !o.obstacles.empty()         ? "--obstacle"
                                : o.edge_contacts_path.empty() ? "--edges"
                                                               : "--edge-contacts") +
                    ": not with --method all, which prints the comparison table (give one --method NAME)");
    params.threads = set_threads(parse_threads(o.threads));
    check_objects_from_labels_value(o.objects_from_labels);
    check_output_paths(o);
    // Obstacles: read and built (checked closed, not self-intersecting) before the work.
    ObstacleSet obstacles;
    for (const std::string& path : o.obstacles) {
        const io::SurfaceMesh surface = io::read_surface(path);
        obstacles.add(Bsp(surface.vertices, surface.triangles, "--obstacle " + path));
    }
    DetectScene sc = load_detect_scene(o);
    params.table_size = parse_table_size(o.table_size, sc.nv);
    if (!side_by_side && params.method == Method::portals && obstacles.size() > 0 && !params.partition.cells) {
        // No cell file: the cells of the free space between the obstacles, over the scene's box too.
        auto derived = std::make_shared<CellLayout>();
        if (sc.nv > 0) {
            const auto [lo, hi] = bounding_box(sc.mesh.positions);
            *derived = cells_from_obstacles(obstacles, lo.data(), hi.data());
        } else {
            *derived = cells_from_obstacles(obstacles);
        }
        const auto free = std::count_if(derived->cells.begin(), derived->cells.end(),
                                        [](const PortalCell& c) { return c.name.rfind("free", 0) == 0; });
        fmt::print("cells from the obstacles: {} cells ({} free, {} solid), {} portals\n", derived->cells.size(), free,
                   static_cast<std::ptrdiff_t>(derived->cells.size()) - free, derived->portals.size());
        params.partition.cells = std::move(derived);
    }
    if (side_by_side) {
        compare_all_methods(sc.mesh, sc.nv, sc.nt, sc.num_objects, sc.vobj, sc.tobj, sc.objects, params, repeat);
        return;
    }
    Detector det(params);
    det.set_topology(sc.mesh.tets, sc.nv, sc.vobj, sc.tobj, sc.objects);
    const TimedDetection timed = time_detection(det, sc.mesh.positions, repeat);
    const std::vector<Contact>& contacts = det.contacts();
    print_detection(sc, params, timed, repeat, contacts.size());
    const std::vector<ObstacleContact> inside =
        query_obstacles(obstacles, sc.mesh.positions, o.obstacles,
                        params.method == Method::portals ? params.partition.cells.get() : nullptr);
    EdgeFaceResult edge_result;
    double edges_ms = 0;
    if (edges) {
        const auto t0 = std::chrono::steady_clock::now();
        edge_result =
            find_edge_face_contacts(sc.mesh.tets, sc.mesh.positions, sc.vobj, sc.tobj, sc.objects, params.threads);
        edges_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        fmt::print("edge-face contacts: {} ({:.3f} ms; {} boundary edges, {} boundary faces, {} candidates)\n",
                   edge_result.contacts.size(), edges_ms, edge_result.edges.rows(), edge_result.faces.rows(),
                   edge_result.candidates);
        if (!o.edge_contacts_path.empty())
            io::write_text_file(o.edge_contacts_path, edge_contacts_csv(edge_result, sc.files));
    }
    if (!o.contacts_path.empty()) write_contacts(o, sc, det.contacts(), inside, obstacles.size() > 0);
    if (!o.stats_path.empty())
        write_stats(o, sc, params, timed, repeat, contacts.size(), inside.size(), edges ? &edge_result : nullptr,
                    edges_ms);
}

Registrar reg{
    {"detect", "Find every vertex inside a tet of another object or of its own (spatial hashing, exact)",
     [](CLI::App& sub) {
         auto o = std::make_shared<DetectOptions>();
         sub.add_option("meshes", o->meshes, "Tet meshes; together one scene, each file an object")->required();
         sub.add_option("--cell-size", o->cell_size,
                        "Cell edge length: L (a length), xF (F × the mean edge length) or auto (= x1)")
             ->capture_default_str();
         sub.add_option("--table-size", o->table_size,
                        "Hash table size: N buckets, xF (F × the vertices, rounded up to a power of two) or auto")
             ->capture_default_str();
         sub.add_option("--skin", o->skin,
                        "Candidate reuse between calls (--repeat): L (a length, 0 = off) or xF (F × cell size)")
             ->capture_default_str();
         sub.add_option("--hash", o->hash, "Hash function: column or teschner")->capture_default_str();
         sub.add_option("--threads", o->threads, "Threads: 0 = every hardware thread, or 1..256")
             ->capture_default_str();
         CLI::Option* repeat = sub.add_option("--repeat", o->repeat,
                                              "Time K calls after the first (which does the set-up and is reported "
                                              "apart); report the median (default 1; 3 with --method all)");
         sub.add_option(
                "--method", o->method,
                "Broad phase: hash, brute, grid, hgrid, octree, octree-point, octree-loose, kd, kd-point, bsp, "
                "bsp-balanced, sort-sweep, bvh, bvh-refit, portals, auto; or all: every method side by side (a table "
                "of time per stage, candidates, memory, nodes, contacts, and whether they agree)")
             ->capture_default_str();
         sub.add_option("--max-depth", o->max_depth, "Trees: deepest level, 1..30 (default: the method's)")
             ->capture_default_str();
         sub.add_option(
                "--leaf-size", o->leaf_size,
                "Trees: items a node holds before it splits; portals: vertices per slab of a cell (default 16), >= 1")
             ->capture_default_str();
         sub.add_option("--looseness", o->looseness, "Loose octree: cell enlargement factor, 1..16 (default 2)")
             ->capture_default_str();
         sub.add_option("--levels", o->levels, "Hierarchical grid: most levels, 1..32 (default: as the tet sizes span)")
             ->capture_default_str();
         sub.add_option(
             "--cells", o->cells_path,
             "Portals: the cells and portals, a text file of lines 'cell NAME XMIN YMIN ZMIN XMAX YMAX ZMAX' "
             "and 'portal CELL_A CELL_B X0 Y0 Z0 X1 Y1 Z1' (default: the free space between the --obstacle surfaces "
             "when "
             "there are any, else a grid of cells of its own; docs/partitions.md)");
         sub.add_option("--contacts", o->contacts_path,
                        "Write the contacts: FILE.csv (scene ids, objects, each side's file and id in that file's "
                        "numbering, barycentric coordinates) or FILE.vtu (the meshes with point data contact, "
                        "penetration_depth, contact_tet; cell data object)");
         sub.add_option("--stats", o->stats_path, "Write statistics JSON");
         sub.add_flag("--no-self", o->no_self, "No self-collisions (only between objects)");
         sub.add_option("--static", o->static_objects,
                        "Object index (file order, from 0) that never moves; repeat the option or give a list 0,2")
             ->allow_extra_args(false)
             ->delimiter(',');
         sub.add_option("--obstacle", o->obstacles,
                        "Closed surface file (.obj .off .stl .ply ...): a static obstacle kept as a BSP tree; the "
                        "vertices inside it (closed: on its faces counts) are reported with depth and direction. "
                        "With --method portals each vertex is tested against the walls of its cell only, and "
                        "without --cells the cells are made of the free space between the obstacles. Repeatable")
             ->allow_extra_args(false);
         sub.add_flag("--continuous", o->continuous,
                      "The two meshes are frames of the same meshes (FRAME0 FRAME1, e.g. simulation frames): report "
                      "the boundary vertex-face and edge-edge pairs that meet during the step between them (linear "
                      "motion), with a time of impact no later than each pair's first contact; --contacts FILE.csv "
                      "writes them");
         sub.add_flag("--edges", o->edges,
                      "Also report the edge-face contacts: boundary edges crossing a boundary triangle of another "
                      "object or of a distant part of their own (no vertex of the edge and of the triangle in one "
                      "tet); exact, the same rules (--no-self, --static)");
         sub.add_option("--edge-contacts", o->edge_contacts_path,
                        "Write the edge-face contacts (implies --edges): FILE.csv (the edge's and triangle's vertices, "
                        "objects, file ids, crossing point, inner end, normal)");
         add_objects_from_labels_option(sub, o->objects_from_labels);
         add_linearize_option(sub, o->linearize);
         sub.callback([o, repeat] {
             o->repeat_given = repeat->count() > 0;
             run(*o);
         });
     }}};

} // namespace
} // namespace tethash::cli
