// The peer in tethash_sim_bench: the same scenes run by Bullet's soft bodies (btSoftRigidDynamicsWorld,
// position-based links on the tet edges, 10 position iterations), built only when libbullet-dev is found.
#pragma once

#include "tethash/mesh.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace tethash::bench {

/// One body of a peer scene: its mesh already placed in the world, its density and initial velocity.
struct PeerBody {
    const TetMesh* mesh = nullptr;
    double density = 1000;
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
};

struct PeerResult {
    std::vector<double> ms;       ///< wall time of each step
    std::vector<double> cpu_ms;   ///< processor time of each step (the process's: one thread, Bullet's step alone)
    std::vector<Positions> final; ///< each body's positions at the end
    std::string failure;          ///< non-empty when a position went non-finite
};

/// Bullet's version as 100 × major + minor.
int bullet_version();

/// Runs the bodies above a ground plane z = 0 for `steps` steps of `dt` with Bullet's soft-body world.
PeerResult run_bullet(const std::vector<PeerBody>& bodies, double dt, int steps, int iterations);

} // namespace tethash::bench
