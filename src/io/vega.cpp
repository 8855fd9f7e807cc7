// Vega FEM .veg (ASCII) reader.
//
// Sections: *VERTICES with a header "n 3 0 0" and lines "id x y z" (ids 1..n), *ELEMENTS followed by
// the element type TET (on the same line or the next) with a header "m 4 0" and lines
// "id v0 v1 v2 v3" (1-based). Other sections (*MATERIAL, *REGION, *SET, *SOLVER ...) are skipped up to
// the next '*' keyword; *INCLUDE is rejected (the included file would be needed). '#' starts a
// comment and commas separate values like spaces.
#include "tethash/io/vega.hpp"

#include "tethash/error.hpp"
#include "text_reader.hpp"

#include <algorithm>
#include <cctype>
#include <limits>
#include <map>

namespace tethash::io {

namespace {

using detail::TextReader;

constexpr std::int64_t k_max_int32 = std::numeric_limits<std::int32_t>::max();

std::string upper(std::string_view s)
{
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return std::toupper(c); });
    return out;
}

/// Reads the number of item `index` (0-based) of `count` items (`kind` "vertex" or "element", `kinds` its
/// plural), which must be index + 1: Vega numbers them 1..count in order.
std::int64_t next_number(TextReader& r, const std::string& kind, const std::string& kinds, std::int64_t index,
                         std::int64_t count)
{
    const std::int64_t id = r.next_int((kind == "element" ? "an " : "a ") + kind + " number");
    if (id != index + 1)
        r.fail(kind + " number " + std::to_string(index + 1) + " (" + kinds + " are numbered 1.." +
                   std::to_string(count) + " in order)",
               std::to_string(id));
    return id;
}

/// Reads a section header "count width ...": the number of `items`, then `width_what`, which must be `width`
/// (`expected` says so in the error), and skips the rest of the line. Returns the number of items.
std::int64_t read_header(TextReader& r, const std::string& items, std::string_view width_what, std::int64_t width,
                         std::string_view expected)
{
    const std::int64_t count = r.next_int_in("the number of " + items, 0, k_max_int32);
    const std::int64_t w = r.next_int(width_what);
    if (w != width) r.fail(expected, std::to_string(w));
    r.skip_rest_of_line();
    r.check_count_fits(count, items);
    return count;
}

} // namespace

TetMesh read_veg(const std::string& path, ReadNotes* notes)
{
    TextReader r(path, '#', ',');
    TetMesh mesh;
    bool have_vertices = false, have_elements = false;
    std::vector<std::int64_t> tet_lines;
    std::map<std::string, int> skipped;
    while (!r.at_end()) {
        const std::string_view tok = r.next("a section keyword");
        if (tok.front() != '*') r.fail("a section keyword such as *VERTICES or *ELEMENTS", TextReader::describe(tok));
        const std::string key = upper(tok);
        if (key == "*VERTICES") {
            if (have_vertices) r.fail_message("a second *VERTICES section");
            const std::int64_t n =
                read_header(r, "vertices", "the dimension", 3, "dimension 3 in the *VERTICES header");
            mesh.positions.resize(static_cast<Index>(n), 3);
            static const char* axis[] = {"x", "y", "z"};
            for (std::int64_t i = 0; i < n; ++i) {
                const std::int64_t id = next_number(r, "vertex", "vertices", i, n);
                for (int a = 0; a < 3; ++a)
                    mesh.positions(static_cast<Index>(i), a) =
                        r.next_double(std::string(axis[a]) + " coordinate of vertex " + std::to_string(id));
            }
            have_vertices = true;
        } else if (key == "*ELEMENTS") {
            if (have_elements) r.fail_message("a second *ELEMENTS section");
            const std::string_view type = r.next("the element type TET");
            if (upper(type) != "TET")
                r.fail("the element type TET (tethash reads tet meshes only)", TextReader::describe(type));
            const std::int64_t m =
                read_header(r, "elements", "the number of vertices per element", 4, "4 vertices per TET element");
            mesh.tets.resize(static_cast<Index>(m), 4);
            tet_lines.resize(static_cast<std::size_t>(m));
            for (std::int64_t t = 0; t < m; ++t) {
                const std::int64_t id = next_number(r, "element", "elements", t, m);
                tet_lines[static_cast<std::size_t>(t)] = r.line();
                for (int k = 0; k < 4; ++k) {
                    const std::int64_t v =
                        r.next_int("vertex " + std::to_string(k + 1) + " of element " + std::to_string(id));
                    if (v < 1 || v > k_max_int32)
                        r.fail_message("element " + std::to_string(id) + ": vertex index " + std::to_string(v) +
                                       " is out of range (vertices are numbered from 1)");
                    mesh.tets(static_cast<Index>(t), k) = static_cast<Index>(v - 1);
                }
            }
            have_elements = true;
        } else if (key == "*INCLUDE") {
            r.fail_message("*INCLUDE is not supported (merge the included file into " + path + ")");
        } else {
            // *MATERIAL, *REGION, *SET, *SOLVER, ...: skip to the next keyword.
            while (!r.at_end() && r.peek().front() != '*')
                r.next("");
            skipped[key] += 1;
        }
    }
    if (!have_vertices) throw Error(path + ": no *VERTICES section");
    if (!have_elements) throw Error(path + ": no *ELEMENTS section");
    const Index n = mesh.num_vertices();
    for (Index t = 0; t < mesh.num_tets(); ++t)
        for (int k = 0; k < 4; ++k)
            if (mesh.tets(t, k) >= n)
                r.fail_at_line(tet_lines[static_cast<std::size_t>(t)],
                               "element " + std::to_string(t + 1) + ": vertex index " +
                                   std::to_string(mesh.tets(t, k) + 1) + " is past the end (*VERTICES has 1.." +
                                   std::to_string(n) + ")");
    if (notes)
        for (const auto& [name, count] : skipped)
            notes->messages.push_back("skipped " + std::to_string(count) + " " + name + " section(s)");
    return mesh;
}

} // namespace tethash::io
