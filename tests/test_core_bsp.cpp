// Solid-leaf BSP trees: exact closed point-in-polyhedron against closed-form and winding-number references on
// convex, concave and genus-1 polyhedra, points exactly on faces, edges and corners and one ulp off them;
// depth against brute force; refusal of bad surfaces; the obstacle set.
#include "support.hpp"

#include "tethash/bsp.hpp"
#include "tethash/error.hpp"
#include "tethash/geometry.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <vector>

using namespace tethash;
using Vec3 = Eigen::Vector3d;

namespace {

struct Soup {
    Positions vertices;
    Triangles triangles;
};

Soup make_soup(const std::vector<Vec3>& v, const std::vector<std::array<Index, 3>>& t)
{
    return {test::matrix_of<Positions>(v), test::matrix_of<Triangles>(t)};
}

using Voxel = std::array<int, 3>;

/// The boundary of a union of unit voxels (no two voxels touching along an edge or corner only), two triangles
/// per exposed unit square, outward.
Soup voxel_surface(const std::vector<Voxel>& voxels)
{
    std::map<Voxel, bool> filled;
    for (const Voxel& v : voxels)
        filled[v] = true;
    std::map<Voxel, Index> ids;
    std::vector<Vec3> points;
    std::vector<std::array<Index, 3>> tris;
    auto id = [&](const Voxel& p) {
        auto [it, fresh] = ids.emplace(p, static_cast<Index>(points.size()));
        if (fresh) points.emplace_back(p[0], p[1], p[2]);
        return it->second;
    };
    // Corner k of a voxel is (k & 1, k >> 1 & 1, k >> 2 & 1); the faces' corners counter-clockwise from outside.
    const std::array<std::array<int, 4>, 6> face{
        {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}}};
    const std::array<Voxel, 6> dir{{{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}}};
    for (const Voxel& v : voxels)
        for (std::size_t f = 0; f < 6; ++f) {
            if (filled.count({v[0] + dir[f][0], v[1] + dir[f][1], v[2] + dir[f][2]})) continue;
            std::array<Index, 4> q{};
            for (std::size_t c = 0; c < 4; ++c) {
                const int k = face[f][c];
                q[c] = id({v[0] + (k & 1), v[1] + (k >> 1 & 1), v[2] + (k >> 2 & 1)});
            }
            tris.push_back({q[0], q[1], q[2]});
            tris.push_back({q[0], q[2], q[3]});
        }
    return make_soup(points, tris);
}

bool in_voxels(const std::vector<Voxel>& voxels, const Vec3& p)
{
    for (const Voxel& v : voxels)
        if (p.x() >= v[0] && p.x() <= v[0] + 1 && p.y() >= v[1] && p.y() <= v[1] + 1 && p.z() >= v[2] &&
            p.z() <= v[2] + 1)
            return true;
    return false;
}

/// |x| + |y| + |z| ≤ 2.
Soup octahedron()
{
    std::vector<Vec3> v{{2, 0, 0}, {-2, 0, 0}, {0, 2, 0}, {0, -2, 0}, {0, 0, 2}, {0, 0, -2}};
    std::vector<std::array<Index, 3>> t;
    for (int sx = 0; sx < 2; ++sx)
        for (int sy = 0; sy < 2; ++sy)
            for (int sz = 0; sz < 2; ++sz) {
                const Index a = sx, b = 2 + sy, c = 4 + sz;
                const bool positive = ((sx == 0) + (sy == 0) + (sz == 0)) % 2 == 1;
                t.push_back(positive ? std::array<Index, 3>{a, b, c} : std::array<Index, 3>{a, c, b});
            }
    return make_soup(v, t);
}

/// The cube [0, 2]³ with its top pushed in to a pyramid whose apex is the centre (1, 1, 1): concave, slanted.
Soup dented_cube()
{
    std::vector<Vec3> v;
    for (int k = 0; k < 8; ++k)
        v.emplace_back(2 * (k & 1), 2 * (k >> 1 & 1), 2 * (k >> 2 & 1));
    v.emplace_back(1, 1, 1);
    std::vector<std::array<Index, 3>> t;
    for (const auto& q :
         std::vector<std::array<Index, 4>>{{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}}) {
        t.push_back({q[0], q[1], q[2]});
        t.push_back({q[0], q[2], q[3]});
    }
    for (const auto& e : std::vector<std::array<Index, 2>>{{4, 5}, {5, 7}, {7, 6}, {6, 4}})
        t.push_back({e[0], e[1], 8});
    return make_soup(v, t);
}

bool in_dented(const Vec3& p)
{
    const bool cube = (p.array() >= 0).all() && (p.array() <= 2).all();
    return cube && p.z() <= 1 + std::max(std::abs(p.x() - 1), std::abs(p.y() - 1));
}

/// Generalised winding number (sum of solid angles / 4π): 1 inside, 0 outside, for points off the surface.
double winding(const Soup& s, const Vec3& p)
{
    double w = 0;
    for (Eigen::Index t = 0; t < s.triangles.rows(); ++t) {
        const Vec3 a = s.vertices.row(s.triangles(t, 0)).transpose() - p;
        const Vec3 b = s.vertices.row(s.triangles(t, 1)).transpose() - p;
        const Vec3 c = s.vertices.row(s.triangles(t, 2)).transpose() - p;
        const double la = a.norm(), lb = b.norm(), lc = c.norm();
        w += 2 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
    }
    return w / (4 * M_PI);
}

double brute_distance(const Soup& s, const Vec3& p)
{
    double best = INFINITY;
    for (Eigen::Index t = 0; t < s.triangles.rows(); ++t) {
        const Vec3 q = closest_point_on_triangle(p, s.vertices.row(s.triangles(t, 0)).transpose(),
                                                 s.vertices.row(s.triangles(t, 1)).transpose(),
                                                 s.vertices.row(s.triangles(t, 2)).transpose());
        best = std::min(best, (q - p).norm());
    }
    return best;
}

/// Every point of the lattice of spacing h over [lo, hi]: contains() must equal `inside`.
void check_lattice(const Bsp& bsp, const Vec3& lo, const Vec3& hi, double h,
                   const std::function<bool(const Vec3&)>& inside)
{
    int checked = 0, in = 0;
    for (double x = lo.x(); x <= hi.x(); x += h)
        for (double y = lo.y(); y <= hi.y(); y += h)
            for (double z = lo.z(); z <= hi.z(); z += h) {
                const Vec3 p(x, y, z);
                const bool expected = inside(p);
                ASSERT_EQ(bsp.contains(p), expected) << "at " << p.transpose();
                ++checked;
                in += expected;
            }
    EXPECT_GT(in, 0);
    EXPECT_LT(in, checked);
}

/// Random points in the enlarged box: contains() must agree with the winding number.
void check_random(const Bsp& bsp, const Soup& s, int count, unsigned seed)
{
    std::mt19937 rng(seed);
    const Vec3 lo = bsp.box_lo() - 0.2 * (bsp.box_hi() - bsp.box_lo());
    const Vec3 hi = bsp.box_hi() + 0.2 * (bsp.box_hi() - bsp.box_lo());
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < count; ++i) {
        const Vec3 p = lo + (hi - lo).cwiseProduct(Vec3(u(rng), u(rng), u(rng)));
        const double w = winding(s, p);
        ASSERT_TRUE(std::abs(w) < 1e-6 || std::abs(w - 1) < 1e-6) << w;
        ASSERT_EQ(bsp.contains(p), w > 0.5) << "at " << p.transpose();
    }
}

/// Points just off each face (its centroid moved by ± `offset` along the normal): outside in front, inside behind,
/// as the winding number says.
void check_near_faces(const Bsp& bsp, const Soup& s, double offset)
{
    for (Eigen::Index t = 0; t < s.triangles.rows(); ++t) {
        const Vec3 a = s.vertices.row(s.triangles(t, 0)).transpose();
        const Vec3 b = s.vertices.row(s.triangles(t, 1)).transpose();
        const Vec3 c = s.vertices.row(s.triangles(t, 2)).transpose();
        const Vec3 n = (b - a).cross(c - a).normalized();
        for (const double sign : {-1.0, 1.0}) {
            const Vec3 p = (a + b + c) / 3 + sign * offset * n;
            const double w = winding(s, p);
            ASSERT_TRUE(std::abs(w) < 1e-6 || std::abs(w - 1) < 1e-6) << w;
            ASSERT_EQ(bsp.contains(p), w > 0.5) << "triangle " << t << " offset " << sign * offset;
            EXPECT_EQ(w > 0.5, sign < 0);
        }
    }
}

const std::vector<Voxel> staircase{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0},
                                   {1, 0, 1}, {2, 0, 1}, {1, 1, 1}, {2, 1, 1}, {2, 0, 2}, {2, 1, 2}};
const std::vector<Voxel> frame{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {2, 1, 0}, {0, 2, 0}, {1, 2, 0}, {2, 2, 0}};
const std::vector<Voxel> bowl{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0},
                              {0, 2, 0}, {1, 2, 0}, {2, 2, 0}, {0, 0, 1}, {1, 0, 1}, {2, 0, 1},
                              {0, 1, 1}, {2, 1, 1}, {0, 2, 1}, {1, 2, 1}, {2, 2, 1}};

} // namespace

TEST(Bsp, CubeOfVoxelsMergesCoplanarFaces)
{
    std::vector<Voxel> cube;
    for (int k = 0; k < 8; ++k)
        cube.push_back({k & 1, k >> 1 & 1, k >> 2 & 1});
    const Soup s = voxel_surface(cube);
    const Bsp bsp(s.vertices, s.triangles);
    EXPECT_EQ(bsp.stats().triangles, 48);
    EXPECT_EQ(bsp.stats().planes, 6); // 8 triangles on each side, one plane each
    EXPECT_EQ(bsp.stats().nodes, 6);
    EXPECT_EQ(bsp.stats().leaves_in, 1);
    EXPECT_EQ(bsp.stats().splits, 0);
    check_lattice(bsp, Vec3(-0.5, -0.5, -0.5), Vec3(2.5, 2.5, 2.5), 0.25,
                  [&](const Vec3& p) { return in_voxels(cube, p); });
    // One ulp outside each face is out, one ulp inside is in.
    for (int axis = 0; axis < 3; ++axis)
        for (const double face : {0.0, 2.0}) {
            Vec3 p(1, 0.5, 1.5);
            p[axis] = face;
            EXPECT_TRUE(bsp.contains(p));
            const double outward = face == 0 ? -1 : 3;
            p[axis] = std::nextafter(face, outward);
            EXPECT_FALSE(bsp.contains(p)) << p.transpose();
            p[axis] = std::nextafter(face, 1.0);
            EXPECT_TRUE(bsp.contains(p)) << p.transpose();
        }
}

TEST(Bsp, ConvexOctahedronExactOnFacesEdgesCorners)
{
    const Soup s = octahedron();
    const Bsp bsp(s.vertices, s.triangles);
    EXPECT_EQ(bsp.stats().planes, 8);
    check_lattice(bsp, Vec3(-2.5, -2.5, -2.5), Vec3(2.5, 2.5, 2.5), 0.25,
                  [](const Vec3& p) { return p.cwiseAbs().sum() <= 2; });
    check_random(bsp, s, 2000, 1);
}

TEST(Bsp, ConcaveStaircaseAndBowl)
{
    for (const auto* shape : {&staircase, &bowl}) {
        const Soup s = voxel_surface(*shape);
        const Bsp bsp(s.vertices, s.triangles);
        EXPECT_GT(bsp.stats().leaves_in, 1); // concave: more than one convex cell
        check_lattice(bsp, Vec3(-0.5, -0.5, -0.5), Vec3(3.5, 3.5, 3.5), 0.25,
                      [&](const Vec3& p) { return in_voxels(*shape, p); });
        check_random(bsp, s, 1000, 2);
    }
}

TEST(Bsp, GenusOneFrame)
{
    const Soup s = voxel_surface(frame);
    const Bsp bsp(s.vertices, s.triangles);
    check_lattice(bsp, Vec3(-0.5, -0.5, -0.5), Vec3(3.5, 3.5, 1.5), 0.125,
                  [&](const Vec3& p) { return in_voxels(frame, p); });
    EXPECT_FALSE(bsp.contains(Vec3(1.5, 1.5, 0.5))); // the hole
    EXPECT_TRUE(bsp.contains(Vec3(1.5, 1, 0.5)));    // the hole's wall
    check_random(bsp, s, 1000, 3);
}

TEST(Bsp, ConcaveSlantedFacesExactOnTheDent)
{
    const Soup s = dented_cube();
    const Bsp bsp(s.vertices, s.triangles);
    check_lattice(bsp, Vec3(-0.5, -0.5, -0.5), Vec3(2.5, 2.5, 2.5), 0.125, in_dented);
    check_random(bsp, s, 2000, 4);
    for (const double offset : {1e-3, 1e-9})
        check_near_faces(bsp, s, offset);
    // Points exactly on the slanted faces (dyadic combinations of their corners), their edges and the apex.
    const Vec3 apex(1, 1, 1);
    for (const Vec3& corner : {Vec3(0, 0, 2), Vec3(2, 0, 2), Vec3(2, 2, 2), Vec3(0, 2, 2)}) {
        EXPECT_TRUE(bsp.contains((corner + apex) / 2));
        EXPECT_TRUE(bsp.contains(corner));
    }
    EXPECT_TRUE(bsp.contains(apex));
    EXPECT_TRUE(bsp.contains(Vec3(1, 0.5, 1.5)));     // on face (0,0,2)-(2,0,2)-apex
    EXPECT_FALSE(bsp.contains(Vec3(1, 0.75, 1.875))); // in the dent, above that face
    EXPECT_TRUE(bsp.contains(Vec3(1, 0.75, 1.25)));   // below it
}

TEST(Bsp, RotatedStaircaseAgreesWithWindingNumber)
{
    Soup s = voxel_surface(staircase);
    const Eigen::Matrix3d r =
        (Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()) * Eigen::AngleAxisd(0.3, Vec3::UnitX())).toRotationMatrix();
    for (Eigen::Index i = 0; i < s.vertices.rows(); ++i)
        s.vertices.row(i) = (r * s.vertices.row(i).transpose() + Vec3(0.1, -3, 7)).transpose();
    const Bsp bsp(s.vertices, s.triangles);
    check_random(bsp, s, 3000, 5);
    for (const double offset : {1e-3, 1e-7, 1e-9})
        check_near_faces(bsp, s, offset);
    // The vertices themselves are corners of the surface: inside (closed).
    for (Eigen::Index i = 0; i < s.vertices.rows(); ++i)
        EXPECT_TRUE(bsp.contains(s.vertices.row(i).transpose()));
}

TEST(Bsp, DepthIsTheDistanceToTheNearestFace)
{
    const Soup s = voxel_surface(bowl);
    const Bsp bsp(s.vertices, s.triangles);
    std::mt19937 rng(6);
    std::uniform_real_distribution<double> u(0, 3);
    int inside = 0;
    for (int i = 0; i < 500; ++i) {
        const Vec3 p(u(rng), u(rng), u(rng) * 2 / 3);
        const BspHit hit = bsp.query(p);
        ASSERT_EQ(hit.inside, in_voxels(bowl, p));
        if (!hit.inside) continue;
        ++inside;
        EXPECT_NEAR(hit.depth, brute_distance(s, p), 1e-12);
        EXPECT_NEAR(hit.direction.norm(), 1, 1e-12);
        EXPECT_FALSE(bsp.contains(p + (hit.depth + 1e-9) * hit.direction)); // pushed out along it
    }
    EXPECT_GT(inside, 50);
    const BspHit on = bsp.query(Vec3(0.5, 0.5, 2)); // on the rim's top face: depth 0, direction the face normal
    EXPECT_TRUE(on.inside);
    EXPECT_EQ(on.depth, 0);
    EXPECT_NEAR(on.direction.z(), 1, 1e-12);
}

TEST(Bsp, RefusesBadSurfaces)
{
    auto message = [](const Soup& s) {
        try {
            const Bsp bsp(s.vertices, s.triangles, "obstacle.obj");
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    const Soup cube = voxel_surface({{0, 0, 0}});
    Soup open = cube;
    open.triangles.conservativeResize(open.triangles.rows() - 1, 3);
    EXPECT_NE(message(open).find("obstacle.obj: open surface: edge"), std::string::npos) << message(open);

    Soup inconsistent = cube;
    std::swap(inconsistent.triangles(0, 1), inconsistent.triangles(0, 2));
    EXPECT_NE(message(inconsistent).find("inconsistently oriented"), std::string::npos) << message(inconsistent);

    // Two cubes overlapping: each closed, together self-intersecting.
    Soup two = cube;
    const Soup shifted = voxel_surface({{0, 0, 0}});
    two.vertices.conservativeResize(2 * cube.vertices.rows(), 3);
    two.vertices.bottomRows(cube.vertices.rows()) = shifted.vertices.array() + 0.5;
    two.triangles.conservativeResize(2 * cube.triangles.rows(), 3);
    two.triangles.bottomRows(cube.triangles.rows()) =
        shifted.triangles.array() + static_cast<Index>(cube.vertices.rows());
    EXPECT_NE(message(two).find("self-intersecting surface: triangles"), std::string::npos) << message(two);

    // The same two cubes apart are fine (two components).
    two.vertices.bottomRows(cube.vertices.rows()) = shifted.vertices.array() + 3.0;
    EXPECT_EQ(message(two), "");

    // A vertex pushed through the opposite face (the surface folds through itself).
    Soup folded = dented_cube();
    folded.vertices.row(8) = Eigen::RowVector3d(1, 1, -1);
    EXPECT_NE(message(folded).find("self-intersecting"), std::string::npos) << message(folded);

    Soup degenerate = cube;
    degenerate.vertices.row(degenerate.triangles(0, 0)) = degenerate.vertices.row(degenerate.triangles(0, 1));
    EXPECT_FALSE(message(degenerate).empty());

    Soup bad_index = cube;
    bad_index.triangles(3, 1) = 99;
    EXPECT_NE(message(bad_index).find("out of range"), std::string::npos);

    // Inward orientation is turned outwards.
    Soup inward = cube;
    inward.triangles.col(1).swap(inward.triangles.col(2));
    const Bsp bsp(inward.vertices, inward.triangles);
    EXPECT_TRUE(bsp.stats().flipped);
    EXPECT_TRUE(bsp.contains(Vec3(0.5, 0.5, 0.5)));
    EXPECT_FALSE(bsp.contains(Vec3(1.5, 0.5, 0.5)));
}

TEST(Bsp, ObstacleSetSortedByVertexThenObstacle)
{
    ObstacleSet set;
    const Soup a = voxel_surface({{0, 0, 0}});
    const Soup b = voxel_surface({{0, 0, 0}, {1, 0, 0}});
    set.add(Bsp(a.vertices, a.triangles));
    set.add(Bsp(b.vertices, b.triangles));
    Positions p(4, 3);
    p << 0.5, 0.5, 0.5, //
        1.5, 0.5, 0.5,  //
        5, 5, 5,        //
        1, 0.25, 0.5;
    const std::vector<ObstacleContact> c = set.query(p);
    ASSERT_EQ(c.size(), 5u);
    EXPECT_EQ(c[0].vertex, 0);
    EXPECT_EQ(c[0].obstacle, 0);
    EXPECT_EQ(c[1].vertex, 0);
    EXPECT_EQ(c[1].obstacle, 1);
    EXPECT_EQ(c[2].vertex, 1);
    EXPECT_EQ(c[2].obstacle, 1);
    EXPECT_EQ(c[3].vertex, 3);
    EXPECT_EQ(c[3].obstacle, 0);
    EXPECT_EQ(c[3].depth, 0); // on obstacle 0's face x = 1
    EXPECT_EQ(c[4].vertex, 3);
    EXPECT_EQ(c[4].obstacle, 1);
    EXPECT_DOUBLE_EQ(c[4].depth, 0.25);
}
