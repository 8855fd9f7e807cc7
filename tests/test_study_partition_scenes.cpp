// The scenes of the space-partition comparison (study/scenarios.hpp: partition_scene): their stated sizes and
// properties, positively oriented tets, deterministic, an unknown name refused.
#include "support.hpp"

#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/oracle.hpp"
#include "tethash/study/scenarios.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace tethash;
using namespace tethash::study;

TEST(StudyPartitionScenes, CubeLatticeHasSixPositiveTetsPerBox)
{
    const TetMesh m = cube_lattice(2, 3, 4, Eigen::Vector3d(1, 0.5, 0.25));
    EXPECT_EQ(m.num_vertices(), 3 * 4 * 5);
    EXPECT_EQ(m.num_tets(), 6 * 2 * 3 * 4);
    const VolumeStats v = volume_stats(m.positions, m.tets);
    EXPECT_GT(v.min, 0);
    EXPECT_NEAR(v.total, 2 * 1.5 * 1.0, 1e-12); // the boxes are filled exactly
}

TEST(StudyPartitionScenes, EachSceneIsWhatItsDescriptionSays)
{
    for (const std::string& name : partition_scene_names()) {
        const NamedScene s = partition_scene(name);
        EXPECT_FALSE(s.description.empty());
        EXPECT_NO_THROW(s.mesh.check_consistency(name));
        EXPECT_GT(volume_stats(s.mesh.positions, s.mesh.tets).min, 0) << name;
        EXPECT_TRUE(partition_scene(name).mesh.positions.isApprox(s.mesh.positions)) << name << ": not deterministic";
        const auto [lo, hi] = bounding_box(s.mesh.positions);
        if (name == "bars") {
            EXPECT_EQ(s.mesh.num_objects(), 100);
            EXPECT_EQ(s.mesh.num_tets(), 50400);
            EXPECT_EQ(s.mesh.num_vertices(), 25800); // V/T 0.51
        } else if (name == "sizes") {
            double shortest = 1e300, longest = 0;
            for (Index t = 0; t < s.mesh.num_tets(); ++t) {
                const double e =
                    (s.mesh.positions.row(s.mesh.tets(t, 0)) - s.mesh.positions.row(s.mesh.tets(t, 3))).norm();
                shortest = std::min(shortest, e);
                longest = std::max(longest, e);
            }
            EXPECT_NEAR(longest / shortest, 1000, 1e-6); // three decades (each tet's main diagonal)
        } else if (name == "corner") {
            EXPECT_GT((hi - lo).minCoeff(), 15.0); // the domain
            Index near = 0;                        // vertices in the corner 0.7 wide
            for (Index v = 0; v < s.mesh.num_vertices(); ++v)
                near += (s.mesh.positions.row(v).array() < 0.8).all();
            EXPECT_EQ(near, 60 * 125);
        } else if (name == "thin") {
            EXPECT_EQ(s.mesh.num_objects(), 12);
        } else if (name == "building" || name == "walled" || name == "hall") {
            EXPECT_EQ(s.mesh.num_objects(), 16 * 10 + 24 * 2);
            EXPECT_EQ(s.mesh.num_tets(), 208 * 162);
            ASSERT_TRUE(s.cells);
            EXPECT_NO_THROW(check_cell_layout(*s.cells));
            EXPECT_EQ(s.walls == nullptr, name == "hall");
            if (name == "walled") {
                // 4 outer walls whole; 6 inner ones of 4 doors each: 5 segments and 4 lintels. The free cells: the
                // 16 rooms whole (3.9 x 3.9 x 3 between the walls) and the 24 door gaps, each gap joined to its two
                // rooms.
                EXPECT_EQ(s.walls->size(), 4 + 6 * (5 + 4));
                int rooms = 0, gaps = 0;
                for (const PortalCell& c : s.cells->cells) {
                    if (c.name.rfind("free", 0) != 0) continue;
                    const double dx = c.hi[0] - c.lo[0], dy = c.hi[1] - c.lo[1], dz = c.hi[2] - c.lo[2];
                    rooms += std::abs(dx - 3.9) < 1e-9 && std::abs(dy - 3.9) < 1e-9 && dz == 3;
                    gaps += std::abs(std::min(dx, dy) - 0.1) < 1e-9 && std::abs(std::max(dx, dy) - 1) < 1e-9 && dz == 2;
                }
                EXPECT_EQ(rooms, 16);
                EXPECT_EQ(gaps, 24);
                EXPECT_EQ(s.cells->portals.size(), 48U);
            } else {
                EXPECT_EQ(s.cells->cells.size(), name == "building" ? 16U : 1U);
                EXPECT_EQ(s.cells->portals.size(), name == "building" ? 24U : 0U);
            }
            EXPECT_GE(lo.minCoeff(), 0.0); // every object inside the building
            EXPECT_LE(hi.x(), 16.0);
            EXPECT_LE(hi.y(), 16.0);
            EXPECT_LE(hi.z(), 3.0);
        }
    }
    EXPECT_THROW(partition_scene("nowhere"), Error);
}

TEST(StudyPartitionScenes, BuildingObjectsStraddleEveryDoorAndPortalsEqualTheOracle)
{
    const NamedScene s = building_scene(3, 2, 7);
    ASSERT_EQ(s.cells->cells.size(), 6U);
    ASSERT_EQ(s.cells->portals.size(), 7U); // 2 × 2 across x, 3 × 1 across y
    // Every door has vertices on both sides of its wall within the door's rectangle.
    for (const Portal& p : s.cells->portals) {
        const int axis = p.lo[0] == p.hi[0] ? 0 : 1;
        bool below = false, above = false;
        for (Index v = 0; v < s.mesh.num_vertices(); ++v) {
            const Eigen::Vector3d x = s.mesh.positions.row(v);
            bool in = true;
            for (int a = 0; a < 3; ++a)
                if (a != axis) in = in && x[a] >= p.lo[a] && x[a] <= p.hi[a];
            if (!in) continue;
            below = below || x[axis] < p.lo[axis];
            above = above || x[axis] > p.lo[axis];
        }
        EXPECT_TRUE(below && above) << "door " << p.a << " - " << p.b;
    }
    const std::vector<Contact> want = brute_force_contacts(s.mesh.positions, s.mesh.tets, s.mesh.vertex_object,
                                                           s.mesh.tet_object, std::span<const ObjectOptions>{});
    ASSERT_GT(want.size(), 100U);
    DetectParams p;
    p.method = Method::portals;
    p.partition.cells = s.cells;
    for (int threads : {1, 2}) {
        p.threads = threads;
        Detector det(p);
        det.set_topology(s.mesh);
        DetectStats st;
        const std::vector<Contact>& got = det.detect(s.mesh.positions, &st);
        ASSERT_EQ(got.size(), want.size()) << "threads " << threads;
        for (std::size_t k = 0; k < got.size(); ++k)
            ASSERT_TRUE(got[k].vertex == want[k].vertex && got[k].tet == want[k].tet) << k;
        EXPECT_GT(st.portal_overlaps, 0); // the doorway objects
    }
}
