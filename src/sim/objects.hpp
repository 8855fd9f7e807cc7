#pragma once
// Scene objects read or generated, transformed and joined into one mesh (private to tethash::sim).

#include "tethash/detect.hpp"
#include "tethash/sim/model.hpp"
#include "tethash/sim/scene.hpp"

#include <utility>
#include <vector>

namespace tethash::sim {

/// The scene's objects as one mesh (objects in order, object ids set) and what the model and detector need.
struct SceneObjects {
    TetMesh mesh;
    std::vector<std::pair<Index, Index>> vertices, tets; ///< per object: (first, count)
    std::vector<Material> materials;
    std::vector<char> is_static;
    std::vector<ObjectOptions> options;
};

/// Applies the object's scale, rotations and translation to `p` (n × 3), in that order.
void transform_positions(const ObjectSpec& o, Positions& p);

/// Loads or generates every object of `scene` (files read, surfaces tetrahedralized, transforms applied).
/// Throws Error naming the object on a missing file, an empty mesh or a non-finite vertex.
SceneObjects load_objects(const Scene& scene);

/// Marks the pinned vertices of `scene.pins` fixed in `model`; returns warnings (a box that holds no vertex).
std::vector<std::string> apply_pins(const Scene& scene, const SceneObjects& objects, Model& model);

} // namespace tethash::sim
