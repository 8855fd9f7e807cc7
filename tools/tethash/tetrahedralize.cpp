// tethash tetrahedralize SURFACE -o OUT: fill a closed surface (through assimp) with tets on the BCC lattice.
#include "command.hpp"

#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/io/surface.hpp"
#include "tethash/meshing/tetrahedralize.hpp"

#include <Eigen/Geometry>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace tethash::cli {

std::string describe_made_mesh(const TetMesh& mesh); // generate.cpp

namespace {

/// Edges of the surface used by exactly one triangle (0 for a closed surface), vertices joined by position.
std::int64_t open_edges(const io::SurfaceMesh& s)
{
    std::map<std::array<double, 3>, Index> by_position;
    std::vector<Index> joined(static_cast<std::size_t>(s.vertices.rows()));
    for (Eigen::Index v = 0; v < s.vertices.rows(); ++v)
        joined[static_cast<std::size_t>(v)] =
            by_position.try_emplace({s.vertices(v, 0), s.vertices(v, 1), s.vertices(v, 2)}, static_cast<Index>(v))
                .first->second;
    std::map<std::pair<Index, Index>, int> uses;
    for (Eigen::Index t = 0; t < s.triangles.rows(); ++t)
        for (int k = 0; k < 3; ++k) {
            Index a = joined[static_cast<std::size_t>(s.triangles(t, k))];
            Index b = joined[static_cast<std::size_t>(s.triangles(t, (k + 1) % 3))];
            if (a > b) std::swap(a, b);
            if (a != b) ++uses[{a, b}];
        }
    std::int64_t open = 0;
    for (const auto& [edge, n] : uses)
        open += n == 1;
    return open;
}

/// Volume enclosed by the surface (divergence theorem; meaningful for a closed, consistently oriented surface).
double enclosed_volume(const io::SurfaceMesh& s)
{
    double v = 0;
    for (Eigen::Index t = 0; t < s.triangles.rows(); ++t) {
        const Eigen::Vector3d a = s.vertices.row(s.triangles(t, 0)), b = s.vertices.row(s.triangles(t, 1)),
                              c = s.vertices.row(s.triangles(t, 2));
        v += a.dot(b.cross(c)) / 6.0;
    }
    return std::abs(v);
}

/// What the fill kept: connected components (and the small ones), volume against the surface's.
void report_fill(const io::SurfaceMesh& s, const TetMesh& mesh, std::int64_t open)
{
    std::vector<Index> component;
    const Index count = tet_components(mesh.tets, mesh.num_vertices(), &component);
    std::vector<std::int64_t> tets(static_cast<std::size_t>(count), 0);
    for (Index c : component)
        ++tets[static_cast<std::size_t>(c)];
    std::sort(tets.begin(), tets.end(), std::greater<>());
    std::string small;
    std::int64_t num_small = 0;
    for (std::size_t k = 1; k < tets.size(); ++k)
        if (tets[k] * 100 < tets[0]) {
            if (++num_small <= 5) small += (small.empty() ? "" : ", ") + std::to_string(tets[k]);
        }
    fmt::print("components: {}{}\n", count,
               count > 1 ? fmt::format(" (largest {} tets{})", tets[0],
                                       num_small ? fmt::format("; {} pieces below 1% of it: {}{} tets", num_small,
                                                               small, num_small > 5 ? ", ..." : "")
                                                 : "")
                         : "");
    const double surface = enclosed_volume(s), filled = volume_stats(mesh.positions, mesh.tets).total;
    if (open == 0 && surface > 0)
        fmt::print("volume: the surface encloses {:.6g}, the tets fill {:.6g} ({:+.2f}%: {})\n", surface, filled,
                   100.0 * (filled - surface) / surface,
                   filled < surface ? "dropped where the lattice is too coarse" : "added along the boundary");
    if (count > 1)
        std::fprintf(stderr,
                     "tethash: warning: the tets form %d separate pieces; thin parts of the surface may be lost "
                     "at this resolution (a higher --resolution keeps them)\n",
                     static_cast<int>(count));
}

struct TetrahedralizeOptions {
    std::string surface;
    std::string out;
    int resolution = 16;
    bool no_snap = false;
};

void run_tetrahedralize(const TetrahedralizeOptions& o)
{
    if (o.resolution < 1 || o.resolution > 1000)
        throw Error("--resolution " + std::to_string(o.resolution) + ": must be at least 1 and at most 1000");
    if (io::classify_path(o.surface) == io::PathKind::tet_mesh)
        throw Error(o.surface + ": is a tet mesh format, expected a closed surface (.obj .stl .ply .off .gltf ...); "
                                "'tethash convert' changes the format of tet meshes");
    io::check_mesh_output_file(o.out, "--out");
    const io::SurfaceMesh s = io::read_surface(o.surface);
    meshing::TetrahedralizeParams p;
    p.resolution = o.resolution;
    p.snap = !o.no_snap;
    const std::int64_t open = open_edges(s);
    if (open)
        std::fprintf(stderr,
                     "tethash: warning: %s: the surface is open (%lld edges belong to one triangle only): its inside "
                     "is not well defined, the tets may leak out of it or miss parts\n",
                     o.surface.c_str(), static_cast<long long>(open));
    TetMesh mesh;
    try {
        mesh = meshing::tetrahedralize(s, p);
    } catch (const Error& e) {
        throw Error(o.surface + ": " + e.what());
    }
    io::write_mesh(o.out, mesh);
    fmt::print("tetrahedralized {} ({} vertices, {} triangles) at resolution {}{}: {} -> {}\n", o.surface,
               s.vertices.rows(), s.triangles.rows(), o.resolution, p.snap ? "" : " (not snapped)",
               describe_made_mesh(mesh), o.out);
    report_fill(s, mesh, open);
}

const Registrar reg{
    {"tetrahedralize", "Fill a closed surface (OBJ, STL, PLY, OFF, glTF, ...) with tets (BCC lattice)",
     [](CLI::App& sub) {
         auto o = std::make_shared<TetrahedralizeOptions>();
         sub.add_option("surface", o->surface, "Surface file (read through assimp)")->required();
         sub.add_option("-o,--out,--output", o->out, "Output mesh (.vtu .vtk .msh .mesh .node)")->required();
         sub.add_option("-r,--resolution", o->resolution, "Lattice cells along the longest extent (1..1000)")
             ->capture_default_str();
         sub.add_flag("--no-snap", o->no_snap, "Do not move boundary vertices onto the surface");
         sub.callback([o] { run_tetrahedralize(*o); });
     }}};

} // namespace
} // namespace tethash::cli
