// Detection on subdomains: regions by recursive coordinate bisection, the local mesh of a subdomain (owned plus
// ghost layer) and the ownership filter of its contacts. See subdomain.hpp for the rules and why they are exact.
#include "tethash/subdomain.hpp"

#include "tethash/error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

namespace tethash {

double max_tet_extent(const PositionsRef& positions, const TetsRef& tets)
{
    double extent = 0;
    for (Eigen::Index t = 0; t < tets.rows(); ++t) {
        Eigen::Vector3d lo = positions.row(tets(t, 0)).transpose(), hi = lo;
        for (int k = 1; k < 4; ++k) {
            const Eigen::Vector3d p = positions.row(tets(t, k)).transpose();
            lo = lo.cwiseMin(p);
            hi = hi.cwiseMax(p);
        }
        extent = std::max(extent, (hi - lo).maxCoeff());
    }
    return extent;
}

double ghost_width(const PositionsRef& positions, const TetsRef& tets, double skin)
{
    if (!(skin >= 0) || !std::isfinite(skin))
        throw Error("ghost_width: skin must be a finite length >= 0, found " + std::to_string(skin));
    return max_tet_extent(positions, tets) + skin;
}

bool Region::contains(const Eigen::Vector3d& p) const
{
    return (lo.array() <= p.array()).all() && (p.array() < hi.array()).all();
}

double Region::distance(const Eigen::Vector3d& p) const
{
    double d = 0;
    for (int a = 0; a < 3; ++a)
        d = std::max({d, lo[a] - p[a], p[a] - hi[a]});
    return d;
}

namespace {

void bisect(const PositionsRef& points, std::vector<Index>& ids, std::size_t first, std::size_t last, int parts,
            Region region, std::vector<Region>& out)
{
    if (parts == 1) {
        out.push_back(region);
        return;
    }
    const int left_parts = parts / 2;
    int axis = 0;
    double cut = 0;
    if (last > first) {
        Eigen::Vector3d lo = points.row(ids[first]).transpose(), hi = lo;
        for (std::size_t i = first + 1; i < last; ++i) {
            lo = lo.cwiseMin(points.row(ids[i]).transpose());
            hi = hi.cwiseMax(points.row(ids[i]).transpose());
        }
        (hi - lo).maxCoeff(&axis);
        // The point at the proportional rank along the axis; points on the cut go right (lo <= x < hi).
        const std::size_t k =
            first + (last - first) * static_cast<std::size_t>(left_parts) / static_cast<std::size_t>(parts);
        const auto coord = [&](Index i) { return points(i, axis); };
        std::nth_element(ids.begin() + static_cast<std::ptrdiff_t>(first), ids.begin() + static_cast<std::ptrdiff_t>(k),
                         ids.begin() + static_cast<std::ptrdiff_t>(last),
                         [&](Index a, Index b) { return coord(a) < coord(b); });
        cut = k < last ? coord(ids[k]) : hi[axis];
    } else {
        // No points left: split the region's finite middle, or at 0.
        const double a = region.lo[axis], b = region.hi[axis];
        cut = std::isfinite(a) && std::isfinite(b) ? 0.5 * (a + b) : std::isfinite(a) ? a : std::isfinite(b) ? b : 0;
    }
    const auto mid =
        std::partition(ids.begin() + static_cast<std::ptrdiff_t>(first),
                       ids.begin() + static_cast<std::ptrdiff_t>(last), [&](Index i) { return points(i, axis) < cut; });
    const auto split = static_cast<std::size_t>(mid - ids.begin());
    Region left = region, right = region;
    left.hi[axis] = cut;
    right.lo[axis] = cut;
    bisect(points, ids, first, split, left_parts, left, out);
    bisect(points, ids, split, last, parts - left_parts, right, out);
}

} // namespace

std::vector<Region> bisect_regions(const PositionsRef& points, int parts)
{
    if (parts < 1) throw Error("bisect_regions: parts must be >= 1, found " + std::to_string(parts));
    for (Eigen::Index i = 0; i < points.rows(); ++i)
        if (!points.row(i).allFinite()) throw Error("bisect_regions: point " + std::to_string(i) + " is not finite");
    std::vector<Index> ids(static_cast<std::size_t>(points.rows()));
    std::iota(ids.begin(), ids.end(), 0);
    const double inf = std::numeric_limits<double>::infinity();
    Region all{Eigen::Vector3d::Constant(-inf), Eigen::Vector3d::Constant(inf)};
    std::vector<Region> out;
    out.reserve(static_cast<std::size_t>(parts));
    bisect(points, ids, 0, ids.size(), parts, all, out);
    return out;
}

int region_of(const std::vector<Region>& regions, const Eigen::Vector3d& p)
{
    for (std::size_t r = 0; r < regions.size(); ++r)
        if (regions[r].contains(p)) return static_cast<int>(r);
    throw Error("region_of: no region holds the point (" + std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " +
                std::to_string(p.z()) + ")");
}

Positions tet_centroids(const PositionsRef& positions, const TetsRef& tets)
{
    Positions c(tets.rows(), 3);
    for (Eigen::Index t = 0; t < tets.rows(); ++t)
        c.row(t) = 0.25 * (positions.row(tets(t, 0)) + positions.row(tets(t, 1)) + positions.row(tets(t, 2)) +
                           positions.row(tets(t, 3)));
    return c;
}

Positions Subdomain::gather(const PositionsRef& global_positions) const
{
    Positions p(static_cast<Eigen::Index>(vertices.size()), 3);
    for (std::size_t i = 0; i < vertices.size(); ++i)
        p.row(static_cast<Eigen::Index>(i)) = global_positions.row(vertices[i]);
    return p;
}

Subdomain make_subdomain(const PositionsRef& positions, const TetsRef& tets, std::span<const int> vertex_part,
                         std::span<const int> tet_part, int part, const Region& region, double width,
                         ContactOwner owner, std::span<const Index> vertex_object, std::span<const Index> tet_object)
{
    const auto n = static_cast<std::size_t>(positions.rows());
    const auto m = static_cast<std::size_t>(tets.rows());
    if (vertex_part.size() != n || tet_part.size() != m)
        throw Error("make_subdomain: vertex_part/tet_part must have one entry per vertex (" + std::to_string(n) +
                    ") / tet (" + std::to_string(m) + ")");
    if ((!vertex_object.empty() && vertex_object.size() != n) || (!tet_object.empty() && tet_object.size() != m))
        throw Error("make_subdomain: vertex_object/tet_object must be empty or have one id per vertex / tet");
    if (!(width >= 0)) throw Error("make_subdomain: width must be >= 0");
    std::vector<std::uint8_t> local_vertex(n, 0), local_tet(m, 0);
    for (std::size_t v = 0; v < n; ++v)
        if (vertex_part[v] == part) local_vertex[v] = 1;
    for (std::size_t t = 0; t < m; ++t)
        if (tet_part[t] == part) local_tet[t] = 1;
    if (owner == ContactOwner::tet) {
        for (std::size_t v = 0; v < n; ++v)
            if (!local_vertex[v] && region.distance(positions.row(static_cast<Eigen::Index>(v)).transpose()) <= width)
                local_vertex[v] = 1;
    } else {
        const Positions c = tet_centroids(positions, tets);
        for (std::size_t t = 0; t < m; ++t)
            if (!local_tet[t] && region.distance(c.row(static_cast<Eigen::Index>(t)).transpose()) <= width)
                local_tet[t] = 1;
    }
    for (std::size_t t = 0; t < m; ++t) // corners of local tets
        if (local_tet[t])
            for (int k = 0; k < 4; ++k)
                local_vertex[static_cast<std::size_t>(tets(static_cast<Eigen::Index>(t), k))] = 1;

    Subdomain s;
    std::vector<Index> local_id(n, -1);
    for (std::size_t v = 0; v < n; ++v)
        if (local_vertex[v]) {
            local_id[v] = static_cast<Index>(s.vertices.size());
            s.vertices.push_back(static_cast<Index>(v));
            s.vertex_owned.push_back(vertex_part[v] == part ? 1 : 0);
            if (!vertex_object.empty()) s.vertex_object.push_back(vertex_object[v]);
        }
    for (std::size_t t = 0; t < m; ++t)
        if (local_tet[t]) {
            s.tets.push_back(static_cast<Index>(t));
            s.tet_owned.push_back(tet_part[t] == part ? 1 : 0);
            if (!tet_object.empty()) s.tet_object.push_back(tet_object[t]);
        }
    s.local_tets.resize(static_cast<Eigen::Index>(s.tets.size()), 4);
    for (std::size_t i = 0; i < s.tets.size(); ++i)
        for (int k = 0; k < 4; ++k)
            s.local_tets(static_cast<Eigen::Index>(i), k) = local_id[static_cast<std::size_t>(tets(s.tets[i], k))];
    return s;
}

void owned_contacts(std::span<const Contact> local, std::span<const std::uint8_t> vertex_owned,
                    std::span<const std::uint8_t> tet_owned, std::span<const Index> vertex_global,
                    std::span<const Index> tet_global, ContactOwner owner, std::vector<Contact>& out)
{
    if (vertex_owned.size() != vertex_global.size() || tet_owned.size() != tet_global.size())
        throw Error("owned_contacts: the ownership masks and the global id maps differ in size (vertices " +
                    std::to_string(vertex_owned.size()) + " vs " + std::to_string(vertex_global.size()) + ", tets " +
                    std::to_string(tet_owned.size()) + " vs " + std::to_string(tet_global.size()) + ")");
    out.clear();
    for (const Contact& c : local) {
        const auto v = static_cast<std::size_t>(c.vertex), t = static_cast<std::size_t>(c.tet);
        if (c.vertex < 0 || v >= vertex_owned.size() || c.tet < 0 || t >= tet_owned.size())
            throw Error("owned_contacts: contact (vertex " + std::to_string(c.vertex) + ", tet " +
                        std::to_string(c.tet) + ") outside the local mesh (" + std::to_string(vertex_owned.size()) +
                        " vertices, " + std::to_string(tet_owned.size()) + " tets)");
        if (!(owner == ContactOwner::tet ? tet_owned[t] : vertex_owned[v])) continue;
        Contact g = c;
        g.vertex = vertex_global[v];
        g.tet = tet_global[t];
        out.push_back(g);
    }
    const auto less = [](const Contact& a, const Contact& b) {
        return a.vertex != b.vertex ? a.vertex < b.vertex : a.tet < b.tet;
    };
    // Ascending global id maps keep the detector's (vertex, tet) order; any other map needs the sort.
    if (!std::is_sorted(out.begin(), out.end(), less)) std::sort(out.begin(), out.end(), less);
}

const std::vector<Contact>& detect_owned(Detector& detector, const PositionsRef& local_positions, const Subdomain& sub,
                                         ContactOwner owner, std::vector<Contact>& out, DetectStats* stats)
{
    const std::vector<Contact>& local = detector.detect(local_positions, stats);
    owned_contacts(local, sub.vertex_owned, sub.tet_owned, sub.vertices, sub.tets, owner, out);
    return out;
}

} // namespace tethash
