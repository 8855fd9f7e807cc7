// Convex cells and polygon portals (portals.hpp): cells of planes and of closed convex surfaces, their corners, the
// separation of two cells and the checks of a polygon portal. Every test here has a tolerance of 1e-9 of the
// coordinates' magnitude: they only judge a description; the method itself is exact whatever the cells.
#include "convex_cells.hpp"

#include "tethash/bsp.hpp"
#include "tethash/error.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace tethash::detail {

namespace {

using Vec3 = Eigen::Vector3d;

Vec3 vec(const double* x)
{
    return {x[0], x[1], x[2]};
}

} // namespace

std::vector<CellPlane> all_planes(const PortalCell& c)
{
    std::vector<CellPlane> out;
    for (int a = 0; a < 3; ++a) {
        CellPlane lo, hi;
        lo.n[a] = -1;
        lo.d = -c.lo[a];
        hi.n[a] = 1;
        hi.d = c.hi[a];
        out.push_back(lo);
        out.push_back(hi);
    }
    out.insert(out.end(), c.planes.begin(), c.planes.end());
    return out;
}

double plane_norm(const CellPlane& p)
{
    return std::sqrt(p.n[0] * p.n[0] + p.n[1] * p.n[1] + p.n[2] * p.n[2]);
}

double plane_value(const CellPlane& p, const double* x)
{
    return p.n[0] * x[0] + p.n[1] * x[1] + p.n[2] * x[2] - p.d;
}

std::vector<std::array<double, 3>> polytope_corners(const std::vector<CellPlane>& planes, double eps)
{
    std::vector<std::array<double, 3>> out;
    const std::size_t m = planes.size();
    for (std::size_t i = 0; i < m; ++i)
        for (std::size_t j = i + 1; j < m; ++j)
            for (std::size_t k = j + 1; k < m; ++k) {
                Eigen::Matrix3d A;
                A << vec(planes[i].n).transpose(), vec(planes[j].n).transpose(), vec(planes[k].n).transpose();
                const double det = A.determinant();
                if (!(std::abs(det) > 1e-12 * plane_norm(planes[i]) * plane_norm(planes[j]) * plane_norm(planes[k])))
                    continue;
                const Vec3 x = A.partialPivLu().solve(Vec3(planes[i].d, planes[j].d, planes[k].d));
                if (!x.allFinite()) continue;
                bool inside = true;
                for (const CellPlane& p : planes)
                    inside = inside && plane_value(p, x.data()) <= eps * plane_norm(p);
                if (inside) out.push_back({x.x(), x.y(), x.z()});
            }
    return out;
}

double magnitude(const PortalCell& c)
{
    double m = 0;
    for (int a = 0; a < 3; ++a)
        m = std::max({m, std::abs(c.lo[a]), std::abs(c.hi[a]), c.hi[a] - c.lo[a]});
    return m;
}

bool contains_near(const PortalCell& c, const double* x, double eps)
{
    for (const CellPlane& p : all_planes(c))
        if (plane_value(p, x) > eps * plane_norm(p)) return false;
    return true;
}

bool separated(const PortalCell& a, const std::vector<std::array<double, 3>>& a_corners, const PortalCell& b,
               const std::vector<std::array<double, 3>>& b_corners, double eps)
{
    // b beyond a plane of a (all of b's corners on or outside it), or the other way.
    const auto beyond = [eps](const PortalCell& c, const std::vector<std::array<double, 3>>& other) {
        for (const CellPlane& p : all_planes(c)) {
            bool all = true;
            for (const auto& x : other)
                all = all && plane_value(p, x.data()) >= -eps * plane_norm(p);
            if (all) return true;
        }
        return false;
    };
    return beyond(a, b_corners) || beyond(b, a_corners);
}

} // namespace tethash::detail

namespace tethash {

using detail::plane_norm;
using detail::plane_value;

PortalCell convex_cell(const std::string& name, const std::vector<CellPlane>& planes)
{
    const std::string what = "cell '" + name + "'";
    if (planes.size() < 4)
        throw Error(what + ": a bounded cell needs at least 4 planes, got " + std::to_string(planes.size()));
    double scale = 0;
    for (std::size_t k = 0; k < planes.size(); ++k) {
        const CellPlane& p = planes[k];
        if (!std::isfinite(p.n[0]) || !std::isfinite(p.n[1]) || !std::isfinite(p.n[2]) || !std::isfinite(p.d))
            throw Error(what + ": plane " + std::to_string(k + 1) + " must be finite");
        const double n = plane_norm(p);
        if (!(n > 0)) throw Error(what + ": plane " + std::to_string(k + 1) + " has a zero normal");
        scale = std::max(scale, std::abs(p.d) / n);
    }
    // Within a box far larger than the planes' offsets: a corner on it means the cell is unbounded.
    const double far = 1e6 * (scale + 1);
    PortalCell big;
    for (int a = 0; a < 3; ++a) {
        big.lo[a] = -far;
        big.hi[a] = far;
    }
    big.planes = planes;
    const double eps = 1e-9 * (scale + 1);
    const std::vector<std::array<double, 3>> corners = detail::polytope_corners(detail::all_planes(big), eps);
    if (corners.empty()) throw Error(what + ": the half-spaces have no point in common");
    PortalCell c;
    c.name = name;
    c.planes = planes;
    for (int a = 0; a < 3; ++a) {
        c.lo[a] = corners[0][static_cast<std::size_t>(a)];
        c.hi[a] = c.lo[a];
    }
    for (const auto& x : corners)
        for (int a = 0; a < 3; ++a) {
            if (std::abs(x[static_cast<std::size_t>(a)]) >= 0.5 * far)
                throw Error(what + ": unbounded (the planes do not close it)");
            c.lo[a] = std::min(c.lo[a], x[static_cast<std::size_t>(a)]);
            c.hi[a] = std::max(c.hi[a], x[static_cast<std::size_t>(a)]);
        }
    return c;
}

PortalCell surface_cell(const std::string& name, const PositionsRef& vertices,
                        const Eigen::Ref<const Triangles>& triangles)
{
    const std::string what = "cell '" + name + "'";
    const Bsp closed(vertices, triangles, what); // closed, not self-intersecting, no zero-area triangle
    double volume = 0;
    for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
        const Eigen::Vector3d a = vertices.row(triangles(t, 0)).transpose(),
                              b = vertices.row(triangles(t, 1)).transpose(),
                              c = vertices.row(triangles(t, 2)).transpose();
        volume += a.dot(b.cross(c));
    }
    const double sign = volume < 0 ? -1 : 1;
    PortalCell cell;
    cell.name = name;
    double scale = 0;
    for (Eigen::Index v = 0; v < vertices.rows(); ++v)
        for (int a = 0; a < 3; ++a) {
            cell.lo[a] = v == 0 ? vertices(v, a) : std::min(cell.lo[a], vertices(v, a));
            cell.hi[a] = v == 0 ? vertices(v, a) : std::max(cell.hi[a], vertices(v, a));
            scale = std::max(scale, std::abs(vertices(v, a)));
        }
    for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
        const Eigen::Vector3d a = vertices.row(triangles(t, 0)).transpose(),
                              b = vertices.row(triangles(t, 1)).transpose(),
                              c = vertices.row(triangles(t, 2)).transpose();
        const Eigen::Vector3d n = sign * (b - a).cross(c - a);
        CellPlane p;
        for (int k = 0; k < 3; ++k)
            p.n[k] = n[k];
        p.d = n.dot(a);
        for (Eigen::Index v = 0; v < vertices.rows(); ++v)
            if (plane_value(p, vertices.row(v).data()) > 1e-9 * (scale + 1) * plane_norm(p))
                throw Error(what + ": the surface is not convex (vertex " + std::to_string(v) +
                            " lies beyond the plane of triangle " + std::to_string(t) + ")");
        // Coplanar triangles (of one facing) give one plane.
        const double len = plane_norm(p);
        const bool known = std::any_of(cell.planes.begin(), cell.planes.end(), [&](const CellPlane& q) {
            const double lq = plane_norm(q);
            double dn = 0;
            for (int k = 0; k < 3; ++k)
                dn = std::max(dn, std::abs(p.n[k] / len - q.n[k] / lq));
            return dn <= 1e-12 && std::abs(p.d / len - q.d / lq) <= 1e-9 * (scale + 1);
        });
        if (!known) cell.planes.push_back(p);
    }
    if (cell.planes.size() > max_cell_planes)
        throw Error(what + ": " + std::to_string(cell.planes.size()) + " face planes (a convex cell has at most " +
                    std::to_string(max_cell_planes) + ")");
    return cell;
}

Portal polygon_portal(Index a, Index b, std::vector<std::array<double, 3>> corners)
{
    Portal p;
    p.a = a;
    p.b = b;
    for (std::size_t k = 0; k < corners.size(); ++k)
        for (std::size_t i = 0; i < 3; ++i) {
            p.lo[i] = k == 0 ? corners[k][i] : std::min(p.lo[i], corners[k][i]);
            p.hi[i] = k == 0 ? corners[k][i] : std::max(p.hi[i], corners[k][i]);
        }
    p.polygon = std::move(corners);
    return p;
}

std::vector<std::array<double, 3>> cell_corners(const PortalCell& cell)
{
    return detail::polytope_corners(detail::all_planes(cell), 1e-9 * (detail::magnitude(cell) + 1e-300));
}

} // namespace tethash
