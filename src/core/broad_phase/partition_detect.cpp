// The exact stage every broad phase other than the hash feeds (docs/partitions.md): object rules, the closed exact
// inside test, then one sort by (vertex, tet). A thread's pairs are taken a tet at a time (the runs of equal tets its
// broad phase wrote): the tet's face planes are built once and tested against all its vertices at once with the
// hash's kernels (scan.hpp: AVX2, four faces in four lanes, or scalar), which reject the vertices certainly outside
// the tet; the few left (inside, or on a face within the filter's error) take the oracle's inside test
// (predicates.hpp; four pairs at a time with AVX2, inside_batch.hpp), whose values and barycentric coordinates they
// get bit for bit. Which thread found a pair and in which order does not matter: the coordinates depend on the point
// and the tet only, and the sort fixes the order, so the output is bit for bit the same for every method and thread
// count.
#include "partition_detect.hpp"

#include "../hash/scan.hpp"
#include "../team.hpp"
#include "../timing.hpp"
#include "inside_batch.hpp"
#include "tethash/predicates.hpp"

#include <algorithm>
#include <cassert>

namespace tethash::detail {

namespace {
/// Pairs per block of the oracle's inside test (each thread's buffers: 41 bytes per pair).
constexpr std::size_t batch_size = 1024;
/// Pairs of one tet from which its face planes are built (scan.hpp) and tested against all of them; a run of fewer
/// goes to the oracle's inside test directly (inside_batch.hpp), and so does every pair of a thread whose runs are
/// shorter than min_mean_run pairs on average: there the planes cost more than they save (scenario 5: 2.2 pairs per
/// run, the stage about 10 % slower with the planes; thin: 43, 2.2 times faster; docs/results.md).
constexpr std::int32_t min_run = 3;
constexpr std::size_t min_mean_run = 4;

/// Whether `method`'s broad phase queries tet by tet, so that a tet's pairs come in one run of a sink (or a few): its
/// runs are tested against the tet's face planes at once. The others query vertex by vertex (runs of one pair), and
/// their pairs are tested one by one. Only the speed depends on it.
bool pairs_by_tet(Method method)
{
    return method != Method::hierarchical_grid && method != Method::octree_loose && method != Method::bvh &&
           method != Method::bvh_refit;
}

/// Whether the pair's vertex is one of its tet's own: the broad phases leave those out (broad_phase.hpp).
[[maybe_unused]] bool own_vertex(const Index* tets, const CandidatePair& c)
{
    const Index* tv = tets + 4 * static_cast<std::size_t>(c.tet);
    return c.vertex == tv[0] || c.vertex == tv[1] || c.vertex == tv[2] || c.vertex == tv[3];
}
} // namespace

std::int64_t PartitionDetector::Work::bytes() const
{
    return static_cast<std::int64_t>((run.capacity() + vertex.capacity() + tet.capacity()) * sizeof(Index) +
                                     (values.capacity() + bary.capacity()) * sizeof(double) + codes.capacity() +
                                     kept.capacity() * sizeof(std::int32_t) + inside.capacity());
}

void PartitionDetector::reset()
{
    m_broad.reset();
}

std::int64_t PartitionDetector::memory_bytes() const
{
    std::int64_t m = m_broad ? m_broad->memory_bytes() : 0;
    for (const CandidateSink& s : m_sinks)
        m += static_cast<std::int64_t>(s.pairs.capacity() * sizeof(CandidatePair));
    for (const auto& f : m_found)
        m += static_cast<std::int64_t>(f.capacity() * sizeof(Found));
    m += static_cast<std::int64_t>(m_all.capacity() * sizeof(Found));
    for (const Work& w : m_work)
        m += w.bytes();
    return m;
}

void PartitionDetector::detect(Method method, const PartitionScene& scene, const Index* vertex_object,
                               const Index* tet_object, const ObjectFlags& flags, std::vector<Contact>& contacts,
                               DetectStats* stats)
{
    if (!m_broad || method != m_method || scene.first) {
        m_broad = make_broad_phase(method);
        m_method = method;
    }
    const int T = std::max(1, scene.threads);
    m_sinks.resize(static_cast<std::size_t>(T));
    m_found.resize(static_cast<std::size_t>(T));
    m_counts.assign(static_cast<std::size_t>(T), Counts{});
    m_work.resize(static_cast<std::size_t>(T));
    for (CandidateSink& s : m_sinks)
        s.pairs.clear();

    const BroadPhaseTimes times = m_broad->find(scene, m_sinks);

    // The exact stage, each thread over its own sink (the sinks' sizes are balanced enough for two to eight threads;
    // the broad phases split their queries evenly).
    const auto t_inside = Clock::now();
    const double* P = scene.positions;
    const bool by_tet = pairs_by_tet(method);
#pragma omp parallel num_threads(T) if (T > 1)
    {
        const int r = team_rank();
        std::vector<Found>& found = m_found[static_cast<std::size_t>(r)];
        found.clear();
        Counts& counts = m_counts[static_cast<std::size_t>(r)];
        Work& w = m_work[static_cast<std::size_t>(r)];
        w.vertex.resize(batch_size);
        w.tet.resize(batch_size);
        w.inside.resize(batch_size);
        w.bary.resize(4 * batch_size);
        // The oracle's inside test of the pairs the face planes left, a block at a time, in the sink's order.
        std::int32_t n = 0;
        auto flush = [&]() {
            counts.exact +=
                inside_tets(P, scene.tets, w.vertex.data(), w.tet.data(), n, w.inside.data(), w.bary.data());
            for (std::int32_t j = 0; j < n; ++j) {
                if (!w.inside[static_cast<std::size_t>(j)]) continue;
                Found& f = found.emplace_back();
                f.vertex = w.vertex[static_cast<std::size_t>(j)];
                f.tet = w.tet[static_cast<std::size_t>(j)];
                std::copy_n(w.bary.data() + 4 * static_cast<std::size_t>(j), 4, f.bary);
            }
            n = 0;
        };
        const std::vector<CandidatePair>& sink = m_sinks[static_cast<std::size_t>(r)].pairs;
        const CandidatePair* pairs = sink.data();
        const std::size_t num_pairs = sink.size();
        const unsigned char* self_flag = flags.self_collision.data();
        const unsigned char* static_flag = flags.is_static.data();
        std::int64_t tested = 0;
        // The object rules: a pair within an object without self-collision, or between two static objects, is not
        // tested.
        const auto ruled_out = [&](Index vo, Index to) {
            return (vo == to && !self_flag[to]) || (static_flag[to] && static_flag[vo]);
        };
        // A pair for the oracle's inside test, whose block is tested when full.
        const auto queue = [&](Index v, Index t) {
            w.vertex[static_cast<std::size_t>(n)] = v;
            w.tet[static_cast<std::size_t>(n)] = t;
            if (++n == static_cast<std::int32_t>(batch_size)) flush();
        };
        // Where the sink's runs of a tet are long on average (min_mean_run pairs; only the broad phases that query tet
        // by tet write runs longer than one pair), a run of min_run pairs or more against the tet's face planes at
        // once; any other pair straight to the oracle's test. Sorting the pairs of the broad phases that query vertex
        // by vertex by tet (two passes of a radix sort) cost more than the face planes saved.
        bool planes = by_tet && num_pairs > 0;
        if (planes) {
            std::size_t runs = 1;
            for (std::size_t i = 1; i < num_pairs; ++i)
                runs += pairs[i].tet != pairs[i - 1].tet;
            planes = num_pairs >= min_mean_run * runs;
        }
        const std::size_t ahead = planes ? static_cast<std::size_t>(min_run) - 1 : num_pairs;
        auto starts_run = [&](std::size_t i, Index t) {
            if (i + ahead >= num_pairs) return false;
            for (std::size_t k = 1; k <= ahead; ++k)
                if (pairs[i + k].tet != t) return false;
            return true;
        };
        for (std::size_t i = 0; i < num_pairs;) {
            const Index t = pairs[i].tet;
            if (!starts_run(i, t)) {
                const Index v = pairs[i++].vertex;
                assert(!own_vertex(scene.tets, {v, t}));
                if (ruled_out(vertex_object[v], tet_object[t])) continue;
                ++tested;
                queue(v, t);
                continue;
            }
            // The run of tet t: the pairs up to the next other tet; those that pass the object rules in w.run.
            std::size_t end = i + ahead + 1;
            while (end < num_pairs && pairs[end].tet == t)
                ++end;
            assert(std::none_of(pairs + i, pairs + end,
                                [&](const CandidatePair& c) { return own_vertex(scene.tets, c); }));
            if (w.run.size() < end - i) {
                w.run.resize(std::max(end - i, 2 * w.run.size()));
                w.values.resize(4 * w.run.size());
                w.codes.resize(w.run.size());
                w.kept.resize(w.run.size());
            }
            const Index to = tet_object[t];
            std::int32_t count = 0;
            for (; i < end; ++i) {
                const Index v = pairs[i].vertex;
                w.run[static_cast<std::size_t>(count)] = v;
                count += !ruled_out(vertex_object[v], to);
            }
            if (count == 0) continue;
            tested += count;
            // The tet's face planes with its orientation folded in (its exact sign; 0: flat, no vertex inside), tested
            // against the run's vertices at once; those not certainly outside go to the oracle's test.
            const Index* tv = scene.tets + 4 * static_cast<std::size_t>(t);
            FacePlanes f;
            bool tet_exact = false;
            const int sign = face_planes(
                P + 3 * static_cast<std::size_t>(tv[0]), P + 3 * static_cast<std::size_t>(tv[1]),
                P + 3 * static_cast<std::size_t>(tv[2]), P + 3 * static_cast<std::size_t>(tv[3]), f, tet_exact);
            counts.exact += tet_exact;
            if (sign == 0) continue;
            const std::int32_t num_kept =
                filter_candidates(f, P, w.run.data(), count, w.values.data(), w.codes.data(), w.kept.data());
            for (std::int32_t k = 0; k < num_kept; ++k)
                queue(w.run[static_cast<std::size_t>(w.kept[static_cast<std::size_t>(k)])], t);
        }
        counts.inside_tests += tested;
        flush();
    }
    const double ms_inside = ms_since(t_inside);
    if (stats) { // degenerate tets, as the hash path counts them: every tet once (not timed with the exact stage)
#pragma omp parallel num_threads(T) if (T > 1)
        {
            const int r = team_rank();
            std::int64_t begin = 0, end = 0;
            team_split(scene.num_tets, r, team_size(), begin, end);
            for (std::int64_t t = begin; t < end; ++t) {
                const Index* tv = scene.tets + 4 * static_cast<std::size_t>(t);
                m_counts[static_cast<std::size_t>(r)].degenerate +=
                    predicates::orient3d(
                        P + 3 * static_cast<std::size_t>(tv[0]), P + 3 * static_cast<std::size_t>(tv[1]),
                        P + 3 * static_cast<std::size_t>(tv[2]), P + 3 * static_cast<std::size_t>(tv[3]))
                        .sign == 0;
            }
        }
    }

    const auto t_sort = Clock::now();
    m_all.clear();
    for (const auto& f : m_found)
        m_all.insert(m_all.end(), f.begin(), f.end());
    std::sort(m_all.begin(), m_all.end(), [](const Found& a, const Found& b) {
        return a.vertex < b.vertex || (a.vertex == b.vertex && a.tet < b.tet);
    });
    contacts.resize(m_all.size());
    for (std::size_t i = 0; i < m_all.size(); ++i) {
        Contact& c = contacts[i];
        const Found& f = m_all[i];
        c = Contact{};
        c.vertex = f.vertex;
        c.tet = f.tet;
        c.vertex_object = vertex_object[f.vertex];
        c.tet_object = tet_object[f.tet];
        std::copy(f.bary, f.bary + 4, c.bary);
    }
    const double ms_sort = ms_since(t_sort);

    if (stats) {
        DetectStats& s = *stats;
        s = DetectStats{};
        s.ms_vertices = times.ms_build;
        s.ms_tets = times.ms_query;
        s.ms_inside = ms_inside;
        s.ms_sort = ms_sort;
        s.cell_size = scene.cell_size;
        s.threads = T;
        s.vertices = scene.num_vertices;
        s.tets = scene.num_tets;
        for (const CandidateSink& sink : m_sinks)
            s.candidates += static_cast<std::int64_t>(sink.pairs.size());
        for (const Counts& c : m_counts) {
            s.inside_tests += c.inside_tests;
            s.exact_fallbacks += c.exact;
            s.degenerate_tets += c.degenerate;
        }
        s.contacts = static_cast<std::int64_t>(contacts.size());
        s.memory_bytes = memory_bytes();
        s.nodes = m_broad->nodes();
        m_broad->add_counters(s);
    }
}

} // namespace tethash::detail
