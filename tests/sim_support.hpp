#pragma once
// Helpers shared by the simulator tests: scene objects built from the generator.
#include "tethash/meshing/generate.hpp"
#include "tethash/sim/scene.hpp"

#include <Eigen/Core>

namespace tethash::test {

/// A generated box of the given size (m) at `at`, `res` cells along its longest side, soft (density 100,
/// Young 1e4, damping 0.01), without self-collision.
inline sim::ObjectSpec box_object(const Eigen::Vector3d& size, const Eigen::Vector3d& at, int res = 2)
{
    sim::ObjectSpec o;
    meshing::GenerateParams g;
    g.shape = "box";
    g.resolution = res;
    g.size = size;
    o.generate = g;
    o.translate = at;
    o.material.density = 100;
    o.material.young = 1e4;
    o.material.damping = 0.01;
    o.self_collision = false;
    return o;
}

/// A generated cube of side `size` (m); see the box above.
inline sim::ObjectSpec box_object(double size, const Eigen::Vector3d& at, int res = 2)
{
    return box_object(Eigen::Vector3d::Constant(size), at, res);
}

} // namespace tethash::test
