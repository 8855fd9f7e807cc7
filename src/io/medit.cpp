// Medit / INRIA .mesh (ASCII): reader and writer.
//
// Keywords: MeshVersionFormatted (1..4), Dimension 3, Vertices (x y z ref -> TetMesh::vertex_label),
// Tetrahedra (v0 v1 v2 v3 ref, 1-based -> TetMesh::tet_label), End. Other blocks (Triangles, Edges,
// Corners, Ridges, Normals, ...) are skipped: known ones by their entry size, unknown ones as
// "KEYWORD count" followed by count lines. '#' starts a comment.
#include "tethash/io/medit.hpp"

#include "number.hpp"
#include "tethash/error.hpp"
#include "text_reader.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <map>

namespace tethash::io {

namespace {

using detail::TextReader;

constexpr std::int64_t k_max_int32 = std::numeric_limits<std::int32_t>::max();

using detail::to_lower;

/// Tokens per entry of blocks that are skipped (lower-case keyword).
int medit_entry_tokens(const std::string& keyword)
{
    static const std::map<std::string, int> sizes = {
        {"edges", 3},
        {"triangles", 4},
        {"quadrilaterals", 5},
        {"hexahedra", 9},
        {"prisms", 7},
        {"pyramids", 6},
        {"corners", 1},
        {"requiredvertices", 1},
        {"ridges", 1},
        {"requirededges", 1},
        {"requiredtriangles", 1},
        {"requiredquadrilaterals", 1},
        {"requiredtetrahedra", 1},
        {"normals", 3},
        {"tangents", 3},
        {"normalatvertices", 2},
        {"tangentatvertices", 2},
        {"normalattrianglevertices", 3},
        {"tetrahedrap2", 11},
        {"trianglesp2", 7},
        {"edgesp2", 4},
        {"crack", 2},
        {"equivalence", 2},
    };
    const auto it = sizes.find(keyword);
    return it == sizes.end() ? 0 : it->second;
}

} // namespace

TetMesh read_medit(const std::string& path, ReadNotes* notes)
{
    TextReader r(path, '#');
    {
        const std::string_view first = r.next("MeshVersionFormatted");
        if (to_lower(first) != "meshversionformatted") r.fail("MeshVersionFormatted", TextReader::describe(first));
        const std::int64_t version = r.next_int("the MeshVersionFormatted number");
        if (version < 1 || version > 4)
            r.fail("MeshVersionFormatted 1, 2, 3 or 4", "version " + std::to_string(version));
    }
    TetMesh mesh;
    bool have_dimension = false, have_vertices = false, have_tets = false;
    std::vector<std::int64_t> tet_lines; // lines of tets read before the vertices (checked at the end)
    std::map<std::string, std::int64_t> skipped;
    while (!r.at_end()) {
        const std::string_view tok = r.next("a keyword");
        const std::string key = to_lower(tok);
        if (key == "end") break;
        if (key == "dimension") {
            const std::int64_t d = r.next_int("the dimension");
            if (d != 3) r.fail("Dimension 3", "Dimension " + std::to_string(d));
            have_dimension = true;
        } else if (key == "vertices") {
            if (!have_dimension) r.fail("Dimension 3 before Vertices", "Vertices");
            if (have_vertices) r.fail_message("a second Vertices block");
            const std::int64_t n = r.next_int_in("the number of vertices", 0, k_max_int32);
            r.check_count_fits(n, "vertices");
            mesh.positions.resize(static_cast<Index>(n), 3);
            mesh.vertex_label.resize(static_cast<std::size_t>(n));
            static const char* axis[] = {"x", "y", "z"};
            for (std::int64_t i = 0; i < n; ++i) {
                for (int a = 0; a < 3; ++a) {
                    const std::string_view t = r.next("a coordinate");
                    const auto v = detail::parse_double(t);
                    if (!v || !std::isfinite(*v))
                        r.fail(std::string("a finite ") + axis[a] + " coordinate of vertex " + std::to_string(i + 1),
                               TextReader::describe(t));
                    mesh.positions(static_cast<Index>(i), a) = *v;
                }
                mesh.vertex_label[static_cast<std::size_t>(i)] =
                    static_cast<Index>(r.next_int_in("the reference of vertex " + std::to_string(i + 1),
                                                     std::numeric_limits<std::int32_t>::min(), k_max_int32));
            }
            have_vertices = true;
        } else if (key == "tetrahedra") {
            if (have_tets) r.fail_message("a second Tetrahedra block");
            const std::int64_t m = r.next_int_in("the number of tetrahedra", 0, k_max_int32);
            r.check_count_fits(m, "tetrahedra");
            mesh.tets.resize(static_cast<Index>(m), 4);
            mesh.tet_label.resize(static_cast<std::size_t>(m));
            const std::int64_t nv = mesh.num_vertices();
            if (!have_vertices) tet_lines.resize(static_cast<std::size_t>(m));
            for (std::int64_t t = 0; t < m; ++t) {
                for (int k = 0; k < 4; ++k) {
                    const std::int64_t v =
                        r.next_int("vertex " + std::to_string(k + 1) + " of tetrahedron " + std::to_string(t + 1));
                    if (have_vertices && (v < 1 || v > nv))
                        r.fail_message("tetrahedron " + std::to_string(t + 1) + ": vertex index " + std::to_string(v) +
                                       " is past the end (Vertices has 1.." + std::to_string(nv) + ")");
                    if (v < 1 || v > k_max_int32)
                        r.fail_message("tetrahedron " + std::to_string(t + 1) + ": vertex index " + std::to_string(v) +
                                       " is out of range (indices start at 1)");
                    mesh.tets(static_cast<Index>(t), k) = static_cast<Index>(v - 1);
                }
                if (!have_vertices) tet_lines[static_cast<std::size_t>(t)] = r.line();
                mesh.tet_label[static_cast<std::size_t>(t)] =
                    static_cast<Index>(r.next_int_in("the reference of tetrahedron " + std::to_string(t + 1),
                                                     std::numeric_limits<std::int32_t>::min(), k_max_int32));
            }
            have_tets = true;
        } else {
            // A block this reader does not need: known ones by entry size, others line by line.
            if (tok.empty() || !(std::isalpha(static_cast<unsigned char>(tok.front()))))
                r.fail("a keyword such as Vertices or Tetrahedra", TextReader::describe(tok));
            const std::string name(tok);
            const std::int64_t count =
                r.next_int_in("the number of entries of " + name, 0, std::numeric_limits<std::int64_t>::max() / 256);
            const int per = medit_entry_tokens(key);
            if (per > 0) {
                for (std::int64_t i = 0; i < count * per; ++i)
                    r.next("an entry of " + name);
            } else {
                r.skip_rest_of_line();
                for (std::int64_t i = 0; i < count; ++i) {
                    bool eof = false;
                    r.next_line(&eof);
                    if (eof) r.fail(std::to_string(count) + " lines of " + name, "end of file");
                }
            }
            skipped[name] += count;
        }
    }
    if (!have_vertices) throw Error(path + ": no Vertices block");
    if (!have_tets) throw Error(path + ": no Tetrahedra block (not a tet mesh?)");
    for (std::size_t t = 0; t < tet_lines.size(); ++t)
        for (int k = 0; k < 4; ++k)
            if (mesh.tets(static_cast<Index>(t), k) >= mesh.num_vertices())
                r.fail_at_line(tet_lines[t], "tetrahedron " + std::to_string(t + 1) + ": vertex index " +
                                                 std::to_string(mesh.tets(static_cast<Index>(t), k) + 1) +
                                                 " is past the end (Vertices has 1.." +
                                                 std::to_string(mesh.num_vertices()) + ")");
    if (notes)
        for (const auto& [name, count] : skipped) {
            if (name == "Triangles" || name == "Quadrilaterals" || name == "Hexahedra" || name == "Prisms" ||
                name == "Pyramids" || name == "Edges") {
                notes->skipped_cells += count;
                if (count) notes->skipped.push_back({count, name, false});
            }
            if (count) notes->messages.push_back("skipped " + std::to_string(count) + " entries of " + name);
        }
    return mesh;
}

void write_medit(const std::string& path, const TetMesh& mesh)
{
    mesh.check_consistency("mesh to write to " + path);
    const Index n = mesh.num_vertices(), m = mesh.num_tets();
    const bool vrefs = static_cast<Index>(mesh.vertex_label.size()) == n;
    const bool trefs = static_cast<Index>(mesh.tet_label.size()) == m;
    using detail::append_double;
    using detail::append_int;
    std::string s;
    s.reserve(static_cast<std::size_t>(n) * 64 + static_cast<std::size_t>(m) * 40 + 256);
    s += "MeshVersionFormatted 2\nDimension 3\n\nVertices\n";
    append_int(s, n);
    s += '\n';
    for (Index v = 0; v < n; ++v) {
        for (int a = 0; a < 3; ++a) {
            append_double(s, mesh.positions(v, a));
            s += ' ';
        }
        append_int(s, vrefs ? mesh.vertex_label[static_cast<std::size_t>(v)] : 0);
        s += '\n';
    }
    s += "\nTetrahedra\n";
    append_int(s, m);
    s += '\n';
    for (Index t = 0; t < m; ++t) {
        for (int k = 0; k < 4; ++k) {
            append_int(s, mesh.tets(t, k) + 1);
            s += ' ';
        }
        append_int(s, trefs ? mesh.tet_label[static_cast<std::size_t>(t)] : 0);
        s += '\n';
    }
    s += "\nEnd\n";
    write_text_file(path, s);
}

} // namespace tethash::io
