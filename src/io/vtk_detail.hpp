#pragma once
// Private helpers shared by the VTK legacy (.vtk) and XML (.vtu/.pvd) readers and writers: scalar types,
// byte order, cell type names, what both readers share (label arrays: vtk_labels.hpp; base64 and zlib:
// vtk_encoding.hpp; numbers as text: number.hpp).
#include "number.hpp"
#include "tethash/io/mesh_io.hpp"

#include <cstdint>
#include <cstring>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
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

/// A value of an integer array read as text: an integer, or for a floating-point array `type` an integral
/// value below 9e18 in magnitude; nullopt otherwise.
std::optional<std::int64_t> parse_integer_value(std::string_view token, Scalar type);

/// A token for an error message: printable, at most 24 characters, in quotes.
inline std::string quote_token(std::string_view token)
{
    return detail::quote_token(token, 24);
}

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

/// What the legacy and XML readers share: the file, where notes go, the options, and messages that name a
/// line or a byte offset of the file.
class FileReaderBase {
  public:
    FileReaderBase(std::string path, ReadNotes* notes, const ReadOptions& options)
        : m_path(std::move(path)), m_notes(notes), m_options(options)
    {
    }

  protected:
    std::string at_line(std::int64_t line) const { return m_path + ":" + std::to_string(line); }
    std::string at_byte(std::size_t pos) const { return m_path + ": byte " + std::to_string(pos); }
    [[noreturn]] void fail(const std::string& where, const std::string& msg) const;
    /// Adds to the notes (if any) the cells skipped by VTK cell type (type -> count).
    void note_skipped_cells(const std::map<std::int64_t, std::int64_t>& skipped) const;

    std::string m_path;
    ReadNotes* m_notes;
    ReadOptions m_options;
};

} // namespace tethash::io::vtk_detail
