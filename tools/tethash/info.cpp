// tethash info MESH... : counts, bounding box, edge lengths, volume, quality histogram, problems.
#include "command.hpp"

#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/mesh.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <string>
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

std::string json_string(const std::string& s)
{
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\')
            out += '\\', out += c;
        else if (static_cast<unsigned char>(c) < 0x20)
            out += fmt::format("\\u{:04x}", c);
        else
            out += c;
    }
    return out + "\"";
}

std::string json_number(double v)
{
    return std::isfinite(v) ? fmt::format("{}", v) : "null";
}

std::string to_json(const Summary& s, const std::string& indent)
{
    const auto& r = s.report;
    std::string o = "{\n";
    auto kv = [&](const std::string& k, const std::string& v, bool last = false) {
        o += indent + "  " + json_string(k) + ": " + v + (last ? "\n" : ",\n");
    };
    kv("name", json_string(s.name));
    kv("vertices", std::to_string(s.vertices));
    kv("tets", std::to_string(s.tets));
    kv("objects", std::to_string(s.objects));
    kv("bounding_box", fmt::format("{{\"min\": [{}, {}, {}], \"max\": [{}, {}, {}]}}", json_number(s.box_min.x()),
                                   json_number(s.box_min.y()), json_number(s.box_min.z()), json_number(s.box_max.x()),
                                   json_number(s.box_max.y()), json_number(s.box_max.z())));
    kv("edges", fmt::format("{{\"count\": {}, \"min\": {}, \"mean\": {}, \"max\": {}}}", s.edges.count,
                            json_number(s.edges.min), json_number(s.edges.mean), json_number(s.edges.max)));
    kv("volume", fmt::format("{{\"total\": {}, \"min\": {}, \"mean\": {}, \"max\": {}}}", json_number(s.volume.total),
                             json_number(s.volume.min), json_number(s.volume.mean), json_number(s.volume.max)));
    kv("boundary_faces", std::to_string(s.boundary_faces));
    kv("components", std::to_string(s.components));
    kv("min_dihedral_deg", json_number(s.min_dihedral));
    kv("max_dihedral_deg", json_number(s.max_dihedral));
    kv("max_aspect_ratio", json_number(s.max_aspect));
    std::string hist = "[";
    for (std::size_t i = 0; i < kDihedralEdges.size(); ++i)
        hist += fmt::format("{}{{\"min_dihedral_from_deg\": {}, \"tets\": {}}}", i ? ", " : "", kDihedralEdges[i],
                            s.histogram[i]);
    kv("quality_histogram", hist + "]");
    kv("inverted_tets", std::to_string(r.inverted_tets));
    kv("degenerate_tets", std::to_string(r.degenerate_tets));
    kv("unreferenced_vertices", std::to_string(r.unreferenced_vertices));
    kv("index_out_of_range", std::to_string(r.index_out_of_range));
    kv("repeated_index", std::to_string(r.repeated_index));
    kv("non_finite_vertices", std::to_string(r.non_finite));
    kv("non_manifold_faces", std::to_string(r.non_manifold_faces));
    std::string problems = "[";
    for (std::size_t i = 0; i < r.problems().size(); ++i)
        problems += (i ? ", " : "") + json_string(r.problems()[i]);
    kv("problems", problems + "]");
    std::string notes = "[";
    for (std::size_t i = 0; i < s.notes.size(); ++i)
        notes += (i ? ", " : "") + json_string(s.notes[i]);
    kv("notes", notes + "]", true);
    return o + indent + "}";
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
                   std::string(static_cast<std::size_t>(frac * 40 + 0.5), '#'));
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

void run(const InfoOptions& opt)
{
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
        std::string out = to_json(total, "");
        if (summaries.size() > 1) {
            out.pop_back(); // closing brace
            out.pop_back(); // newline before it: to_json ends with "\n}" -> reopen the object
            out += ",\n  \"files\": [";
            for (std::size_t i = 0; i < summaries.size(); ++i)
                out += (i ? ", " : "") + to_json(summaries[i], "  ");
            out += "]\n}";
        }
        fmt::print("{}\n", out);
        return;
    }
    if (summaries.size() > 1 && opt.per_file)
        for (const auto& s : summaries)
            print_text(s);
    print_text(total);
}

Registrar reg{
    {"info", "Print counts, bounding box, edge lengths, volume, quality and problems of tet meshes", [](CLI::App& sub) {
         auto opt = std::make_shared<InfoOptions>();
         sub.add_option("meshes", opt->meshes,
                        "Tet mesh files (.vtk .vtu .msh .node/.ele .mesh .veg); "
                        "several files are one scene, one object each")
             ->required();
         sub.add_flag("--json", opt->json, "Print JSON for scripts");
         sub.add_flag("--per-file", opt->per_file, "With several files, also print each file");
         add_objects_from_labels_option(sub, opt->objects_from_labels);
         add_linearize_option(sub, opt->linearize);
         sub.callback([opt] { run(*opt); });
     }}};

} // namespace
} // namespace tethash::cli
