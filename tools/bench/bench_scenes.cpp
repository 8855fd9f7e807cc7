// The scenes of tethash_bench (bench_scenes.hpp).
#include "bench_scenes.hpp"

#include "tethash/meshing/generate.hpp"

#include <Eigen/Geometry>

#include <algorithm>

namespace tethash::bench {

TetMesh lattice_scene(int objects, std::uint32_t seed)
{
    meshing::GenerateParams g;
    g.shape = "blob";
    g.resolution = 6;
    TetMesh obj = meshing::generate(g);
    obj.vertex_object.clear();
    obj.tet_object.clear();
    obj.rest_positions.resize(0, 3);
    const Eigen::RowVector3d lo = obj.positions.colwise().minCoeff(), hi = obj.positions.colwise().maxCoeff();
    const double size = (hi - lo).maxCoeff();
    for (Eigen::Index v = 0; v < obj.positions.rows(); ++v)
        obj.positions.row(v) -= 0.5 * (lo + hi);
    int k = 1;
    while (k * k * k < objects)
        ++k;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    Positions p(static_cast<Eigen::Index>(objects) * obj.positions.rows(), 3);
    Tets t(static_cast<Eigen::Index>(objects) * obj.tets.rows(), 4);
    TetMesh scene;
    for (int o = 0; o < objects; ++o) {
        const Eigen::Matrix3d rot =
            Eigen::AngleAxisd(3.14159 * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized())
                .toRotationMatrix();
        const Eigen::RowVector3d c(0.6 * size * (o % k), 0.6 * size * ((o / k) % k), 0.6 * size * (o / (k * k)));
        const Eigen::Index vb = o * obj.positions.rows(), tb = o * obj.tets.rows();
        for (Eigen::Index v = 0; v < obj.positions.rows(); ++v)
            p.row(vb + v) = (rot * obj.positions.row(v).transpose()).transpose() + c;
        t.middleRows(tb, obj.tets.rows()) = (obj.tets.array() + static_cast<Index>(vb)).matrix();
        scene.vertex_object.insert(scene.vertex_object.end(), obj.positions.rows(), o);
        scene.tet_object.insert(scene.tet_object.end(), obj.tets.rows(), o);
    }
    scene.positions = std::move(p);
    scene.tets = std::move(t);
    return scene;
}

MovingScene::MovingScene(const TetMesh& m, double mean_edge, double speed, std::uint32_t seed)
    : m_positions(m.positions), m_rng(seed), m_step_length(speed * mean_edge)
{
    const int objects = m.num_objects();
    m_members.assign(static_cast<std::size_t>(objects), {});
    for (Eigen::Index v = 0; v < m.positions.rows(); ++v)
        m_members[static_cast<std::size_t>(m.vertex_object[static_cast<std::size_t>(v)])].push_back(
            static_cast<Index>(v));
    std::normal_distribution<double> g;
    for (int o = 0; o < objects; ++o) {
        Eigen::Vector3d dir(g(m_rng), g(m_rng), g(m_rng)), axis(g(m_rng), g(m_rng), g(m_rng));
        m_velocity.push_back(0.5 * m_step_length * dir.normalized());
        m_axis.push_back(axis.normalized());
        double radius = 1e-12;
        const Eigen::RowVector3d c = centroid(static_cast<std::size_t>(o));
        for (Index v : m_members[static_cast<std::size_t>(o)])
            radius = std::max(radius, (m_positions.row(v) - c).norm());
        m_omega.push_back(0.5 * m_step_length / radius); // rim speed: half a step length
    }
}

void MovingScene::step()
{
    ++m_step;
    std::normal_distribution<double> g;
    const double sign = (m_step / 40) % 2 ? -1.0 : 1.0;
    for (std::size_t o = 0; o < m_members.size(); ++o) {
        const Eigen::RowVector3d c = centroid(o);
        const Eigen::Vector3d jitter_axis = Eigen::Vector3d(g(m_rng), g(m_rng), g(m_rng)).normalized();
        const Eigen::Matrix3d R =
            (Eigen::AngleAxisd(m_omega[o], m_axis[o]) * Eigen::AngleAxisd(0.25 * m_omega[o] * g(m_rng), jitter_axis))
                .toRotationMatrix();
        const Eigen::Vector3d shift =
            sign * m_velocity[o] +
            0.25 * 0.5 * m_step_length * Eigen::Vector3d(g(m_rng), g(m_rng), g(m_rng)).normalized();
        for (Index v : m_members[o]) {
            const Eigen::Vector3d p = (m_positions.row(v) - c).transpose();
            m_positions.row(v) = (R * p + c.transpose() + shift).transpose();
        }
    }
}

Eigen::RowVector3d MovingScene::centroid(std::size_t o) const
{
    Eigen::RowVector3d c = Eigen::RowVector3d::Zero();
    for (Index v : m_members[o])
        c += m_positions.row(v);
    return c / std::max<double>(1.0, static_cast<double>(m_members[o].size()));
}

} // namespace tethash::bench
