#pragma once
/// \file io/mesh_io.hpp
/// Reading and writing tet meshes by file extension, and the types every format shares.
///
/// Readers throw tethash::Error with a message "FILE:LINE: expected X, found Y" (or "FILE: byte
/// OFFSET: ..." for binary data). Writers write atomically (io/file.hpp).

#include "tethash/error.hpp"
#include "tethash/io/file.hpp"
#include "tethash/mesh.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace tethash::io {

/// A data array attached to points or cells for output (ParaView shows it by name).
struct Field {
    std::string name;
    int components = 1;         ///< 1 (scalar) or 3 (vector)
    std::vector<double> values; ///< size = count × components, row-major
};
struct Fields {
    std::vector<Field> point; ///< one value per vertex
    std::vector<Field> cell;  ///< one value per tet
};

/// Cells of one kind a reader skipped.
struct SkippedCells {
    std::int64_t count = 0;
    std::string kind;            ///< "type 24 (quadratic tetra)" in the file format's own words
    bool quadratic_tets = false; ///< 10-node tets: ReadOptions::linearize would keep their corners
};

/// Notes a reader makes without failing (for example "skipped 12 cells of type 5").
struct ReadNotes {
    std::int64_t skipped_cells = 0;    ///< non-tet cells skipped
    std::vector<std::string> messages; ///< human-readable notes
    std::vector<SkippedCells> skipped; ///< the skipped cells by kind
    /// The file's own numbering, for output that refers back to it: vertex k and tet t are number
    /// vertex_ids[k] and tet_ids[t] in the file where these are given (Gmsh node and element tags; vertices
    /// kept by --linearize), else first_id + k and first_id + t.
    std::vector<std::int64_t> vertex_ids, tet_ids;
    int first_id = 0; ///< 1 for formats that count from 1 (Gmsh, Medit, Vega; TetGen files starting at 1)
};

/// What a reader may do beyond reading 4-node tets.
struct ReadOptions {
    /// Quadratic (10-node) tets (VTK type 24, Gmsh type 11) are read as 4-node tets of their corner nodes, which
    /// every format lists first; their mid-edge nodes stay as vertices of no tet. Off: they are skipped.
    bool linearize = false;
};

/// Formats by extension: .vtk .vtu .msh .node/.ele (either name) .mesh .veg (tet meshes);
/// surfaces (.obj .stl .ply .off .gltf .glb ...) are not tet meshes: use surface.hpp.
TetMesh read_mesh(const std::string& path, ReadNotes* notes = nullptr, const ReadOptions& options = {});
/// read_mesh for the commands that need tets: a file that holds no 4-node tet after reading is an Error naming
/// the file and what it held instead ("3717 cells of type 24 (quadratic tetra)"), with the remedy where there is
/// one (ReadOptions::linearize, the command line's --linearize).
TetMesh read_tet_mesh(const std::string& path, ReadNotes* notes = nullptr, const ReadOptions& options = {});
/// Writers by extension: .vtu .vtk .msh (4.1) .mesh .node/.ele; surfaces (.obj .ply .stl .gltf/.glb) write the
/// boundary.
void write_mesh(const std::string& path, const TetMesh& mesh, const Fields& fields = {});
/// True if `path` has an extension read_mesh knows.
bool is_tet_mesh_path(const std::string& path);

/// What a file holds, told by its extension: a tet mesh (read_mesh), a surface (io/surface.hpp: obstacles and
/// tetrahedralization) or neither. The one test the simulator, `info` and `tetrahedralize` make.
enum class PathKind { tet_mesh, surface, unknown };
PathKind classify_path(const std::string& path);

/// check_output_file plus: the extension is one write_mesh knows.
void check_mesh_output_file(const std::string& path, const std::string& what = "output");

} // namespace tethash::io
