// Helpers shared by the VTK legacy and XML readers/writers (see vtk_detail.hpp).
#include "vtk_detail.hpp"

#include "number.hpp"
#include "tethash/error.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <limits>

static_assert(std::endian::native == std::endian::little, "the VTK readers and writers assume a little-endian host");

namespace tethash::io {

namespace vtk_detail {

int scalar_size(Scalar t)
{
    switch (t) {
    case Scalar::Bit:
        return 0;
    case Scalar::Int8:
    case Scalar::UInt8:
        return 1;
    case Scalar::Int16:
    case Scalar::UInt16:
        return 2;
    case Scalar::Int32:
    case Scalar::UInt32:
    case Scalar::Float32:
        return 4;
    case Scalar::Int64:
    case Scalar::UInt64:
    case Scalar::Float64:
        return 8;
    }
    return 0;
}

bool scalar_is_integer(Scalar t)
{
    return t != Scalar::Float32 && t != Scalar::Float64;
}

const char* xml_type_name(Scalar t)
{
    switch (t) {
    case Scalar::Bit:
        return "Bit";
    case Scalar::Int8:
        return "Int8";
    case Scalar::UInt8:
        return "UInt8";
    case Scalar::Int16:
        return "Int16";
    case Scalar::UInt16:
        return "UInt16";
    case Scalar::Int32:
        return "Int32";
    case Scalar::UInt32:
        return "UInt32";
    case Scalar::Int64:
        return "Int64";
    case Scalar::UInt64:
        return "UInt64";
    case Scalar::Float32:
        return "Float32";
    case Scalar::Float64:
        return "Float64";
    }
    return "?";
}

std::optional<Scalar> scalar_from_xml(std::string_view n)
{
    static const std::pair<const char*, Scalar> table[] = {
        {"Int8", Scalar::Int8},       {"UInt8", Scalar::UInt8},   {"Int16", Scalar::Int16},
        {"UInt16", Scalar::UInt16},   {"Int32", Scalar::Int32},   {"UInt32", Scalar::UInt32},
        {"Int64", Scalar::Int64},     {"UInt64", Scalar::UInt64}, {"Float32", Scalar::Float32},
        {"Float64", Scalar::Float64},
    };
    for (const auto& [name, t] : table)
        if (n == name) return t;
    return std::nullopt;
}

using detail::to_lower;

std::optional<Scalar> scalar_from_legacy(std::string_view name)
{
    static const std::pair<const char*, Scalar> table[] = {
        {"bit", Scalar::Bit},
        {"char", Scalar::Int8},
        {"signed_char", Scalar::Int8},
        {"unsigned_char", Scalar::UInt8},
        {"short", Scalar::Int16},
        {"unsigned_short", Scalar::UInt16},
        {"int", Scalar::Int32},
        {"unsigned_int", Scalar::UInt32},
        {"long", Scalar::Int64}, // LP64: VTK writes sizeof(long) bytes
        {"unsigned_long", Scalar::UInt64},
        {"vtkidtype", Scalar::Int32}, // the legacy writer stores vtkIdType arrays as int
        {"float", Scalar::Float32},
        {"double", Scalar::Float64},
        {"vtktypeint8", Scalar::Int8},
        {"vtktypeuint8", Scalar::UInt8},
        {"vtktypeint16", Scalar::Int16},
        {"vtktypeuint16", Scalar::UInt16},
        {"vtktypeint32", Scalar::Int32},
        {"vtktypeuint32", Scalar::UInt32},
        {"vtktypeint64", Scalar::Int64},
        {"vtktypeuint64", Scalar::UInt64},
        {"vtktypefloat32", Scalar::Float32},
        {"vtktypefloat64", Scalar::Float64},
    };
    const std::string n = to_lower(name);
    for (const auto& [key, t] : table)
        if (n == key) return t;
    return std::nullopt;
}

namespace {
template <class T> T load(const unsigned char* p, bool big_endian)
{
    unsigned char b[sizeof(T)];
    std::memcpy(b, p, sizeof(T));
    if (big_endian)
        for (std::size_t i = 0; i < sizeof(T) / 2; ++i)
            std::swap(b[i], b[sizeof(T) - 1 - i]);
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
}

template <class Out> void convert(const unsigned char* src, Scalar t, std::size_t count, bool be, Out* out)
{
    const int s = scalar_size(t);
    for (std::size_t i = 0; i < count; ++i, src += s) {
        switch (t) {
        case Scalar::Bit:
            out[i] = 0;
            break;
        case Scalar::Int8:
            out[i] = static_cast<Out>(load<std::int8_t>(src, be));
            break;
        case Scalar::UInt8:
            out[i] = static_cast<Out>(load<std::uint8_t>(src, be));
            break;
        case Scalar::Int16:
            out[i] = static_cast<Out>(load<std::int16_t>(src, be));
            break;
        case Scalar::UInt16:
            out[i] = static_cast<Out>(load<std::uint16_t>(src, be));
            break;
        case Scalar::Int32:
            out[i] = static_cast<Out>(load<std::int32_t>(src, be));
            break;
        case Scalar::UInt32:
            out[i] = static_cast<Out>(load<std::uint32_t>(src, be));
            break;
        case Scalar::Int64:
            out[i] = static_cast<Out>(load<std::int64_t>(src, be));
            break;
        case Scalar::UInt64: {
            const std::uint64_t v = load<std::uint64_t>(src, be);
            // Values past int64 become -1 so that range checks reject them.
            if constexpr (std::is_integral_v<Out>)
                out[i] = v > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()) ? Out(-1)
                                                                                                  : static_cast<Out>(v);
            else
                out[i] = static_cast<Out>(v);
            break;
        }
        case Scalar::Float32:
        case Scalar::Float64: {
            const double v = t == Scalar::Float32 ? double(load<float>(src, be)) : load<double>(src, be);
            if constexpr (std::is_integral_v<Out>)
                out[i] = std::isfinite(v) && std::abs(v) < 9e18 ? static_cast<Out>(v) : Out(-1);
            else
                out[i] = v;
            break;
        }
        }
    }
}
} // namespace

void convert_to_double(const unsigned char* src, Scalar t, std::size_t count, bool big_endian, double* out)
{
    convert(src, t, count, big_endian, out);
}

void convert_to_int64(const unsigned char* src, Scalar t, std::size_t count, bool big_endian, std::int64_t* out)
{
    convert(src, t, count, big_endian, out);
}

std::optional<std::int64_t> parse_integer_value(std::string_view token, Scalar type)
{
    auto v = parse_int(token);
    if (!v && !scalar_is_integer(type)) {
        const auto d = parse_double(token);
        if (d && std::isfinite(*d) && *d == std::floor(*d) && std::abs(*d) < 9e18) v = static_cast<std::int64_t>(*d);
    }
    return v;
}

void FileReaderBase::fail(const std::string& where, const std::string& msg) const
{
    throw Error(where + ": " + msg);
}

void FileReaderBase::note_skipped_cells(const std::map<std::int64_t, std::int64_t>& skipped) const
{
    if (!m_notes) return;
    for (const auto& [type, count] : skipped) {
        const std::string kind = "type " + std::to_string(type) + " (" + cell_type_name(type) + ")";
        m_notes->skipped_cells += count;
        m_notes->messages.push_back(m_path + ": skipped " + std::to_string(count) + " cells of " + kind);
        m_notes->skipped.push_back({count, kind, type == 24});
    }
}

std::string cell_type_name(std::int64_t type)
{
    switch (type) {
    case 1:
        return "vertex";
    case 2:
        return "poly-vertex";
    case 3:
        return "line";
    case 4:
        return "poly-line";
    case 5:
        return "triangle";
    case 6:
        return "triangle strip";
    case 7:
        return "polygon";
    case 8:
        return "pixel";
    case 9:
        return "quad";
    case 10:
        return "tetra";
    case 11:
        return "voxel";
    case 12:
        return "hexahedron";
    case 13:
        return "wedge";
    case 14:
        return "pyramid";
    case 22:
        return "quadratic triangle";
    case 24:
        return "quadratic tetra";
    case 25:
        return "quadratic hexahedron";
    case 42:
        return "polyhedron";
    default:
        return "type " + std::to_string(type);
    }
}

} // namespace vtk_detail
} // namespace tethash::io
