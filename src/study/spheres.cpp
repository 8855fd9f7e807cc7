// The spheres experiment of the octree / k-d / BSP comparison (study/spheres.hpp, docs/results.md).
#include "tethash/study/spheres.hpp"

#include "report.hpp"

#include "core/timing.hpp"

#include "core/broad_phase/split_tree.hpp"
#include "tethash/error.hpp"
#include "tethash/study/json.hpp"
#include "tethash/study/table.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>
#include <set>
#include <utility>

namespace tethash::study {

namespace {

using Vec = std::array<double, 3>;
using tethash::detail::ms_since;
using Pair = std::pair<std::uint32_t, std::uint32_t>;

constexpr double kGravity = -9.81; ///< m/s^2 along z
constexpr double kWallBounce = 0.3;
constexpr double kDamping = 0.995; ///< velocity kept per frame

struct Method {
    std::string name;
    bool brute = false;
    SplitRule rule = SplitRule::point_kd;
    int depth = 0;
    SplitTree tree;
    SpheresSummary total;
};

/// Sphere-sphere test: the centres closer than the diameter (touching spheres do not collide).
bool collide(const Vec& a, const Vec& b, double d2)
{
    const double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
    return x * x + y * y + z * z < d2;
}

/// The pairs of the frame by testing every pair; returns the number of tests.
std::int64_t brute_pairs(const std::vector<Vec>& c, double d2, std::vector<Pair>& out)
{
    const auto n = static_cast<std::uint32_t>(c.size());
    for (std::uint32_t i = 0; i < n; ++i)
        for (std::uint32_t j = i + 1; j < n; ++j)
            if (collide(c[i], c[j], d2)) out.emplace_back(i, j);
    return static_cast<std::int64_t>(n) * (n - 1) / 2;
}

/// Scratch of the leaf pass: the leaves of each sphere (CSR) and a stamp per sphere.
struct LeafScratch {
    std::vector<std::uint32_t> offsets, fill, leaves, stamp;
};

/// The pairs sharing a leaf, each unordered pair tested once although it may share several leaves: for each
/// sphere i, the spheres j > i of its leaves, a stamp marking the j already tested for this i. Returns the
/// number of tests.
std::int64_t tree_pairs(const SplitTree& tree, const std::vector<Vec>& c, double d2, LeafScratch& s,
                        std::vector<Pair>& out)
{
    const std::size_t n = c.size();
    const std::size_t nl = tree.leaf_count();
    s.offsets.assign(n + 1, 0);
    for (std::size_t l = 0; l < nl; ++l)
        for (std::uint32_t id : tree.leaf_items(l))
            ++s.offsets[id + 1];
    for (std::size_t i = 0; i < n; ++i)
        s.offsets[i + 1] += s.offsets[i];
    s.fill.assign(s.offsets.begin(), s.offsets.end() - 1);
    s.leaves.resize(s.offsets[n]);
    for (std::size_t l = 0; l < nl; ++l)
        for (std::uint32_t id : tree.leaf_items(l))
            s.leaves[s.fill[id]++] = static_cast<std::uint32_t>(l);
    s.stamp.assign(n, std::numeric_limits<std::uint32_t>::max());
    std::int64_t tests = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
        for (std::uint32_t k = s.offsets[i]; k < s.offsets[i + 1]; ++k) {
            const auto ids = tree.leaf_items(s.leaves[k]);
            for (auto it = std::upper_bound(ids.begin(), ids.end(), i); it != ids.end(); ++it) { // ids ascending
                const std::uint32_t j = *it;
                if (s.stamp[j] == i) continue;
                s.stamp[j] = i;
                ++tests;
                if (collide(c[i], c[j], d2)) out.emplace_back(i, j);
            }
        }
    }
    return tests;
}

/// FNV-1a of the sorted pair list: equal lists give equal hashes (a column the tests compare with brute's).
std::uint64_t pairs_hash(const std::vector<Pair>& p)
{
    std::uint64_t h = 1469598103934665603ULL;
    for (const auto& [a, b] : p)
        for (std::uint32_t v : {a, b})
            for (int k = 0; k < 4; ++k) {
                h ^= (v >> (8 * k)) & 0xFFU;
                h *= 1099511628211ULL;
            }
    return h;
}

std::string hex(std::uint64_t v)
{
    char buf[24];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
    return buf;
}

/// Positional response in the sorted pair order (the same for every method): each pair pushed apart by half
/// the overlap each along the centre line, the approaching normal velocity removed; then the walls.
void respond(std::vector<Vec>& x, std::vector<Vec>& v, const std::vector<Pair>& pairs, double r)
{
    for (const auto& [i, j] : pairs) {
        Vec d{x[j][0] - x[i][0], x[j][1] - x[i][1], x[j][2] - x[i][2]};
        double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (len < 1e-12) { // coincident centres: separate along x
            d = {1, 0, 0};
            len = 1;
        } else {
            for (double& e : d)
                e /= len;
        }
        const double push = 0.5 * std::max(0.0, 2 * r - len);
        const double vn = (v[j][0] - v[i][0]) * d[0] + (v[j][1] - v[i][1]) * d[1] + (v[j][2] - v[i][2]) * d[2];
        for (std::size_t a = 0; a < 3; ++a) {
            x[i][a] -= push * d[a];
            x[j][a] += push * d[a];
            if (vn < 0) {
                v[i][a] += 0.5 * vn * d[a];
                v[j][a] -= 0.5 * vn * d[a];
            }
        }
    }
    for (std::size_t i = 0; i < x.size(); ++i)
        for (std::size_t a = 0; a < 3; ++a) {
            if (x[i][a] < r) {
                x[i][a] = r;
                if (v[i][a] < 0) v[i][a] = -kWallBounce * v[i][a];
            } else if (x[i][a] > 1 - r) {
                x[i][a] = 1 - r;
                if (v[i][a] > 0) v[i][a] = -kWallBounce * v[i][a];
            }
        }
}

/// The options of the run, as spheres.json's "options" object.
void write_options(JsonWriter& j, const SpheresOptions& o)
{
    j.begin_object()
        .member("spheres", o.spheres)
        .member("frames", o.frames)
        .member("radius", o.radius)
        .member("seed", static_cast<std::int64_t>(o.seed))
        .member("leaf_size", o.leaf_size)
        .member("dt", o.dt)
        .end_object();
}

/// DIR/spheres.json of a run that took `seconds`: command, machine, options, the frames done and each method's
/// totals (res.summary).
void write_spheres_json(const SpheresOptions& o, const SpheresResult& res, double seconds)
{
    JsonWriter j;
    j.begin_object().member("tethash_spheres", 1);
    write_run_members(j, o.command_line, o.compiler_flags);
    j.key("options");
    write_options(j, o);
    j.member("frames_done", res.frames_done)
        .member("interrupted", res.interrupted)
        .member("rows", res.rows)
        .member("seconds", seconds);
    j.key("summary").begin_array(JsonWriter::block_layout);
    for (const SpheresSummary& m : res.summary)
        j.begin_object(JsonWriter::inline_layout)
            .member("method", m.method)
            .member("depth", m.depth)
            .member("total_ms", m.total_ms)
            .member("mean_ms", res.frames_done ? m.total_ms / res.frames_done : 0.0)
            .member("tests", m.tests)
            .member("collisions", m.collisions)
            .end_object();
    j.end_array().end_object();
    write_json_file(res.json_path, j);
}

} // namespace

void check_spheres_options(const SpheresOptions& o)
{
    if (o.spheres < 1 || o.spheres > 1000000)
        throw Error("--spheres: must be 1..1000000, found " + std::to_string(o.spheres));
    if (o.frames < 1 || o.frames > 10000000)
        throw Error("--frames: must be 1..10000000, found " + std::to_string(o.frames));
    if (o.methods.empty()) throw Error("--methods: empty list");
    std::set<std::string> seen;
    for (const auto& m : o.methods) {
        if (m != "brute" && !parse_split_rule(m))
            throw Error("--methods: unknown method '" + m +
                        "' (brute, octree, octree-point, kd, kd-point, bsp, bsp-balanced)");
        if (!seen.insert(m).second) throw Error("--methods: '" + m + "' given twice");
    }
    if (o.depths.empty()) throw Error("--depths: empty list");
    std::set<int> depths;
    for (int d : o.depths) {
        if (d < 0 || d > 30) throw Error("--depths: each must be 0..30, found " + std::to_string(d));
        if (!depths.insert(d).second) throw Error("--depths: " + std::to_string(d) + " given twice");
    }
    if (!(o.radius > 0 && o.radius < 0.25))
        throw Error("--radius: must be in (0, 0.25) (the box is the unit cube), found " + fmt_double(o.radius));
    if (o.leaf_size < 1) throw Error("--leaf-size: must be >= 1, found " + std::to_string(o.leaf_size));
    if (!(o.dt > 0 && o.dt <= 1)) throw Error("--dt: must be in (0, 1], found " + fmt_double(o.dt));
    check_out_dir(o.out_dir);
}

SpheresResult run_spheres(const SpheresOptions& o, const SpheresHooks& hooks)
{
    check_spheres_options(o);
    std::vector<Method> methods;
    for (const auto& name : o.methods) {
        if (name == "brute") {
            methods.push_back({});
            methods.back().name = name;
            methods.back().brute = true;
            continue;
        }
        for (int d : o.depths) {
            methods.push_back({});
            Method& m = methods.back();
            m.name = name;
            m.rule = *parse_split_rule(name);
            m.depth = d;
            m.tree.set_params({m.rule, d, o.leaf_size});
        }
    }
    for (auto& m : methods) {
        m.total.method = m.name;
        m.total.depth = m.depth;
    }

    make_out_dir(o.out_dir);
    SpheresResult res;
    res.csv_path = (std::filesystem::path(o.out_dir) / "spheres.csv").string();
    res.json_path = (std::filesystem::path(o.out_dir) / "spheres.json").string();
    CsvWriter csv;
    csv.open(res.csv_path, {"method", "depth", "frame", "spheres", "time_ms", "build_ms", "tests", "collisions",
                            "collision_hash", "nodes", "leaves", "items_stored", "tree_depth"});

    const double r = o.radius;
    const double d2 = 4 * r * r;
    std::mt19937_64 rng(o.seed);
    std::uniform_real_distribution<double> drop(r, 1 - r);
    std::vector<Vec> x, v;
    std::vector<SplitBox> boxes;
    std::vector<Pair> reference, pairs;
    LeafScratch scratch;
    const auto started = tethash::detail::Clock::now();

    for (int frame = 0; frame < o.frames; ++frame) {
        if (hooks.stop && hooks.stop->load()) {
            res.interrupted = true;
            break;
        }
        if (frame < o.spheres) { // one new sphere at the top, at rest
            const double px = drop(rng);
            const double py = drop(rng);
            x.push_back({px, py, 1 - r});
            v.push_back({0, 0, 0});
        }
        for (std::size_t i = 0; i < x.size(); ++i) { // gravity, damping, motion
            v[i][2] += kGravity * o.dt;
            for (std::size_t a = 0; a < 3; ++a) {
                v[i][a] *= kDamping;
                x[i][a] += v[i][a] * o.dt;
            }
        }
        for (std::size_t i = 0; i < x.size(); ++i) // keep the centres in the box before detection
            for (std::size_t a = 0; a < 3; ++a)
                x[i][a] = std::clamp(x[i][a], r, 1 - r);
        boxes.resize(x.size());
        for (std::size_t i = 0; i < x.size(); ++i)
            for (std::size_t a = 0; a < 3; ++a) {
                boxes[i].lo[a] = x[i][a] - r;
                boxes[i].hi[a] = x[i][a] + r;
            }

        for (std::size_t k = 0; k < methods.size(); ++k) {
            Method& m = methods[k];
            pairs.clear();
            std::int64_t tests = 0;
            double build_ms = 0;
            const auto t0 = tethash::detail::Clock::now();
            if (m.brute) {
                tests = brute_pairs(x, d2, pairs);
            } else {
                m.tree.build(boxes);
                build_ms = ms_since(t0);
                tests = tree_pairs(m.tree, x, d2, scratch, pairs);
            }
            const double ms = ms_since(t0);
            std::sort(pairs.begin(), pairs.end());
            if (k == 0) {
                reference.swap(pairs);
            } else if (pairs != reference) {
                throw RunFailure("spheres: frame " + std::to_string(frame) + ": " + m.name + " depth " +
                                 std::to_string(m.depth) + " found " + std::to_string(pairs.size()) +
                                 " colliding pairs, " + methods[0].name + " " + std::to_string(reference.size()) +
                                 " (different sets)");
            }
            const std::vector<Pair>& mine = k == 0 ? reference : pairs;
            m.total.total_ms += ms;
            m.total.tests += tests;
            m.total.collisions += static_cast<std::int64_t>(mine.size());
            Row row{m.name,
                    std::to_string(m.depth),
                    std::to_string(frame),
                    std::to_string(x.size()),
                    fmt_double(ms),
                    fmt_double(build_ms),
                    std::to_string(tests),
                    std::to_string(mine.size()),
                    hex(pairs_hash(mine))};
            if (m.brute) {
                row.insert(row.end(), {"0", "0", "0", "0"});
            } else {
                const auto st = m.tree.stats();
                row.insert(row.end(), {std::to_string(st.nodes), std::to_string(st.leaves),
                                       std::to_string(st.items_stored), std::to_string(st.max_depth)});
            }
            csv.write(row);
            ++res.rows;
        }
        respond(x, v, reference, r);
        res.frames_done = frame + 1;
        if (hooks.on_frame) hooks.on_frame(frame, o.frames);
    }
    csv.close();

    for (const auto& m : methods)
        res.summary.push_back(m.total);
    write_spheres_json(o, res, ms_since(started) / 1000);
    return res;
}

} // namespace tethash::study
