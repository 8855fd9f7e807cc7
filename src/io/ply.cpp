// PLY surfaces (ASCII, binary little- and big-endian): tethash's own reader. assimp 5.2's PLY importer
// reads past its buffer on broken headers and truncated bodies (found by tests/fuzz/fuzz_surface), so
// .ply files do not go through it. Vertices: the x, y, z properties; faces: the list property
// vertex_indices (or vertex_index), fanned into triangles; every other element and property is skipped.
#include "ply.hpp"

#include "tethash/error.hpp"
#include "tethash/io/file.hpp"
#include "vtk_detail.hpp"

#include <cmath>
#include <optional>
#include <sstream>
#include <string_view>

namespace tethash::io::detail {

namespace {

using vtk_detail::Scalar;

/// A PLY type name (both the old "float" and the sized "float32" spellings).
std::optional<Scalar> ply_type(std::string_view s)
{
    if (s == "char" || s == "int8") return Scalar::Int8;
    if (s == "uchar" || s == "uint8") return Scalar::UInt8;
    if (s == "short" || s == "int16") return Scalar::Int16;
    if (s == "ushort" || s == "uint16") return Scalar::UInt16;
    if (s == "int" || s == "int32") return Scalar::Int32;
    if (s == "uint" || s == "uint32") return Scalar::UInt32;
    if (s == "float" || s == "float32") return Scalar::Float32;
    if (s == "double" || s == "float64") return Scalar::Float64;
    return std::nullopt;
}

struct Property {
    std::string name;
    Scalar type = Scalar::Float32;
    bool list = false;
    Scalar count_type = Scalar::UInt8;
};

struct Element {
    std::string name;
    std::int64_t count = 0;
    std::vector<Property> props;
    std::int64_t line = 0;
};

class PlyReader {
  public:
    PlyReader(const std::string& path, std::string data) : m_path(path), m_data(std::move(data)) {}

    void read(std::vector<double>& xyz, std::vector<Index>& tri)
    {
        read_header();
        ++m_line; // from here on: the line at m_pos
        for (const Element& e : m_elements) {
            const bool vertex = e.name == "vertex";
            const bool face = e.name == "face";
            int axis[3] = {-1, -1, -1};
            int indices = -1;
            for (std::size_t p = 0; p < e.props.size(); ++p) {
                const Property& pr = e.props[p];
                if (vertex && !pr.list && (pr.name == "x" || pr.name == "y" || pr.name == "z"))
                    axis[pr.name[0] - 'x'] = static_cast<int>(p);
                if (face && pr.list && (pr.name == "vertex_indices" || pr.name == "vertex_index"))
                    indices = static_cast<int>(p);
            }
            if (vertex && (axis[0] < 0 || axis[1] < 0 || axis[2] < 0))
                fail(e.line, "element vertex has no x, y and z properties");
            if (vertex) m_vertices_in_file = e.count;
            std::vector<double> row(e.props.size());
            std::vector<std::int64_t> list;
            for (std::int64_t i = 0; i < e.count; ++i) {
                if (!m_binary) skip_space(); // an ASCII item is one line
                for (std::size_t p = 0; p < e.props.size(); ++p) {
                    const Property& pr = e.props[p];
                    if (!pr.list) {
                        row[p] = value(pr.type, e, i);
                        continue;
                    }
                    const double n = value(pr.count_type, e, i);
                    if (!(n >= 0) || n != std::floor(n) || n > 1e6)
                        fail_at(e, i, "list " + pr.name + " has length " + format(n) + ", expected 0 to 1000000");
                    const bool keep = static_cast<int>(p) == indices;
                    if (keep) list.clear();
                    for (std::int64_t k = 0; k < static_cast<std::int64_t>(n); ++k) {
                        const double v = value(pr.type, e, i);
                        if (keep) {
                            if (!(v >= 0) || v != std::floor(v) || v >= static_cast<double>(m_vertices_in_file))
                                fail_at(e, i,
                                        "face refers to vertex " + format(v) + ", but there are " +
                                            std::to_string(m_vertices_in_file) + " vertices");
                            list.push_back(static_cast<std::int64_t>(v));
                        }
                    }
                }
                if (!m_binary) end_line(e, i);
                if (vertex) {
                    for (int a = 0; a < 3; ++a) {
                        const double c = row[static_cast<std::size_t>(axis[a])];
                        if (!std::isfinite(c))
                            fail_at(e, i, std::string("vertex has a non-finite ") + char('x' + a) + " coordinate");
                        xyz.push_back(c);
                    }
                } else if (indices >= 0) {
                    for (std::size_t k = 2; k < list.size(); ++k) // fan: polygons are convex in practice
                        tri.insert(tri.end(), {static_cast<Index>(list[0]), static_cast<Index>(list[k - 1]),
                                               static_cast<Index>(list[k])});
                }
            }
        }
        skip_space();
        if (m_pos < m_data.size() && !m_binary)
            fail(m_line, "expected the end of the file after the last element, found more data");
    }

  private:
    [[noreturn]] void fail(std::int64_t line, const std::string& msg) const
    {
        throw Error(m_path + ":" + std::to_string(line) + ": " + msg);
    }
    [[noreturn]] void fail_at(const Element& e, std::int64_t i, const std::string& msg) const
    {
        if (m_binary)
            throw Error(m_path + ": byte " + std::to_string(m_pos) + ": " + e.name + " " + std::to_string(i) + ": " +
                        msg);
        fail(m_line, e.name + " " + std::to_string(i) + ": " + msg);
    }
    /// A header line for a message: at most 40 characters, non-printable ones as '?'.
    static std::string printable(std::string_view l)
    {
        std::string r(l.substr(0, 40));
        for (char& c : r)
            if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
        return r;
    }
    static std::string format(double v)
    {
        std::ostringstream s;
        s << v;
        return s.str();
    }

    std::string header_line()
    {
        // m_line: the line just read (1-based).
        const std::size_t nl = m_data.find('\n', m_pos);
        if (nl == std::string::npos) fail(m_line, "expected end_header, found the end of the file");
        std::string l = m_data.substr(m_pos, nl - m_pos);
        if (!l.empty() && l.back() == '\r') l.pop_back();
        m_pos = nl + 1;
        ++m_line;
        return l;
    }

    void read_header()
    {
        if (header_line() != "ply") fail(1, "expected 'ply' on the first line");
        bool have_format = false;
        for (;;) {
            const std::int64_t line = m_line + 1;
            const std::string l = header_line();
            std::istringstream in(l);
            std::string key;
            in >> key;
            if (key == "end_header") break;
            if (key == "comment" || key == "obj_info" || key.empty()) continue;
            std::vector<std::string> w;
            for (std::string t; in >> t;)
                w.push_back(t);
            if (key == "format") {
                if (w.size() != 2 || (w[0] != "ascii" && w[0] != "binary_little_endian" && w[0] != "binary_big_endian"))
                    fail(line, "expected 'format ascii|binary_little_endian|binary_big_endian 1.0', found '" +
                                   printable(l) + "'");
                m_binary = w[0] != "ascii";
                m_big_endian = w[0] == "binary_big_endian";
                have_format = true;
            } else if (key == "element") {
                std::int64_t n = -1;
                if (w.size() == 2) {
                    std::istringstream c(w[1]);
                    if (!(c >> n) || !c.eof()) n = -1;
                }
                if (n < 0) fail(line, "expected 'element NAME COUNT', found '" + printable(l) + "'");
                // Every item takes at least a byte: a count the file cannot hold fails here.
                if (static_cast<std::uint64_t>(n) > m_data.size())
                    fail(line, "element " + w[0] + " declares " + std::to_string(n) + " items, more than the file (" +
                                   std::to_string(m_data.size()) + " bytes) can hold");
                m_elements.push_back({w[0], n, {}, line});
            } else if (key == "property") {
                if (m_elements.empty()) fail(line, "expected 'element' before 'property'");
                Property p;
                std::optional<Scalar> t, ct;
                if (w.size() == 4 && w[0] == "list" && (ct = ply_type(w[1])) && (t = ply_type(w[2])) &&
                    *ct != Scalar::Float32 && *ct != Scalar::Float64) {
                    p = {w[3], *t, true, *ct};
                } else if (w.size() == 2 && (t = ply_type(w[0]))) {
                    p = {w[1], *t, false, Scalar::UInt8};
                } else {
                    fail(line, "expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME', found '" +
                                   printable(l) + "'");
                }
                Element& e = m_elements.back();
                if (!e.props.empty() && e.count > 0 && e.props.size() >= 1000)
                    fail(line, "element " + e.name + " has more than 1000 properties");
                e.props.push_back(p);
            } else {
                fail(line, "unknown header line '" + printable(l) + "'");
            }
        }
        if (!have_format) fail(m_line, "expected a 'format' line in the header, found none");
        for (const Element& e : m_elements)
            if (e.props.empty() && e.count > 0)
                fail(e.line, "element " + e.name + " has " + std::to_string(e.count) + " items but no properties");
    }

    void skip_space()
    {
        while (m_pos < m_data.size() &&
               (m_data[m_pos] == ' ' || m_data[m_pos] == '\t' || m_data[m_pos] == '\r' || m_data[m_pos] == '\n')) {
            if (m_data[m_pos] == '\n') ++m_line;
            ++m_pos;
        }
    }

    /// ASCII: the rest of the line must be empty (an item is one line).
    void end_line(const Element& e, std::int64_t i)
    {
        while (m_pos < m_data.size() && (m_data[m_pos] == ' ' || m_data[m_pos] == '\t' || m_data[m_pos] == '\r'))
            ++m_pos;
        if (m_pos < m_data.size() && m_data[m_pos] != '\n')
            fail_at(e, i, "expected the end of the line, found more values than the header lists");
    }

    double value(Scalar t, const Element& e, std::int64_t i)
    {
        if (m_binary) {
            const auto n = static_cast<std::size_t>(vtk_detail::scalar_size(t));
            if (m_data.size() - m_pos < n)
                fail_at(e, i, "expected " + std::to_string(n) + " more bytes, found the end of the file");
            double v = 0;
            vtk_detail::convert_to_double(reinterpret_cast<const unsigned char*>(m_data.data() + m_pos), t, 1,
                                          m_big_endian, &v);
            m_pos += n;
            return v;
        }
        // ASCII: the values of one item are on its line.
        while (m_pos < m_data.size() && (m_data[m_pos] == ' ' || m_data[m_pos] == '\t' || m_data[m_pos] == '\r'))
            ++m_pos;
        const std::size_t s = m_pos;
        while (m_pos < m_data.size() && m_data[m_pos] != ' ' && m_data[m_pos] != '\t' && m_data[m_pos] != '\r' &&
               m_data[m_pos] != '\n')
            ++m_pos;
        if (s == m_pos)
            fail_at(e, i,
                    std::string("expected a number, found the end of the ") +
                        (m_pos < m_data.size() ? "line" : "file"));
        const std::string tok = m_data.substr(s, m_pos - s);
        char* end = nullptr;
        const double v = std::strtod(tok.c_str(), &end);
        if (end != tok.c_str() + tok.size()) fail_at(e, i, "expected a number, found '" + tok.substr(0, 24) + "'");
        return v;
    }

    const std::string& m_path;
    std::string m_data;
    std::size_t m_pos = 0;
    std::int64_t m_line = 0;
    bool m_binary = false;
    bool m_big_endian = false;
    std::vector<Element> m_elements;
    std::int64_t m_vertices_in_file = 0;
};

} // namespace

void read_ply(const std::string& path, std::vector<double>& xyz, std::vector<Index>& tri)
{
    PlyReader(path, read_file(path)).read(xyz, tri);
}

} // namespace tethash::io::detail
