// Cells and portals (portals.hpp): the checks of a layout and the grid layout the method makes for itself.
#include "tethash/portals.hpp"

#include "tethash/error.hpp"

#include <cmath>
#include <sstream>

namespace tethash {

namespace {

std::string box_text(const double lo[3], const double hi[3])
{
    std::ostringstream s;
    s.precision(17);
    s << "(" << lo[0] << " " << lo[1] << " " << lo[2] << ") .. (" << hi[0] << " " << hi[1] << " " << hi[2] << ")";
    return s.str();
}

bool finite3(const double x[3])
{
    return std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
}

/// The axis of the face cells a and b share (a's hi against b's lo or the other way), -1 when they share none. A
/// shared face has positive area: the cells' ranges on the two other axes overlap with positive length.
int shared_face(const PortalCell& a, const PortalCell& b, double& plane)
{
    for (int k = 0; k < 3; ++k) {
        if (a.hi[k] != b.lo[k] && b.hi[k] != a.lo[k]) continue;
        bool area = true;
        for (int j = 0; j < 3; ++j)
            if (j != k) area = area && std::fmin(a.hi[j], b.hi[j]) > std::fmax(a.lo[j], b.lo[j]);
        if (!area) continue;
        plane = a.hi[k] == b.lo[k] ? a.hi[k] : a.lo[k];
        return k;
    }
    return -1;
}

} // namespace

void check_cell(const CellLayout& layout, std::size_t k)
{
    const PortalCell& c = layout.cells.at(k);
    const std::string name = "cell '" + c.name + "'";
    if (c.name.empty()) throw Error("a cell needs a name");
    if (!finite3(c.lo) || !finite3(c.hi)) throw Error(name + ": coordinates must be finite");
    for (int a = 0; a < 3; ++a)
        if (!(c.lo[a] < c.hi[a]))
            throw Error(name + ": inverted or flat box " + box_text(c.lo, c.hi) +
                        " (expected min < max on every axis)");
    for (std::size_t j = 0; j < k; ++j) {
        const PortalCell& o = layout.cells[j];
        if (o.name == c.name) throw Error(name + ": the name is used twice");
        bool overlap = true;
        for (int a = 0; a < 3; ++a)
            overlap = overlap && c.lo[a] < o.hi[a] && o.lo[a] < c.hi[a];
        if (overlap)
            throw Error(name + " " + box_text(c.lo, c.hi) + " overlaps cell '" + o.name + "' " + box_text(o.lo, o.hi) +
                        " (cells may share faces, not volume)");
    }
}

void check_portal(const CellLayout& layout, std::size_t k)
{
    const Portal& p = layout.portals.at(k);
    const auto n = static_cast<Index>(layout.cells.size());
    if (p.a < 0 || p.a >= n || p.b < 0 || p.b >= n)
        throw Error("portal " + std::to_string(k) + ": unknown cell index (" + std::to_string(p.a) + ", " +
                    std::to_string(p.b) + " of " + std::to_string(n) + " cells)");
    const PortalCell& a = layout.cells[static_cast<std::size_t>(p.a)];
    const PortalCell& b = layout.cells[static_cast<std::size_t>(p.b)];
    const std::string name = "portal '" + a.name + "' - '" + b.name + "'";
    if (p.a == p.b) throw Error(name + ": a portal joins two different cells");
    if (!finite3(p.lo) || !finite3(p.hi)) throw Error(name + ": coordinates must be finite");
    double plane = 0;
    const int axis = shared_face(a, b, plane);
    if (axis < 0) throw Error(name + ": the two cells share no face");
    for (int j = 0; j < 3; ++j)
        if (p.lo[j] > p.hi[j]) throw Error(name + ": inverted rectangle " + box_text(p.lo, p.hi));
    if (p.lo[axis] != plane || p.hi[axis] != plane) {
        std::ostringstream s;
        s.precision(17);
        s << name << ": the rectangle " << box_text(p.lo, p.hi) << " is not on the shared face ("
          << "xyz"[axis] << " = " << plane << ")";
        throw Error(s.str());
    }
    for (int j = 0; j < 3; ++j) {
        if (j == axis) continue;
        const double lo = std::fmax(a.lo[j], b.lo[j]), hi = std::fmin(a.hi[j], b.hi[j]);
        if (p.lo[j] < lo || p.hi[j] > hi) {
            std::ostringstream s;
            s.precision(17);
            s << name << ": the rectangle " << box_text(p.lo, p.hi) << " leaves the shared face ("
              << "xyz"[j] << " from " << lo << " to " << hi << ")";
            throw Error(s.str());
        }
    }
}

void check_cell_layout(const CellLayout& layout)
{
    for (std::size_t k = 0; k < layout.cells.size(); ++k)
        check_cell(layout, k);
    for (std::size_t k = 0; k < layout.portals.size(); ++k)
        check_portal(layout, k);
}

CellLayout grid_cell_layout(const double lo[3], const double hi[3], const int n[3])
{
    for (int a = 0; a < 3; ++a)
        if (n[a] < 1) throw Error("grid_cell_layout: expected at least one cell per axis");
    CellLayout out;
    // Cell borders: the same expression for both cells of a face, so neighbours share it exactly.
    auto border = [&](int a, int i) { return i == n[a] ? hi[a] : lo[a] + (hi[a] - lo[a]) * i / n[a]; };
    auto index = [&](int x, int y, int z) { return static_cast<Index>((x * n[1] + y) * n[2] + z); };
    for (int x = 0; x < n[0]; ++x)
        for (int y = 0; y < n[1]; ++y)
            for (int z = 0; z < n[2]; ++z) {
                PortalCell c;
                c.name = std::to_string(x) + "," + std::to_string(y) + "," + std::to_string(z);
                const int i[3] = {x, y, z};
                for (int a = 0; a < 3; ++a) {
                    c.lo[a] = border(a, i[a]);
                    c.hi[a] = border(a, i[a] + 1);
                }
                out.cells.push_back(c);
            }
    for (int x = 0; x < n[0]; ++x)
        for (int y = 0; y < n[1]; ++y)
            for (int z = 0; z < n[2]; ++z) {
                const int i[3] = {x, y, z};
                for (int a = 0; a < 3; ++a) {
                    if (i[a] + 1 >= n[a]) continue;
                    int j[3] = {x, y, z};
                    ++j[a];
                    Portal p;
                    p.a = index(x, y, z);
                    p.b = index(j[0], j[1], j[2]);
                    const PortalCell& c = out.cells[static_cast<std::size_t>(p.a)];
                    for (int b = 0; b < 3; ++b) {
                        p.lo[b] = c.lo[b];
                        p.hi[b] = c.hi[b];
                    }
                    p.lo[a] = p.hi[a] = c.hi[a];
                    out.portals.push_back(p);
                }
            }
    return out;
}

} // namespace tethash
