// VTK XML UnstructuredGrid (.vtu) reader: ASCII, base64 (plain or zlib) and appended raw data.
#include "tethash/io/vtu.hpp"

#include "number.hpp"
#include "tethash/error.hpp"
#include "tethash/io/file.hpp"
#include "vtk_detail.hpp"
#include "vtk_encoding.hpp"
#include "vtk_labels.hpp"
#include "xml.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

namespace tethash::io {
namespace {

using namespace vtk_detail;
using detail::XmlDocument;
using detail::XmlElement;
constexpr auto is_space = detail::is_xml_space;

// ---- .vtu reader ---------------------------------------------------------------------------

class VtuReader : FileReaderBase {
  public:
    using FileReaderBase::FileReaderBase;
    TetMesh read();
    /// read() also fills `extra` with the triangles and every data array (read_vtu_contents).
    void set_contents(VtuContents* extra) { m_extra = extra; }

  private:
    /// What the pieces gave, piece after piece (ids already offset by the points of the pieces before).
    struct Pieces {
        std::vector<double> coords;
        std::vector<std::int64_t> tet_cells;
        std::vector<Index> tet_ids, triangle_ids;
        std::map<std::int64_t, std::int64_t> skipped;
        std::map<std::string, Field> point_fields, cell_fields; // read_vtu_contents: every array of 1 or 3 components
        std::map<std::string, NamedArray> point_arrays, cell_arrays;
        std::int64_t total_points = 0, total_cells = 0;
    };
    /// <VTKFile>'s attributes (byte order, header type, compressor) and the appended data's encoding checked and
    /// kept; returns the <UnstructuredGrid>.
    const XmlElement& read_header();
    /// A piece's points, checked finite.
    void read_points(const XmlElement& piece, std::int64_t np, Pieces& all);
    /// A piece's cells: its tets (its triangles too for read_vtu_contents), the other types counted as skipped.
    void read_cells(const XmlElement& piece, std::int64_t np, std::int64_t nc, Pieces& all);
    /// A piece's point or cell arrays (`section` PointData or CellData, `count` values each): those that may hold
    /// object ids or labels, and for read_vtu_contents every array of 1 or 3 components.
    void read_data_arrays(const XmlElement& piece, const char* section, bool cell, std::size_t count, Pieces& all);
    /// The mesh (and the contents) of all pieces, their label arrays applied.
    TetMesh assemble(Pieces& all);

    std::string attr(const XmlElement& el, const char* key, bool required = true) const
    {
        const std::string* v = el.attr(key);
        if (!v && required)
            fail(at_line(el.line),
                 "expected attribute " + std::string(key) + "=\"...\" in <" + el.name + ">, found none");
        return v ? *v : std::string();
    }
    std::int64_t int_attr(const XmlElement& el, const char* key, std::int64_t min_value) const;
    std::string array_label(const XmlElement& da) const
    {
        const std::string* n = da.attr("Name");
        return "DataArray" + (n ? " '" + *n + "'" : std::string());
    }
    /// Place of value k of an array, for error messages (line of the value for ASCII arrays).
    std::string at_value(const XmlElement& da, std::size_t k) const;

    /// Decodes a DataArray of `expected` values (components included) into T (double or int64).
    template <class T> std::vector<T> read_array(const XmlElement& da, std::size_t expected, const std::string& what);
    template <class T>
    std::vector<T> read_ascii(const XmlElement& da, Scalar type, std::size_t expected, const std::string& what);
    /// The payload bytes of a binary block (header + data, possibly zlib-compressed).
    template <class Source>
    std::vector<unsigned char> read_block(Source& src, const XmlElement& da, std::size_t expected_bytes,
                                          const std::string& what);

    std::string m_data;
    XmlDocument m_doc;
    bool m_big_endian = false;
    bool m_header64 = false;
    bool m_zlib = false;
    VtuContents* m_extra = nullptr;
};

std::int64_t VtuReader::int_attr(const XmlElement& el, const char* key, std::int64_t min_value) const
{
    const std::string v = attr(el, key);
    std::string_view s = v;
    while (!s.empty() && is_space(s.front()))
        s.remove_prefix(1);
    while (!s.empty() && is_space(s.back()))
        s.remove_suffix(1);
    const auto i = parse_int(s);
    if (!i || *i < min_value)
        fail(at_line(el.line), "expected " + std::string(key) + " in <" + el.name + "> to be an integer ≥ " +
                                   std::to_string(min_value) + ", found \"" + v + "\"");
    return *i;
}

std::string VtuReader::at_value(const XmlElement& da, std::size_t k) const
{
    const std::string* format = da.attr("format");
    if (!format || *format != "ascii")
        return at_line(da.line) + ": " + array_label(da) + ", value " + std::to_string(k);
    // Find the line of the k-th token of the text (error path only).
    std::size_t count = 0;
    std::int64_t line = da.line;
    for (std::size_t r = 0; r < da.text.size(); ++r) {
        const auto [b, e] = da.text[r];
        line = da.text_line[r];
        for (std::size_t p = b; p < e;) {
            if (is_space(m_data[p])) {
                if (m_data[p] == '\n') ++line;
                ++p;
                continue;
            }
            if (count == k) return at_line(line);
            while (p < e && !is_space(m_data[p]))
                ++p;
            ++count;
        }
    }
    return at_line(line);
}

template <class T>
std::vector<T> VtuReader::read_ascii(const XmlElement& da, Scalar type, std::size_t expected, const std::string& what)
{
    std::vector<T> out;
    out.reserve(std::min(expected, m_data.size() / 2 + 1)); // a count from a broken file may be huge
    std::int64_t line = da.line;
    std::size_t count = 0;
    std::int64_t last_line = line;
    for (std::size_t r = 0; r < da.text.size(); ++r) {
        const auto [b, e] = da.text[r];
        line = da.text_line[r];
        std::size_t p = b;
        while (p < e) {
            if (is_space(m_data[p])) {
                if (m_data[p] == '\n') ++line;
                ++p;
                continue;
            }
            const std::size_t s = p;
            while (p < e && !is_space(m_data[p]))
                ++p;
            const std::string_view tok(m_data.data() + s, p - s);
            last_line = line;
            if (count >= expected) {
                // Count the rest for the message.
                std::size_t total = count;
                for (const auto& [rb, re] : da.text) {
                    for (std::size_t q = std::max(rb, s); q < re;) {
                        if (is_space(m_data[q])) {
                            ++q;
                            continue;
                        }
                        ++total;
                        while (q < re && !is_space(m_data[q]))
                            ++q;
                    }
                }
                fail(at_line(line), "expected " + std::to_string(expected) + " values in " + what + ", found " +
                                        std::to_string(total));
            }
            if constexpr (std::is_same_v<T, double>) {
                const auto v = parse_double(tok);
                if (!v)
                    fail(at_line(line), "expected a number (value " + std::to_string(count) + " of " + what +
                                            "), found " + quote_token(tok));
                out.push_back(*v);
            } else {
                const auto v = parse_integer_value(tok, type);
                if (!v)
                    fail(at_line(line), "expected an integer (value " + std::to_string(count) + " of " + what +
                                            "), found " + quote_token(tok));
                out.push_back(*v);
            }
            ++count;
        }
    }
    if (count != expected)
        fail(at_line(last_line),
             "expected " + std::to_string(expected) + " values in " + what + ", found " + std::to_string(count));
    return out;
}

/// Bytes straight from the file (raw appended data).
struct RawSource {
    const std::string& data;
    std::size_t pos;
    bool take(std::size_t n, std::vector<unsigned char>& out)
    {
        if (n > data.size() - std::min(pos, data.size())) return false;
        out.insert(out.end(), data.begin() + static_cast<std::ptrdiff_t>(pos),
                   data.begin() + static_cast<std::ptrdiff_t>(pos + n));
        pos += n;
        return true;
    }
};

/// Bytes decoded from base64 text (inline binary or base64 appended data).
struct Base64Source {
    Base64Reader reader;
    std::size_t pos = 0; ///< decoded bytes so far
    bool take(std::size_t n, std::vector<unsigned char>& out)
    {
        const std::size_t got = reader.read(n, out);
        pos += got;
        return got == n;
    }
};

/// The most a deflate stream can expand (258-byte matches coded in 2 bits, rounded up).
constexpr std::size_t k_max_inflate_ratio = 1032;

template <class Source>
std::vector<unsigned char> VtuReader::read_block(Source& src, const XmlElement& da, std::size_t expected_bytes,
                                                 const std::string& what)
{
    constexpr bool raw = std::is_same_v<Source, RawSource>;
    const std::size_t hs = m_header64 ? 8 : 4;
    const Scalar ht = m_header64 ? Scalar::UInt64 : Scalar::UInt32;
    const auto where = [&] { return raw ? at_byte(src.pos) : at_line(da.line); };
    const auto short_data = [&](std::size_t need, const char* part) {
        if constexpr (raw) {
            fail(at_byte(src.pos), "expected " + std::to_string(need) + " bytes of " + part + " of " + what +
                                       " (line " + std::to_string(da.line) + "), found only " +
                                       std::to_string(m_data.size() - std::min(src.pos, m_data.size())) +
                                       " before the end of the file");
        } else {
            if (src.reader.bad())
                fail(at_line(da.line), what + ": invalid character " +
                                           quote_token(std::string(1, src.reader.bad_char())) + " in base64 data");
            fail(at_line(da.line), "expected " + std::to_string(need) + " bytes of " + part + " of " + what +
                                       ", found the end of the base64 text after " + std::to_string(src.pos) +
                                       " decoded bytes");
        }
    };
    const auto header_words = [&](std::size_t n) {
        std::vector<unsigned char> b;
        if (!src.take(n * hs, b)) short_data(n * hs, "the block header");
        std::vector<std::int64_t> w(n);
        convert_to_int64(b.data(), ht, n, m_big_endian, w.data());
        return w;
    };
    std::vector<unsigned char> out;
    if (!m_zlib) {
        const std::size_t header_pos = src.pos;
        const std::int64_t nbytes = header_words(1)[0];
        if (nbytes < 0 || static_cast<std::size_t>(nbytes) != expected_bytes)
            fail(raw ? at_byte(header_pos) : at_line(da.line), "expected the block header of " + what + " to give " +
                                                                   std::to_string(expected_bytes) + " bytes, found " +
                                                                   std::to_string(nbytes));
        out.reserve(std::min(expected_bytes, m_data.size()));
        if (!src.take(expected_bytes, out)) short_data(expected_bytes, "data");
        return out;
    }
    const std::size_t header_pos = src.pos;
    const auto h = header_words(3);
    const std::int64_t nblocks = h[0], block_size = h[1], last_size = h[2];
    const std::int64_t last = nblocks > 0 && last_size == 0 ? block_size : last_size;
    const bool sane = nblocks >= 0 && nblocks <= (1 << 30) && block_size >= 0 &&
                      block_size <= (std::int64_t(1) << 32) && last >= 0 && last <= block_size;
    const std::int64_t total = sane && nblocks > 0 ? (nblocks - 1) * block_size + last : 0;
    if (!sane || total != static_cast<std::int64_t>(expected_bytes))
        fail(raw ? at_byte(header_pos) : at_line(da.line),
             "expected the compressed block header of " + what + " to give " + std::to_string(expected_bytes) +
                 " bytes, found " + std::to_string(nblocks) + " blocks of " + std::to_string(block_size) + " (last " +
                 std::to_string(last_size) + ")");
    if (static_cast<std::size_t>(nblocks) > m_data.size() / hs + 1)
        fail(raw ? at_byte(header_pos) : at_line(da.line), what + ": the compressed block header lists " +
                                                               std::to_string(nblocks) +
                                                               " blocks, more than the file can hold");
    const auto sizes = header_words(static_cast<std::size_t>(nblocks));
    std::vector<unsigned char> comp;
    for (std::int64_t b = 0; b < nblocks; ++b) {
        const std::int64_t cs = sizes[static_cast<std::size_t>(b)];
        if (cs < 0 || cs > (std::int64_t(1) << 40))
            fail(where(),
                 what + ": compressed block " + std::to_string(b) + " has an invalid size " + std::to_string(cs));
        comp.clear();
        const std::size_t block_pos = src.pos;
        if (!src.take(static_cast<std::size_t>(cs), comp)) short_data(static_cast<std::size_t>(cs), "compressed data");
        const std::size_t expect = static_cast<std::size_t>(b + 1 == nblocks ? last : block_size);
        // Deflate expands at most ~1032:1; a block that cannot hold what its header declares fails
        // here, before any output is allocated.
        if (expect / k_max_inflate_ratio > static_cast<std::size_t>(cs) + 1)
            fail(raw ? at_byte(block_pos) : at_line(da.line),
                 what + ": zlib block " + std::to_string(b) + " of " + std::to_string(nblocks) + " has " +
                     std::to_string(cs) + " compressed bytes, which cannot inflate to the " + std::to_string(expect) +
                     " bytes its header declares (zlib inflates at most " + std::to_string(k_max_inflate_ratio) +
                     " times)");
        if (!zlib_inflate(comp.data(), comp.size(), expect, out, raw ? at_byte(block_pos) : at_line(da.line)))
            fail(raw ? at_byte(block_pos) : at_line(da.line),
                 what + ": zlib block " + std::to_string(b) + " of " + std::to_string(nblocks) +
                     " is corrupt or does not inflate to " + std::to_string(expect) + " bytes");
    }
    return out;
}

template <class T>
std::vector<T> VtuReader::read_array(const XmlElement& da, std::size_t expected, const std::string& what)
{
    const std::string type_name = attr(da, "type");
    const auto type = scalar_from_xml(type_name);
    if (!type)
        fail(at_line(da.line), "expected the type of " + what +
                                   " to be one of Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, "
                                   "Float32, Float64, found \"" +
                                   type_name + "\"");
    const std::string format = attr(da, "format", false);
    if (format == "ascii") return read_ascii<T>(da, *type, expected, what);
    const std::size_t size = static_cast<std::size_t>(scalar_size(*type));
    const std::size_t bytes = expected * size;
    std::vector<unsigned char> payload;
    if (format == "binary") {
        std::size_t b = 0, e = 0;
        if (!da.text.empty()) b = da.text.front().first, e = da.text.back().second;
        std::string joined;
        const char* pb = m_data.data() + b;
        const char* pe = m_data.data() + e;
        if (da.text.size() > 1) { // text split by comments or child elements
            for (const auto& [tb, te] : da.text)
                joined.append(m_data, tb, te - tb);
            pb = joined.data();
            pe = joined.data() + joined.size();
        }
        Base64Source src{Base64Reader(pb, pe)};
        payload = read_block(src, da, bytes, what);
    } else if (format == "appended") {
        if (m_doc.appended_pos == std::string::npos)
            fail(at_line(da.line), "expected <AppendedData> for " + what + " (format=\"appended\"), found none");
        const std::int64_t offset = int_attr(da, "offset", 0);
        const std::size_t start = m_doc.appended_pos + static_cast<std::size_t>(offset);
        if (offset > static_cast<std::int64_t>(m_data.size()) || start > m_data.size())
            fail(at_line(da.line), "expected the offset of " + what + " to lie inside the file, found offset=\"" +
                                       std::to_string(offset) + "\" past its end");
        if (m_doc.appended_encoding == "raw") {
            RawSource src{m_data, start};
            payload = read_block(src, da, bytes, what);
        } else {
            Base64Source src{Base64Reader(m_data.data() + start, m_data.data() + m_data.size())};
            payload = read_block(src, da, bytes, what);
        }
    } else {
        fail(at_line(da.line),
             "expected format=\"ascii\", \"binary\" or \"appended\" for " + what + ", found \"" + format + "\"");
    }
    std::vector<T> out(expected);
    if constexpr (std::is_same_v<T, double>)
        convert_to_double(payload.data(), *type, expected, m_big_endian, out.data());
    else
        convert_to_int64(payload.data(), *type, expected, m_big_endian, out.data());
    return out;
}

TetMesh VtuReader::read()
{
    const XmlElement& grid = read_header();
    Pieces all;
    for (const XmlElement& piece : grid.children) {
        if (piece.name != "Piece") continue;
        const std::int64_t np = int_attr(piece, "NumberOfPoints", 0);
        const std::int64_t nc = int_attr(piece, "NumberOfCells", 0);
        if (nc > (std::int64_t(1) << 40))
            fail(at_line(piece.line), "implausible NumberOfCells=\"" + std::to_string(nc) + "\"");
        if (np > 2147483647 - all.total_points)
            fail(at_line(piece.line), "too many points for tethash (" + std::to_string(all.total_points) + " + " +
                                          std::to_string(np) + ", at most 2147483647)");
        read_points(piece, np, all);
        read_cells(piece, np, nc, all);
        // Point and cell arrays that may hold object ids or labels.
        read_data_arrays(piece, "PointData", false, static_cast<std::size_t>(np), all);
        read_data_arrays(piece, "CellData", true, static_cast<std::size_t>(nc), all);
        all.total_points += np;
        all.total_cells += nc;
    }
    return assemble(all);
}

const XmlElement& VtuReader::read_header()
{
    m_data = read_file(m_path);
    m_doc = detail::parse_xml(m_path, m_data);
    const XmlElement& root = m_doc.root;
    if (root.name != "VTKFile") fail(at_line(root.line), "expected <VTKFile>, found <" + root.name + ">");
    const std::string type = attr(root, "type");
    if (type != "UnstructuredGrid")
        fail(at_line(root.line),
             "expected type=\"UnstructuredGrid\" (the only VTK XML dataset tethash reads), found \"" + type + "\"");
    if (const std::string* v = root.attr("version")) {
        const auto dot = v->find('.');
        const auto major = parse_int(std::string_view(*v).substr(0, dot));
        if (!major || *major < 0 || *major > 2)
            fail(at_line(root.line), "unknown VTK XML version \"" + *v + "\" (expected 0.1 to 2.x)");
    }
    const std::string order = attr(root, "byte_order", false);
    if (order == "BigEndian")
        m_big_endian = true;
    else if (!order.empty() && order != "LittleEndian")
        fail(at_line(root.line), "expected byte_order=\"LittleEndian\" or \"BigEndian\", found \"" + order + "\"");
    const std::string header = attr(root, "header_type", false);
    if (header == "UInt64")
        m_header64 = true;
    else if (!header.empty() && header != "UInt32")
        fail(at_line(root.line), "expected header_type=\"UInt32\" or \"UInt64\", found \"" + header + "\"");
    const std::string compressor = attr(root, "compressor", false);
    if (compressor == "vtkZLibDataCompressor") {
        m_zlib = true;
        if (!vtu_zlib_supported())
            fail(at_line(root.line),
                 "zlib-compressed data (compressor=\"vtkZLibDataCompressor\"), but tethash was built without zlib");
    } else if (!compressor.empty()) {
        fail(at_line(root.line),
             "unsupported compressor \"" + compressor + "\" (expected vtkZLibDataCompressor or none)");
    }
    if (!m_doc.appended_encoding.empty() || m_doc.appended_pos != std::string::npos) {
        if (m_doc.appended_encoding != "raw" && m_doc.appended_encoding != "base64")
            fail(at_line(m_doc.appended_line), "expected encoding=\"raw\" or \"base64\" in <AppendedData>, found \"" +
                                                   m_doc.appended_encoding + "\"");
    }
    const XmlElement* grid = root.child("UnstructuredGrid");
    if (!grid) fail(at_line(root.line), "expected <UnstructuredGrid> in <VTKFile>, found none");
    return *grid;
}

void VtuReader::read_points(const XmlElement& piece, std::int64_t np, Pieces& all)
{
    const std::size_t npz = static_cast<std::size_t>(np);
    const XmlElement* points = piece.child("Points");
    if (!points) fail(at_line(piece.line), "expected <Points> in <Piece>, found none");
    const XmlElement* pda = points->child("DataArray");
    if (!pda) fail(at_line(points->line), "expected a <DataArray> in <Points>, found none");
    const std::string comps = attr(*pda, "NumberOfComponents", false);
    if (comps != "3")
        fail(at_line(pda->line),
             "expected NumberOfComponents=\"3\" for the points, found \"" + (comps.empty() ? "1" : comps) + "\"");
    const std::vector<double> pc =
        read_array<double>(*pda, 3 * npz, "the points (" + std::to_string(np) + " × 3 values)");
    for (std::size_t i = 0; i < npz; ++i)
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(pc[3 * i + k]))
                fail(at_value(*pda, 3 * i + k), "point " +
                                                    std::to_string(all.total_points + static_cast<std::int64_t>(i)) +
                                                    " has a non-finite coordinate");
    all.coords.insert(all.coords.end(), pc.begin(), pc.end());
}

void VtuReader::read_cells(const XmlElement& piece, std::int64_t np, std::int64_t nc, Pieces& all)
{
    const std::size_t ncz = static_cast<std::size_t>(nc);
    const XmlElement* cells = piece.child("Cells");
    if (!cells) {
        if (nc > 0) fail(at_line(piece.line), "expected <Cells> in <Piece>, found none");
        return;
    }
    const auto find = [&](const char* name) -> const XmlElement& {
        for (const auto& c : cells->children)
            if (c.name == "DataArray" && c.attr("Name") && *c.attr("Name") == name) return c;
        fail(at_line(cells->line), "expected a DataArray Name=\"" + std::string(name) + "\" in <Cells>, found none");
    };
    const XmlElement& oda = find("offsets");
    const XmlElement& cda = find("connectivity");
    const XmlElement& tda = find("types");
    const auto offsets = read_array<std::int64_t>(oda, ncz, "DataArray 'offsets' (" + std::to_string(nc) + " cells)");
    const auto types = read_array<std::int64_t>(tda, ncz, "DataArray 'types' (" + std::to_string(nc) + " cells)");
    std::int64_t prev = 0;
    for (std::size_t c = 0; c < ncz; ++c) {
        if (offsets[c] < prev)
            fail(at_value(oda, c), "offset of cell " + std::to_string(c) + " is " + std::to_string(offsets[c]) +
                                       ", expected at least " + std::to_string(prev) + " (offsets must not decrease)");
        prev = offsets[c];
    }
    const std::int64_t conn_size = nc > 0 ? offsets[ncz - 1] : 0;
    if (conn_size > (std::int64_t(1) << 40))
        fail(at_value(oda, ncz - 1), "last offset " + std::to_string(conn_size) + " is implausibly large");
    const auto conn = read_array<std::int64_t>(cda, static_cast<std::size_t>(conn_size),
                                               "DataArray 'connectivity' (" + std::to_string(conn_size) +
                                                   " values, the last offset)");
    for (std::size_t c = 0; c < ncz; ++c) {
        const bool quadratic = types[c] == 24 && m_options.linearize; // corners first, then mid-edge nodes
        if (types[c] == 5 && m_extra) {
            const std::int64_t first = c == 0 ? 0 : offsets[c - 1];
            if (offsets[c] - first != 3)
                fail(at_value(tda, c), "cell " + std::to_string(c) + " has type 5 (triangle) but " +
                                           std::to_string(offsets[c] - first) + " points, expected 3");
            for (int k = 0; k < 3; ++k) {
                const std::int64_t v = conn[static_cast<std::size_t>(first + k)];
                if (v < 0 || v >= np)
                    fail(at_value(cda, static_cast<std::size_t>(first + k)),
                         "triangle (cell " + std::to_string(c) + ") refers to point " + std::to_string(v) +
                             ", but the piece has only " + std::to_string(np) + " points (0-based ids)");
                all.triangle_ids.push_back(static_cast<Index>(v + all.total_points));
            }
            m_extra->triangle_cells.push_back(all.total_cells + static_cast<std::int64_t>(c));
        }
        if (types[c] != 10 && !quadratic) {
            ++all.skipped[types[c]];
            continue;
        }
        const std::int64_t first = c == 0 ? 0 : offsets[c - 1];
        if (offsets[c] - first != (quadratic ? 10 : 4))
            fail(at_value(tda, c),
                 "cell " + std::to_string(c) + " has type " + (quadratic ? "24 (quadratic tetra)" : "10 (tetra)") +
                     " but " + std::to_string(offsets[c] - first) + " points, expected " + (quadratic ? "10" : "4"));
        for (int k = 0; k < 4; ++k) {
            const std::int64_t v = conn[static_cast<std::size_t>(first + k)];
            if (v < 0 || v >= np)
                fail(at_value(cda, static_cast<std::size_t>(first + k)),
                     "tet " + std::to_string(all.tet_cells.size()) + " (cell " + std::to_string(c) +
                         ") refers to point " + std::to_string(v) + ", but the piece has only " + std::to_string(np) +
                         " points (0-based ids)");
            all.tet_ids.push_back(static_cast<Index>(v + all.total_points));
        }
        all.tet_cells.push_back(all.total_cells + static_cast<std::int64_t>(c));
    }
}

void VtuReader::read_data_arrays(const XmlElement& piece, const char* section, bool cell, std::size_t count,
                                 Pieces& all)
{
    const XmlElement* s = piece.child(section);
    if (!s) return;
    for (const auto& da : s->children) {
        if (da.name != "DataArray" || !da.attr("Name")) continue;
        const std::string& name = *da.attr("Name");
        const std::string* nc_attr = da.attr("NumberOfComponents");
        if (m_extra && (!nc_attr || *nc_attr == "1" || *nc_attr == "3")) {
            const int comps = nc_attr && *nc_attr == "3" ? 3 : 1;
            auto values = read_array<double>(da, count * static_cast<std::size_t>(comps), "DataArray '" + name + "'");
            Field& f = (cell ? all.cell_fields : all.point_fields)[name];
            if (f.name.empty()) f = Field{name, comps, {}};
            // A piece without the array (or with other components) leaves it short: dropped below.
            if (f.components == comps) f.values.insert(f.values.end(), values.begin(), values.end());
        }
        if ((nc_attr && *nc_attr != "1") || !is_label_array_name(name, cell)) continue;
        auto values = read_array<double>(da, count, "DataArray '" + name + "'");
        NamedArray& a = (cell ? all.cell_arrays : all.point_arrays)[name];
        if (a.name.empty()) a = {name, {}, at_line(da.line)};
        // Pieces missing the array leave it short; apply_label_arrays then ignores it.
        a.values.insert(a.values.end(), values.begin(), values.end());
    }
}

TetMesh VtuReader::assemble(Pieces& all)
{
    TetMesh mesh;
    mesh.positions.resize(all.total_points, 3);
    std::copy(all.coords.begin(), all.coords.end(), mesh.positions.data());
    mesh.tets.resize(static_cast<Eigen::Index>(all.tet_cells.size()), 4);
    std::copy(all.tet_ids.begin(), all.tet_ids.end(), mesh.tets.data());
    note_skipped_cells(all.skipped);
    if (m_extra) {
        m_extra->triangles.resize(static_cast<Eigen::Index>(all.triangle_ids.size() / 3), 3);
        std::copy(all.triangle_ids.begin(), all.triangle_ids.end(), m_extra->triangles.data());
        m_extra->tet_cells = all.tet_cells;
        for (auto& [k, f] : all.point_fields)
            if (f.values.size() == static_cast<std::size_t>(all.total_points) * static_cast<std::size_t>(f.components))
                m_extra->fields.point.push_back(std::move(f));
        for (auto& [k, f] : all.cell_fields)
            if (f.values.size() == static_cast<std::size_t>(all.total_cells) * static_cast<std::size_t>(f.components))
                m_extra->fields.cell.push_back(std::move(f));
    }
    std::vector<NamedArray> pa, ca;
    for (auto& [k, a] : all.point_arrays)
        pa.push_back(std::move(a));
    for (auto& [k, a] : all.cell_arrays)
        ca.push_back(std::move(a));
    apply_label_arrays(mesh, pa, ca, all.tet_cells, static_cast<std::size_t>(all.total_cells), m_notes);
    return mesh;
}

} // namespace

bool vtu_zlib_supported()
{
#ifdef TETHASH_HAVE_ZLIB
    return true;
#else
    return false;
#endif
}

TetMesh read_vtu(const std::string& path, ReadNotes* notes, const ReadOptions& options)
{
    return VtuReader(path, notes, options).read();
}

VtuContents read_vtu_contents(const std::string& path, ReadNotes* notes, const ReadOptions& options)
{
    VtuContents c;
    VtuReader reader(path, notes, options);
    reader.set_contents(&c);
    c.mesh = reader.read();
    return c;
}

} // namespace tethash::io
