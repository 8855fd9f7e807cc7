// TetGen .node + .ele pairs: reader and writer.
//
// .node: "n 3 nattr nmarkers" then "id x y z [attributes] [marker]"; .ele: "m 4|10 nattr" then
// "id v0 v1 v2 v3 [...] [attributes]". '#' starts a comment. The first node id (0 or 1) sets the
// numbering of both files, as in TetGen. Node markers -> TetMesh::vertex_label, the first tet attribute
// -> TetMesh::tet_label (when every value of it is an integer). 10-node tets are read as their 4 corner
// nodes (the first four indices), with a note.
#include "tethash/io/tetgen.hpp"

#include "number.hpp"
#include "tethash/error.hpp"
#include "text_reader.hpp"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

namespace tethash::io {

namespace {

using detail::TextReader;

constexpr std::int64_t k_max_int32 = std::numeric_limits<std::int32_t>::max();

/// The .node and .ele paths of a TetGen pair named by either file.
std::pair<std::string, std::string> tetgen_pair(const std::string& path)
{
    std::filesystem::path p(path);
    const std::string ext = extension_of(path);
    if (ext != ".node" && ext != ".ele")
        throw Error(path + ": a TetGen file name must end in .node or .ele, found '" + ext + "'");
    std::filesystem::path node = p, ele = p;
    node.replace_extension(".node");
    ele.replace_extension(".ele");
    return {node.string(), ele.string()};
}

/// Reads an index token `what` and checks it is an integer.
std::int64_t read_index(TextReader& r, std::string_view what)
{
    return r.next_int(what);
}

/// Reads the next integer if it is on line `line` (TetGen headers may leave out trailing values), else `fallback`.
std::int64_t header_value(TextReader& r, std::int64_t line, std::string_view what, std::int64_t fallback)
{
    if (r.at_end() || r.peek_line() != line) return fallback;
    return r.next_int(what);
}

} // namespace

TetMesh read_tetgen(const std::string& path, ReadNotes* notes)
{
    const auto [node_path, ele_path] = tetgen_pair(path);
    if (!std::filesystem::exists(node_path))
        throw Error(node_path + ": no such file (the vertices of " + path + " are read from it)");
    if (!std::filesystem::exists(ele_path))
        throw Error(ele_path + ": no such file (the tets of " + path + " are read from it)");

    TetMesh mesh;
    std::int64_t base = 0;
    // ---- .node
    {
        TextReader r(node_path, '#');
        const std::int64_t n = r.next_int_in("the number of nodes", 0, k_max_int32);
        const std::int64_t header = r.line();
        const std::int64_t dim = header_value(r, header, "the dimension", 3);
        if (dim != 3) r.fail("dimension 3", std::to_string(dim));
        const std::int64_t nattr = header_value(r, header, "the number of node attributes", 0);
        if (nattr < 0 || nattr > 1000) r.fail("a number of node attributes in 0..1000", std::to_string(nattr));
        const std::int64_t nmark = header_value(r, header, "the number of boundary markers (0 or 1)", 0);
        if (nmark != 0 && nmark != 1) r.fail("0 or 1 boundary markers", std::to_string(nmark));
        // Each node takes more than one byte: a larger count is wrong (and is not allocated for).
        r.check_count_fits(n, "nodes", " in the header");
        mesh.positions.resize(static_cast<Index>(n), 3);
        if (nmark) mesh.vertex_label.resize(static_cast<std::size_t>(n));
        for (std::int64_t i = 0; i < n; ++i) {
            const std::int64_t id = read_index(r, "a node index");
            if (i == 0) {
                if (id != 0 && id != 1) r.fail("the first node index 0 or 1", std::to_string(id));
                base = id;
            } else if (id != base + i) {
                r.fail("node index " + std::to_string(base + i) + " (indices must be consecutive; the header says " +
                           std::to_string(n) + " nodes)",
                       std::to_string(id));
            }
            static const char* axis[] = {"x", "y", "z"};
            for (int a = 0; a < 3; ++a)
                mesh.positions(static_cast<Index>(i), a) =
                    r.next_double(std::string(axis[a]) + " coordinate of node " + std::to_string(id));
            for (std::int64_t k = 0; k < nattr; ++k)
                r.next_double_any("a node attribute");
            if (nmark)
                mesh.vertex_label[static_cast<std::size_t>(i)] =
                    static_cast<Index>(r.next_int_in("the boundary marker of node " + std::to_string(id),
                                                     std::numeric_limits<std::int32_t>::min(), k_max_int32));
        }
        if (!r.at_end()) r.fail("end of file after " + std::to_string(n) + " nodes", TextReader::describe(r.next("")));
        if (nattr && notes) notes->messages.push_back("ignored " + std::to_string(nattr) + " node attribute(s)");
        if (notes) notes->first_id = static_cast<int>(base);
    }
    // ---- .ele
    {
        TextReader r(ele_path, '#');
        const std::int64_t m = r.next_int_in("the number of tets", 0, k_max_int32);
        const std::int64_t header = r.line();
        const std::int64_t per = header_value(r, header, "the number of nodes per tet (4 or 10)", 4);
        if (per != 4 && per != 10) r.fail("4 or 10 nodes per tet", std::to_string(per));
        const std::int64_t nattr = header_value(r, header, "the number of tet attributes", 0);
        if (nattr < 0 || nattr > 1000) r.fail("a number of tet attributes in 0..1000", std::to_string(nattr));
        const auto nv = static_cast<std::int64_t>(mesh.num_vertices());
        r.check_count_fits(m, "tets", " in the header");
        mesh.tets.resize(static_cast<Index>(m), 4);
        std::vector<double> first_attr;
        if (nattr) first_attr.resize(static_cast<std::size_t>(m));
        for (std::int64_t t = 0; t < m; ++t) {
            const std::int64_t id = read_index(r, "a tet index");
            if (id != base + t)
                r.fail("tet index " + std::to_string(base + t) +
                           " (indices are consecutive from the first node index " + std::to_string(base) +
                           "; the header says " + std::to_string(m) + " tets)",
                       std::to_string(id));
            for (std::int64_t k = 0; k < per; ++k) {
                const std::int64_t v = r.next_int("node " + std::to_string(k + 1) + " of tet " + std::to_string(id));
                if (v < base || v >= base + nv)
                    r.fail_message("tet " + std::to_string(id) + ": node index " + std::to_string(v) +
                                   " is past the end (the .node file has indices " + std::to_string(base) + ".." +
                                   std::to_string(base + nv - 1) + ")");
                if (k < 4) mesh.tets(static_cast<Index>(t), static_cast<Index>(k)) = static_cast<Index>(v - base);
            }
            for (std::int64_t k = 0; k < nattr; ++k) {
                const double a = r.next_double("attribute " + std::to_string(k + 1) + " of tet " + std::to_string(id));
                if (k == 0) first_attr[static_cast<std::size_t>(t)] = a;
            }
        }
        if (!r.at_end()) r.fail("end of file after " + std::to_string(m) + " tets", TextReader::describe(r.next("")));
        if (nattr) {
            bool integral = true;
            for (double a : first_attr)
                integral = integral && a == std::floor(a) && std::abs(a) <= static_cast<double>(k_max_int32);
            if (integral) {
                mesh.tet_label.resize(first_attr.size());
                for (std::size_t t = 0; t < first_attr.size(); ++t)
                    mesh.tet_label[t] = static_cast<Index>(first_attr[t]);
            } else if (notes) {
                notes->messages.push_back(ele_path +
                                          ": the first tet attribute is not integer-valued; not kept as labels");
            }
        }
        if (per == 10 && notes)
            notes->messages.push_back(ele_path +
                                      ": 10-node tets read as 4-node tets (their first 4 nodes, the corners)");
    }
    return mesh;
}

namespace {

/// One TetGen file: the comment `columns_comment` (naming `label_name` when there are labels), the header
/// line "COUNT HEADER_FIELDS 0|1" (the last: whether a label column follows), then one line per row: its
/// 1-based index, `columns` values written by `append_value(out, row, column)` and its label.
template <class AppendValue>
std::string tetgen_table(const std::string& columns_comment, const char* label_name, Index count,
                         const char* header_fields, int columns, std::size_t bytes_per_row, AppendValue append_value,
                         const std::vector<Index>* labels)
{
    std::string out;
    out.reserve(static_cast<std::size_t>(count) * bytes_per_row + 128);
    out += columns_comment;
    if (labels) {
        out += ' ';
        out += label_name;
    }
    out += '\n';
    detail::append_int(out, count);
    out += ' ';
    out += header_fields;
    out += labels ? " 1\n" : " 0\n";
    for (Index i = 0; i < count; ++i) {
        detail::append_int(out, i + 1);
        for (int c = 0; c < columns; ++c) {
            out += ' ';
            append_value(out, i, c);
        }
        if (labels) {
            out += ' ';
            detail::append_int(out, (*labels)[static_cast<std::size_t>(i)]);
        }
        out += '\n';
    }
    return out;
}

} // namespace

void write_tetgen(const std::string& path, const TetMesh& mesh)
{
    mesh.check_consistency("mesh to write to " + path);
    const auto [node_path, ele_path] = tetgen_pair(path);
    const Index n = mesh.num_vertices(), m = mesh.num_tets();
    const bool markers = static_cast<Index>(mesh.vertex_label.size()) == n && n > 0;
    const bool labels = static_cast<Index>(mesh.tet_label.size()) == m && m > 0;
    const std::string s = tetgen_table(
        "# TetGen .node written by tethash: index x y z", "marker", n, "3 0", 3, 64,
        [&](std::string& out, Index v, int a) { detail::append_double(out, mesh.positions(v, a)); },
        markers ? &mesh.vertex_label : nullptr);
    const std::string e = tetgen_table(
        "# TetGen .ele written by tethash: index v0 v1 v2 v3 (1-based)", "label", m, "4", 4, 48,
        [&](std::string& out, Index t, int k) { detail::append_int(out, mesh.tets(t, k) + 1); },
        labels ? &mesh.tet_label : nullptr);
    // Both files are complete before either replaces an existing one: a failed write never leaves a
    // new .node beside an old .ele.
    write_text_files({node_path, ele_path}, {s, e});
}

} // namespace tethash::io
