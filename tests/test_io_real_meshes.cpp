// The real meshes of ../shared/meshes, deformed by a fixed smooth random field and overlapped with a moved
// copy of themselves: detector == oracle. Skips when the meshes (or their readers) are absent.
#include "support.hpp"
#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/oracle.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace tethash;

namespace {

/// Displacement field: a sum of a few sinusoids with fixed random wave vectors, amplitude ~ 2 mean edges.
void deform(Positions& p, double edge, std::uint32_t seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    const Eigen::RowVector3d lo = p.colwise().minCoeff(), hi = p.colwise().maxCoeff();
    const double size = (hi - lo).norm();
    Eigen::Vector3d k[4], a[4];
    double phase[4];
    for (int i = 0; i < 4; ++i) {
        k[i] = Eigen::Vector3d(u(rng), u(rng), u(rng)) * (6.0 / size);
        a[i] = Eigen::Vector3d(u(rng), u(rng), u(rng)) * edge;
        phase[i] = 3 * u(rng);
    }
    for (Eigen::Index v = 0; v < p.rows(); ++v) {
        const Eigen::Vector3d x = p.row(v).transpose();
        Eigen::Vector3d d = Eigen::Vector3d::Zero();
        for (int i = 0; i < 4; ++i)
            d += a[i] * std::sin(k[i].dot(x) + phase[i]);
        p.row(v) += d.transpose();
    }
}

void check_mesh(const std::string& name)
{
    const auto path = test::shared_mesh(name);
    if (!path) GTEST_SKIP() << name << " not present";
    const TetMesh one = io::read_mesh(path->string());
    ASSERT_GT(one.num_tets(), 0);
    const double edge = mean_edge_length(one.positions, one.tets);
    const Index n = one.num_vertices(), m = one.num_tets();
    // Scene: the mesh deformed, plus a copy deformed differently and moved by 10 % of its size.
    Positions p(2 * n, 3);
    Tets t(2 * m, 4);
    p.topRows(n) = one.positions;
    p.bottomRows(n) = one.positions;
    const Eigen::RowVector3d lo = one.positions.colwise().minCoeff(), hi = one.positions.colwise().maxCoeff();
    p.bottomRows(n).rowwise() += 0.1 * (hi - lo);
    Positions a = p.topRows(n), b = p.bottomRows(n);
    deform(a, 2 * edge, 1);
    deform(b, 2 * edge, 2);
    p.topRows(n) = a;
    p.bottomRows(n) = b;
    t.topRows(m) = one.tets;
    t.bottomRows(m) = one.tets.array() + n;
    std::vector<Index> vobj(2 * n, 0), tobj(2 * m, 0);
    std::fill(vobj.begin() + n, vobj.end(), 1);
    std::fill(tobj.begin() + m, tobj.end(), 1);
    const std::vector<Contact> want = brute_force_contacts(p, t, vobj, tobj);
    EXPECT_FALSE(want.empty());
    // The hash with three parameter sets, then every other broad phase (2 threads): the oracle's contacts.
    std::vector<DetectParams> variants;
    for (int variant = 0; variant < 3; ++variant) {
        DetectParams params;
        params.threads = 1 + variant % 2;
        params.hash = variant == 1 ? HashFunction::teschner : HashFunction::column;
        params.cell_size_mode = DetectParams::CellSizeMode::factor_of_mean_edge;
        params.cell_size = variant == 2 ? 0.4 : 1.3;
        params.table_size = variant == 2 ? 1009 : 0;
        variants.push_back(params);
    }
    for (Method method : all_methods()) {
        if (method == Method::hash) continue;
        DetectParams params;
        params.method = method;
        params.threads = 2;
        variants.push_back(params);
    }
    for (const DetectParams& params : variants) {
        Detector det(params);
        det.set_topology(t, 2 * n, vobj, tobj);
        const std::vector<Contact>& got = det.detect(p);
        const std::string what = name + " method " + to_string(params.method);
        ASSERT_EQ(got.size(), want.size()) << what;
        for (std::size_t i = 0; i < got.size(); ++i) {
            ASSERT_EQ(got[i].vertex, want[i].vertex) << what << " contact " << i;
            ASSERT_EQ(got[i].tet, want[i].tet) << what << " contact " << i;
        }
    }
}

} // namespace

TEST(CoreRealMeshes, Octopus)
{
    check_mesh("octopus-low.mesh");
}
TEST(CoreRealMeshes, Armadillo)
{
    check_mesh("armadillo_4k.ele");
}
TEST(CoreRealMeshes, ScrewGmsh)
{
    check_mesh("screw.msh");
}
TEST(CoreRealMeshes, P1WithInvertedTets)
{
    check_mesh("P1.msh");
}
TEST(CoreRealMeshes, RaptorVtu)
{
    check_mesh("raptorTetra_8418.vtu");
}
TEST(CoreRealMeshes, Hand)
{
    check_mesh("hand.mesh");
}
TEST(CoreRealMeshes, QuintupleTorusVeg)
{
    check_mesh("quintupleTorus.veg");
}
