#pragma once
// Helpers shared by the simulator tests: scene objects built from the generator, and a bar of one cube.
#include "support.hpp"

#include "tethash/meshing/generate.hpp"
#include "tethash/sim/scene.hpp"

#include <Eigen/Core>

#include <array>
#include <vector>

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

/// A bar: one cube of six tets (vertices at its corners only), `size`, centred at `at`; the test box's material and
/// options above, with this mesh in place of the generated one.
inline sim::ObjectSpec bar_object(const Eigen::Vector3d& size, const Eigen::Vector3d& at)
{
    std::vector<Eigen::Vector3d> x;
    for (int k = 0; k <= 1; ++k)
        for (int j = 0; j <= 1; ++j)
            for (int i = 0; i <= 1; ++i)
                x.emplace_back(i - 0.5, j - 0.5, k - 0.5);
    const auto id = [](int i, int j, int k) { return static_cast<Index>(i + 2 * (j + 2 * k)); };
    const auto tets = kuhn_tets(0, 0, 0, id);
    sim::ObjectSpec o = box_object(1.0, at);
    o.generate.reset();
    TetMesh m;
    m.positions = matrix_of<Positions>(x);
    m.tets = matrix_of<Tets>(std::vector<std::array<Index, 4>>(tets.begin(), tets.end()));
    o.data = m;
    o.scale = size;
    return o;
}

/// A bar along y (0.05 thick) with its centre `height` above a static bar along x as thin (both one cube, 1 long), no
/// gravity, dt 1/100, no output: at height 0.03 the two cross edge through face with no vertex of either inside the
/// other (their vertices are at their far ends).
inline sim::Scene crossed_bars_scene(double height)
{
    sim::Scene s;
    sim::ObjectSpec lower = bar_object({1.0, 0.05, 0.05}, {0, 0, 0});
    lower.is_static = true;
    s.objects.push_back(lower);
    s.objects.push_back(bar_object({0.05, 1.0, 0.05}, {0, 0, height}));
    s.gravity.setZero();
    s.dt = 1.0 / 100;
    s.output.every = 0;
    return s;
}

} // namespace tethash::test
