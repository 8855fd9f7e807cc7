// Cell files (io/cells.hpp): one cell or portal per line, each checked as it is read so that a problem names its line.
#include "tethash/io/cells.hpp"

#include "number.hpp"

#include "tethash/error.hpp"
#include "tethash/io/file.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <vector>

namespace tethash::io {

namespace {

/// The words of a line, up to a '#'.
std::vector<std::string_view> words_of(std::string_view line)
{
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    std::vector<std::string_view> out;
    std::size_t i = 0;
    auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; };
    while (i < line.size()) {
        while (i < line.size() && space(line[i]))
            ++i;
        const std::size_t start = i;
        while (i < line.size() && !space(line[i]))
            ++i;
        if (i > start) out.push_back(line.substr(start, i - start));
    }
    return out;
}

} // namespace

CellLayout parse_cells(const std::string& path, std::string_view text)
{
    CellLayout layout;
    std::map<std::string, Index, std::less<>> index;
    std::int64_t line_no = 0;
    auto fail = [&](const std::string& message) { throw Error(path + ":" + std::to_string(line_no) + ": " + message); };
    auto number = [&](std::string_view token, const char* what) {
        const std::optional<double> v = detail::parse_double(token);
        if (!v || !std::isfinite(*v))
            fail(std::string("expected ") + what + " (a finite number), found " + detail::quote_token(token, 40));
        return *v;
    };
    static const char* const corner[6] = {"the min x", "the min y", "the min z", "the max x", "the max y", "the max z"};
    static const char* const rect[6] = {"x0", "y0", "z0", "x1", "y1", "z1"};
    std::size_t pos = 0;
    while (pos <= text.size()) {
        const std::size_t end = std::min(text.find('\n', pos), text.size());
        const std::string_view line = text.substr(pos, end - pos);
        pos = end + 1;
        ++line_no;
        const std::vector<std::string_view> w = words_of(line);
        if (w.empty()) continue;
        if (w[0] == "cell") {
            if (w.size() != 8)
                fail("expected 'cell NAME XMIN YMIN ZMIN XMAX YMAX ZMAX' (8 fields), found " +
                     std::to_string(w.size()));
            PortalCell c;
            c.name = std::string(w[1]);
            for (int a = 0; a < 3; ++a) {
                c.lo[a] = number(w[2 + a], corner[a]);
                c.hi[a] = number(w[5 + a], corner[3 + a]);
            }
            layout.cells.push_back(c);
            try {
                check_cell(layout, layout.cells.size() - 1);
            } catch (const Error& e) {
                fail(e.what());
            }
            index.emplace(c.name, static_cast<Index>(layout.cells.size() - 1));
        } else if (w[0] == "portal") {
            if (w.size() != 9)
                fail("expected 'portal CELL_A CELL_B X0 Y0 Z0 X1 Y1 Z1' (9 fields), found " + std::to_string(w.size()));
            Portal p;
            for (int k = 0; k < 2; ++k) {
                const auto it = index.find(w[1 + k]);
                if (it == index.end())
                    fail("portal between unknown cell " + detail::quote_token(w[1 + k], 40) +
                         " (cells are declared above the portals that join them)");
                (k ? p.b : p.a) = it->second;
            }
            for (int a = 0; a < 3; ++a) {
                const double u = number(w[3 + a], rect[a]), v = number(w[6 + a], rect[3 + a]);
                p.lo[a] = std::min(u, v);
                p.hi[a] = std::max(u, v);
            }
            layout.portals.push_back(p);
            try {
                check_portal(layout, layout.portals.size() - 1);
            } catch (const Error& e) {
                fail(e.what());
            }
        } else {
            fail("expected 'cell' or 'portal', found " + detail::quote_token(w[0], 40));
        }
    }
    if (layout.cells.empty())
        throw Error(path + ": no cell (expected lines 'cell NAME XMIN YMIN ZMIN XMAX YMAX ZMAX')");
    return layout;
}

CellLayout read_cells(const std::string& path)
{
    return parse_cells(path, read_file(path));
}

std::string cells_text(const CellLayout& layout)
{
    std::string out = "# cells and portals (tethash detect --method portals --cells FILE)\n";
    auto numbers = [&](const double lo[3], const double hi[3]) {
        for (int a = 0; a < 6; ++a) {
            out += ' ';
            detail::append_double(out, a < 3 ? lo[a] : hi[a - 3]);
        }
        out += '\n';
    };
    for (const PortalCell& c : layout.cells) {
        out += "cell " + c.name;
        numbers(c.lo, c.hi);
    }
    for (const Portal& p : layout.portals) {
        out += "portal " + layout.cells.at(static_cast<std::size_t>(p.a)).name + " " +
               layout.cells.at(static_cast<std::size_t>(p.b)).name;
        numbers(p.lo, p.hi);
    }
    return out;
}

} // namespace tethash::io
