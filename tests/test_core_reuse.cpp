// Candidate reuse with a skin (DetectParams::skin): over sequences of moving scenes every call must equal a
// from-scratch detection bit for bit and the brute-force oracle; reuse happens exactly when every moving vertex
// moved less than skin / 2 since the last full detection, less the displacements' common translation; 1 and 2
// threads agree; no allocation once warm.
#include "core_scenes.hpp"
#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/oracle.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <random>
#include <string>

// Counts heap allocations while g_count_allocations is set (this test binary only).
namespace {
std::atomic<bool> g_count_allocations{false};
std::atomic<long> g_allocations{0};
} // namespace

void* operator new(std::size_t n)
{
    if (g_count_allocations.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
    if (void* p = std::malloc(n ? n : 1)) return p;
    throw std::bad_alloc();
}
void operator delete(void* p) noexcept
{
    std::free(p);
}
void operator delete(void* p, std::size_t) noexcept
{
    std::free(p);
}

using namespace tethash;
using tethash::test::identical;
using tethash::test::Scene;

namespace {

/// Same (vertex, tet) sequence as the oracle, barycentric coordinates equal up to rounding with the same exact zeros.
::testing::AssertionResult same_as_oracle(const std::vector<Contact>& got, const std::vector<Contact>& want)
{
    if (got.size() != want.size())
        return ::testing::AssertionFailure() << got.size() << " contacts, oracle " << want.size();
    for (std::size_t i = 0; i < got.size(); ++i) {
        const Contact &a = got[i], &b = want[i];
        if (a.vertex != b.vertex || a.tet != b.tet)
            return ::testing::AssertionFailure() << "contact " << i << ": got (" << a.vertex << ", " << a.tet
                                                 << "), oracle (" << b.vertex << ", " << b.tet << ")";
        for (int k = 0; k < 4; ++k)
            if (std::fabs(a.bary[k] - b.bary[k]) > 1e-6 || (a.bary[k] == 0.0) != (b.bary[k] == 0.0))
                return ::testing::AssertionFailure()
                       << "contact " << i << ": bary[" << k << "] " << a.bary[k] << " vs oracle " << b.bary[k];
    }
    return ::testing::AssertionSuccess();
}

DetectParams with_threads(DetectParams p, int threads)
{
    p.threads = threads;
    return p;
}

void set_topology(Detector& d, const Scene& s)
{
    d.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object, s.objects);
}

/// A moving scene: per object a rigid increment (small rotation about its centroid and a translation whose direction
/// flips every `period` steps, so objects move apart and together again) plus a small per-vertex jitter; every
/// `jump_every` steps one object jumps by `jump` (beyond skin / 2: a rebuild). Static objects never move.
struct Motion {
    double angle = 0.01, speed = 0.004, jitter = 0.001, jump = 0.05;
    int period = 8, jump_every = 7;
};

void step_scene(Scene& s, int step, std::mt19937& rng, const Motion& mo)
{
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const Index objects = *std::max_element(s.vertex_object.begin(), s.vertex_object.end()) + 1;
    const Eigen::RowVector3d centre = s.positions.colwise().mean();
    for (Index o = 0; o < objects; ++o) {
        if (o < static_cast<Index>(s.objects.size()) && s.objects[static_cast<std::size_t>(o)].is_static) continue;
        Eigen::RowVector3d c = Eigen::RowVector3d::Zero();
        int n = 0;
        for (Eigen::Index v = 0; v < s.positions.rows(); ++v)
            if (s.vertex_object[static_cast<std::size_t>(v)] == o) {
                c += s.positions.row(v);
                ++n;
            }
        c /= std::max(n, 1);
        const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng) + 2).normalized();
        const Eigen::Matrix3d R = Eigen::AngleAxisd(mo.angle * u(rng), axis).toRotationMatrix();
        Eigen::RowVector3d dir = c - centre;
        if (dir.norm() < 1e-9) dir = Eigen::RowVector3d(1, 0, 0);
        const double sign = (step / mo.period) % 2 ? -1.0 : 1.0;
        Eigen::RowVector3d shift = sign * mo.speed * dir.normalized();
        if (mo.jump_every > 0 && step % mo.jump_every == mo.jump_every - 1 && o == step % objects)
            shift += Eigen::RowVector3d(mo.jump, -0.5 * mo.jump, 0.25 * mo.jump);
        for (Eigen::Index v = 0; v < s.positions.rows(); ++v)
            if (s.vertex_object[static_cast<std::size_t>(v)] == o) {
                const Eigen::RowVector3d p = s.positions.row(v) - c;
                s.positions.row(v) = (R * p.transpose()).transpose() + c + shift +
                                     mo.jitter * Eigen::RowVector3d(u(rng), u(rng), u(rng));
            }
    }
}

bool is_static_vertex(const Scene& s, Eigen::Index v)
{
    const Index o = s.vertex_object[static_cast<std::size_t>(v)];
    return o < static_cast<Index>(s.objects.size()) && s.objects[static_cast<std::size_t>(o)].is_static;
}

/// Runs `steps` moving steps with skin detectors at 1 and 2 threads against a from-scratch detector and the oracle;
/// checks reuse against the displacement since the last full detection. Returns the number of reused calls.
int run_sequence(Scene s, DetectParams p, int steps, std::uint32_t seed, const Motion& mo, const std::string& what)
{
    std::mt19937 rng(seed);
    DetectParams p1 = p, p2 = p, fresh_params = p;
    p1.threads = 1;
    p2.threads = 2;
    fresh_params.skin = 0;
    fresh_params.threads = 1;
    Detector d1(p1), d2(p2);
    set_topology(d1, s);
    set_topology(d2, s);
    Positions reference = s.positions;
    int reused = 0;
    bool kept = false; // the last full detection kept candidates (ran with the skin)
    for (int step = 0; step < steps; ++step) {
        if (step > 0) step_scene(s, step, rng, mo);
        DetectStats st1, st2;
        const std::vector<Contact> a = d1.detect(s.positions, &st1);
        const std::vector<Contact>& b = d2.detect(s.positions, &st2);
        Detector fresh(fresh_params);
        set_topology(fresh, s);
        const std::vector<Contact>& want = fresh.detect(s.positions);
        const std::vector<Contact> oracle =
            brute_force_contacts(s.positions, s.tets, s.vertex_object, s.tet_object, s.objects);
        EXPECT_TRUE(identical(a, want)) << what << " step " << step << ": 1 thread with skin differs from scratch";
        EXPECT_TRUE(identical(b, want)) << what << " step " << step << ": 2 threads with skin differ from scratch";
        EXPECT_TRUE(same_as_oracle(a, oracle)) << what << " step " << step;
        // Expected reuse: from the displacements since the last full detection, less their common translation
        // (half the span of each axis; a static vertex adds a displacement of 0).
        Eigen::RowVector3d lo = Eigen::RowVector3d::Constant(std::numeric_limits<double>::infinity());
        Eigen::RowVector3d hi = -lo;
        for (Eigen::Index v = 0; v < s.positions.rows(); ++v) {
            const Eigen::RowVector3d d = is_static_vertex(s, v)
                                             ? Eigen::RowVector3d::Zero()
                                             : Eigen::RowVector3d(s.positions.row(v) - reference.row(v));
            lo = lo.cwiseMin(d);
            hi = hi.cwiseMax(d);
        }
        const double moved = 0.5 * (hi - lo).maxCoeff();
        // With candidates kept, reuse happens exactly when every vertex moved less than skin / 2 since, relative to
        // that translation; without (the first call, or reuse paused: stats skin 0) it does not happen.
        const double half = 0.5 * st1.skin;
        if (!kept || moved >= half) {
            EXPECT_EQ(st1.reused, 0) << what << " step " << step << " moved " << moved << " skin/2 " << half;
        } else if (moved < half * (1 - 1e-9)) {
            EXPECT_EQ(st1.reused, 1) << what << " step " << step << " moved " << moved << " skin/2 " << half;
        }
        EXPECT_EQ(st1.reused, st2.reused) << what << " step " << step;
        EXPECT_EQ(st1.skin, st2.skin) << what << " step " << step;
        if (st1.skin > 0) {
            EXPECT_GT(st1.cached_candidates, 0);
            EXPECT_GE(st1.cached_candidates, st1.inside_tests);
        }
        EXPECT_EQ(st1.contacts, static_cast<std::int64_t>(a.size()));
        if (!st1.reused) {
            reference = s.positions;
            kept = st1.skin > 0;
        }
        reused += st1.reused;
    }
    return reused;
}

} // namespace

TEST(CoreReuse, MovingObjectsEqualScratchAndOracleEveryStep)
{
    const Motion mo;
    for (std::uint32_t seed = 1; seed <= 3; ++seed) {
        const Scene s = test::random_scene(seed, 4, 3, 0.3);
        DetectParams p;
        p.skin = 0.06;
        const int reused = run_sequence(s, p, 24, seed, mo, "seed " + std::to_string(seed));
        EXPECT_GT(reused, 5) << "small motions should mostly reuse";
        EXPECT_LT(reused, 23) << "the jumps must force rebuilds";
    }
}

TEST(CoreReuse, EveryHashTableAndCellSize)
{
    const Motion mo;
    const Scene s = test::random_scene(7, 3, 3, 0.3);
    struct V {
        double cell;
        std::int64_t table;
        HashFunction hash;
    } vs[] = {{0.4, 0, HashFunction::column},
              {2.0, 1, HashFunction::column},
              {1.0, 97, HashFunction::teschner},
              {1.0, 2, HashFunction::teschner}};
    for (const V& v : vs) {
        DetectParams p;
        p.cell_size_mode = DetectParams::CellSizeMode::factor_of_mean_edge;
        p.cell_size = v.cell;
        p.table_size = v.table;
        p.hash = v.hash;
        p.skin_mode = DetectParams::SkinMode::factor_of_cell_size;
        p.skin = 0.25;
        run_sequence(s, p, 12, 7, mo, "cell ×" + std::to_string(v.cell) + " table " + std::to_string(v.table));
    }
}

TEST(CoreReuse, StaticObjectsAndSelfCollisionOff)
{
    Motion mo;
    mo.jump_every = 5;
    for (std::uint32_t seed = 11; seed <= 13; ++seed) {
        Scene s = test::random_scene(seed, 4, 3, 0.6);
        s.objects.resize(4);
        s.objects[seed % 4].is_static = true;
        s.objects[(seed + 1) % 4].self_collision = false;
        DetectParams p;
        p.skin = 0.05;
        const int reused = run_sequence(s, p, 16, seed, mo, "objects seed " + std::to_string(seed));
        EXPECT_GT(reused, 0);
    }
}

TEST(CoreReuse, LatticeContactsOnFacesEdgesCornersWhileMoving)
{
    // Two exactly representable lattices; the second moves by exact steps of h/64 (below skin / 2 = h/16), so
    // vertices keep landing exactly on faces, edges and corners of the other object's tets.
    const double h = 0.25;
    Scene s = test::lattice_pair(3, h, {h / 2, 0, 0}, {0, 0, 0});
    DetectParams p;
    p.skin = h / 8;
    p.threads = 1;
    Detector det(p), det2([&] {
        DetectParams q = p;
        q.threads = 2;
        return q;
    }());
    set_topology(det, s);
    set_topology(det2, s);
    int reused = 0, with_zeros = 0;
    for (int step = 0; step < 20; ++step) {
        if (step > 0)
            for (Eigen::Index v = 0; v < s.positions.rows(); ++v)
                if (s.vertex_object[static_cast<std::size_t>(v)] == 1) s.positions(v, step % 3) += h / 64;
        DetectStats st;
        const std::vector<Contact> got = det.detect(s.positions, &st);
        const std::vector<Contact> oracle = brute_force_contacts(s.positions, s.tets, s.vertex_object, s.tet_object);
        EXPECT_FALSE(oracle.empty());
        EXPECT_TRUE(same_as_oracle(got, oracle)) << "step " << step;
        EXPECT_TRUE(identical(got, det2.detect(s.positions))) << "step " << step;
        for (const Contact& c : got)
            with_zeros += c.bary[0] == 0 || c.bary[1] == 0 || c.bary[2] == 0 || c.bary[3] == 0;
        reused += st.reused;
    }
    EXPECT_GT(reused, 10);
    EXPECT_GT(with_zeros, 0); // contacts exactly on the boundary were checked
}

TEST(CoreReuse, ACommonTranslationKeepsTheCandidates)
{
    // Every object moves by the same 3 skins per call (a falling scene) plus a jitter far below the skin: the
    // candidates of the first call serve every later one, and the contacts stay those of a fresh detection and the
    // oracle. With one object static the same motion is relative motion again: every call is a full one.
    for (const bool with_static : {false, true}) {
        Scene s = test::random_scene(21, 4, 3, 0.4);
        s.objects.resize(4);
        s.objects[2].is_static = with_static;
        const double skin = 0.05;
        DetectParams p;
        p.skin = skin;
        p.threads = 1;
        Detector det(p), det2(with_threads(p, 2));
        for (Detector* d : {&det, &det2})
            set_topology(*d, s);
        std::mt19937 rng(5);
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        int reused = 0, contacts = 0;
        for (int call = 0; call < 10; ++call) {
            if (call > 0)
                for (Eigen::Index v = 0; v < s.positions.rows(); ++v) {
                    if (is_static_vertex(s, v)) continue;
                    s.positions.row(v) += 3 * skin * Eigen::RowVector3d(0.5, -1.0, 0.25);
                    s.positions.row(v) += 0.01 * skin * Eigen::RowVector3d(u(rng), u(rng), u(rng));
                }
            DetectStats st, st2;
            const std::vector<Contact> got = det.detect(s.positions, &st);
            DetectParams fresh_params = p;
            fresh_params.skin = 0;
            Detector fresh(fresh_params);
            set_topology(fresh, s);
            EXPECT_TRUE(identical(got, fresh.detect(s.positions))) << "call " << call;
            EXPECT_TRUE(same_as_oracle(
                got, brute_force_contacts(s.positions, s.tets, s.vertex_object, s.tet_object, s.objects)))
                << "call " << call;
            EXPECT_TRUE(identical(got, det2.detect(s.positions, &st2))) << "call " << call;
            EXPECT_EQ(st.reused, st2.reused) << "call " << call;
            reused += st.reused;
            contacts += static_cast<int>(got.size());
        }
        EXPECT_GT(contacts, 0);
        EXPECT_EQ(reused, with_static ? 0 : 9) << (with_static ? "with" : "without") << " a static object";
    }
}

TEST(CoreReuse, FastMotionPausesTheSkinAndSlowMotionResumesIt)
{
    // A kept list not reused once pauses the skin (a scene that moves more than skin / 2 per call pays for the
    // inflated boxes and never gets anything back); a call that moved less than skin / 4 since the previous one
    // resumes it. Contacts equal the oracle's at every call, and 1 and 2 threads take the same decisions.
    const double h = 0.25, skin = h / 4;
    Scene s = test::lattice_pair(3, h, {h / 2, 0, 0}, {0, 0, 0});
    DetectParams p;
    p.skin = skin;
    p.threads = 1;
    Detector det(p), det2(with_threads(p, 2));
    set_topology(det, s);
    set_topology(det2, s);
    // Calls 0-5 move object 1 by 1.2 skin per call along x (object 0 stays: relative to each other they moved more
    // than the skin; call 1 finds the list of call 0 unused: paused from there), calls 6-11 by skin / 64 (call 6
    // resumes, the later ones reuse its list).
    const double used[12] = {skin, 0, 0, 0, 0, 0, skin, skin, skin, skin, skin, skin};
    const int reused[12] = {0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1};
    for (int call = 0; call < 12; ++call) {
        if (call > 0)
            for (Eigen::Index v = 0; v < s.positions.rows(); ++v)
                if (s.vertex_object[static_cast<std::size_t>(v)] == 1)
                    s.positions(v, 0) += call < 6 ? 1.2 * skin : skin / 64;
        DetectStats st, st2;
        const std::vector<Contact> got = det.detect(s.positions, &st);
        const std::vector<Contact> oracle = brute_force_contacts(s.positions, s.tets, s.vertex_object, s.tet_object);
        EXPECT_TRUE(same_as_oracle(got, oracle)) << "call " << call;
        EXPECT_TRUE(identical(got, det2.detect(s.positions, &st2))) << "call " << call;
        EXPECT_EQ(st.skin, used[call]) << "call " << call;
        EXPECT_EQ(st.reused, reused[call]) << "call " << call;
        EXPECT_EQ(st2.skin, st.skin) << "call " << call;
        EXPECT_EQ(st2.reused, st.reused) << "call " << call;
    }
}

TEST(CoreReuse, SkinOffNeverReusesAndStatsSayWhatWasUsed)
{
    const Scene s = test::random_scene(3, 3, 3, 0.3);
    Detector det;
    set_topology(det, s);
    DetectStats st;
    det.detect(s.positions, &st);
    det.detect(s.positions, &st);
    EXPECT_EQ(st.reused, 0);
    EXPECT_EQ(st.skin, 0);
    EXPECT_EQ(st.cached_candidates, 0);

    DetectParams p;
    p.skin_mode = DetectParams::SkinMode::factor_of_cell_size;
    p.skin = 0.3;
    det.set_params(p); // invalidates the cache: the next call is a full detection
    det.detect(s.positions, &st);
    EXPECT_EQ(st.reused, 0);
    EXPECT_DOUBLE_EQ(st.skin, 0.3 * st.cell_size);
    DetectStats again;
    det.detect(s.positions, &again); // nothing moved
    EXPECT_EQ(again.reused, 1);
    EXPECT_EQ(again.cached_candidates, st.cached_candidates);
    EXPECT_EQ(again.contacts, st.contacts);
    EXPECT_EQ(again.memory_bytes, st.memory_bytes);
    set_topology(det, s); // so does a new topology
    det.detect(s.positions, &again);
    EXPECT_EQ(again.reused, 0);
}

TEST(CoreReuse, NoAllocationOnceWarm)
{
    for (int threads : {1, 2}) {
        Scene s = test::random_scene(9, 4, 3, 0.3);
        DetectParams p;
        p.skin = 0.06;
        p.threads = threads;
        Detector det(p);
        set_topology(det, s);
        std::mt19937 rng(9);
        Motion mo;
        mo.jump_every = 4;
        // Warm: one pass over a sequence of rebuilds and reuses grows every buffer to what the sequence needs; a
        // further pass over the same frames (the same calls after its first, a rebuild) must not allocate. At two
        // threads the dynamic schedule splits the work differently from call to call, so a thread's grown-only
        // buffers may still grow in a later pass: they must settle within a few passes.
        std::vector<Scene> frames;
        for (int step = 0; step < 16; ++step) {
            if (step > 0) step_scene(s, step, rng, mo);
            frames.push_back(s);
        }
        DetectStats st;
        for (const Scene& f : frames)
            det.detect(f.positions, &st);
        const Contact* data = det.contacts().data();
        long allocations = -1;
        for (int pass = 0; pass < (threads == 1 ? 1 : 6) && allocations != 0; ++pass) {
            int reused = 0, rebuilt = 0;
            g_allocations = 0;
            g_count_allocations = true;
            for (const Scene& f : frames) {
                det.detect(f.positions, &st);
                (st.reused ? reused : rebuilt) += 1;
            }
            g_count_allocations = false;
            allocations = g_allocations.load();
            EXPECT_GT(reused, 0);
            EXPECT_GT(rebuilt, 1);
        }
        EXPECT_EQ(allocations, 0) << threads << " threads";
        if (threads == 1) {
            EXPECT_EQ(det.contacts().data(), data);
        }
    }
}

TEST(CoreReuse, NonFinitePositionAfterReuseIsAnError)
{
    Scene s = test::random_scene(4, 3, 3, 0.3);
    DetectParams p;
    p.skin = 0.05;
    Detector det(p);
    set_topology(det, s);
    det.detect(s.positions);
    s.positions(17, 1) = std::numeric_limits<double>::quiet_NaN();
    try {
        det.detect(s.positions);
        FAIL() << "expected an Error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("vertex 17"), std::string::npos) << e.what();
    }
}

TEST(CoreReuse, BadSkinIsAnErrorNamingTheParameter)
{
    for (double bad :
         {-1.0, -1e-300, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
        DetectParams p;
        p.skin = bad;
        try {
            Detector det(p);
            FAIL() << "skin " << bad << " accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("skin"), std::string::npos) << e.what();
        }
        Detector det;
        EXPECT_THROW(det.set_params(p), Error);
        p.skin_mode = DetectParams::SkinMode::factor_of_cell_size;
        EXPECT_THROW(det.set_params(p), Error);
    }
}

TEST(CoreReuse, ThreadCountChangedBetweenCallsKeepsTheAnswer)
{
    // Detector::set_threads between calls (the simulator's count chosen step by step): every call equals a
    // from-scratch detection; a call on another count than the last runs a full detection (its kept candidates
    // were sorted by the old team), a call on the same count may reuse them; the set-up is kept (no ms_setup).
    const Motion mo{.angle = 0.002, .speed = 0.001, .jitter = 0.0002, .jump = 0.0, .period = 8, .jump_every = 0};
    Scene s = test::random_scene(11, 4, 3, 0.3);
    DetectParams p;
    p.skin = 0.06;
    p.threads = 1;
    Detector d(p);
    set_topology(d, s);
    DetectParams fresh_params = p;
    fresh_params.skin = 0;
    std::mt19937 rng(11);
    const int counts[] = {1, 1, 2, 2, 2, 1, 1, 2, 2, 1, 1, 1};
    int last = 1, reused_after_change = 0, reused_same = 0;
    for (int step = 0; step < 12; ++step) {
        if (step > 0) step_scene(s, step, rng, mo);
        d.set_threads(counts[step]);
        DetectStats st;
        const std::vector<Contact> got = d.detect(s.positions, &st);
        Detector fresh(fresh_params);
        set_topology(fresh, s);
        EXPECT_TRUE(identical(got, fresh.detect(s.positions))) << "step " << step;
        if (step > 0) {
            EXPECT_EQ(st.ms_setup, 0.0) << "step " << step << ": a new thread count must not redo the set-up";
            (counts[step] != last ? reused_after_change : reused_same) += st.reused;
        }
        last = counts[step];
    }
    EXPECT_EQ(reused_after_change, 0);
    EXPECT_GT(reused_same, 0);
    EXPECT_THROW(d.set_threads(-1), Error);
    EXPECT_EQ(d.params().threads, 1) << "a refused count leaves the last one";
}
