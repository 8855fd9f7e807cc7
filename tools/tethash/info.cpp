// tethash info MESH... : counts, bounding box, edge lengths, volume, quality histogram, problems.
#include "command.hpp"

#include "tethash/bsp.hpp"
#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/io/surface.hpp"
#include "tethash/mesh.hpp"
#include "tethash/study/json.hpp"
#include "tethash/study/stats_table.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace tethash::cli {
namespace {

struct InfoOptions {
    std::vector<std::string> meshes;
    bool json = false;
    bool per_file = false;
    std::string objects_from_labels; ///< "" (each file one object), "separate" or "join"
    bool linearize = false;
};

/// Bins of the minimum dihedral angle, in degrees (a regular tet has 70.5°).
constexpr std::array<double, 7> kDihedralEdges = {0, 5, 10, 20, 30, 40, 50};

struct Summary {
    std::string name;
    Index vertices = 0, tets = 0, objects = 0;
    Eigen::Vector3d box_min = Eigen::Vector3d::Zero(), box_max = Eigen::Vector3d::Zero();
    EdgeStats edges;
    VolumeStats volume;
    double min_dihedral = 0, max_dihedral = 0, max_aspect = 0;
    std::array<std::int64_t, kDihedralEdges.size()> histogram{};
    std::int64_t boundary_faces = 0;
    Index components = 0; ///< connected components (tets sharing a vertex are connected)
    ValidationReport report;
    std::vector<std::string> notes;
};

Summary summarize(const std::string& name, const TetMesh& mesh, const io::ReadNotes& notes)
{
    Summary s;
    s.name = name;
    s.vertices = mesh.num_vertices();
    s.tets = mesh.num_tets();
    s.objects = mesh.num_objects();
    s.report = validate(mesh);
    s.notes = notes.messages;
    if (notes.skipped_cells) s.notes.push_back(fmt::format("{} non-tet cells skipped", notes.skipped_cells));
    if (!s.report.ok()) return s; // statistics need valid indices and finite coordinates
    std::tie(s.box_min, s.box_max) = bounding_box(mesh.positions);
    s.edges = edge_stats(mesh.positions, mesh.tets);
    s.volume = volume_stats(mesh.positions, mesh.tets);
    s.boundary_faces = boundary_faces(mesh.tets).rows();
    s.components = tet_components(mesh.tets, mesh.num_vertices());
    s.min_dihedral = mesh.num_tets() ? 180.0 : 0.0;
    for (Index t = 0; t < mesh.num_tets(); ++t) {
        const TetQuality q =
            tet_quality(mesh.positions, {mesh.tets(t, 0), mesh.tets(t, 1), mesh.tets(t, 2), mesh.tets(t, 3)});
        s.min_dihedral = std::min(s.min_dihedral, q.min_dihedral_deg);
        s.max_dihedral = std::max(s.max_dihedral, q.max_dihedral_deg);
        if (std::isfinite(q.aspect_ratio)) s.max_aspect = std::max(s.max_aspect, q.aspect_ratio);
        std::size_t bin = 0;
        while (bin + 1 < kDihedralEdges.size() && q.min_dihedral_deg >= kDihedralEdges[bin + 1])
            ++bin;
        ++s.histogram[bin];
    }
    return s;
}

/// The members of one summary's JSON object.
void write_members(study::JsonWriter& j, const Summary& s)
{
    using study::JsonWriter;
    const auto& r = s.report;
    j.member("name", s.name).member("vertices", s.vertices).member("tets", s.tets).member("objects", s.objects);
    j.key("bounding_box").begin_object(JsonWriter::inline_layout);
    for (const auto& [key, corner] :
         {std::pair<const char*, const Eigen::Vector3d*>{"min", &s.box_min}, {"max", &s.box_max}}) {
        j.key(key).begin_array();
        for (int k = 0; k < 3; ++k)
            j.value((*corner)[k]);
        j.end_array();
    }
    j.end_object();
    const auto spread = [&j](const char* key, const char* first, auto first_value, double min, double mean,
                             double max) {
        j.key(key)
            .begin_object(JsonWriter::inline_layout)
            .member(first, first_value)
            .member("min", min)
            .member("mean", mean)
            .member("max", max)
            .end_object();
    };
    spread("edges", "count", s.edges.count, s.edges.min, s.edges.mean, s.edges.max);
    spread("volume", "total", s.volume.total, s.volume.min, s.volume.mean, s.volume.max);
    j.member("boundary_faces", s.boundary_faces)
        .member("components", s.components)
        .member("min_dihedral_deg", s.min_dihedral)
        .member("max_dihedral_deg", s.max_dihedral)
        .member("max_aspect_ratio", s.max_aspect);
    j.key("quality_histogram").begin_array();
    for (std::size_t i = 0; i < kDihedralEdges.size(); ++i)
        j.begin_object().member("min_dihedral_from_deg", kDihedralEdges[i]).member("tets", s.histogram[i]).end_object();
    j.end_array();
    j.member("inverted_tets", r.inverted_tets)
        .member("degenerate_tets", r.degenerate_tets)
        .member("unreferenced_vertices", r.unreferenced_vertices)
        .member("index_out_of_range", r.index_out_of_range)
        .member("repeated_index", r.repeated_index)
        .member("non_finite_vertices", r.non_finite)
        .member("non_manifold_faces", r.non_manifold_faces);
    j.key("problems").begin_array();
    for (const auto& p : r.problems())
        j.value(p);
    j.end_array().key("notes").begin_array();
    for (const auto& n : s.notes)
        j.value(n);
    j.end_array();
}

void print_text(const Summary& s)
{
    const auto& r = s.report;
    fmt::print("{}\n", s.name);
    fmt::print("  vertices {}   tets {}   objects {}   connected components {}   boundary faces {}\n", s.vertices,
               s.tets, s.objects, s.components, s.boundary_faces);
    fmt::print("  bounding box [{:.6g}, {:.6g}, {:.6g}] - [{:.6g}, {:.6g}, {:.6g}]\n", s.box_min.x(), s.box_min.y(),
               s.box_min.z(), s.box_max.x(), s.box_max.y(), s.box_max.z());
    fmt::print("  edges {}: length min {:.6g}  mean {:.6g}  max {:.6g}\n", s.edges.count, s.edges.min, s.edges.mean,
               s.edges.max);
    fmt::print("  volume total {:.6g}: per tet min {:.6g}  mean {:.6g}  max {:.6g}\n", s.volume.total, s.volume.min,
               s.volume.mean, s.volume.max);
    fmt::print("  dihedral angles {:.2f}° - {:.2f}°, worst aspect ratio {:.3g}\n", s.min_dihedral, s.max_dihedral,
               s.max_aspect);
    fmt::print("  tets by smallest dihedral angle:\n");
    for (std::size_t i = 0; i < kDihedralEdges.size(); ++i) {
        const std::string range = i + 1 < kDihedralEdges.size()
                                      ? fmt::format("{:>3g}-{:<3g}°", kDihedralEdges[i], kDihedralEdges[i + 1])
                                      : fmt::format("{:>3g}+    ", kDihedralEdges[i]);
        const double frac = s.tets ? double(s.histogram[i]) / double(s.tets) : 0.0;
        fmt::print("    {} {:>9} {}\n", range, s.histogram[i],
                   std::string(static_cast<std::size_t>(std::lround(frac * 40)), '#'));
    }
    const auto problems = r.problems();
    if (problems.empty()) fmt::print("  problems: none\n");
    for (const auto& p : problems)
        fmt::print("  problem: {}\n", p);
    if (!r.first_bad_tets.empty()) {
        std::string ids;
        for (Index t : r.first_bad_tets)
            ids += " " + std::to_string(t);
        fmt::print("  first tets with problems:{}\n", ids);
    }
    if (!r.first_bad_vertices.empty()) {
        std::string ids;
        for (Index v : r.first_bad_vertices)
            ids += " " + std::to_string(v);
        fmt::print("  first vertices with problems:{}\n", ids);
    }
    for (const auto& n : s.notes)
        fmt::print("  note: {}\n", n);
}

/// A closed surface (an obstacle): its BSP tree's statistics.
void print_surface(const std::string& path, const io::SurfaceMesh& surface, const Bsp& bsp, bool json)
{
    const BspStats& s = bsp.stats();
    if (json) {
        study::JsonWriter j;
        j.begin_object().member("file", path).member("vertices", static_cast<Index>(surface.vertices.rows()));
        study::write_stats(j, s);
        j.end_object();
        fmt::print("{}\n", j.str());
        return;
    }
    fmt::print("{}: closed surface, {} vertices, {} triangles, {} planes (coplanar triangles merged)\n", path,
               surface.vertices.rows(), s.triangles, s.planes);
    fmt::print("  box: ({:.6g}, {:.6g}, {:.6g}) .. ({:.6g}, {:.6g}, {:.6g})\n", bsp.box_lo().x(), bsp.box_lo().y(),
               bsp.box_lo().z(), bsp.box_hi().x(), bsp.box_hi().y(), bsp.box_hi().z());
    fmt::print("  bsp: {} nodes, {} IN leaves, {} OUT leaves, depth {} (mean {:.2f}), {} face splits, {} bytes, "
               "built in {:.3f} ms{}\n",
               s.nodes, s.leaves_in, s.leaves_out, s.depth, s.mean_depth, s.splits, s.bytes, s.build_ms,
               s.flipped ? " (the surface was oriented inwards: turned outwards)" : "");
}

void run(const InfoOptions& given)
{
    // Surface files are obstacles: their BSP statistics; the tet meshes follow as one scene.
    InfoOptions opt = given;
    std::vector<std::string> surfaces;
    std::erase_if(opt.meshes, [&](const std::string& path) {
        const bool surface = io::classify_path(path) == io::PathKind::surface;
        if (surface) surfaces.push_back(path);
        return surface;
    });
    if (!surfaces.empty()) {
        // Every tree is built before printing, so that a bad surface fails before any output.
        std::vector<io::SurfaceMesh> meshes;
        std::vector<Bsp> trees;
        for (const std::string& path : surfaces) {
            meshes.push_back(io::read_surface(path));
            trees.emplace_back(meshes.back().vertices, meshes.back().triangles, path);
        }
        for (std::size_t k = 0; k < surfaces.size(); ++k)
            print_surface(surfaces[k], meshes[k], trees[k], opt.json);
        if (opt.meshes.empty()) return;
    }
    check_objects_from_labels_value(opt.objects_from_labels);
    // Read everything first, so that a bad file fails before any output.
    std::vector<Summary> summaries;
    TetMesh scene;
    io::ReadNotes all_notes;
    for (const auto& path : opt.meshes) {
        io::ReadNotes notes;
        io::ReadOptions read_options;
        read_options.linearize = opt.linearize;
        TetMesh mesh = io::read_tet_mesh(path, &notes, read_options);
        if (!opt.objects_from_labels.empty())
            notes.messages.push_back(objects_from_labels(mesh, path, opt.objects_from_labels));
        summaries.push_back(summarize(path, mesh, notes));
        scene.append(mesh);
        all_notes.skipped_cells += notes.skipped_cells;
    }
    Summary total = summaries.size() == 1 ? summaries.front() : summarize("scene", scene, all_notes);
    if (opt.json) {
        // The scene; with several files, each file's summary in "files".
        study::JsonWriter j;
        j.begin_object();
        write_members(j, total);
        if (summaries.size() > 1) {
            j.key("files").begin_array(study::JsonWriter::block_layout);
            for (const auto& one : summaries) {
                j.begin_object();
                write_members(j, one);
                j.end_object();
            }
            j.end_array();
        }
        j.end_object();
        const std::string out = j.str();
        fmt::print("{}\n", out);
        return;
    }
    if (summaries.size() > 1 && opt.per_file)
        for (const auto& s : summaries)
            print_text(s);
    print_text(total);
}

Registrar reg{
    {"info",
     "Print counts, bounding box, edge lengths, volume, quality and problems of tet meshes; BSP statistics of surfaces",
     [](CLI::App& sub) {
         auto opt = std::make_shared<InfoOptions>();
         sub.add_option("meshes", opt->meshes,
                        "Tet mesh files (.vtk .vtu .msh .node/.ele .mesh .veg); "
                        "several files are one scene, one object each. A closed surface (.obj .off .stl .ply ...) "
                        "prints the statistics of its BSP tree (the obstacle of detect --obstacle)")
             ->required();
         sub.add_flag("--json", opt->json, "Print JSON for scripts");
         sub.add_flag("--per-file", opt->per_file, "With several files, also print each file");
         add_objects_from_labels_option(sub, opt->objects_from_labels);
         add_linearize_option(sub, opt->linearize);
         sub.callback([opt] { run(*opt); });
     }}};

} // namespace
} // namespace tethash::cli
