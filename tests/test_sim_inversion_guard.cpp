// The vbd integrator's turning back of inverted tets on whole states (src/sim/inversion_guard.hpp): after a step,
// small moves that give inverted tets their orientation back without inverting others, fixed vertices left alone.
#include "../src/sim/inversion_guard.hpp"

#include "tethash/meshing/generate.hpp"
#include "tethash/sim/model.hpp"

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

using namespace tethash;
using namespace tethash::sim;

namespace {

struct BoxState {
    TetMesh mesh;
    Model model;
    std::vector<double> x; ///< stride 4
};

BoxState box()
{
    meshing::GenerateParams g;
    g.shape = "box";
    g.resolution = 3;
    g.size = Eigen::Vector3d::Constant(1.0);
    BoxState s;
    s.mesh = meshing::generate(g);
    s.model = Model::build(s.mesh, {Material{}}, {0});
    s.x.assign(4 * static_cast<size_t>(s.mesh.num_vertices()), 0.0);
    for (Index i = 0; i < s.mesh.num_vertices(); ++i)
        for (int r = 0; r < 3; ++r)
            s.x[4 * static_cast<size_t>(i) + static_cast<size_t>(r)] = s.mesh.positions(i, r);
    return s;
}

double w(const Model& m, const std::vector<double>& x, Index t)
{
    auto p = [&](int k) {
        const size_t v = static_cast<size_t>(m.volumes.tets(t, k));
        return Eigen::Vector3d(x[4 * v], x[4 * v + 1], x[4 * v + 2]);
    };
    return (p(1) - p(0)).dot((p(2) - p(0)).cross(p(3) - p(0)));
}

/// The tets inverted in x, by row (what Simulation hands the integrator after a step).
std::vector<std::int32_t> inverted_tets(const Model& m, const std::vector<double>& x)
{
    std::vector<std::int32_t> out;
    for (Index t = 0; t < m.volumes.tets.rows(); ++t)
        if (!(w(m, x, t) > 0)) out.push_back(static_cast<std::int32_t>(t));
    return out;
}

/// Moves corner 0 of tet t through its opposite face, to W = −depth · W0.
void push_through(const Model& m, std::vector<double>& x, Index t, double depth)
{
    auto p = [&](int k) {
        const size_t v = static_cast<size_t>(m.volumes.tets(t, k));
        return Eigen::Vector3d(x[4 * v], x[4 * v + 1], x[4 * v + 2]);
    };
    const Eigen::Vector3d g = -((p(2) - p(1)).cross(p(3) - p(1))); // ∇W at corner 0
    const double w0 = 6 * m.volumes.rest[static_cast<size_t>(t)];
    const Eigen::Vector3d d = (-depth * w0 - w(m, x, t)) / g.squaredNorm() * g;
    const size_t v = static_cast<size_t>(m.volumes.tets(t, 0));
    for (int r = 0; r < 3; ++r)
        x[4 * v + static_cast<size_t>(r)] += d[r];
}

} // namespace

TEST(SimInversionGuard, RestoreAfterStepTurnsBackWithoutInvertingOthers)
{
    BoxState s = box();
    const Model& m = s.model;
    ASSERT_TRUE(inverted_tets(m, s.x).empty());
    const Index t = m.volumes.tets.rows() / 2;
    push_through(m, s.x, t, 0.05); // a shallow inversion: a few small moves undo it
    const std::vector<std::int32_t> before = inverted_tets(m, s.x);
    ASSERT_FALSE(before.empty());
    const std::vector<double> pushed = s.x;
    InversionGuard guard(m);
    guard.restore_after_step(s.x.data(), before);
    EXPECT_TRUE(inverted_tets(m, s.x).empty());
    // A shallow inversion takes one short move per corner: none longer than restore_move_edges × the mean edge
    // (without that bound the corner would go to a tenth of its rest volume at once, 0.12 of an edge).
    const double longest = InversionGuard::restore_move_edges * m.object_mean_edge[0];
    bool moved = false;
    for (size_t i = 0; i < pushed.size(); i += 4) {
        const double d = std::hypot(s.x[i] - pushed[i], s.x[i + 1] - pushed[i + 1], s.x[i + 2] - pushed[i + 2]);
        EXPECT_LE(d, longest * (1 + 1e-12));
        moved = moved || d > 0;
    }
    EXPECT_TRUE(moved);
}

TEST(SimInversionGuard, RestoreAfterStepLeavesFixedVerticesAlone)
{
    BoxState s = box();
    const Index t = s.model.volumes.tets.rows() / 2;
    // A deep inversion (the corner twice the tet's height through), the pushed corner fixed: the others move.
    push_through(s.model, s.x, t, 2.0);
    const std::vector<double> pushed = s.x;
    const size_t corner = static_cast<size_t>(s.model.volumes.tets(t, 0));
    s.model.fixed[corner] = 1;
    InversionGuard guard(s.model);
    const std::vector<std::int32_t> before = inverted_tets(s.model, s.x);
    ASSERT_FALSE(before.empty());
    guard.restore_after_step(s.x.data(), before);
    EXPECT_GT(w(s.model, s.x, t), w(s.model, pushed, t)); // on its way back (small moves: not all the way)
    for (int r = 0; r < 3; ++r)
        EXPECT_EQ(s.x[4 * corner + static_cast<size_t>(r)], pushed[4 * corner + static_cast<size_t>(r)]);
    // Nothing that was the right way out before the moves is inverted after them.
    for (Index u = 0; u < s.model.volumes.tets.rows(); ++u)
        if (w(s.model, pushed, u) > 0) {
            EXPECT_GT(w(s.model, s.x, u), 0) << "tet " << u;
        }
}
