#pragma once
// Small scene generators for the detection tests (independent of meshing::generate): cube lattices split into
// 6 tets per cube (Kuhn), placed, deformed and combined into multi-object scenes.
#include "support.hpp"

#include "tethash/detect.hpp"
#include "tethash/oracle.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace tethash::test {

struct Scene {
    Positions positions;
    Tets tets;
    std::vector<Index> vertex_object, tet_object;
    std::vector<ObjectOptions> objects;
};

/// The same contacts bit for bit: vertex, tet, both objects and the barycentric coordinates.
inline bool identical(const std::vector<Contact>& a, const std::vector<Contact>& b)
{
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (a[i].vertex != b[i].vertex || a[i].tet != b[i].tet || a[i].vertex_object != b[i].vertex_object ||
            a[i].tet_object != b[i].tet_object || std::memcmp(a[i].bary, b[i].bary, sizeof a[i].bary) != 0)
            return false;
    return true;
}

/// Identical (vertex, tet, objects) sequence, barycentric coordinates equal up to rounding.
inline ::testing::AssertionResult same_contacts(const std::vector<Contact>& got, const std::vector<Contact>& want)
{
    const std::size_t n = std::min(got.size(), want.size());
    for (std::size_t i = 0; i < n; ++i) {
        const Contact &a = got[i], &b = want[i];
        if (a.vertex != b.vertex || a.tet != b.tet)
            return ::testing::AssertionFailure() << "contact " << i << ": got (" << a.vertex << ", " << a.tet
                                                 << "), oracle (" << b.vertex << ", " << b.tet << ")";
        if (a.vertex_object != b.vertex_object || a.tet_object != b.tet_object)
            return ::testing::AssertionFailure() << "contact " << i << ": objects differ";
        double sum = 0;
        for (int k = 0; k < 4; ++k) {
            sum += a.bary[k];
            if (std::fabs(a.bary[k] - b.bary[k]) > 1e-6 || a.bary[k] < -1e-9)
                return ::testing::AssertionFailure()
                       << "contact " << i << ": bary[" << k << "] " << a.bary[k] << " vs oracle " << b.bary[k];
            if ((a.bary[k] == 0.0) != (b.bary[k] == 0.0))
                return ::testing::AssertionFailure() << "contact " << i << ": exact zero of bary[" << k << "] differs";
        }
        if (std::fabs(sum - 1.0) > 1e-9)
            return ::testing::AssertionFailure() << "contact " << i << ": bary sum " << sum;
    }
    if (got.size() != want.size())
        return ::testing::AssertionFailure() << got.size() << " contacts, oracle " << want.size();
    return ::testing::AssertionSuccess();
}

/// One object as the text of a Medit .mesh file (1-based indices).
inline std::string medit_text(const Scene& s)
{
    std::ostringstream o;
    o.precision(17);
    o << "MeshVersionFormatted 1\nDimension 3\nVertices\n" << s.positions.rows() << "\n";
    for (Eigen::Index v = 0; v < s.positions.rows(); ++v)
        o << s.positions(v, 0) << " " << s.positions(v, 1) << " " << s.positions(v, 2) << " 0\n";
    o << "Tetrahedra\n" << s.tets.rows() << "\n";
    for (Eigen::Index t = 0; t < s.tets.rows(); ++t)
        o << s.tets(t, 0) + 1 << " " << s.tets(t, 1) + 1 << " " << s.tets(t, 2) + 1 << " " << s.tets(t, 3) + 1
          << " 0\n";
    o << "End\n";
    return o.str();
}

/// Cube lattice of nx × ny × nz cubes of edge h at `origin`, 6 tets per cube (all positively oriented).
inline Scene lattice_object(int nx, int ny, int nz, double h, const Eigen::Vector3d& origin)
{
    Scene s;
    auto vid = [&](int i, int j, int k) { return static_cast<Index>((k * (ny + 1) + j) * (nx + 1) + i); };
    s.positions.resize((nx + 1) * (ny + 1) * (nz + 1), 3);
    for (int k = 0; k <= nz; ++k)
        for (int j = 0; j <= ny; ++j)
            for (int i = 0; i <= nx; ++i)
                s.positions.row(vid(i, j, k)) = origin + h * Eigen::Vector3d(i, j, k);
    s.tets.resize(6 * nx * ny * nz, 4);
    int t = 0;
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                for (const auto& ids : kuhn_tets(i, j, k, vid)) {
                    s.tets.row(t) << ids[0], ids[1], ids[2], ids[3];
                    const Eigen::Vector3d a = s.positions.row(ids[0]), b = s.positions.row(ids[1]),
                                          cc = s.positions.row(ids[2]), d = s.positions.row(ids[3]);
                    if ((b - a).dot((cc - a).cross(d - a)) < 0) std::swap(s.tets(t, 2), s.tets(t, 3));
                    ++t;
                }
    s.vertex_object.assign(s.positions.rows(), 0);
    s.tet_object.assign(s.tets.rows(), 0);
    return s;
}

/// Appends `o` as a new object.
inline void append_object(Scene& s, const Scene& o)
{
    const Index base = static_cast<Index>(s.positions.rows());
    const Index obj =
        s.vertex_object.empty() ? 0 : *std::max_element(s.vertex_object.begin(), s.vertex_object.end()) + 1;
    Positions p(s.positions.rows() + o.positions.rows(), 3);
    p << s.positions, o.positions;
    Tets t(s.tets.rows() + o.tets.rows(), 4);
    t.topRows(s.tets.rows()) = s.tets;
    t.bottomRows(o.tets.rows()) = o.tets.array() + base;
    s.positions = p;
    s.tets = t;
    s.vertex_object.insert(s.vertex_object.end(), o.positions.rows(), obj);
    s.tet_object.insert(s.tet_object.end(), o.tets.rows(), obj);
}

/// `count` lattice objects with random placement and rotation, overlapping inside a box of size ~2,
/// vertices jittered by `jitter` × h.
inline Scene random_scene(std::uint32_t seed, int count, int cubes, double jitter)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Scene s;
    s.positions.resize(0, 3);
    s.tets.resize(0, 4);
    for (int o = 0; o < count; ++o) {
        const double h = 0.15 + 0.1 * (u(rng) + 1);
        Scene obj = lattice_object(cubes, cubes, cubes, h, Eigen::Vector3d::Zero());
        const Eigen::Matrix3d rot =
            Eigen::AngleAxisd(3 * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng) + 2).normalized()).toRotationMatrix();
        const Eigen::Vector3d shift(0.5 * u(rng), 0.5 * u(rng), 0.5 * u(rng));
        for (Eigen::Index v = 0; v < obj.positions.rows(); ++v) {
            Eigen::Vector3d p = obj.positions.row(v).transpose();
            p = rot * p + shift + jitter * h * Eigen::Vector3d(u(rng), u(rng), u(rng));
            obj.positions.row(v) = p.transpose();
        }
        append_object(s, obj);
    }
    return s;
}

/// Two copies of a cube lattice with exactly representable coordinates, the second moved by `shift`
/// (e.g. half a cell or one lattice vector): vertices land exactly on faces, edges and corners.
inline Scene lattice_pair(int cubes, double h, const Eigen::Vector3d& shift, const Eigen::Vector3d& origin)
{
    Scene s = lattice_object(cubes, cubes, cubes, h, origin);
    append_object(s, lattice_object(cubes, cubes, cubes, h, origin + shift));
    return s;
}

/// Object rules of the random scene `seed` of 4 objects: one object without self-collision, one or two static.
inline void set_object_rules(Scene& s, std::uint32_t seed)
{
    s.objects.resize(4);
    s.objects[seed % 4].self_collision = false;
    s.objects[(seed + 1) % 4].is_static = true;
    s.objects[(seed + 2) % 4].is_static = (seed % 2) != 0;
}

/// Coincident vertices (25 random pairs of distinct ids, across and within objects; tets holding both become
/// flat) and flat tets (one vertex of every 41st tet moved exactly onto another of its vertices).
inline void make_coincident(Scene& s, std::uint32_t seed)
{
    std::mt19937 rng(seed);
    std::uniform_int_distribution<Index> pick(0, static_cast<Index>(s.positions.rows()) - 1);
    for (int k = 0; k < 25; ++k)
        s.positions.row(pick(rng)) = s.positions.row(pick(rng)).eval();
    for (Eigen::Index t = 3; t < s.tets.rows(); t += 41)
        s.positions.row(s.tets(t, 1)) = s.positions.row(s.tets(t, 0)).eval();
}

/// A detector of the `portals` method with the cell layout `layout` (null: cells of its own making) over scene s.
inline Detector portal_detector(const Scene& s, std::shared_ptr<const CellLayout> layout, int threads)
{
    DetectParams p;
    p.method = Method::portals;
    p.threads = threads;
    p.partition.cells = std::move(layout);
    Detector det(p);
    det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object, s.objects);
    return det;
}

/// One call of two detectors (1 and 2 threads) on s: the first's contacts must equal the oracle's (not empty), the
/// second's be identical; returns the first's statistics.
inline DetectStats expect_oracle_at_two_thread_counts(Detector& one, Detector& two, const Scene& s,
                                                      const std::string& where)
{
    DetectStats st;
    const std::vector<Contact> want =
        brute_force_contacts(s.positions, s.tets, s.vertex_object, s.tet_object, s.objects);
    EXPECT_FALSE(want.empty()) << where;
    const std::vector<Contact>& a = one.detect(s.positions, &st);
    EXPECT_TRUE(same_contacts(a, want)) << where;
    EXPECT_TRUE(identical(a, two.detect(s.positions))) << where;
    return st;
}

} // namespace tethash::test
