#include "tethash/io/mesh_io.hpp"

#include "tethash/error.hpp"
#include "tethash/io/gmsh.hpp"
#include "tethash/io/medit.hpp"
#include "tethash/io/surface.hpp"
#include "tethash/io/tetgen.hpp"
#include "tethash/io/vega.hpp"
#include "tethash/io/vtk_legacy.hpp"
#include "tethash/io/vtu.hpp"

#include <algorithm>
#include <array>
#include <filesystem>
#include <string_view>

namespace tethash::io {

namespace {

// The extensions of the tet-mesh formats read_mesh and write_mesh know, and of the surfaces written.
constexpr std::array<std::string_view, 7> k_tet_read{".vtk", ".vtu", ".msh", ".node", ".ele", ".mesh", ".veg"};
constexpr std::array<std::string_view, 6> k_tet_write{".vtu", ".vtk", ".msh", ".mesh", ".node", ".ele"};
constexpr std::array<std::string_view, 5> k_surface_write{".obj", ".ply", ".stl", ".gltf", ".glb"};
constexpr const char* k_write_formats = "(expected .vtu .vtk .msh .mesh .node, or a surface .obj .ply .stl .gltf .glb)";

template <std::size_t N> bool is_one_of(const std::string& e, const std::array<std::string_view, N>& list)
{
    return std::find(list.begin(), list.end(), e) != list.end();
}

/// After --linearize: the mid-edge nodes of quadratic tets are vertices of no tet, and would be found lying on the
/// edges of their tets. Drops every vertex of no tet; the rest keep their order, and notes->vertex_ids their
/// number in the file.
void drop_unused_vertices(TetMesh& mesh, ReadNotes* notes)
{
    const Index n = mesh.num_vertices();
    std::vector<Index> new_index(static_cast<std::size_t>(n), -1);
    for (Index t = 0; t < mesh.num_tets(); ++t)
        for (int k = 0; k < 4; ++k)
            new_index[static_cast<std::size_t>(mesh.tets(t, k))] = 0;
    Index kept = 0;
    for (Index& i : new_index)
        if (i == 0) i = kept++;
    if (kept == n) return;
    const int first = notes ? notes->first_id : 0;
    std::vector<std::int64_t> ids;
    Positions positions(kept, 3), rest(mesh.rest_positions.rows() ? kept : 0, 3);
    std::vector<Index> vertex_object, vertex_label;
    for (Index v = 0; v < n; ++v) {
        const Index i = new_index[static_cast<std::size_t>(v)];
        if (i < 0) continue;
        positions.row(i) = mesh.positions.row(v);
        if (rest.rows()) rest.row(i) = mesh.rest_positions.row(v);
        if (!mesh.vertex_object.empty()) vertex_object.push_back(mesh.vertex_object[static_cast<std::size_t>(v)]);
        if (!mesh.vertex_label.empty()) vertex_label.push_back(mesh.vertex_label[static_cast<std::size_t>(v)]);
        ids.push_back(notes && !notes->vertex_ids.empty() ? notes->vertex_ids[static_cast<std::size_t>(v)]
                                                          : std::int64_t{first} + v);
    }
    for (Index t = 0; t < mesh.num_tets(); ++t)
        for (int k = 0; k < 4; ++k)
            mesh.tets(t, k) = new_index[static_cast<std::size_t>(mesh.tets(t, k))];
    mesh.positions = std::move(positions);
    mesh.rest_positions = std::move(rest);
    mesh.vertex_object = std::move(vertex_object);
    mesh.vertex_label = std::move(vertex_label);
    if (notes) {
        notes->vertex_ids = std::move(ids);
        notes->messages.push_back("--linearize: " + std::to_string(n - kept) +
                                  " nodes of no tet (mid-edge nodes) dropped; vertex ids in output count the " +
                                  std::to_string(kept) + " kept nodes");
    }
}

} // namespace

bool is_tet_mesh_path(const std::string& path)
{
    return is_one_of(extension_of(path), k_tet_read);
}

PathKind classify_path(const std::string& path)
{
    if (is_tet_mesh_path(path)) return PathKind::tet_mesh;
    if (is_surface_path(path)) return PathKind::surface;
    return PathKind::unknown;
}

TetMesh read_mesh(const std::string& path, ReadNotes* notes, const ReadOptions& options)
{
    if (!std::filesystem::exists(path)) throw Error(path + ": no such file");
    if (std::filesystem::is_directory(path)) throw Error(path + ": is a directory, expected a mesh file");
    const std::string e = extension_of(path);
    TetMesh mesh;
    if (e == ".vtk")
        mesh = read_vtk(path, notes, options);
    else if (e == ".vtu")
        mesh = read_vtu(path, notes, options);
    else if (e == ".msh")
        mesh = read_msh(path, notes, options);
    else if (e == ".node" || e == ".ele")
        mesh = read_tetgen(path, notes);
    else if (e == ".mesh")
        mesh = read_medit(path, notes);
    else if (e == ".veg")
        mesh = read_veg(path, notes);
    else if (is_surface_path(path))
        throw Error(path + ": is a surface mesh, not a tet mesh (use 'tethash tetrahedralize' to fill it with tets)");
    else
        throw Error(path + ": unknown mesh format '" + e + "' (expected .vtk .vtu .msh .node .ele .mesh .veg)");
    mesh.check_consistency(path);
    if (notes && (e == ".msh" || e == ".mesh" || e == ".veg")) notes->first_id = 1;
    if (options.linearize) drop_unused_vertices(mesh, notes);
    return mesh;
}

TetMesh read_tet_mesh(const std::string& path, ReadNotes* notes, const ReadOptions& options)
{
    ReadNotes local;
    ReadNotes& n = notes ? *notes : local;
    const std::size_t first_skipped = n.skipped.size();
    TetMesh mesh = read_mesh(path, &n, options);
    if (mesh.num_tets() > 0) return mesh;
    std::string held;
    bool quadratic = false;
    for (std::size_t k = first_skipped; k < n.skipped.size(); ++k) {
        const SkippedCells& s = n.skipped[k];
        held += (held.empty() ? "" : ", ") + std::to_string(s.count) + " cells of " + s.kind;
        quadratic = quadratic || s.quadratic_tets;
    }
    if (held.empty()) held = "no cells";
    std::string message = path + ": no tets to work on: the file holds " + std::to_string(mesh.num_vertices()) +
                          " points and " + held + "; tethash needs 4-node tets";
    if (quadratic) message += "; use the corner nodes of the quadratic tets with --linearize";
    throw Error(message);
}

void write_mesh(const std::string& path, const TetMesh& mesh, const Fields& fields)
{
    mesh.check_consistency("mesh to write to " + path);
    const std::string e = extension_of(path);
    if (e == ".vtu")
        write_vtu(path, mesh, fields);
    else if (e == ".vtk")
        write_vtk(path, mesh, fields);
    else if (e == ".msh")
        write_msh(path, mesh);
    else if (e == ".mesh")
        write_medit(path, mesh);
    else if (e == ".node" || e == ".ele")
        write_tetgen(path, mesh);
    else if (is_surface_path(path))
        write_surface(path, meshing::boundary_surface(mesh));
    else
        throw Error(path + ": unknown output format '" + e + "' " + k_write_formats);
}

void check_mesh_output_file(const std::string& path, const std::string& what)
{
    const std::string e = extension_of(path);
    const bool tet = is_one_of(e, k_tet_write);
    const bool surface = is_one_of(e, k_surface_write);
    if (!std::filesystem::is_directory(path) && !tet && !surface)
        throw Error(what + ": " + path + ": unknown output format '" + e + "' " + k_write_formats);
    if (surface && !have_assimp())
        throw Error(what + ": " + path + ": cannot write surfaces: tethash was built without assimp");
    check_output_file(path, what);
}

} // namespace tethash::io
