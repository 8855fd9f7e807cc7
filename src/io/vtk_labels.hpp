#pragma once
// Private to the VTK readers and writers: object ids and labels as data arrays (which names hold them,
// applying them to a mesh read, the arrays a writer puts out).
#include "tethash/io/mesh_io.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace tethash::io::vtk_detail {

/// A single-component data array a reader kept because its name may hold labels or object ids.
struct NamedArray {
    std::string name;
    std::vector<double> values; ///< one per point or per cell of the file
    std::string where;          ///< "FILE:LINE" of the array, for notes
};

/// True if a point/cell array called `name` may be turned into object ids or labels.
bool is_label_array_name(std::string_view name, bool cell);

/// Fills tet_object/tet_label/vertex_object/vertex_label from arrays named like "object",
/// "tet_label", "gmsh:physical", "medit:ref", ... `tet_cells[t]` is the file's cell index of tet t;
/// cell arrays must have `num_cells_in_file` values, point arrays one per vertex.
/// Arrays with non-integer values or of the wrong length are ignored with a note.
void apply_label_arrays(TetMesh& mesh, const std::vector<NamedArray>& point_arrays,
                        const std::vector<NamedArray>& cell_arrays, const std::vector<std::int64_t>& tet_cells,
                        std::size_t num_cells_in_file, ReadNotes* notes);

/// Arrays a writer puts into a file: user fields plus object ids and labels of the mesh.
struct OutArray {
    std::string name;
    int components = 1;
    bool integer = false; ///< written as Int32
    const std::vector<double>* values = nullptr;
    const std::vector<Index>* ints = nullptr;
};
/// Checks the fields against the mesh (sizes, names; throws Error naming `path` and the field) and the
/// positions (finite), and returns point and cell arrays to write. `allow_spaces`: legacy .vtk cannot store them.
void collect_out_arrays(const std::string& path, const TetMesh& mesh, const Fields& fields, bool allow_spaces,
                        std::vector<OutArray>& point, std::vector<OutArray>& cell);

} // namespace tethash::io::vtk_detail
