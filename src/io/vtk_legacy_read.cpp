// Legacy VTK (.vtk) UNSTRUCTURED_GRID reader (ASCII and binary, versions 1.0 to 5.1).
#include "tethash/error.hpp"
#include "tethash/io/file.hpp"
#include "tethash/io/vtk_legacy.hpp"
#include "vtk_detail.hpp"
#include "vtk_labels.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace tethash::io {
namespace {

using namespace vtk_detail;

bool is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

using detail::to_lower;

/// Where an array's values start, to name the place of value k in an error message.
struct ArrayPlace {
    std::size_t pos = 0;   ///< byte offset of the data (binary) or of the text before the first value
    std::int64_t line = 0; ///< line at `pos` (ASCII)
    int value_size = 0;    ///< bytes per value (binary)
};

/// What the sections of a file hold, as read.
struct Sections {
    std::vector<double> coords;
    ArrayPlace coords_place;
    bool have_points = false, have_cells = false, have_types = false;
    std::int64_t num_points = 0, num_cells = 0;
    std::vector<std::int64_t> offsets; ///< num_cells + 1 entries into `conn`
    std::vector<std::int64_t> conn;    ///< point ids (new layout) or count-prefixed lists (old layout)
    bool old_layout = false;
    ArrayPlace conn_place, types_place;
    std::vector<std::int64_t> types;
    std::vector<NamedArray> point_arrays, cell_arrays;
};

class LegacyReader : FileReaderBase {
  public:
    using FileReaderBase::FileReaderBase;
    TetMesh read();

  private:
    // ---- the parts of a file
    /// Version line, title, ASCII/BINARY and the DATASET line.
    void read_header();
    void read_points(Sections& s);
    /// CELLS in either layout: OFFSETS and CONNECTIVITY (version 5), or count-prefixed lists.
    void read_cells(Sections& s);
    void read_offsets_layout(Sections& s, std::int64_t a, std::int64_t b);
    void read_count_prefixed_layout(Sections& s, std::int64_t a, std::int64_t b);
    /// The mesh of the sections: finite points, the tets (type 10, or 24 with linearize) with ids in range, labels.
    TetMesh make_mesh(Sections& s);

    // ---- positions and errors
    /// Place of the last token read (line in ASCII files, byte offset in binary ones).
    std::string at_token() const { return m_binary ? at_byte(m_tok_pos) : at_line(m_tok_line); }
    /// Place of value k of an array.
    std::string at_value(const ArrayPlace& a, std::size_t k) const;
    std::string found_token() const { return m_tok.empty() ? "end of file" : quote_token(m_tok); }

    // ---- text
    std::string_view next_token();
    std::string_view peek_token();
    /// True if another token follows on the current line.
    bool token_on_line() const;
    /// Skips the rest of the current line including its '\n' (binary data starts after it).
    void end_line();
    std::string read_line();
    std::int64_t expect_int(const std::string& what, std::int64_t min_value);
    std::string expect_word(const std::string& what);
    Scalar expect_type(const std::string& what);

    // ---- arrays
    template <class T>
    std::vector<T> read_values(std::size_t count, Scalar type, const std::string& what, ArrayPlace* place = nullptr);
    void skip_values(std::size_t count, Scalar type, const std::string& what);
    /// Fails when `count` values cannot fit in the rest of the file (before anything is allocated for them).
    void check_count_plausible(std::size_t count, const std::string& what);
    /// Binary data: moves to the start of the values and returns their size in bytes (checked to be in the file).
    std::size_t binary_extent(std::size_t count, Scalar type, const std::string& what);
    void read_field_block(bool in_data, std::size_t count, std::vector<NamedArray>* keep);
    void read_attribute(const std::string& key, std::size_t count, std::vector<NamedArray>* keep);
    void skip_metadata();

    std::string m_data;
    std::size_t m_pos = 0;
    std::int64_t m_line = 1;
    bool m_binary = false;
    std::string_view m_tok;
    std::size_t m_tok_pos = 0;
    std::int64_t m_tok_line = 1;
};

std::string_view LegacyReader::next_token()
{
    while (m_pos < m_data.size() && is_space(m_data[m_pos])) {
        if (m_data[m_pos] == '\n') ++m_line;
        ++m_pos;
    }
    m_tok_pos = m_pos;
    m_tok_line = m_line;
    // At the end of a file that ends with a newline, name the last line rather than the empty one after it.
    if (m_pos == m_data.size() && m_pos > 0 && m_data[m_pos - 1] == '\n' && m_tok_line > 1) --m_tok_line;
    const std::size_t start = m_pos;
    while (m_pos < m_data.size() && !is_space(m_data[m_pos]))
        ++m_pos;
    m_tok = std::string_view(m_data).substr(start, m_pos - start);
    return m_tok;
}

std::string_view LegacyReader::peek_token()
{
    const std::size_t pos = m_pos;
    const std::int64_t line = m_line;
    const auto tok = m_tok;
    const auto tok_pos = m_tok_pos;
    const auto tok_line = m_tok_line;
    const std::string_view r = next_token();
    m_pos = pos, m_line = line, m_tok = tok, m_tok_pos = tok_pos, m_tok_line = tok_line;
    return r;
}

bool LegacyReader::token_on_line() const
{
    std::size_t p = m_pos;
    while (p < m_data.size() && (m_data[p] == ' ' || m_data[p] == '\t' || m_data[p] == '\r'))
        ++p;
    return p < m_data.size() && m_data[p] != '\n';
}

void LegacyReader::end_line()
{
    while (m_pos < m_data.size() && m_data[m_pos] != '\n')
        ++m_pos;
    if (m_pos < m_data.size()) ++m_pos, ++m_line;
}

std::string LegacyReader::read_line()
{
    const std::size_t start = m_pos;
    end_line();
    std::string s = m_data.substr(start, m_pos - start);
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r'))
        s.pop_back();
    return s;
}

std::int64_t LegacyReader::expect_int(const std::string& what, std::int64_t min_value)
{
    next_token();
    const auto v = parse_int(m_tok);
    if (!v) fail(at_token(), "expected " + what + " (an integer), found " + found_token());
    if (*v < min_value)
        fail(at_token(),
             "expected " + what + " (an integer ≥ " + std::to_string(min_value) + "), found " + found_token());
    return *v;
}

std::string LegacyReader::expect_word(const std::string& what)
{
    next_token();
    if (m_tok.empty()) fail(at_token(), "expected " + what + ", found end of file");
    return std::string(m_tok);
}

Scalar LegacyReader::expect_type(const std::string& what)
{
    next_token();
    const auto t = scalar_from_legacy(m_tok);
    if (!t)
        fail(at_token(), "expected the data type of " + what +
                             " (bit, unsigned_char, char, short, int, long, float, double, vtktypeint64, ...), found " +
                             found_token());
    return *t;
}

std::string LegacyReader::at_value(const ArrayPlace& a, std::size_t k) const
{
    if (m_binary) return at_byte(a.pos + k * static_cast<std::size_t>(a.value_size));
    // Re-scan the text to the k-th token (only on the error path).
    std::size_t p = a.pos;
    std::int64_t line = a.line;
    for (std::size_t i = 0;; ++i) {
        while (p < m_data.size() && is_space(m_data[p])) {
            if (m_data[p] == '\n') ++line;
            ++p;
        }
        if (i == k || p >= m_data.size()) break;
        while (p < m_data.size() && !is_space(m_data[p]))
            ++p;
    }
    return at_line(line);
}

void LegacyReader::check_count_plausible(std::size_t count, const std::string& what)
{
    if (count > 8 * (m_data.size() - std::min(m_pos, m_data.size())) + 8) // also keeps count × size from overflowing
        fail(m_binary ? at_byte(m_pos) : at_token(), "expected " + std::to_string(count) + " values of " + what +
                                                         ", but the rest of the file is far too short to hold them");
}

std::size_t LegacyReader::binary_extent(std::size_t count, Scalar type, const std::string& what)
{
    end_line();
    const std::size_t need =
        type == Scalar::Bit ? (count + 7) / 8 : count * static_cast<std::size_t>(scalar_size(type));
    if (need > m_data.size() - m_pos)
        fail(at_byte(m_pos), "expected " + std::to_string(need) + " bytes of " + what + " (" + std::to_string(count) +
                                 " values), found only " + std::to_string(m_data.size() - m_pos) +
                                 " before the end of the file");
    return need;
}

template <class T>
std::vector<T> LegacyReader::read_values(std::size_t count, Scalar type, const std::string& what, ArrayPlace* place)
{
    std::vector<T> out;
    check_count_plausible(count, what);
    if (m_binary) {
        const std::size_t need = binary_extent(count, type, what);
        if (place) *place = {m_pos, m_line, scalar_size(type)};
        out.resize(count);
        const auto* src = reinterpret_cast<const unsigned char*>(m_data.data() + m_pos);
        if (type == Scalar::Bit) {
            for (std::size_t i = 0; i < count; ++i)
                out[i] = static_cast<T>((src[i / 8] >> (7 - i % 8)) & 1);
        } else if constexpr (std::is_same_v<T, double>) {
            convert_to_double(src, type, count, true, out.data());
        } else {
            convert_to_int64(src, type, count, true, out.data());
        }
        m_pos += need;
        return out;
    }
    if (place) *place = {m_pos, m_line, 0};
    out.reserve(std::min(count, (m_data.size() - m_pos) / 2 + 1)); // a count from a broken header may be huge
    for (std::size_t i = 0; i < count; ++i) {
        next_token();
        if (m_tok.empty())
            fail(at_token(), "expected " + std::to_string(count) + " values of " + what + ", found end of file after " +
                                 std::to_string(i));
        if constexpr (std::is_same_v<T, double>) {
            const auto v = parse_double(m_tok);
            if (!v)
                fail(at_token(), "expected a number (value " + std::to_string(i + 1) + " of " + std::to_string(count) +
                                     " of " + what + "), found " + found_token());
            out.push_back(*v);
        } else {
            const auto v = parse_integer_value(m_tok, type);
            if (!v)
                fail(at_token(), "expected an integer (value " + std::to_string(i + 1) + " of " +
                                     std::to_string(count) + " of " + what + "), found " + found_token());
            out.push_back(*v);
        }
    }
    return out;
}

void LegacyReader::skip_values(std::size_t count, Scalar type, const std::string& what)
{
    if (!m_binary) {
        (void)read_values<double>(count, type, what); // every value must still be a number
        return;
    }
    check_count_plausible(count, what);
    m_pos += binary_extent(count, type, what);
}

void LegacyReader::skip_metadata()
{
    // METADATA blocks (VTK ≥ 8) run to the next empty line.
    end_line();
    while (m_pos < m_data.size()) {
        std::string l = read_line();
        while (!l.empty() && is_space(l.back()))
            l.pop_back();
        if (l.empty()) break;
    }
}

void LegacyReader::read_field_block(bool in_data, std::size_t count, std::vector<NamedArray>* keep)
{
    const std::string field_name = expect_word("the FIELD name");
    const std::int64_t arrays = expect_int("the number of arrays of FIELD " + field_name, 0);
    for (std::int64_t a = 0; a < arrays; ++a) {
        const std::string name = expect_word("an array name in FIELD " + field_name);
        if (to_lower(name) == "null_array") continue;
        if (to_lower(name) == "metadata") {
            skip_metadata();
            --a;
            continue;
        }
        const std::string what = "FIELD array '" + name + "'";
        const std::int64_t comps = expect_int("the number of components of " + what, 0);
        const std::int64_t tuples = expect_int("the number of tuples of " + what, 0);
        const Scalar type = expect_type(what);
        if (in_data && static_cast<std::size_t>(tuples) != count)
            fail(at_token(),
                 "expected " + std::to_string(count) + " tuples in " + what + ", found " + std::to_string(tuples));
        const std::string where = at_token();
        const std::size_t n = static_cast<std::size_t>(comps) * static_cast<std::size_t>(tuples);
        if (keep && comps == 1 && (is_label_array_name(name, true) || is_label_array_name(name, false)))
            keep->push_back({name, read_values<double>(n, type, what), where});
        else
            skip_values(n, type, what);
    }
}

void LegacyReader::read_attribute(const std::string& key, std::size_t count, std::vector<NamedArray>* keep)
{
    if (key == "field") return read_field_block(true, count, keep);
    const std::string name = expect_word("the name of " + key);
    const std::string what = key + " '" + name + "'";
    if (key == "scalars") {
        const Scalar type = expect_type(what);
        std::int64_t comps = 1;
        if (token_on_line()) comps = expect_int("the number of components of " + what, 1);
        const std::string where = at_token();
        if (to_lower(peek_token()) == "lookup_table") {
            next_token();
            expect_word("the lookup table name of " + what);
        }
        const std::size_t n = count * static_cast<std::size_t>(comps);
        if (keep && comps == 1 && (is_label_array_name(name, true) || is_label_array_name(name, false)))
            keep->push_back({name, read_values<double>(n, type, what), where});
        else
            skip_values(n, type, what);
    } else if (key == "vectors" || key == "normals") {
        skip_values(3 * count, expect_type(what), what);
    } else if (key == "tensors" || key == "tensors6") {
        skip_values((key == "tensors" ? 9 : 6) * count, expect_type(what), what);
    } else if (key == "texture_coordinates") {
        const std::int64_t dim = expect_int("the dimension of " + what, 1);
        skip_values(static_cast<std::size_t>(dim) * count, expect_type(what), what);
    } else if (key == "color_scalars") {
        const std::int64_t nv = expect_int("the number of values of " + what, 1);
        skip_values(static_cast<std::size_t>(nv) * count, m_binary ? Scalar::UInt8 : Scalar::Float32, what);
    } else if (key == "lookup_table") {
        const std::int64_t size = expect_int("the size of " + what, 0);
        skip_values(4 * static_cast<std::size_t>(size), m_binary ? Scalar::UInt8 : Scalar::Float32, what);
    } else if (key == "global_ids" || key == "pedigree_ids") {
        skip_values(count, expect_type(what), what);
    }
}

void LegacyReader::read_header()
{
    const std::string first = read_line();
    const std::string magic = "# vtk datafile version";
    if (to_lower(first.substr(0, magic.size())) != magic)
        fail(at_line(1), "expected '# vtk DataFile Version X.Y', found " + quote_token(first));
    std::string version = first.substr(magic.size());
    while (!version.empty() && is_space(version.front()))
        version.erase(version.begin());
    while (!version.empty() && is_space(version.back()))
        version.pop_back();
    {
        const auto dot = version.find('.');
        const auto major = parse_int(version.substr(0, dot));
        const auto minor =
            dot == std::string::npos ? std::optional<std::int64_t>(0) : parse_int(version.substr(dot + 1));
        if (!major || !minor || *major < 1 || *major > 5 || *minor < 0)
            fail(at_line(1), "unknown legacy VTK version " + quote_token(version) + " (expected 1.0 to 5.1)");
    }
    if (m_pos >= m_data.size()) fail(at_line(2), "expected a title line, found end of file");
    read_line(); // title
    if (m_pos >= m_data.size()) fail(at_line(3), "expected ASCII or BINARY, found end of file");
    std::string format = read_line();
    while (!format.empty() && is_space(format.back()))
        format.pop_back();
    while (!format.empty() && is_space(format.front()))
        format.erase(format.begin());
    if (to_lower(format) == "binary")
        m_binary = true;
    else if (to_lower(format) != "ascii")
        fail(at_line(3), "expected ASCII or BINARY, found " + quote_token(format));

    next_token();
    if (to_lower(m_tok) != "dataset") fail(at_token(), "expected DATASET, found " + found_token());
    next_token();
    if (to_lower(m_tok) != "unstructured_grid")
        fail(at_token(), "expected UNSTRUCTURED_GRID (the only dataset tethash reads), found " + found_token());
}

void LegacyReader::read_points(Sections& s)
{
    if (s.have_points) fail(at_token(), "expected one POINTS section, found a second one");
    s.num_points = expect_int("the number of points", 0);
    if (s.num_points > 2147483647)
        fail(at_token(), "too many points for tethash (" + std::to_string(s.num_points) + ")");
    const Scalar type = expect_type("POINTS");
    // A bit holds no coordinate, and decoding bits costs a double per bit (64 times the file).
    if (type == Scalar::Bit)
        fail(at_token(), "expected the data type of POINTS to be a number type (float, double, int, ...), "
                         "found bit");
    s.coords = read_values<double>(3 * static_cast<std::size_t>(s.num_points), type,
                                   "POINTS (" + std::to_string(s.num_points) + " points × 3)", &s.coords_place);
    s.have_points = true;
}

void LegacyReader::read_cells(Sections& s)
{
    if (s.have_cells) fail(at_token(), "expected one CELLS section, found a second one");
    const std::int64_t a = expect_int("the number of cells", 0);
    const std::int64_t b = expect_int("the size of the cell list", 0);
    if (to_lower(peek_token()) == "offsets")
        read_offsets_layout(s, a, b);
    else
        read_count_prefixed_layout(s, a, b);
    s.have_cells = true;
}

void LegacyReader::read_offsets_layout(Sections& s, std::int64_t a, std::int64_t b)
{
    // Version 5.x layout: OFFSETS (a values) then CONNECTIVITY (b values).
    std::vector<std::int64_t>& offsets = s.offsets;
    next_token();
    const Scalar ot = expect_type("OFFSETS");
    if (ot == Scalar::Bit) fail(at_token(), "expected the data type of OFFSETS to be an integer type, found bit");
    ArrayPlace offsets_place;
    offsets = read_values<std::int64_t>(static_cast<std::size_t>(a), ot, "OFFSETS", &offsets_place);
    next_token();
    if (to_lower(m_tok) != "connectivity") fail(at_token(), "expected CONNECTIVITY, found " + found_token());
    const Scalar ct = expect_type("CONNECTIVITY");
    if (ct == Scalar::Bit) fail(at_token(), "expected the data type of CONNECTIVITY to be an integer type, found bit");
    s.conn = read_values<std::int64_t>(static_cast<std::size_t>(b), ct, "CONNECTIVITY", &s.conn_place);
    const std::int64_t num_cells = a > 0 ? a - 1 : 0;
    s.num_cells = num_cells;
    if (a == 0) offsets.push_back(0);
    if (offsets[0] != 0)
        fail(at_value(offsets_place, 0), "expected the first offset to be 0, found " + std::to_string(offsets[0]));
    for (std::int64_t c = 0; c < num_cells; ++c)
        if (offsets[c + 1] < offsets[c] || offsets[c + 1] > b)
            fail(at_value(offsets_place, static_cast<std::size_t>(c + 1)),
                 "offset " + std::to_string(c + 1) + " is " + std::to_string(offsets[c + 1]) +
                     ", expected a value from " + std::to_string(offsets[c]) + " to " + std::to_string(b) +
                     " (the CONNECTIVITY size)");
    if (offsets[num_cells] != b)
        fail(at_value(offsets_place, static_cast<std::size_t>(num_cells)),
             "expected the last offset to equal the CONNECTIVITY size " + std::to_string(b) + ", found " +
                 std::to_string(offsets[num_cells]));
}

void LegacyReader::read_count_prefixed_layout(Sections& s, std::int64_t a, std::int64_t b)
{
    std::vector<std::int64_t>& conn = s.conn;
    s.old_layout = true;
    s.num_cells = a;
    if (a > b)
        fail(at_token(), "expected a cell list of at least " + std::to_string(a) + " values for " + std::to_string(a) +
                             " cells, found CELLS " + std::to_string(a) + " " + std::to_string(b));
    conn = read_values<std::int64_t>(static_cast<std::size_t>(b), Scalar::Int32,
                                     "CELLS (" + std::to_string(a) + " cells, " + std::to_string(b) + " values)",
                                     &s.conn_place);
    s.offsets.resize(static_cast<std::size_t>(a) + 1);
    std::size_t p = 0;
    for (std::int64_t c = 0; c < a; ++c) {
        if (p >= conn.size())
            fail(at_value(s.conn_place, p), "expected cell " + std::to_string(c) + " of " + std::to_string(a) +
                                                ", found the end of the CELLS list (" + std::to_string(b) +
                                                " values); the counts in 'CELLS " + std::to_string(a) + " " +
                                                std::to_string(b) + "' do not match");
        const std::int64_t k = conn[p];
        if (k < 0 || static_cast<std::size_t>(k) >= conn.size() - p)
            fail(at_value(s.conn_place, p), "cell " + std::to_string(c) + " has " + std::to_string(k) +
                                                " points, but only " + std::to_string(conn.size() - p - 1) +
                                                " values remain in the CELLS list");
        s.offsets[static_cast<std::size_t>(c)] = static_cast<std::int64_t>(p);
        p += static_cast<std::size_t>(k) + 1;
    }
    s.offsets[static_cast<std::size_t>(a)] = static_cast<std::int64_t>(p);
    if (p != conn.size())
        fail(at_value(s.conn_place, p), "expected " + std::to_string(a) + " cells to use all " + std::to_string(b) +
                                            " values of the CELLS list, but they use " + std::to_string(p));
}

TetMesh LegacyReader::read()
{
    m_data = read_file(m_path);
    read_header();

    Sections s;
    enum class Mode { None, Point, Cell } mode = Mode::None;
    for (;;) {
        next_token();
        if (m_tok.empty()) break;
        const std::string key = to_lower(m_tok);
        if (key == "points") {
            read_points(s);
            mode = Mode::None;
        } else if (key == "cells") {
            read_cells(s);
            mode = Mode::None;
        } else if (key == "cell_types") {
            if (!s.have_cells) fail(at_token(), "expected CELLS before CELL_TYPES");
            const std::int64_t n = expect_int("the number of cell types", 0);
            if (n != s.num_cells)
                fail(at_token(), "expected CELL_TYPES " + std::to_string(s.num_cells) +
                                     " (the number of CELLS), found " + std::to_string(n));
            s.types =
                read_values<std::int64_t>(static_cast<std::size_t>(n), Scalar::Int32, "CELL_TYPES", &s.types_place);
            s.have_types = true;
            mode = Mode::None;
        } else if (key == "point_data" || key == "cell_data") {
            const bool point = key == "point_data";
            const std::int64_t n = expect_int("the number of " + std::string(point ? "points" : "cells"), 0);
            const std::int64_t expected = point ? s.num_points : s.num_cells;
            if ((point ? s.have_points : s.have_cells) && n != expected)
                fail(at_token(), "expected " + std::string(point ? "POINT_DATA " : "CELL_DATA ") +
                                     std::to_string(expected) + " (the number of " + (point ? "points" : "cells") +
                                     "), found " + std::to_string(n));
            mode = point ? Mode::Point : Mode::Cell;
        } else if (key == "metadata") {
            skip_metadata();
        } else if (key == "field" && mode == Mode::None) {
            read_field_block(false, 0, nullptr);
        } else if (mode != Mode::None &&
                   (key == "field" || key == "scalars" || key == "vectors" || key == "normals" || key == "tensors" ||
                    key == "tensors6" || key == "texture_coordinates" || key == "color_scalars" ||
                    key == "lookup_table" || key == "global_ids" || key == "pedigree_ids")) {
            const bool point = mode == Mode::Point;
            const std::size_t count = static_cast<std::size_t>(point ? s.num_points : s.num_cells);
            std::vector<NamedArray> found;
            read_attribute(key, count, &found);
            for (auto& a : found)
                if (is_label_array_name(a.name, !point))
                    (point ? s.point_arrays : s.cell_arrays).push_back(std::move(a));
        } else {
            fail(at_token(), "expected a section keyword (POINTS, CELLS, CELL_TYPES, POINT_DATA, CELL_DATA, FIELD, "
                             "SCALARS, ...), found " +
                                 found_token());
        }
    }

    // at_token() is now the end of the file.
    if (s.have_cells && !s.have_types) fail(at_token(), "expected CELL_TYPES, found end of file");
    if (!s.have_points) fail(at_token(), "expected POINTS, found end of file");
    return make_mesh(s);
}

TetMesh LegacyReader::make_mesh(Sections& s)
{
    const std::int64_t num_points = s.num_points, num_cells = s.num_cells;
    TetMesh mesh;
    mesh.positions.resize(num_points, 3);
    for (std::int64_t i = 0; i < num_points; ++i)
        for (int k = 0; k < 3; ++k) {
            const double v = s.coords[static_cast<std::size_t>(3 * i + k)];
            if (!std::isfinite(v))
                fail(at_value(s.coords_place, static_cast<std::size_t>(3 * i + k)),
                     "point " + std::to_string(i) + " has a non-finite coordinate");
            mesh.positions(i, k) = v;
        }

    std::vector<std::int64_t> tet_cells;
    std::map<std::int64_t, std::int64_t> skipped;
    for (std::int64_t c = 0; c < num_cells; ++c) {
        const std::size_t cs = static_cast<std::size_t>(c);
        const bool quadratic = s.types[cs] == 24 && m_options.linearize; // corners first, then mid-edge nodes
        if (s.types[cs] != 10 && !quadratic) {
            ++skipped[s.types[cs]];
            continue;
        }
        const std::size_t first = static_cast<std::size_t>(s.offsets[cs]) + (s.old_layout ? 1 : 0);
        const std::size_t size = static_cast<std::size_t>(s.offsets[cs + 1]) - first;
        if (size != (quadratic ? 10u : 4u))
            fail(at_value(s.types_place, cs),
                 "cell " + std::to_string(c) + " has type " + (quadratic ? "24 (quadratic tetra)" : "10 (tetra)") +
                     " but " + std::to_string(size) + " points, expected " + (quadratic ? "10" : "4"));
        for (std::size_t k = 0; k < 4; ++k) {
            const std::int64_t v = s.conn[first + k];
            if (v < 0 || v >= num_points)
                fail(at_value(s.conn_place, first + k), "tet " + std::to_string(tet_cells.size()) + " (cell " +
                                                            std::to_string(c) + ") refers to point " +
                                                            std::to_string(v) + ", but the file has only " +
                                                            std::to_string(num_points) + " points (0-based ids)");
        }
        tet_cells.push_back(c);
    }
    mesh.tets.resize(static_cast<Eigen::Index>(tet_cells.size()), 4);
    for (std::size_t t = 0; t < tet_cells.size(); ++t) {
        const std::size_t first =
            static_cast<std::size_t>(s.offsets[static_cast<std::size_t>(tet_cells[t])]) + (s.old_layout ? 1 : 0);
        for (int k = 0; k < 4; ++k)
            mesh.tets(static_cast<Eigen::Index>(t), k) = static_cast<Index>(s.conn[first + k]);
    }
    note_skipped_cells(skipped);
    apply_label_arrays(mesh, s.point_arrays, s.cell_arrays, tet_cells, static_cast<std::size_t>(num_cells), m_notes);
    return mesh;
}

} // namespace

TetMesh read_vtk(const std::string& path, ReadNotes* notes, const ReadOptions& options)
{
    return LegacyReader(path, notes, options).read();
}

} // namespace tethash::io
