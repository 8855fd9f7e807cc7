// tethash convert IN OUT [--reorient]: reads a tet mesh and writes it in another format, both by extension.
#include "command.hpp"

#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/io/surface.hpp"

#include <fmt/core.h>

#include <memory>

namespace tethash::cli {

namespace {

struct ConvertOptions {
    std::string in;
    std::string out;            ///< -o/--out
    std::string out_positional; ///< the older form: convert IN OUT
    bool reorient = false;
    bool linearize = false;
};

void run_convert(ConvertOptions o)
{
    if (!o.out.empty() && !o.out_positional.empty())
        throw Error("convert: two outputs ('" + o.out_positional + "' and -o '" + o.out + "'): give one");
    if (o.out.empty()) o.out = o.out_positional;
    if (o.out.empty()) throw Error("convert: missing output file -o OUT (see 'tethash convert --help')");
    io::check_mesh_output_file(o.out, "--out"); // before reading: a bad output name costs no work
    io::ReadNotes notes;
    io::ReadOptions read_options;
    read_options.linearize = o.linearize;
    TetMesh mesh = io::read_tet_mesh(o.in, &notes, read_options);
    fmt::print("read {}: {} vertices, {} tets", o.in, mesh.num_vertices(), mesh.num_tets());
    if (notes.skipped_cells) fmt::print(" ({} non-tet cells skipped)", notes.skipped_cells);
    fmt::print("\n");
    for (const std::string& m : notes.messages)
        fmt::print("  note: {}\n", m);
    const ValidationReport report = validate(mesh);
    if (o.reorient) {
        const std::int64_t flipped = reorient_inverted(mesh);
        fmt::print("reoriented {} inverted tets\n", flipped);
    } else if (report.inverted_tets) {
        fmt::print("  note: {} inverted tets kept as they are (--reorient flips them)\n", report.inverted_tets);
    }
    io::write_mesh(o.out, mesh);
    if (io::is_surface_path(o.out))
        fmt::print("wrote {}: the boundary surface ({} triangles)\n", o.out, boundary_faces(mesh.tets).rows());
    else
        fmt::print("wrote {}: {} vertices, {} tets\n", o.out, mesh.num_vertices(), mesh.num_tets());
}

const Registrar reg{
    {"convert", "Convert a tet mesh between formats (chosen by file extension)", [](CLI::App& sub) {
         auto o = std::make_shared<ConvertOptions>();
         sub.add_option("IN", o->in, "Input tet mesh (.vtk .vtu .msh .node/.ele .mesh .veg)")->required();
         sub.add_option("-o,--out", o->out,
                        "Output (.vtu .vtk .msh .mesh .node/.ele, or a boundary surface .obj .ply .stl .gltf .glb)");
         sub.add_option("OUT", o->out_positional, "The output as a second argument (the same as -o OUT)");
         sub.add_flag("--reorient", o->reorient, "Flip inverted (negative-volume) tets before writing");
         add_linearize_option(sub, o->linearize);
         sub.callback([o] { run_convert(*o); });
     }}};

} // namespace

} // namespace tethash::cli
