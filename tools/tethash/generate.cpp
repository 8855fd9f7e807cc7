// tethash generate SHAPE -o OUT: a tet mesh of a built-in shape on the BCC lattice.
#include "command.hpp"

#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/meshing/generate.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

namespace tethash::cli {

/// One line describing a made mesh: counts, volume, dihedral-angle range (shared with tetrahedralize).
std::string describe_made_mesh(const TetMesh& mesh)
{
    double min_dihedral = 180, max_dihedral = 0;
    for (Index t = 0; t < mesh.num_tets(); ++t) {
        const TetQuality q =
            tet_quality(mesh.positions, {mesh.tets(t, 0), mesh.tets(t, 1), mesh.tets(t, 2), mesh.tets(t, 3)});
        min_dihedral = std::min(min_dihedral, q.min_dihedral_deg);
        max_dihedral = std::max(max_dihedral, q.max_dihedral_deg);
    }
    const VolumeStats v = volume_stats(mesh.positions, mesh.tets);
    const auto [lo, hi] = bounding_box(mesh.positions);
    return fmt::format("{} vertices, {} tets, volume {:.6g}, bounding box {:.4g} x {:.4g} x {:.4g}, "
                       "dihedral angles {:.1f}..{:.1f} deg",
                       mesh.num_vertices(), mesh.num_tets(), v.total, hi.x() - lo.x(), hi.y() - lo.y(), hi.z() - lo.z(),
                       min_dihedral, max_dihedral);
}

namespace {

struct GenerateOptions {
    std::string shape;
    std::string out;
    int resolution = 8;
    std::vector<double> size;
    double scale = 1.0;
    bool no_snap = false;
    bool list = false;
};

void run_generate(const GenerateOptions& o)
{
    if (o.list && (!o.shape.empty() || !o.out.empty()))
        throw Error("--list prints the shapes and makes nothing: give it alone, or drop --list to make '" +
                    (o.shape.empty() ? std::string("SHAPE") : o.shape) + "'");
    if (o.list) {
        for (const meshing::ShapeInfo& s : meshing::shape_catalog())
            fmt::print("{:<10} {:.4g} x {:.4g} x {:.4g}  {}\n", s.name, s.natural_size.x(), s.natural_size.y(),
                       s.natural_size.z(), s.description);
        return;
    }
    if (o.shape.empty()) throw Error("generate: missing SHAPE (see 'tethash generate --list')");
    if (o.out.empty()) throw Error("generate: missing output file (-o OUT)");
    if (o.resolution < 1 || o.resolution > 1000)
        throw Error("--resolution " + std::to_string(o.resolution) + ": must be at least 1 and at most 1000");
    io::check_mesh_output_file(o.out, "--out");
    meshing::GenerateParams p;
    p.shape = o.shape;
    p.resolution = o.resolution;
    p.snap = !o.no_snap;
    if (!(o.scale > 0) || !std::isfinite(o.scale))
        throw Error(fmt::format("--scale {}: must be a positive number", o.scale));
    p.scale = o.scale;
    if (!o.size.empty()) {
        for (double s : o.size)
            if (!(s > 0) || !std::isfinite(s))
                throw Error(fmt::format("--size {} {} {}: every extent must be a positive number", o.size[0], o.size[1],
                                        o.size[2]));
        p.size = Eigen::Vector3d(o.size[0], o.size[1], o.size[2]);
    }
    const TetMesh mesh = meshing::generate(p);
    io::write_mesh(o.out, mesh);
    fmt::print("generated {} at resolution {}{}: {} -> {}\n", o.shape, o.resolution, p.snap ? "" : " (not snapped)",
               describe_made_mesh(mesh), o.out);
}

const Registrar reg{
    {"generate", "Make a tet mesh of a built-in shape (BCC lattice; see --list)", [](CLI::App& sub) {
         auto o = std::make_shared<GenerateOptions>();
         sub.add_option("shape", o->shape, "Shape name (see --list)");
         sub.add_option("-o,--out,--output", o->out,
                        "Output mesh (.vtu .vtk .msh .mesh .node, or a surface .obj .ply .stl .gltf .glb)");
         sub.add_option("-r,--resolution", o->resolution, "Lattice cells along the longest extent (1..1000)")
             ->capture_default_str();
         auto* size =
             sub.add_option("--size", o->size, "Bounding-box extents X Y Z (default: the shape's natural size)")
                 ->expected(3);
         sub.add_option("--scale", o->scale, "Multiply the size by S")->capture_default_str()->excludes(size);
         sub.add_flag("--no-snap", o->no_snap,
                      "Keep the lattice staircase (do not move boundary vertices onto the surface)");
         sub.add_flag("--list", o->list, "List the shapes and exit");
         sub.callback([o] { run_generate(*o); });
     }}};

} // namespace
} // namespace tethash::cli
