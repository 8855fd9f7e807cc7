// Helpers shared by the VTK legacy and XML readers/writers (see vtk_detail.hpp).
#include "vtk_detail.hpp"

#include "number.hpp"

#include "core/enum_names.hpp"
#include "tethash/error.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <iterator>
#include <limits>
#include <type_traits>

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

namespace {
constexpr tethash::detail::EnumName<Scalar> k_xml_names[] = {
    {Scalar::Bit, "Bit"},       {Scalar::Int8, "Int8"},       {Scalar::UInt8, "UInt8"},     {Scalar::Int16, "Int16"},
    {Scalar::UInt16, "UInt16"}, {Scalar::Int32, "Int32"},     {Scalar::UInt32, "UInt32"},   {Scalar::Int64, "Int64"},
    {Scalar::UInt64, "UInt64"}, {Scalar::Float32, "Float32"}, {Scalar::Float64, "Float64"},
};
} // namespace

const char* xml_type_name(Scalar t)
{
    return tethash::detail::name_of(k_xml_names, t);
}

std::optional<Scalar> scalar_from_xml(std::string_view n)
{
    const auto t = tethash::detail::value_named(k_xml_names, n);
    return t == Scalar::Bit ? std::nullopt : t; // bit arrays are not read
}

using detail::to_lower;

std::optional<Scalar> scalar_from_legacy(std::string_view name)
{
    static constexpr tethash::detail::EnumName<Scalar> table[] = {
        {Scalar::Bit, "bit"},
        {Scalar::Int8, "char"},
        {Scalar::Int8, "signed_char"},
        {Scalar::UInt8, "unsigned_char"},
        {Scalar::Int16, "short"},
        {Scalar::UInt16, "unsigned_short"},
        {Scalar::Int32, "int"},
        {Scalar::UInt32, "unsigned_int"},
        {Scalar::Int64, "long"}, // LP64: VTK writes sizeof(long) bytes
        {Scalar::UInt64, "unsigned_long"},
        {Scalar::Int32, "vtkidtype"}, // the legacy writer stores vtkIdType arrays as int
        {Scalar::Float32, "float"},
        {Scalar::Float64, "double"},
        {Scalar::Int8, "vtktypeint8"},
        {Scalar::UInt8, "vtktypeuint8"},
        {Scalar::Int16, "vtktypeint16"},
        {Scalar::UInt16, "vtktypeuint16"},
        {Scalar::Int32, "vtktypeint32"},
        {Scalar::UInt32, "vtktypeuint32"},
        {Scalar::Int64, "vtktypeint64"},
        {Scalar::UInt64, "vtktypeuint64"},
        {Scalar::Float32, "vtktypefloat32"},
        {Scalar::Float64, "vtktypefloat64"},
    };
    return tethash::detail::value_named(table, to_lower(name));
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

/// One value of type T at `src` as an Out. Integer outputs take -1 for what they cannot hold (uint64 values past
/// int64, non-finite or huge floating-point values) so that range checks reject it.
template <class T, class Out> Out load_as(const unsigned char* src, bool big_endian)
{
    const T v = load<T>(src, big_endian);
    if constexpr (std::is_integral_v<Out> && std::is_floating_point_v<T>) {
        const double d = v;
        return std::isfinite(d) && std::abs(d) < 9e18 ? static_cast<Out>(d) : Out(-1);
    } else if constexpr (std::is_integral_v<Out> && std::is_same_v<T, std::uint64_t>) {
        return v > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()) ? Out(-1) : static_cast<Out>(v);
    } else {
        return static_cast<Out>(v);
    }
}

template <class Out> Out load_bit(const unsigned char*, bool)
{
    return 0;
}

template <class Out> void convert(const unsigned char* src, Scalar t, std::size_t count, bool be, Out* out)
{
    using Load = Out (*)(const unsigned char*, bool);
    // In the order of Scalar.
    static constexpr Load loads[] = {
        load_bit<Out>,
        load_as<std::int8_t, Out>,
        load_as<std::uint8_t, Out>,
        load_as<std::int16_t, Out>,
        load_as<std::uint16_t, Out>,
        load_as<std::int32_t, Out>,
        load_as<std::uint32_t, Out>,
        load_as<std::int64_t, Out>,
        load_as<std::uint64_t, Out>,
        load_as<float, Out>,
        load_as<double, Out>,
    };
    static_assert(std::size(loads) == static_cast<std::size_t>(Scalar::Float64) + 1);
    const Load load_one = loads[static_cast<std::size_t>(t)];
    const int s = scalar_size(t);
    for (std::size_t i = 0; i < count; ++i, src += s)
        out[i] = load_one(src, be);
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
