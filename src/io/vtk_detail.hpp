#pragma once
// Private helpers shared by the VTK legacy (.vtk) and XML (.vtu/.pvd) readers and writers:
// scalar types, byte order, label fields, base64 (numbers as text: number.hpp).
#include "number.hpp"
#include "tethash/io/mesh_io.hpp"

#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tethash::io::vtk_detail {

/// Binary scalar types of the VTK formats.
enum class Scalar { Bit, Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };

/// Size in bytes of one value (Bit: 0, packed 8 per byte).
int scalar_size(Scalar t);
bool scalar_is_integer(Scalar t);
/// VTK XML name ("Float32") of a type.
const char* xml_type_name(Scalar t);
/// Type from a VTK XML name (Int8 ... Float64), nullopt if unknown.
std::optional<Scalar> scalar_from_xml(std::string_view name);
/// Type from a legacy name (unsigned_char, int, vtktypeint64, double, ...), case-insensitive.
std::optional<Scalar> scalar_from_legacy(std::string_view name);

/// Converts `count` values of type `t` (not Bit) stored at `src` in the given byte order to double.
void convert_to_double(const unsigned char* src, Scalar t, std::size_t count, bool big_endian, double* out);
/// Same, to int64 (floating values are truncated toward zero; callers use integer types for indices).
void convert_to_int64(const unsigned char* src, Scalar t, std::size_t count, bool big_endian, std::int64_t* out);

using detail::format_double;
using detail::parse_double;
using detail::parse_int;

/// A token for an error message: printable, at most ~24 characters, in quotes.
std::string quote_token(std::string_view token);

/// Human-readable VTK cell type name ("triangle") for notes.
std::string cell_type_name(std::int64_t type);

/// Appends `v` in big-/little-endian byte order.
template <class T> void append_bytes(std::string& out, T v, bool big_endian)
{
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    const bool host_big = false; // tethash targets little-endian hosts (checked in vtk.cpp)
    if (big_endian != host_big)
        for (std::size_t i = 0; i < sizeof(T) / 2; ++i)
            std::swap(b[i], b[sizeof(T) - 1 - i]);
    out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

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
/// Checks the fields against the mesh (sizes, names; throws Error naming `path` and the field)
/// and returns point and cell arrays to write. `allow_spaces`: legacy .vtk cannot store them.
void collect_out_arrays(const std::string& path, const TetMesh& mesh, const Fields& fields, bool allow_spaces,
                        std::vector<OutArray>& point, std::vector<OutArray>& cell);

/// Base64 of `bytes` (with '=' padding).
std::string base64_encode(const unsigned char* bytes, std::size_t size);

/// Decodes base64 text piece by piece; whitespace is skipped and '=' padding may occur in the
/// middle (VTK encodes header and data separately), so concatenated encodings decode correctly.
class Base64Reader {
  public:
    Base64Reader(const char* begin, const char* end) : m_p(begin), m_end(end) {}
    /// Appends up to `n` decoded bytes to `out`; returns how many were appended (fewer at the end).
    std::size_t read(std::size_t n, std::vector<unsigned char>& out);
    /// Characters consumed so far from `begin`.
    const char* position() const { return m_p; }
    /// Set when a character outside the base64 alphabet was met (decoding stops there).
    bool bad() const { return m_bad; }
    char bad_char() const { return m_bad_char; }

  private:
    bool fill();
    const char* m_p;
    const char* m_end;
    unsigned char m_buf[3] = {0, 0, 0};
    int m_have = 0, m_next = 0;
    bool m_bad = false;
    char m_bad_char = 0;
};

/// Inflates one zlib block into `out` (appended); false on a corrupt block or a size mismatch.
/// `out` grows with the data actually inflated, never to `expected` before the stream yields it.
/// Throws Error(`where` ...) if tethash was built without zlib.
bool zlib_inflate(const unsigned char* src, std::size_t size, std::size_t expected, std::vector<unsigned char>& out,
                  const std::string& where);

} // namespace tethash::io::vtk_detail
