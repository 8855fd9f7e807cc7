#pragma once
// Static polyhedral obstacles of a scene (objects with collider = "bsp"), private to tethash::sim: their closed
// surfaces kept as solid-leaf BSP trees (bsp.hpp), not tetrahedralized, and their contacts in the form the
// contact response uses (a contact with tet −1, the vertex alone in its stencil).

#include "tethash/bsp.hpp"
#include "tethash/detect.hpp"
#include "tethash/meshing/surface_mesh.hpp"
#include "tethash/sim/scene.hpp"

#include <string>
#include <vector>

namespace tethash::sim {

struct SceneObstacles {
    ObstacleSet set;
    std::vector<std::string> names;
    std::vector<meshing::SurfaceMesh> surfaces; ///< each obstacle's surface, transformed (for the output frames)
    Index first_object = 0; ///< obstacle k is object first_object + k in the contacts (after the tet objects)

    Index size() const { return set.size(); }
    /// Adds a contact for each vertex of `x` not `fixed` that lies in or on an obstacle: tet −1, tet_object
    /// first_object + k, zero barycentric coordinates, depth and direction against the nearest face. `contacts`
    /// stays sorted by (vertex, tet).
    void add_contacts(const Positions& x, const std::vector<char>& fixed, const std::vector<Index>& vertex_object,
                      std::vector<Contact>& contacts) const;
    /// Exact distance of an obstacle contact's vertex to its obstacle's surface.
    double exact_depth(const Positions& x, const Contact& c) const;
};

/// Takes the collider = "bsp" objects out of `scene` (their surfaces read, transformed like any object, built
/// into trees) and renumbers the pins of the objects after them. Throws Error naming the object for a surface
/// that is open or self-intersecting, and for a pin of an obstacle.
SceneObstacles take_obstacles(Scene& scene);

} // namespace tethash::sim
