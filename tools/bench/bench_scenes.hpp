#pragma once
// The scenes tethash_bench builds besides the Teschner scenarios (study/scenarios.hpp): a lattice of overlapping
// objects of any size (the flatness sweep) and a scene whose objects move rigidly step by step (candidate reuse).
#include "tethash/mesh.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <random>
#include <vector>

namespace tethash::bench {

/// `objects` copies of the scenario-5 object (meshing::generate "blob", resolution 6, as study/scenarios.hpp chooses
/// it) on a k × k × k lattice with centre spacing 0.6 × the object size, randomly rotated: every object overlaps
/// its lattice neighbours as in scenario 5, whatever the count.
TetMesh lattice_scene(int objects, std::uint32_t seed);

/// The objects of a mesh moving rigidly, each by its own small rotation about its centroid and translation per
/// step (random axis and direction per object; the fastest vertex moves about `speed` × mean edge per step), plus
/// a random perturbation of both per step (a quarter of that); the translations reverse every 40 steps, so
/// objects move apart and together again. Deterministic for a seed.
class MovingScene {
  public:
    MovingScene(const TetMesh& m, double mean_edge, double speed, std::uint32_t seed);
    const Positions& positions() const { return m_positions; }
    void step();

  private:
    Eigen::RowVector3d centroid(std::size_t object) const;

    Positions m_positions;
    std::mt19937 m_rng;
    double m_step_length;
    int m_step = 0;
    std::vector<std::vector<Index>> m_members;
    std::vector<Eigen::Vector3d> m_velocity, m_axis;
    std::vector<double> m_omega;
};

} // namespace tethash::bench
