// The C interface (tethash.h): the same contacts as the C++ Detector and the oracle on several scenes, the same
// penetration as Penetration, parameters and object options passed through, and every error path answered by a
// status and a message naming the function (never a crash).
#include "core_scenes.hpp"
#include "tethash/continuous.hpp"

#include "tethash/edge_contacts.hpp"
#include "tethash/oracle.hpp"
#include "tethash/penetration.hpp"
#include "tethash/tethash.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <regex>
#include <string>
#include <thread>
#include <vector>

using namespace tethash;

namespace {

/// Owns a C detector for the length of a test.
struct Handle {
    tethash_detector* d = nullptr;
    Handle() { EXPECT_EQ(tethash_detector_create(&d), TETHASH_OK); }
    ~Handle() { tethash_detector_destroy(d); }
    Handle(const Handle&) = delete;
    Handle& operator=(const Handle&) = delete;
};

void set_topology(tethash_detector* d, const test::Scene& s)
{
    ASSERT_EQ(tethash_detector_set_topology(d, s.tets.data(), s.tets.rows(), s.positions.rows(), s.vertex_object.data(),
                                            s.tet_object.data()),
              TETHASH_OK)
        << tethash_last_error();
}

/// The contacts of the C detector's last detection, read through both accessors (checked to agree).
std::vector<tethash_contact> read_contacts(const tethash_detector* d)
{
    int64_t count = -1;
    EXPECT_EQ(tethash_detector_contact_count(d, &count), TETHASH_OK);
    std::vector<tethash_contact> out(static_cast<size_t>(count));
    for (int64_t i = 0; i < count; ++i)
        EXPECT_EQ(tethash_detector_contact(d, i, &out[static_cast<size_t>(i)]), TETHASH_OK);
    std::vector<int32_t> vertex(out.size()), tet(out.size());
    std::vector<double> bary(4 * out.size()), depth(out.size()), direction(3 * out.size());
    EXPECT_EQ(
        tethash_detector_get_contacts(d, count, vertex.data(), tet.data(), bary.data(), depth.data(), direction.data()),
        TETHASH_OK);
    for (size_t i = 0; i < out.size(); ++i) {
        EXPECT_EQ(vertex[i], out[i].vertex);
        EXPECT_EQ(tet[i], out[i].tet);
        for (size_t k = 0; k < 4; ++k)
            EXPECT_EQ(bary[4 * i + k], out[i].bary[k]);
        if (std::isnan(out[i].depth))
            EXPECT_TRUE(std::isnan(depth[i]));
        else
            EXPECT_EQ(depth[i], out[i].depth);
        for (size_t k = 0; k < 3; ++k)
            EXPECT_EQ(direction[3 * i + k], out[i].direction[k]);
    }
    return out;
}

void expect_same(const std::vector<tethash_contact>& c, const std::vector<Contact>& cpp, const char* what)
{
    ASSERT_EQ(c.size(), cpp.size()) << what;
    for (size_t i = 0; i < c.size(); ++i) {
        EXPECT_EQ(c[i].vertex, cpp[i].vertex) << what << " contact " << i;
        EXPECT_EQ(c[i].tet, cpp[i].tet) << what << " contact " << i;
        EXPECT_EQ(c[i].vertex_object, cpp[i].vertex_object) << what << " contact " << i;
        EXPECT_EQ(c[i].tet_object, cpp[i].tet_object) << what << " contact " << i;
        for (int k = 0; k < 4; ++k)
            EXPECT_NEAR(c[i].bary[k], cpp[i].bary[k], 1e-12) << what << " contact " << i;
    }
}

std::vector<test::Scene> scenes()
{
    std::vector<test::Scene> out;
    out.push_back(test::random_scene(7, 3, 2, 0.1));
    out.push_back(test::random_scene(11, 4, 3, 0.2));
    out.push_back(test::lattice_pair(2, 0.25, Eigen::Vector3d(0.125, 0.125, 0.125), Eigen::Vector3d::Zero()));
    return out;
}

void expect_error(tethash_status got, tethash_status want, const std::string& function)
{
    EXPECT_EQ(got, want) << tethash_last_error();
    const std::string msg = tethash_last_error();
    EXPECT_NE(msg.find(function), std::string::npos) << msg;
}

} // namespace

TEST(CoreCapi, SameContactsAsDetectorAndOracle)
{
    int scene_no = 0;
    for (const test::Scene& s : scenes()) {
        const std::string what = "scene " + std::to_string(scene_no++);
        Handle h;
        set_topology(h.d, s);
        int64_t count = -1;
        ASSERT_EQ(tethash_detector_detect(h.d, s.positions.data(), s.positions.rows(), &count), TETHASH_OK)
            << tethash_last_error();
        const std::vector<tethash_contact> c = read_contacts(h.d);
        EXPECT_EQ(count, static_cast<int64_t>(c.size()));
        EXPECT_GT(c.size(), 0u) << what;

        Detector det;
        det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object);
        expect_same(c, det.detect(s.positions), what.c_str());
        expect_same(c, brute_force_contacts(s.positions, s.tets, s.vertex_object, s.tet_object), what.c_str());
        for (const tethash_contact& x : c)
            EXPECT_TRUE(std::isnan(x.depth));
    }
}

namespace {

/// The end of a step of `s`: each object moved along x by 0.3 (odd objects one way, even the other) and each vertex
/// by a jitter of up to 0.15 per axis.
Positions step_end(const test::Scene& s)
{
    Positions x1 = s.positions;
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-0.15, 0.15);
    for (Eigen::Index v = 0; v < x1.rows(); ++v)
        x1.row(v) += Eigen::RowVector3d(0.3 * (s.vertex_object[static_cast<size_t>(v)] % 2 ? 1 : -1), 0, 0) +
                     Eigen::RowVector3d(u(rng), u(rng), u(rng));
    return x1;
}

} // namespace

TEST(CoreCapi, ContinuousContactsAsTheBruteForceOverAStep)
{
    // A step of a random scene (each object moved by its own translation and a jitter) through the C API at 1 and 2
    // threads: the brute force's contacts over all pairs, as vertex ids (the vertex and its face's corners, or the two
    // edges' ends), kinds and times of impact; too small a capacity, a missing `end` and a wrong vertex count are
    // refused with a status and the function's name; set_topology forgets the contacts.
    const test::Scene s = test::random_scene(13, 4, 3, 0.3);
    const Positions x1 = step_end(s);
    const ccd::ContinuousResult want = ccd::detect_continuous_brute_force(s.tets, s.positions, x1);
    ASSERT_GT(want.contacts.size(), 0u);
    for (int threads : {1, 2}) {
        Handle h;
        set_topology(h.d, s);
        ASSERT_EQ(tethash_detector_set_threads(h.d, threads), TETHASH_OK);
        int64_t count = -1;
        ASSERT_EQ(
            tethash_detector_detect_continuous(h.d, s.positions.data(), x1.data(), x1.rows(), 1e-6, 1000000, &count),
            TETHASH_OK)
            << tethash_last_error();
        ASSERT_EQ(count, static_cast<int64_t>(want.contacts.size()));
        std::vector<int32_t> kind(static_cast<size_t>(count)), vertices(4 * static_cast<size_t>(count));
        std::vector<double> toi(static_cast<size_t>(count));
        ASSERT_EQ(tethash_detector_get_continuous_contacts(h.d, count, kind.data(), vertices.data(), toi.data()),
                  TETHASH_OK);
        for (size_t i = 0; i < want.contacts.size(); ++i) {
            const ccd::ContinuousContact& c = want.contacts[i];
            const bool vf = c.kind == ccd::ContinuousKind::vertex_face;
            EXPECT_EQ(kind[i], vf ? 0 : 1) << i;
            EXPECT_EQ(toi[i], c.toi) << i;
            const std::array<Index, 4> ids =
                vf ? std::array<Index, 4>{c.a, want.faces(c.b, 0), want.faces(c.b, 1), want.faces(c.b, 2)}
                   : std::array<Index, 4>{want.edges(c.a, 0), want.edges(c.a, 1), want.edges(c.b, 0),
                                          want.edges(c.b, 1)};
            for (size_t k = 0; k < 4; ++k)
                EXPECT_EQ(vertices[4 * i + k], ids[k]) << "contact " << i << " vertex " << k;
        }
        expect_error(tethash_detector_get_continuous_contacts(h.d, count - 1, nullptr, nullptr, nullptr),
                     TETHASH_ERROR_INVALID_ARGUMENT, "tethash_detector_get_continuous_contacts");
        expect_error(
            tethash_detector_detect_continuous(h.d, s.positions.data(), nullptr, x1.rows(), 1e-6, 1000000, &count),
            TETHASH_ERROR_NULL_ARGUMENT, "tethash_detector_detect_continuous");
        expect_error(tethash_detector_detect_continuous(h.d, s.positions.data(), x1.data(), x1.rows() - 1, 1e-6,
                                                        1000000, &count),
                     TETHASH_ERROR_INVALID_ARGUMENT, "tethash_detector_detect_continuous");
        expect_error(
            tethash_detector_detect_continuous(h.d, s.positions.data(), x1.data(), x1.rows(), -1.0, 1000000, &count),
            TETHASH_ERROR_INVALID_ARGUMENT, "tethash_detector_detect_continuous");
        EXPECT_EQ(count, 0) << "a refused call reports no contacts";
        set_topology(h.d, s);
        EXPECT_EQ(tethash_detector_get_continuous_contacts(h.d, 0, nullptr, nullptr, nullptr), TETHASH_OK)
            << "set_topology forgets the last continuous contacts";
    }
}

TEST(CoreCapi, ContinuousLocalityAsCpp)
{
    // The step of the test above with a locality rule by object (reaches of 0.3, 0, 0.3, 0.3 for the objects): the C
    // detector's contacts and broad-phase pairs are the C++ ContinuousDetector's with the same rule, fewer contacts
    // than without it, and the rule outlives object options (set_object_options re-applies the topology) but not
    // set_topology; num_groups 0 removes it.
    const test::Scene s = test::random_scene(13, 4, 3, 0.3);
    const Positions x1 = step_end(s);
    const std::vector<double> reach_sq{0.09, 0.0, 0.09, 0.09};
    ccd::ContinuousDetector cpp;
    cpp.set_topology(s.tets, static_cast<Index>(s.positions.rows()));
    const std::int64_t all = static_cast<std::int64_t>(cpp.detect(s.positions, x1).contacts.size());
    cpp.set_locality(s.positions, s.vertex_object, reach_sq);
    const ccd::ContinuousResult& want = cpp.detect(s.positions, x1);
    ASSERT_GT(want.contacts.size(), 0u);
    ASSERT_LT(static_cast<std::int64_t>(want.contacts.size()), all) << "the rule leaves some pairs out";
    ASSERT_GT(want.broad_phase_pairs, 0);

    Handle h;
    set_topology(h.d, s);
    ASSERT_EQ(tethash_detector_set_threads(h.d, 1), TETHASH_OK);
    const auto groups = static_cast<int64_t>(reach_sq.size());
    ASSERT_EQ(tethash_detector_set_continuous_locality(h.d, s.positions.data(), s.positions.rows(),
                                                       s.vertex_object.data(), reach_sq.data(), groups),
              TETHASH_OK)
        << tethash_last_error();
    ASSERT_EQ(tethash_detector_set_object_options(h.d, 1, 0, 0), TETHASH_OK); // keeps the rule
    const auto count_of = [&] {
        int64_t count = -1;
        EXPECT_EQ(
            tethash_detector_detect_continuous(h.d, s.positions.data(), x1.data(), x1.rows(), 1e-6, 1000000, &count),
            TETHASH_OK)
            << tethash_last_error();
        return count;
    };
    ASSERT_EQ(count_of(), static_cast<int64_t>(want.contacts.size()));
    int64_t pairs = -1;
    ASSERT_EQ(tethash_detector_continuous_broad_phase_pairs(h.d, &pairs), TETHASH_OK);
    EXPECT_EQ(pairs, want.broad_phase_pairs);
    const auto n = static_cast<size_t>(want.contacts.size());
    std::vector<int32_t> kind(n), vertices(4 * n);
    ASSERT_EQ(
        tethash_detector_get_continuous_contacts(h.d, static_cast<int64_t>(n), kind.data(), vertices.data(), nullptr),
        TETHASH_OK);
    for (size_t i = 0; i < n; ++i) {
        const ccd::ContinuousContact& c = want.contacts[i];
        const bool vf = c.kind == ccd::ContinuousKind::vertex_face;
        EXPECT_EQ(kind[i], vf ? 0 : 1) << i;
        EXPECT_EQ(vertices[4 * i], vf ? c.a : want.edges(c.a, 0)) << i;
    }
    // A refused rule names what is wrong and leaves the one before.
    std::vector<int32_t> bad = s.vertex_object;
    bad[3] = 7;
    expect_error(tethash_detector_set_continuous_locality(h.d, s.positions.data(), s.positions.rows(), bad.data(),
                                                          reach_sq.data(), groups),
                 TETHASH_ERROR_INVALID_ARGUMENT, "tethash_detector_set_continuous_locality");
    EXPECT_NE(std::string(tethash_last_error()).find("vertex 3 is in group 7"), std::string::npos)
        << tethash_last_error();
    const std::vector<double> negative{0.09, -1.0, 0.09, 0.09};
    expect_error(tethash_detector_set_continuous_locality(h.d, s.positions.data(), s.positions.rows(),
                                                          s.vertex_object.data(), negative.data(), groups),
                 TETHASH_ERROR_INVALID_ARGUMENT, "squared reach of group 1");
    expect_error(tethash_detector_set_continuous_locality(h.d, nullptr, s.positions.rows(), s.vertex_object.data(),
                                                          reach_sq.data(), groups),
                 TETHASH_ERROR_NULL_ARGUMENT, "rest is NULL");
    expect_error(tethash_detector_set_continuous_locality(h.d, s.positions.data(), s.positions.rows(),
                                                          s.vertex_object.data(), reach_sq.data(), -1),
                 TETHASH_ERROR_INVALID_ARGUMENT, "num_groups");
    expect_error(tethash_detector_continuous_broad_phase_pairs(h.d, nullptr), TETHASH_ERROR_NULL_ARGUMENT, "out_pairs");
    EXPECT_EQ(count_of(), static_cast<int64_t>(want.contacts.size())) << "the rule before stays";
    // Without the rule, all the contacts again; set_topology forgets the rule too.
    ASSERT_EQ(tethash_detector_set_continuous_locality(h.d, nullptr, s.positions.rows(), nullptr, nullptr, 0),
              TETHASH_OK);
    EXPECT_EQ(count_of(), all);
    ASSERT_EQ(tethash_detector_set_continuous_locality(h.d, s.positions.data(), s.positions.rows(),
                                                       s.vertex_object.data(), reach_sq.data(), groups),
              TETHASH_OK);
    set_topology(h.d, s);
    EXPECT_EQ(count_of(), all);
    {
        Handle none;
        expect_error(tethash_detector_set_continuous_locality(none.d, s.positions.data(), s.positions.rows(),
                                                              s.vertex_object.data(), reach_sq.data(), groups),
                     TETHASH_ERROR_STATE, "no topology set");
    }
}

TEST(CoreCapi, EdgeContactsAsCppWithObjectOptions)
{
    const test::Scene s = test::random_scene(7, 3, 3, 0.3);
    std::vector<ObjectOptions> objects(3);
    objects[1].self_collision = false;
    objects[0].is_static = objects[2].is_static = true;
    Handle h;
    ASSERT_EQ(tethash_detector_set_object_options(h.d, 1, 0, 0), TETHASH_OK);
    ASSERT_EQ(tethash_detector_set_object_options(h.d, 0, 1, 1), TETHASH_OK);
    ASSERT_EQ(tethash_detector_set_object_options(h.d, 2, 1, 1), TETHASH_OK);
    ASSERT_EQ(tethash_detector_set_threads(h.d, 2), TETHASH_OK);
    set_topology(h.d, s);
    int64_t count = -1;
    ASSERT_EQ(tethash_detector_find_edge_contacts(h.d, s.positions.data(), s.positions.rows(), &count), TETHASH_OK)
        << tethash_last_error();
    const EdgeFaceResult want =
        brute_force_edge_face_contacts(s.tets, s.positions, s.vertex_object, s.tet_object, objects);
    ASSERT_EQ(count, static_cast<int64_t>(want.contacts.size()));
    EXPECT_GT(count, 0);
    const auto n = static_cast<std::size_t>(count);
    std::vector<int32_t> edge(2 * n), face(3 * n), obj(2 * n), inner(n);
    std::vector<double> t(n), bary(3 * n), normal(3 * n);
    EXPECT_EQ(tethash_detector_get_edge_contacts(h.d, count - 1, edge.data(), nullptr, nullptr, nullptr, nullptr,
                                                 nullptr, nullptr),
              TETHASH_ERROR_INVALID_ARGUMENT);
    ASSERT_EQ(tethash_detector_get_edge_contacts(h.d, count, edge.data(), face.data(), obj.data(), t.data(),
                                                 bary.data(), inner.data(), normal.data()),
              TETHASH_OK);
    for (std::size_t i = 0; i < n; ++i) {
        const EdgeFaceContact& c = want.contacts[i];
        EXPECT_EQ(edge[2 * i], c.edge_vertices[0]);
        EXPECT_EQ(edge[2 * i + 1], c.edge_vertices[1]);
        for (std::size_t k = 0; k < 3; ++k) {
            EXPECT_EQ(face[3 * i + k], c.face_vertices[k]);
            EXPECT_EQ(bary[3 * i + k], c.face_bary[k]);
            EXPECT_EQ(normal[3 * i + k], c.normal[k]);
        }
        EXPECT_EQ(obj[2 * i], c.edge_object);
        EXPECT_EQ(obj[2 * i + 1], c.face_object);
        EXPECT_EQ(t[i], c.edge_t);
        EXPECT_EQ(inner[i], c.inner_end);
        EXPECT_FALSE(objects[static_cast<std::size_t>(c.edge_object)].is_static &&
                     objects[static_cast<std::size_t>(c.face_object)].is_static);
    }
    // A wrong vertex count, and no topology: a status and a message.
    EXPECT_EQ(tethash_detector_find_edge_contacts(h.d, s.positions.data(), s.positions.rows() - 1, &count),
              TETHASH_ERROR_INVALID_ARGUMENT);
    Handle fresh;
    EXPECT_EQ(tethash_detector_find_edge_contacts(fresh.d, s.positions.data(), s.positions.rows(), &count),
              TETHASH_ERROR_STATE);
    EXPECT_EQ(
        tethash_detector_get_edge_contacts(fresh.d, 0, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr),
        TETHASH_OK);
}

TEST(CoreCapi, ParametersAndObjectOptionsPassThrough)
{
    const test::Scene s = test::random_scene(5, 3, 3, 0.15);
    std::vector<ObjectOptions> objects(3);
    objects[1].self_collision = false;
    objects[2].is_static = true;
    const auto oracle = brute_force_contacts(s.positions, s.tets, s.vertex_object, s.tet_object, objects);

    Handle h;
    // Options before and after the topology: both apply.
    ASSERT_EQ(tethash_detector_set_object_options(h.d, 1, 0, 0), TETHASH_OK);
    set_topology(h.d, s);
    ASSERT_EQ(tethash_detector_set_object_options(h.d, 2, 1, 1), TETHASH_OK);
    ASSERT_EQ(tethash_detector_set_cell_size(h.d, TETHASH_CELL_SIZE_FACTOR, 1.5), TETHASH_OK);
    ASSERT_EQ(tethash_detector_set_table_size(h.d, 1009), TETHASH_OK);
    ASSERT_EQ(tethash_detector_set_hash(h.d, TETHASH_HASH_TESCHNER), TETHASH_OK);
    ASSERT_EQ(tethash_detector_set_threads(h.d, 1), TETHASH_OK);
    ASSERT_EQ(tethash_detector_set_skin(h.d, 0.01), TETHASH_OK);
    int64_t count = 0;
    ASSERT_EQ(tethash_detector_detect(h.d, s.positions.data(), s.positions.rows(), &count), TETHASH_OK)
        << tethash_last_error();
    expect_same(read_contacts(h.d), oracle, "options");

    tethash_stats st{};
    ASSERT_EQ(tethash_detector_stats(h.d, &st), TETHASH_OK);
    EXPECT_EQ(st.table_size, 1009);
    EXPECT_EQ(st.threads, 1);
    EXPECT_EQ(st.contacts, count);
    Detector det;
    det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object, objects);
    DetectStats cs;
    det.detect(s.positions, &cs);
    EXPECT_NEAR(st.cell_size, 1.5 * cs.cell_size, 1e-12 * cs.cell_size);

    // Same positions again: the skin's candidates are reused, same contacts.
    ASSERT_EQ(tethash_detector_detect(h.d, s.positions.data(), s.positions.rows(), &count), TETHASH_OK);
    ASSERT_EQ(tethash_detector_stats(h.d, &st), TETHASH_OK);
    EXPECT_EQ(st.reused, 1);
    expect_same(read_contacts(h.d), oracle, "reused");
    EXPECT_TRUE(std::regex_match(std::string(tethash_version()), std::regex("[0-9]+\\.[0-9]+\\.[0-9]+")))
        << tethash_version();
}

TEST(CoreCapi, PenetrationMatchesCpp)
{
    const test::Scene s = test::random_scene(3, 2, 3, 0.05);
    Handle h;
    set_topology(h.d, s);
    int64_t count = 0;
    ASSERT_EQ(tethash_detector_detect(h.d, s.positions.data(), s.positions.rows(), &count), TETHASH_OK);
    ASSERT_GT(count, 0);
    ASSERT_EQ(tethash_detector_compute_penetration(h.d, s.positions.data(), s.positions.rows()), TETHASH_OK)
        << tethash_last_error();
    const auto c = read_contacts(h.d);

    Detector det;
    det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object);
    std::vector<Contact> cpp = det.detect(s.positions);
    Penetration pen;
    pen.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object);
    pen.compute(s.positions, cpp);
    ASSERT_EQ(c.size(), cpp.size());
    for (size_t i = 0; i < c.size(); ++i) {
        EXPECT_GE(c[i].depth, 0);
        EXPECT_DOUBLE_EQ(c[i].depth, cpp[i].depth) << i;
        for (int k = 0; k < 3; ++k)
            EXPECT_DOUBLE_EQ(c[i].direction[k], cpp[i].direction[k]) << i;
        EXPECT_NEAR(std::hypot(c[i].direction[0], c[i].direction[1], c[i].direction[2]), 1.0, 1e-9);
    }
}

TEST(CoreCapi, NullPointersAnswerAStatus)
{
    expect_error(tethash_detector_create(nullptr), TETHASH_ERROR_NULL_ARGUMENT, "tethash_detector_create");
    tethash_detector_destroy(nullptr); // accepted
    const double xyz[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const int32_t tet[4] = {0, 1, 2, 3};
    int64_t count = 0;
    expect_error(tethash_detector_detect(nullptr, xyz, 4, &count), TETHASH_ERROR_NULL_ARGUMENT,
                 "tethash_detector_detect");
    expect_error(tethash_detector_set_topology(nullptr, tet, 1, 4, nullptr, nullptr), TETHASH_ERROR_NULL_ARGUMENT,
                 "tethash_detector_set_topology");
    expect_error(tethash_detector_set_threads(nullptr, 1), TETHASH_ERROR_NULL_ARGUMENT, "set_threads");
    expect_error(tethash_detector_set_skin(nullptr, 0), TETHASH_ERROR_NULL_ARGUMENT, "set_skin");
    expect_error(tethash_detector_stats(nullptr, nullptr), TETHASH_ERROR_NULL_ARGUMENT, "tethash_detector_stats");

    Handle h;
    expect_error(tethash_detector_set_topology(h.d, nullptr, 1, 4, nullptr, nullptr), TETHASH_ERROR_NULL_ARGUMENT,
                 "tets is NULL");
    ASSERT_EQ(tethash_detector_set_topology(h.d, tet, 1, 4, nullptr, nullptr), TETHASH_OK);
    expect_error(tethash_detector_detect(h.d, nullptr, 4, &count), TETHASH_ERROR_NULL_ARGUMENT, "positions is NULL");
    expect_error(tethash_detector_contact_count(h.d, nullptr), TETHASH_ERROR_NULL_ARGUMENT, "out_count");
    expect_error(tethash_detector_contact(h.d, 0, nullptr), TETHASH_ERROR_NULL_ARGUMENT, "out_contact");
    expect_error(tethash_detector_stats(h.d, nullptr), TETHASH_ERROR_NULL_ARGUMENT, "out_stats");
    // NULL outputs of get_contacts are skipped, not an error.
    ASSERT_EQ(tethash_detector_detect(h.d, xyz, 4, nullptr), TETHASH_OK);
    EXPECT_EQ(tethash_detector_get_contacts(h.d, 0, nullptr, nullptr, nullptr, nullptr, nullptr), TETHASH_OK);
}

TEST(CoreCapi, BadValuesAnswerAStatusAndAMessage)
{
    const double xyz[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.1, 0.1, 0.1};
    const int32_t good[8] = {0, 1, 2, 3, 1, 2, 3, 4};
    const int32_t bad[8] = {0, 1, 2, 3, 1, 2, 3, 5};
    Handle h;
    int64_t count = 7;
    expect_error(tethash_detector_detect(h.d, xyz, 5, &count), TETHASH_ERROR_STATE, "no topology");
    EXPECT_EQ(count, 0);
    expect_error(tethash_detector_compute_penetration(h.d, xyz, 5), TETHASH_ERROR_STATE, "no detection");
    expect_error(tethash_detector_set_topology(h.d, bad, 2, 5, nullptr, nullptr), TETHASH_ERROR_INVALID_ARGUMENT,
                 "tethash_detector_set_topology");
    EXPECT_NE(std::string(tethash_last_error()).find("range"), std::string::npos) << tethash_last_error();
    expect_error(tethash_detector_detect(h.d, xyz, 5, &count), TETHASH_ERROR_STATE, "no topology");
    expect_error(tethash_detector_set_topology(h.d, good, -1, 5, nullptr, nullptr), TETHASH_ERROR_INVALID_ARGUMENT,
                 "num_tets");
    expect_error(tethash_detector_set_topology(h.d, good, 2, -5, nullptr, nullptr), TETHASH_ERROR_INVALID_ARGUMENT,
                 "num_vertices");
    const int32_t bad_objects[5] = {0, 0, 0, 0, -3};
    expect_error(tethash_detector_set_topology(h.d, good, 2, 5, bad_objects, nullptr), TETHASH_ERROR_INVALID_ARGUMENT,
                 "tethash_detector_set_topology");

    ASSERT_EQ(tethash_detector_set_topology(h.d, good, 2, 5, nullptr, nullptr), TETHASH_OK) << tethash_last_error();
    expect_error(tethash_detector_detect(h.d, xyz, 4, &count), TETHASH_ERROR_INVALID_ARGUMENT, "topology has 5");
    double nan_xyz[15];
    std::copy(xyz, xyz + 15, nan_xyz);
    nan_xyz[7] = std::numeric_limits<double>::quiet_NaN();
    expect_error(tethash_detector_detect(h.d, nan_xyz, 5, &count), TETHASH_ERROR_INVALID_ARGUMENT,
                 "tethash_detector_detect");
    int64_t n = -1;
    EXPECT_EQ(tethash_detector_contact_count(h.d, &n), TETHASH_OK);
    EXPECT_EQ(n, 0); // a failed detection leaves no contacts to read

    ASSERT_EQ(tethash_detector_detect(h.d, xyz, 5, &count), TETHASH_OK) << tethash_last_error();
    ASSERT_EQ(count, 1); // vertex 4 inside tet 0 (tet 1 holds it as its own vertex)
    tethash_contact c{};
    ASSERT_EQ(tethash_detector_contact(h.d, 0, &c), TETHASH_OK);
    EXPECT_EQ(c.vertex, 4);
    EXPECT_EQ(c.tet, 0);
    EXPECT_NEAR(c.bary[0], 0.7, 1e-12);
    expect_error(tethash_detector_contact(h.d, 1, &c), TETHASH_ERROR_INVALID_ARGUMENT, "out of range");
    expect_error(tethash_detector_contact(h.d, -1, &c), TETHASH_ERROR_INVALID_ARGUMENT, "out of range");
    int32_t v[1];
    expect_error(tethash_detector_get_contacts(h.d, 0, v, nullptr, nullptr, nullptr, nullptr),
                 TETHASH_ERROR_INVALID_ARGUMENT, "capacity");
    expect_error(tethash_detector_compute_penetration(h.d, xyz, 3), TETHASH_ERROR_INVALID_ARGUMENT, "num_vertices");
    expect_error(tethash_detector_compute_penetration(h.d, nan_xyz, 5), TETHASH_ERROR_INVALID_ARGUMENT, "not finite");

    expect_error(tethash_detector_set_cell_size(h.d, TETHASH_CELL_SIZE_ABSOLUTE, -1), TETHASH_ERROR_INVALID_ARGUMENT,
                 "set_cell_size");
    expect_error(tethash_detector_set_cell_size(h.d, 9, 1), TETHASH_ERROR_INVALID_ARGUMENT, "unknown mode");
    expect_error(tethash_detector_set_table_size(h.d, -2), TETHASH_ERROR_INVALID_ARGUMENT, "set_table_size");
    expect_error(tethash_detector_set_threads(h.d, -1), TETHASH_ERROR_INVALID_ARGUMENT, "set_threads");
    expect_error(tethash_detector_set_threads(h.d, 1 << 30), TETHASH_ERROR_INVALID_ARGUMENT, "set_threads");
    expect_error(tethash_detector_set_hash(h.d, 5), TETHASH_ERROR_INVALID_ARGUMENT, "unknown hash");
    expect_error(tethash_detector_set_skin(h.d, std::numeric_limits<double>::infinity()),
                 TETHASH_ERROR_INVALID_ARGUMENT, "skin");
    expect_error(tethash_detector_set_object_options(h.d, -1, 1, 0), TETHASH_ERROR_INVALID_ARGUMENT, "object");

    // After all these failures the detector still works as before.
    ASSERT_EQ(tethash_detector_detect(h.d, xyz, 5, &count), TETHASH_OK) << tethash_last_error();
    EXPECT_EQ(count, 1);
}

TEST(CoreCapi, LastErrorIsPerThread)
{
    expect_error(tethash_detector_create(nullptr), TETHASH_ERROR_NULL_ARGUMENT, "tethash_detector_create");
    std::string other;
    std::thread t([&] { other = tethash_last_error(); });
    t.join();
    EXPECT_EQ(other, "");
    EXPECT_NE(std::string(tethash_last_error()).find("create"), std::string::npos);
}
