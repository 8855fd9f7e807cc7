// Cell files (io/cells.hpp): one cell or portal per line, each checked as it is read so that a problem names its line.
#include "tethash/io/cells.hpp"

#include "number.hpp"

#include "tethash/error.hpp"
#include "tethash/io/file.hpp"
#include "tethash/io/surface.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
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
        if (w[0] == "cell" && w.size() >= 3 && w[2] == "planes") {
            // cell NAME planes NX NY NZ D ...: the half-spaces n · x <= d.
            if ((w.size() - 3) % 4 != 0 || w.size() < 3 + 4 * 4)
                fail("expected 'cell NAME planes NX NY NZ D ...' (4 numbers per plane, at least 4 planes), found " +
                     std::to_string(w.size() - 3) + " numbers");
            std::vector<CellPlane> planes((w.size() - 3) / 4);
            for (std::size_t k = 0; k < planes.size(); ++k) {
                for (std::size_t a = 0; a < 3; ++a)
                    planes[k].n[a] = number(w[3 + 4 * k + a], "a plane's normal");
                planes[k].d = number(w[3 + 4 * k + 3], "a plane's offset");
            }
            try {
                layout.cells.push_back(convex_cell(std::string(w[1]), planes));
                check_cell(layout, layout.cells.size() - 1);
            } catch (const Error& e) {
                fail(e.what());
            }
            index.emplace(layout.cells.back().name, static_cast<Index>(layout.cells.size() - 1));
        } else if (w[0] == "cell" && w.size() >= 3 && w[2] == "surface") {
            // cell NAME surface FILE: a closed convex surface, FILE relative to the cell file's folder.
            if (w.size() != 4) fail("expected 'cell NAME surface FILE' (4 fields), found " + std::to_string(w.size()));
            const std::filesystem::path file = std::filesystem::path(path).parent_path() / std::string(w[3]);
            try {
                const SurfaceMesh surface = read_surface(file.string());
                layout.cells.push_back(surface_cell(std::string(w[1]), surface.vertices, surface.triangles));
                check_cell(layout, layout.cells.size() - 1);
            } catch (const Error& e) {
                fail(e.what());
            }
            index.emplace(layout.cells.back().name, static_cast<Index>(layout.cells.size() - 1));
        } else if (w[0] == "cell") {
            if (w.size() != 8)
                fail("expected 'cell NAME XMIN YMIN ZMIN XMAX YMAX ZMAX' (8 fields), 'cell NAME planes ...' or "
                     "'cell NAME surface FILE', found " +
                     std::to_string(w.size()) + " fields");
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
        } else if (w[0] == "portal" && w.size() >= 4 && w[3] == "polygon") {
            // portal A B polygon X Y Z X Y Z X Y Z ...: a convex polygon, its corners in order.
            if ((w.size() - 4) % 3 != 0 || w.size() < 4 + 3 * 3)
                fail("expected 'portal CELL_A CELL_B polygon X Y Z ...' (3 numbers per corner, at least 3 corners), "
                     "found " +
                     std::to_string(w.size() - 4) + " numbers");
            Index ab[2] = {0, 0};
            for (int k = 0; k < 2; ++k) {
                const auto it = index.find(w[1 + static_cast<std::size_t>(k)]);
                if (it == index.end())
                    fail("portal between unknown cell " + detail::quote_token(w[1 + static_cast<std::size_t>(k)], 40) +
                         " (cells are declared above the portals that join them)");
                ab[k] = it->second;
            }
            std::vector<std::array<double, 3>> corners((w.size() - 4) / 3);
            for (std::size_t k = 0; k < corners.size(); ++k)
                for (std::size_t a = 0; a < 3; ++a)
                    corners[k][a] = number(w[4 + 3 * k + a], "a corner's coordinate");
            layout.portals.push_back(polygon_portal(ab[0], ab[1], std::move(corners)));
            try {
                check_portal(layout, layout.portals.size() - 1);
            } catch (const Error& e) {
                fail(e.what());
            }
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
    auto number = [&](double x) {
        out += ' ';
        detail::append_double(out, x);
    };
    for (const PortalCell& c : layout.cells) {
        out += "cell " + c.name;
        if (c.planes.empty()) {
            numbers(c.lo, c.hi);
            continue;
        }
        // A convex cell as its planes, its box's faces among them (it reads back as the same set).
        out += " planes";
        for (int a = 0; a < 3; ++a) {
            const double e[3] = {a == 0 ? 1.0 : 0.0, a == 1 ? 1.0 : 0.0, a == 2 ? 1.0 : 0.0};
            for (double x : {-e[0], -e[1], -e[2], -c.lo[a], e[0], e[1], e[2], c.hi[a]})
                number(x);
        }
        for (const CellPlane& p : c.planes)
            for (double x : {p.n[0], p.n[1], p.n[2], p.d})
                number(x);
        out += '\n';
    }
    for (const Portal& p : layout.portals) {
        out += "portal " + layout.cells.at(static_cast<std::size_t>(p.a)).name + " " +
               layout.cells.at(static_cast<std::size_t>(p.b)).name;
        if (p.polygon.empty()) {
            numbers(p.lo, p.hi);
            continue;
        }
        out += " polygon";
        for (const auto& x : p.polygon)
            for (double v : x)
                number(v);
        out += '\n';
    }
    return out;
}

} // namespace tethash::io
