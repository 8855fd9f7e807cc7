// Detection on subdomains (subdomain.hpp) with the ranks simulated in one process: regions by coordinate
// bisection, local meshes with their ghost layer, the ownership filter. The union over subdomains must equal the
// detection on the whole mesh, each contact reported once, for both ownership rules and several part counts.
#include "tethash/subdomain.hpp"

#include "core_scenes.hpp"
#include "tethash/error.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <tuple>

namespace tethash {
namespace {

using test::Scene;

struct Partition {
    std::vector<Region> regions;
    std::vector<int> vertex_part, tet_part;
};

Partition partition(const Scene& s, int parts)
{
    Partition p;
    const Positions c = tet_centroids(s.positions, s.tets);
    p.regions = bisect_regions(c, parts);
    for (Eigen::Index t = 0; t < c.rows(); ++t)
        p.tet_part.push_back(region_of(p.regions, c.row(t).transpose()));
    for (Eigen::Index v = 0; v < s.positions.rows(); ++v)
        p.vertex_part.push_back(region_of(p.regions, s.positions.row(v).transpose()));
    return p;
}

struct UnionResult {
    std::vector<Contact> contacts; ///< concatenated over parts, then sorted
    std::int64_t ghost_vertices = 0, ghost_tets = 0;
};

/// Runs every part at `positions` with subdomains built at `built_at`, the ghost layer `width` wide.
UnionResult run_parts(const Scene& s, const Partition& p, double width, ContactOwner owner, const Positions& built_at,
                      const Positions& positions)
{
    UnionResult r;
    for (int part = 0; part < static_cast<int>(p.regions.size()); ++part) {
        const Subdomain sub = make_subdomain(built_at, s.tets, p.vertex_part, p.tet_part, part, p.regions[part], width,
                                             owner, s.vertex_object, s.tet_object);
        for (auto o : sub.vertex_owned)
            r.ghost_vertices += o ? 0 : 1;
        for (auto o : sub.tet_owned)
            r.ghost_tets += o ? 0 : 1;
        Detector det;
        det.set_topology(sub.local_tets, static_cast<Index>(sub.vertices.size()), sub.vertex_object, sub.tet_object,
                         s.objects);
        std::vector<Contact> mine;
        detect_owned(det, sub.gather(positions), sub, owner, mine);
        EXPECT_TRUE(std::is_sorted(mine.begin(), mine.end(), [](const Contact& a, const Contact& b) {
            return std::tie(a.vertex, a.tet) < std::tie(b.vertex, b.tet);
        }));
        r.contacts.insert(r.contacts.end(), mine.begin(), mine.end());
    }
    std::sort(r.contacts.begin(), r.contacts.end(),
              [](const Contact& a, const Contact& b) { return std::tie(a.vertex, a.tet) < std::tie(b.vertex, b.tet); });
    return r;
}

std::vector<Contact> serial(const Scene& s, const Positions& positions)
{
    Detector det;
    det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object, s.objects);
    return det.detect(positions);
}

/// Same pairs in the same order, each once, with the same objects and barycentric coordinates.
void expect_same(const std::vector<Contact>& got, const std::vector<Contact>& want, const std::string& what)
{
    ASSERT_EQ(got.size(), want.size()) << what;
    for (std::size_t i = 0; i < got.size(); ++i) {
        ASSERT_EQ(got[i].vertex, want[i].vertex) << what << " contact " << i;
        ASSERT_EQ(got[i].tet, want[i].tet) << what << " contact " << i;
        ASSERT_EQ(got[i].vertex_object, want[i].vertex_object) << what;
        ASSERT_EQ(got[i].tet_object, want[i].tet_object) << what;
        for (int k = 0; k < 4; ++k)
            ASSERT_EQ(got[i].bary[k], want[i].bary[k]) << what << " contact " << i;
    }
}

std::vector<Scene> scenes()
{
    std::vector<Scene> out;
    out.push_back(test::random_scene(7, 4, 4, 0.2));
    out.push_back(test::random_scene(11, 6, 3, 0.3));
    // Exactly representable lattices moved by half a cell: vertices on faces, edges and corners of the other's tets.
    out.push_back(test::lattice_pair(4, 0.25, Eigen::Vector3d(0.125, 0.125, 0.125), Eigen::Vector3d::Zero()));
    Scene self = test::random_scene(3, 3, 4, 0.2);
    self.objects.assign(3, ObjectOptions{});
    self.objects[1].self_collision = false;
    self.objects[2].is_static = true;
    out.push_back(self);
    return out;
}

TEST(CoreSubdomain, UnionOverPartsEqualsSerialEachContactOnce)
{
    int scene_index = 0;
    for (const Scene& s : scenes()) {
        const std::vector<Contact> want = serial(s, s.positions);
        ASSERT_GT(want.size(), 20U) << "scene " << scene_index;
        const double width = ghost_width(s.positions, s.tets);
        for (int parts : {1, 2, 3, 4, 7}) {
            const Partition p = partition(s, parts);
            for (ContactOwner owner : {ContactOwner::tet, ContactOwner::vertex}) {
                const std::string what = "scene " + std::to_string(scene_index) + ", " + std::to_string(parts) +
                                         " parts, owner " + (owner == ContactOwner::tet ? "tet" : "vertex");
                const UnionResult r = run_parts(s, p, width, owner, s.positions, s.positions);
                expect_same(r.contacts, want, what); // equal sorted lists: nothing missed, nothing twice
                if (parts > 1) {
                    EXPECT_GT(owner == ContactOwner::tet ? r.ghost_vertices : r.ghost_tets, 0) << what;
                }
            }
        }
        ++scene_index;
    }
}

TEST(CoreSubdomain, WithoutGhostLayerContactsAreLost)
{
    // The ghost layer matters: without it, pairs across the cuts are lost (a vertex inside an owned tet but neither
    // owned nor a corner of an owned tet); with the computed width none is. (Half the width lost none on these
    // scenes: the width is a bound, reached only by a vertex at the far corner of a long tet's box.)
    std::int64_t lost = 0;
    for (const Scene& s : scenes()) {
        const std::vector<Contact> want = serial(s, s.positions);
        const double width = ghost_width(s.positions, s.tets);
        for (int parts : {4, 7}) {
            const Partition p = partition(s, parts);
            const UnionResult half = run_parts(s, p, 0.0, ContactOwner::tet, s.positions, s.positions);
            EXPECT_LE(half.contacts.size(), want.size());
            lost += static_cast<std::int64_t>(want.size() - half.contacts.size());
            EXPECT_EQ(run_parts(s, p, width, ContactOwner::tet, s.positions, s.positions).contacts.size(), want.size());
        }
    }
    EXPECT_GT(lost, 0);
}

TEST(CoreSubdomain, SkinCoversMotionBelowHalfTheSkin)
{
    // Ghost layers built once with width extent + skin stay exact while every vertex moves less than skin / 2.
    const Scene s = test::random_scene(11, 6, 3, 0.3);
    const double skin = 0.05;
    const double width = ghost_width(s.positions, s.tets, skin);
    EXPECT_DOUBLE_EQ(width, max_tet_extent(s.positions, s.tets) + skin);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-0.49 * skin / 2, 0.49 * skin / 2); // per axis, |Δ| < skin/2 overall
    Positions moved = s.positions;
    for (Eigen::Index v = 0; v < moved.rows(); ++v)
        for (int a = 0; a < 3; ++a)
            moved(v, a) += u(rng);
    const Partition p = partition(s, 4);
    for (ContactOwner owner : {ContactOwner::tet, ContactOwner::vertex})
        expect_same(run_parts(s, p, width, owner, s.positions, moved).contacts, serial(s, moved), "moved");
}

TEST(CoreSubdomain, BisectionTilesSpaceAndBalances)
{
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(-1, 1);
    Positions pts(1000, 3);
    for (Eigen::Index i = 0; i < pts.rows(); ++i)
        pts.row(i) << 4 * u(rng), u(rng), 0.5 * u(rng);
    for (int parts : {1, 2, 3, 4, 5, 8}) {
        const auto regions = bisect_regions(pts, parts);
        ASSERT_EQ(static_cast<int>(regions.size()), parts);
        std::vector<int> count(static_cast<std::size_t>(parts), 0);
        for (Eigen::Index i = 0; i < pts.rows(); ++i) {
            int holders = 0;
            for (const Region& r : regions)
                holders += r.contains(pts.row(i).transpose()) ? 1 : 0;
            ASSERT_EQ(holders, 1);
            ++count[static_cast<std::size_t>(region_of(regions, pts.row(i).transpose()))];
        }
        for (int c : count)
            EXPECT_NEAR(c, 1000.0 / parts, 2.0) << parts << " parts";
    }
    // Far points outside every point's box still land in exactly one region.
    const auto regions = bisect_regions(pts, 4);
    EXPECT_NO_THROW(region_of(regions, Eigen::Vector3d(1e9, -1e9, 3)));
    EXPECT_THROW(bisect_regions(pts, 0), Error);
}

TEST(CoreSubdomain, OwnedContactsChecksItsArguments)
{
    Contact c;
    c.vertex = 3;
    c.tet = 0;
    const std::vector<Contact> local{c};
    const std::vector<std::uint8_t> owned2{1, 1}, owned4{1, 1, 1, 1}, owned1{1};
    const std::vector<Index> ids2{5, 6}, ids4{10, 11, 12, 13}, ids1{42};
    std::vector<Contact> out;
    EXPECT_THROW(owned_contacts(local, owned2, owned1, ids2, ids1, ContactOwner::tet, out), Error); // vertex 3
    EXPECT_THROW(owned_contacts(local, owned4, owned1, ids2, ids1, ContactOwner::tet, out), Error); // sizes
    owned_contacts(local, owned4, owned1, ids4, ids1, ContactOwner::tet, out);
    ASSERT_EQ(out.size(), 1U);
    EXPECT_EQ(out[0].vertex, 13);
    EXPECT_EQ(out[0].tet, 42);
    const std::vector<std::uint8_t> ghost1{0};
    owned_contacts(local, owned4, ghost1, ids4, ids1, ContactOwner::tet, out);
    EXPECT_TRUE(out.empty());
    owned_contacts(local, owned4, ghost1, ids4, ids1, ContactOwner::vertex, out);
    EXPECT_EQ(out.size(), 1U);
}

} // namespace
} // namespace tethash
