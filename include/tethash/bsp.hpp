#pragma once
/// \file bsp.hpp
/// Static polyhedral obstacles as solid-leaf BSP trees: exact closed point-in-polyhedron, penetration depth
/// and direction against the nearest face, and a set of obstacles queried together.
///
/// A tree's inner nodes are the planes of the surface's faces (coplanar triangles of one facing share one
/// plane, given by three original vertices); its leaves are IN or OUT. A point is classified by walking from
/// the root with exact orient3d tests against those original vertices; a point exactly on a plane follows
/// both children, so the test is closed (on a face, edge or corner counts as inside) and decided the same way
/// every time. The tree is built once: candidate planes from the faces, each scored by
/// 4 × (faces it splits) + |faces in front − faces behind|.
#include "tethash/error.hpp"
#include "tethash/mesh.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace tethash {

/// What a built tree looks like.
struct BspStats {
    Index triangles = 0;     ///< input triangles
    Index planes = 0;        ///< distinct face planes (coplanar triangles of one facing merged)
    Index nodes = 0;         ///< inner nodes (planes tested)
    Index leaves_in = 0;     ///< IN leaves
    Index leaves_out = 0;    ///< OUT leaves
    Index depth = 0;         ///< longest root-to-leaf path (inner nodes)
    double mean_depth = 0;   ///< mean root-to-leaf path length over the leaves
    std::int64_t splits = 0; ///< face fragments split by a plane during the build
    std::int64_t bytes = 0;  ///< memory held by the tree, its faces and their triangle tree
    bool flipped = false;    ///< the surface was oriented inwards and was turned outwards
    double build_ms = 0;     ///< wall time of the build (checks included)
};

/// The answer for one point.
struct BspHit {
    bool inside = false;                ///< in the closed polyhedron
    double depth = 0;                   ///< distance to the nearest face (valid when inside), ≥ 0
    Eigen::Vector3d direction{0, 0, 0}; ///< unit, towards the nearest surface point (out of the polyhedron)
    Index face = -1;                    ///< nearest triangle (valid when inside)
};

class BspImpl;

/// A closed polyhedron as a solid-leaf BSP tree.
class Bsp {
  public:
    /// Builds the tree of a closed triangle surface (vertices k × 3, triangles t × 3, 0-based). The surface must
    /// be closed (every edge in exactly two triangles, in opposite directions), without zero-area triangles and
    /// without self-intersections; an inward orientation is turned outwards. Throws Error naming `what` and the
    /// problem (edge, triangles) otherwise.
    Bsp(const PositionsRef& vertices, const Eigen::Ref<const Triangles>& triangles,
        const std::string& what = "surface");
    ~Bsp();
    Bsp(Bsp&&) noexcept;
    Bsp& operator=(Bsp&&) noexcept;
    Bsp(const Bsp&) = delete;
    Bsp& operator=(const Bsp&) = delete;

    /// Closed, exact point-in-polyhedron test (the bounding box first, then the tree); false for a non-finite p.
    bool contains(const Eigen::Vector3d& p) const;
    /// contains() plus, when inside, depth and direction to the nearest face.
    BspHit query(const Eigen::Vector3d& p) const;
    /// Unsigned distance from p to the surface (closest point over all triangles).
    double distance(const Eigen::Vector3d& p) const;

    /// The surface's vertices (as given, k × 3).
    const Positions& vertices() const;
    const Eigen::Vector3d& box_lo() const;
    const Eigen::Vector3d& box_hi() const;
    const BspStats& stats() const;

  private:
    std::unique_ptr<BspImpl> m_impl;
};

/// A vertex inside (or on) an obstacle. Arrays of it are sorted by (vertex, obstacle).
struct ObstacleContact {
    Index vertex = -1;               ///< vertex id in the queried positions
    Index obstacle = -1;             ///< obstacle id in its ObstacleSet
    double depth = 0;                ///< distance to the obstacle's nearest face, ≥ 0
    double direction[3] = {0, 0, 0}; ///< unit, out of the obstacle (the way to push the vertex)
};

/// Many obstacles in one structure: their boxes cull the vertices, then each tree decides.
class ObstacleSet {
  public:
    /// Adds an obstacle; returns its id (0, 1, ...).
    Index add(Bsp bsp);
    Index size() const { return static_cast<Index>(m_obstacles.size()); }
    const Bsp& operator[](Index i) const { return m_obstacles[static_cast<std::size_t>(i)]; }
    /// The vertices of `positions` (n × 3) inside some obstacle, sorted by (vertex, obstacle).
    std::vector<ObstacleContact> query(const PositionsRef& positions) const;

  private:
    std::vector<Bsp> m_obstacles;
};

} // namespace tethash
