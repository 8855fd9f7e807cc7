// Helpers shared by the VTK legacy and XML readers/writers (see vtk_detail.hpp).
#include "vtk_detail.hpp"

#include "number.hpp"
#include "tethash/error.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <limits>

#ifdef TETHASH_HAVE_ZLIB
#include <zlib.h>
#endif

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

std::string quote_token(std::string_view token)
{
    std::string r = "'";
    std::size_t n = 0;
    for (unsigned char c : token) {
        if (++n > 24) {
            r += "...";
            break;
        }
        if (c >= 32 && c < 127) {
            r += static_cast<char>(c);
        } else {
            static const char* hex = "0123456789abcdef";
            r += "\\x";
            r += hex[c >> 4];
            r += hex[c & 15];
        }
    }
    return r + "'";
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

// ---- label arrays --------------------------------------------------------------------------

namespace {
const char* const k_object_names[] = {"object", "tet_object", "vertex_object"};
const char* const k_cell_label_names[] = {"tet_label",     "label",       "gmsh:physical", "medit:ref",
                                          "cellentityids", "materialids", "material"};
const char* const k_point_label_names[] = {"vertex_label", "label", "medit:ref", "tetgen:ref"};

/// Rank of `name` in `list` (lower is preferred), or -1.
template <std::size_t N> int rank_in(const std::string& name, const char* const (&list)[N])
{
    for (std::size_t i = 0; i < N; ++i)
        if (name == list[i]) return static_cast<int>(i);
    return -1;
}

bool all_integers(const std::vector<double>& v, double min_value)
{
    return std::all_of(v.begin(), v.end(), [&](double x) {
        return std::isfinite(x) && x == std::floor(x) && x >= min_value && x <= 2147483647.0;
    });
}
} // namespace

bool is_label_array_name(std::string_view name, bool cell)
{
    const std::string n = to_lower(name);
    if (rank_in(n, k_object_names) >= 0) return true;
    return cell ? rank_in(n, k_cell_label_names) >= 0 : rank_in(n, k_point_label_names) >= 0;
}

void apply_label_arrays(TetMesh& mesh, const std::vector<NamedArray>& point_arrays,
                        const std::vector<NamedArray>& cell_arrays, const std::vector<std::int64_t>& tet_cells,
                        std::size_t num_cells_in_file, ReadNotes* notes)
{
    const auto note = [&](const std::string& s) {
        if (notes) notes->messages.push_back(s);
    };
    const std::size_t n = static_cast<std::size_t>(mesh.num_vertices());
    // Picks the best-ranked usable array of a list.
    const auto pick = [&](const std::vector<NamedArray>& arrays, const auto& names, double min_value,
                          std::size_t expected, const char* what) -> const NamedArray* {
        const NamedArray* best = nullptr;
        int best_rank = 1 << 30;
        for (const NamedArray& a : arrays) {
            const int r = rank_in(to_lower(a.name), names);
            if (r < 0 || r >= best_rank) continue;
            if (a.values.size() != expected) {
                note(a.where + ": array '" + a.name + "' has " + std::to_string(a.values.size()) +
                     " values, expected " + std::to_string(expected) + "; not used as " + what);
                continue;
            }
            if (!all_integers(a.values, min_value)) {
                note(a.where + ": array '" + a.name + "' holds values that are not " +
                     (min_value >= 0 ? "non-negative " : "") + "integers; not used as " + what);
                continue;
            }
            best = &a;
            best_rank = r;
        }
        return best;
    };
    const auto per_tet = [&](const NamedArray& a) {
        std::vector<Index> r(tet_cells.size());
        for (std::size_t t = 0; t < tet_cells.size(); ++t)
            r[t] = static_cast<Index>(a.values[static_cast<std::size_t>(tet_cells[t])]);
        return r;
    };
    // Object ids number objects from 0 and every object holds at least one cell or point, so an id
    // must be below their count: larger ones (2147483647) would overflow the object count.
    const auto check_object_ids = [&](const NamedArray& a, const char* element) {
        for (std::size_t i = 0; i < a.values.size(); ++i)
            if (a.values[i] >= static_cast<double>(a.values.size()))
                throw Error(a.where + ": array '" + a.name + "' gives " + element + " " + std::to_string(i) +
                            " object id " + std::to_string(static_cast<std::int64_t>(a.values[i])) +
                            ", expected an id below the number of " + element + "s (" +
                            std::to_string(a.values.size()) + "): objects are numbered from 0");
    };
    const std::size_t cells = num_cells_in_file;
    if (const NamedArray* a = pick(cell_arrays, k_object_names, 0, cells, "object ids")) {
        check_object_ids(*a, "cell");
        mesh.tet_object = per_tet(*a);
    }
    if (const NamedArray* a = pick(cell_arrays, k_cell_label_names, -2147483648.0, cells, "tet labels"))
        mesh.tet_label = per_tet(*a);
    if (const NamedArray* a = pick(point_arrays, k_object_names, 0, n, "object ids")) {
        check_object_ids(*a, "point");
        mesh.vertex_object.assign(a->values.begin(), a->values.end());
    }
    if (const NamedArray* a = pick(point_arrays, k_point_label_names, -2147483648.0, n, "vertex labels"))
        mesh.vertex_label.assign(a->values.begin(), a->values.end());

    // Object ids on one side only: derive the other (a vertex takes the object of a tet using it).
    if (!mesh.tet_object.empty() && mesh.vertex_object.empty()) {
        mesh.vertex_object.assign(n, 0);
        for (Index t = 0; t < mesh.num_tets(); ++t)
            for (int k = 0; k < 4; ++k)
                mesh.vertex_object[static_cast<std::size_t>(mesh.tets(t, k))] = mesh.tet_object[t];
    } else if (mesh.tet_object.empty() && !mesh.vertex_object.empty()) {
        mesh.tet_object.resize(static_cast<std::size_t>(mesh.num_tets()));
        for (Index t = 0; t < mesh.num_tets(); ++t)
            mesh.tet_object[t] = mesh.vertex_object[static_cast<std::size_t>(mesh.tets(t, 0))];
    }
}

void collect_out_arrays(const std::string& path, const TetMesh& mesh, const Fields& fields, bool allow_spaces,
                        std::vector<OutArray>& point, std::vector<OutArray>& cell)
{
    point.clear();
    cell.clear();
    const auto check = [&](const Field& f, std::size_t count, const char* where) {
        if (f.name.empty()) throw Error(path + ": a " + std::string(where) + " field has an empty name");
        for (unsigned char c : f.name) {
            if (c < 32 || c == 127 || (!allow_spaces && c == ' '))
                throw Error(path + ": " + where + " field name '" + f.name + "' contains " +
                            (c == ' ' ? "a space, which legacy .vtk cannot store" : "a control character"));
            if (c == '"' || c == '<' || c == '&')
                throw Error(path + ": " + where + " field name '" + f.name + "' contains '" +
                            std::string(1, static_cast<char>(c)) + "'");
        }
        if (f.components < 1)
            throw Error(path + ": " + where + " field '" + f.name + "' has " + std::to_string(f.components) +
                        " components, expected at least 1");
        if (f.values.size() != count * static_cast<std::size_t>(f.components))
            throw Error(path + ": " + where + " field '" + f.name + "' has " + std::to_string(f.values.size()) +
                        " values, expected " + std::to_string(count) + " × " + std::to_string(f.components) + " = " +
                        std::to_string(count * static_cast<std::size_t>(f.components)));
    };
    const auto add_fields = [&](const std::vector<Field>& in, std::size_t count, const char* where,
                                std::vector<OutArray>& out) {
        for (const Field& f : in) {
            check(f, count, where);
            for (const OutArray& o : out)
                if (o.name == f.name)
                    throw Error(path + ": two " + std::string(where) + " fields are called '" + f.name + "'");
            out.push_back({f.name, f.components, false, &f.values, nullptr});
        }
    };
    const std::size_t n = static_cast<std::size_t>(mesh.num_vertices()), m = static_cast<std::size_t>(mesh.num_tets());
    add_fields(fields.point, n, "point", point);
    add_fields(fields.cell, m, "cell", cell);
    const auto add_ints = [](std::vector<OutArray>& out, const char* name, const std::vector<Index>& v,
                             std::size_t count) {
        if (v.size() != count || count == 0) return;
        for (const OutArray& o : out)
            if (o.name == name) return; // a user field of that name wins
        out.push_back({name, 1, true, nullptr, &v});
    };
    add_ints(point, "object", mesh.vertex_object, n);
    add_ints(point, "vertex_label", mesh.vertex_label, n);
    add_ints(cell, "object", mesh.tet_object, m);
    add_ints(cell, "tet_label", mesh.tet_label, m);
}

// ---- base64 ----------------------------------------------------------------------------------

namespace {
const char* const k_b64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
int b64_value(unsigned char c)
{
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
}
} // namespace

std::string base64_encode(const unsigned char* b, std::size_t size)
{
    std::string out;
    out.reserve((size + 2) / 3 * 4);
    std::size_t i = 0;
    for (; i + 3 <= size; i += 3) {
        const unsigned v = (unsigned(b[i]) << 16) | (unsigned(b[i + 1]) << 8) | b[i + 2];
        out += k_b64[(v >> 18) & 63];
        out += k_b64[(v >> 12) & 63];
        out += k_b64[(v >> 6) & 63];
        out += k_b64[v & 63];
    }
    if (i < size) {
        const unsigned v = (unsigned(b[i]) << 16) | (i + 1 < size ? unsigned(b[i + 1]) << 8 : 0u);
        out += k_b64[(v >> 18) & 63];
        out += k_b64[(v >> 12) & 63];
        out += i + 1 < size ? k_b64[(v >> 6) & 63] : '=';
        out += '=';
    }
    return out;
}

bool Base64Reader::fill()
{
    // Reads one quantum of 4 characters (skipping whitespace); '=' ends it early.
    int vals[4];
    int got = 0;
    while (got < 4 && m_p < m_end) {
        const unsigned char c = static_cast<unsigned char>(*m_p);
        if (c == ' ' || c == '\n' || c == '\r' || c == '\t') {
            ++m_p;
            continue;
        }
        if (c == '=') {
            ++m_p;
            if (got == 0) continue; // stray padding between pieces
            // Consume the rest of the padding of this quantum.
            int pads = 1;
            while (got + pads < 4 && m_p < m_end && *m_p == '=')
                ++m_p, ++pads;
            break;
        }
        const int v = b64_value(c);
        if (v < 0) {
            m_bad = true;
            m_bad_char = static_cast<char>(c);
            m_end = m_p;
            break;
        }
        vals[got++] = v;
        ++m_p;
    }
    if (got < 2) return false;
    for (int i = got; i < 4; ++i)
        vals[i] = 0;
    const unsigned v =
        (unsigned(vals[0]) << 18) | (unsigned(vals[1]) << 12) | (unsigned(vals[2]) << 6) | unsigned(vals[3]);
    m_buf[0] = static_cast<unsigned char>(v >> 16);
    m_buf[1] = static_cast<unsigned char>(v >> 8);
    m_buf[2] = static_cast<unsigned char>(v);
    m_have = got - 1;
    m_next = 0;
    return true;
}

std::size_t Base64Reader::read(std::size_t n, std::vector<unsigned char>& out)
{
    std::size_t done = 0;
    while (done < n) {
        if (m_next >= m_have && !fill()) break;
        while (m_next < m_have && done < n) {
            out.push_back(m_buf[m_next++]);
            ++done;
        }
    }
    return done;
}

bool zlib_inflate(const unsigned char* src, std::size_t size, std::size_t expected, std::vector<unsigned char>& out,
                  const std::string& where)
{
#ifdef TETHASH_HAVE_ZLIB
    (void)where;
    // The output grows with what the stream actually yields (never to the declared size up front),
    // so that a header declaring gigabytes costs only what its data inflate to.
    const std::size_t start = out.size();
    z_stream zs{};
    if (inflateInit(&zs) != Z_OK) return false;
    zs.next_in = const_cast<Bytef*>(src);
    zs.avail_in = static_cast<uInt>(std::min<std::size_t>(size, std::numeric_limits<uInt>::max()));
    std::size_t produced = 0;
    bool ok = false;
    for (;;) {
        if (zs.avail_in == 0 && size > 0) { // feed the rest of a block larger than 4 GiB
            const std::size_t used = static_cast<std::size_t>(zs.next_in - src);
            zs.avail_in = static_cast<uInt>(std::min<std::size_t>(size - used, std::numeric_limits<uInt>::max()));
        }
        if (produced == expected) {
            // All expected bytes are there: the stream must end without yielding another byte.
            unsigned char extra = 0;
            int rc = Z_OK;
            do {
                zs.next_out = &extra;
                zs.avail_out = 1;
                rc = inflate(&zs, Z_NO_FLUSH);
            } while (rc == Z_OK && zs.avail_out == 1);
            ok = rc == Z_STREAM_END && zs.avail_out == 1;
            break;
        }
        const std::size_t grow = std::min(
            {expected - produced, std::max<std::size_t>(std::size_t(1) << 16, produced), std::size_t(1) << 30});
        out.resize(start + produced + grow);
        zs.next_out = out.data() + start + produced;
        zs.avail_out = static_cast<uInt>(grow);
        const int rc = inflate(&zs, Z_NO_FLUSH);
        produced += grow - zs.avail_out;
        if (rc == Z_STREAM_END) {
            ok = produced == expected;
            break;
        }
        if (rc != Z_OK) break; // corrupt, or the input ended before the stream did
    }
    inflateEnd(&zs);
    out.resize(ok ? start + expected : start);
    return ok;
#else
    (void)src, (void)size, (void)expected, (void)out;
    throw Error(where + ": zlib-compressed data (vtkZLibDataCompressor), but tethash was built without zlib");
#endif
}

} // namespace vtk_detail
} // namespace tethash::io
