#include "bullet_peer.hpp"

#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <memory>

namespace tethash::bench {

namespace {

/// Processor time of the process (ms).
double process_cpu_ms()
{
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

} // namespace

int bullet_version()
{
    return btGetVersion();
}

PeerResult run_bullet(const std::vector<PeerBody>& bodies, double dt, int steps, int iterations)
{
    btSoftBodyRigidBodyCollisionConfiguration config;
    btCollisionDispatcher dispatcher(&config);
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btSoftRigidDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
    const btVector3 gravity(0, 0, -9.81);
    world.setGravity(gravity);
    btSoftBodyWorldInfo& info = world.getWorldInfo();
    info.m_gravity = gravity;
    info.m_dispatcher = &dispatcher;
    info.m_broadphase = &broadphase;
    info.m_sparsesdf.Initialize();

    btStaticPlaneShape plane(btVector3(0, 0, 1), 0);
    btRigidBody::btRigidBodyConstructionInfo ground_info(0, nullptr, &plane);
    btRigidBody ground(ground_info);
    ground.setFriction(0.5);
    world.addRigidBody(&ground);

    std::vector<std::unique_ptr<btSoftBody>> soft;
    for (const PeerBody& body : bodies) {
        const TetMesh& m = *body.mesh;
        const int n = static_cast<int>(m.num_vertices());
        std::vector<btVector3> x(static_cast<size_t>(n));
        std::vector<btScalar> mass(static_cast<size_t>(n), 0);
        for (int i = 0; i < n; ++i)
            x[static_cast<size_t>(i)] = btVector3(m.positions(i, 0), m.positions(i, 1), m.positions(i, 2));
        // Lumped masses: a quarter of each tet's mass to each corner (the usual choice with Bullet's tets).
        for (Index t = 0; t < m.num_tets(); ++t) {
            const double v =
                std::abs(signed_volume(m.positions, {m.tets(t, 0), m.tets(t, 1), m.tets(t, 2), m.tets(t, 3)}));
            for (int k = 0; k < 4; ++k)
                mass[static_cast<size_t>(m.tets(t, k))] += body.density * v / 4;
        }
        for (btScalar& w : mass)
            if (!(w > 0)) w = 1e-6; // unreferenced vertices: Bullet treats mass 0 as pinned
        auto sb = std::make_unique<btSoftBody>(&info, n, x.data(), mass.data());
        const Edges edges = unique_edges(m.tets);
        for (Index e = 0; e < edges.rows(); ++e)
            sb->appendLink(edges(e, 0), edges(e, 1));
        for (Index t = 0; t < m.num_tets(); ++t)
            sb->appendTetra(m.tets(t, 0), m.tets(t, 1), m.tets(t, 2), m.tets(t, 3));
        const Triangles faces = boundary_faces(m.tets);
        for (Index f = 0; f < faces.rows(); ++f)
            sb->appendFace(faces(f, 0), faces(f, 1), faces(f, 2));
        sb->m_materials[0]->m_kLST = 1;
        sb->m_cfg.piterations = iterations;
        sb->m_cfg.kDF = 0.5; // friction
        sb->m_cfg.collisions = btSoftBody::fCollision::SDF_RS | btSoftBody::fCollision::VF_SS;
        const EdgeStats es = edge_stats(m.positions, m.tets);
        sb->getCollisionShape()->setMargin(static_cast<btScalar>(0.25 * es.mean));
        sb->setVelocity(btVector3(body.velocity.x(), body.velocity.y(), body.velocity.z()));
        world.addSoftBody(sb.get());
        soft.push_back(std::move(sb));
    }

    PeerResult r;
    for (int s = 0; s < steps; ++s) {
        const auto t0 = std::chrono::steady_clock::now();
        const double cpu0 = process_cpu_ms();
        world.stepSimulation(static_cast<btScalar>(dt), 0, static_cast<btScalar>(dt));
        r.cpu_ms.push_back(process_cpu_ms() - cpu0);
        r.ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        bool finite = true;
        for (const auto& sb : soft)
            for (int i = 0; i < sb->m_nodes.size() && finite; ++i)
                finite = std::isfinite(sb->m_nodes[i].m_x.x()) && std::isfinite(sb->m_nodes[i].m_x.z());
        if (!finite) {
            r.failure = "non-finite position at step " + std::to_string(s + 1);
            break;
        }
    }
    for (const auto& sb : soft) {
        Positions p(sb->m_nodes.size(), 3);
        for (int i = 0; i < sb->m_nodes.size(); ++i)
            for (int k = 0; k < 3; ++k)
                p(i, k) = sb->m_nodes[i].m_x[k];
        r.final.push_back(std::move(p));
    }
    for (const auto& sb : soft)
        world.removeSoftBody(sb.get());
    world.removeRigidBody(&ground);
    return r;
}

} // namespace tethash::bench
