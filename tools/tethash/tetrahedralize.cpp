// tethash tetrahedralize SURFACE -o OUT: fill a closed surface (through assimp) with tets on the BCC lattice.
#include "command.hpp"

#include "tethash/error.hpp"
#include "tethash/io/generate.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/io/surface.hpp"

#include <fmt/core.h>

namespace tethash::cli {

std::string describe_made_mesh(const TetMesh& mesh); // generate.cpp

namespace {

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
    if (io::is_tet_mesh_path(o.surface) && !io::is_surface_path(o.surface))
        throw Error(o.surface + ": is a tet mesh format, expected a closed surface (.obj .stl .ply .off .gltf ...); "
                                "'tethash convert' changes the format of tet meshes");
    io::check_mesh_output_file(o.out, "--output");
    const io::SurfaceMesh s = io::read_surface(o.surface);
    io::TetrahedralizeParams p;
    p.resolution = o.resolution;
    p.snap = !o.no_snap;
    TetMesh mesh;
    try {
        mesh = io::tetrahedralize(s, p);
    } catch (const Error& e) {
        throw Error(o.surface + ": " + e.what());
    }
    io::write_mesh(o.out, mesh);
    fmt::print("tetrahedralized {} ({} vertices, {} triangles) at resolution {}{}: {} -> {}\n", o.surface,
               s.vertices.rows(), s.triangles.rows(), o.resolution, p.snap ? "" : " (not snapped)",
               describe_made_mesh(mesh), o.out);
}

const Registrar reg{{"tetrahedralize", "Fill a closed surface (OBJ, STL, PLY, OFF, glTF, ...) with tets (BCC lattice)",
                     [](CLI::App& sub) {
                         auto o = std::make_shared<TetrahedralizeOptions>();
                         sub.add_option("surface", o->surface, "Surface file (read through assimp)")->required();
                         sub.add_option("-o,--output", o->out, "Output mesh (.vtu .vtk .msh .mesh .node)")->required();
                         sub.add_option("-r,--resolution", o->resolution,
                                        "Lattice cells along the longest extent (1..1000)")
                             ->capture_default_str();
                         sub.add_flag("--no-snap", o->no_snap, "Do not move boundary vertices onto the surface");
                         sub.callback([o] { run_tetrahedralize(*o); });
                     }}};

} // namespace
} // namespace tethash::cli
