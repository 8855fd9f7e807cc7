// Cells and portals (portals.hpp): the checks of a layout and the grid layout the method makes for itself.
#include "tethash/portals.hpp"

#include "convex_cells.hpp"

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
    std::vector<std::array<double, 3>> corners;
    if (!c.planes.empty()) {
        if (c.planes.size() > max_cell_planes)
            throw Error(name + ": " + std::to_string(c.planes.size()) + " planes (at most " +
                        std::to_string(max_cell_planes) + ")");
        for (std::size_t p = 0; p < c.planes.size(); ++p)
            if (!finite3(c.planes[p].n) || !std::isfinite(c.planes[p].d) || !(detail::plane_norm(c.planes[p]) > 0))
                throw Error(name + ": plane " + std::to_string(p + 1) + " must be finite, with a non-zero normal");
        // An interior: the corners' centroid strictly inside every half-space.
        corners = cell_corners(c);
        const double eps = 1e-9 * detail::magnitude(c);
        double mid[3] = {0, 0, 0};
        for (const auto& x : corners)
            for (int a = 0; a < 3; ++a)
                mid[a] += x[static_cast<std::size_t>(a)] / static_cast<double>(corners.size());
        bool interior = corners.size() >= 4;
        for (const CellPlane& p : detail::all_planes(c))
            interior = interior && detail::plane_value(p, mid) < -eps * detail::plane_norm(p);
        if (!interior) throw Error(name + ": the planes leave no volume in the box " + box_text(c.lo, c.hi));
    }
    for (std::size_t j = 0; j < k; ++j) {
        const PortalCell& o = layout.cells[j];
        if (o.name == c.name) throw Error(name + ": the name is used twice");
        bool overlap = true;
        for (int a = 0; a < 3; ++a)
            overlap = overlap && c.lo[a] < o.hi[a] && o.lo[a] < c.hi[a];
        if (overlap && (!c.planes.empty() || !o.planes.empty())) {
            // Convex cells: apart when a face plane of one has the other on its far side.
            if (corners.empty()) corners = cell_corners(c);
            const double eps = 1e-9 * std::max(detail::magnitude(c), detail::magnitude(o));
            overlap = !detail::separated(c, corners, o, cell_corners(o), eps);
        }
        if (overlap)
            throw Error(name + " " + box_text(c.lo, c.hi) + " overlaps cell '" + o.name + "' " + box_text(o.lo, o.hi) +
                        " (cells may share faces, not volume; convex cells must lie on either side of a face plane "
                        "of one of them)");
    }
}

namespace {

/// The checks of a polygon portal (portals.hpp: check_portal).
void check_polygon(const PortalCell& a, const PortalCell& b, const std::vector<std::array<double, 3>>& poly,
                   const std::string& name)
{
    if (poly.size() < 3) throw Error(name + ": a polygon needs at least 3 corners, got " + std::to_string(poly.size()));
    double scale = std::max(detail::magnitude(a), detail::magnitude(b));
    for (const auto& x : poly) {
        if (!finite3(x.data())) throw Error(name + ": coordinates must be finite");
        for (double v : x)
            scale = std::max(scale, std::abs(v));
    }
    const double eps = 1e-9 * scale;
    // Newell's normal: twice the area along each axis.
    double n[3] = {0, 0, 0};
    for (std::size_t i = 0; i < poly.size(); ++i) {
        const auto& p = poly[i];
        const auto& q = poly[(i + 1) % poly.size()];
        n[0] += (p[1] - q[1]) * (p[2] + q[2]);
        n[1] += (p[2] - q[2]) * (p[0] + q[0]);
        n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > eps * scale)) throw Error(name + ": the polygon has no area");
    for (std::size_t i = 0; i < poly.size(); ++i) {
        double off = 0;
        for (int k = 0; k < 3; ++k)
            off += n[k] / len * (poly[i][static_cast<std::size_t>(k)] - poly[0][static_cast<std::size_t>(k)]);
        if (std::abs(off) > eps)
            throw Error(name + ": the polygon is not planar (corner " + std::to_string(i + 1) +
                        " is off the plane of the others)");
    }
    // Convex: every turn the same way as the normal.
    for (std::size_t i = 0; i < poly.size(); ++i) {
        const auto& p = poly[i];
        const auto& q = poly[(i + 1) % poly.size()];
        const auto& r = poly[(i + 2) % poly.size()];
        double u[3], v[3];
        for (std::size_t k = 0; k < 3; ++k) {
            u[k] = q[k] - p[k];
            v[k] = r[k] - q[k];
        }
        const double turn = (u[1] * v[2] - u[2] * v[1]) * n[0] + (u[2] * v[0] - u[0] * v[2]) * n[1] +
                            (u[0] * v[1] - u[1] * v[0]) * n[2];
        if (turn < -eps * scale * len)
            throw Error(name + ": the polygon is not convex (at corner " + std::to_string((i + 1) % poly.size() + 1) +
                        ")");
    }
    // On the boundary both cells share: on a face plane of each, and within both.
    for (const PortalCell* c : {&a, &b}) {
        bool on_face = false;
        for (const CellPlane& p : detail::all_planes(*c)) {
            bool all = true;
            for (const auto& x : poly)
                all = all && std::abs(detail::plane_value(p, x.data())) <= eps * detail::plane_norm(p);
            on_face = on_face || all;
        }
        for (std::size_t i = 0; i < poly.size() && on_face; ++i)
            if (!detail::contains_near(*c, poly[i].data(), eps))
                throw Error(name + ": the polygon is not on the shared boundary (corner " + std::to_string(i + 1) +
                            " is outside cell '" + c->name + "')");
        if (!on_face)
            throw Error(name + ": the polygon is not on the shared boundary (not on a face of cell '" + c->name + "')");
    }
}

} // namespace

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
    if (!p.polygon.empty() || !a.planes.empty() || !b.planes.empty()) {
        if (!p.polygon.empty()) {
            check_polygon(a, b, p.polygon, name);
            return;
        }
        // A rectangle touching a convex cell: its four corners as a polygon.
        int flat = -1;
        for (int j = 0; j < 3; ++j)
            if (p.lo[j] == p.hi[j]) flat = j;
        if (flat < 0) throw Error(name + ": the rectangle " + box_text(p.lo, p.hi) + " is not flat on any axis");
        const int u = (flat + 1) % 3, v = (flat + 2) % 3;
        std::vector<std::array<double, 3>> poly(4);
        for (std::size_t k = 0; k < 4; ++k) {
            poly[k][static_cast<std::size_t>(flat)] = p.lo[flat];
            poly[k][static_cast<std::size_t>(u)] = k == 1 || k == 2 ? p.hi[u] : p.lo[u];
            poly[k][static_cast<std::size_t>(v)] = k >= 2 ? p.hi[v] : p.lo[v];
        }
        check_polygon(a, b, poly, name);
        return;
    }
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
