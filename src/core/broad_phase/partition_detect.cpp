// The exact stage every broad phase other than the hash feeds (docs/partitions.md): object rules,
// the closed exact inside test (predicates.hpp, the oracle's; four pairs at a time with AVX2, inside_batch.hpp),
// then one sort by (vertex, tet). Which thread found a
// pair and in which order does not matter: the barycentric coordinates depend on the point and the tet only, and the
// sort fixes the order, so the output is bit for bit the same for every method and thread count.
#include "partition_detect.hpp"

#include "../team.hpp"
#include "../timing.hpp"
#include "inside_batch.hpp"
#include "tethash/predicates.hpp"

#include <algorithm>
#include <cassert>

namespace tethash::detail {

namespace {
/// Pairs per block of the exact stage (each thread's buffers: 36 bytes per pair).
constexpr std::size_t batch_size = 1024;
} // namespace

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
    for (const Batch& b : m_batches)
        m += static_cast<std::int64_t>((b.vertex.capacity() + b.tet.capacity()) * sizeof(Index) + b.inside.capacity() +
                                       b.bary.capacity() * sizeof(double));
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
    m_batches.resize(static_cast<std::size_t>(T));
    for (CandidateSink& s : m_sinks)
        s.pairs.clear();

    const BroadPhaseTimes times = m_broad->find(scene, m_sinks);

    // The exact stage, each thread over its own sink (the sinks' sizes are balanced enough for two to eight threads;
    // the broad phases split their queries evenly).
    const auto t_inside = Clock::now();
    const double* P = scene.positions;
#pragma omp parallel num_threads(T) if (T > 1)
    {
        const int r = team_rank();
        std::vector<Found>& found = m_found[static_cast<std::size_t>(r)];
        found.clear();
        Counts& counts = m_counts[static_cast<std::size_t>(r)];
        // The pairs that pass the object rules, a block at a time, then their inside tests at once (four per step
        // with AVX2), in the sink's order.
        Batch& batch = m_batches[static_cast<std::size_t>(r)];
        batch.vertex.resize(batch_size);
        batch.tet.resize(batch_size);
        batch.inside.resize(batch_size);
        batch.bary.resize(4 * batch_size);
        std::int32_t n = 0;
        auto flush = [&]() {
            counts.inside_tests += n;
            counts.exact += inside_tets(P, scene.tets, batch.vertex.data(), batch.tet.data(), n, batch.inside.data(),
                                        batch.bary.data());
            for (std::int32_t j = 0; j < n; ++j) {
                if (!batch.inside[static_cast<std::size_t>(j)]) continue;
                Found& f = found.emplace_back();
                f.vertex = batch.vertex[static_cast<std::size_t>(j)];
                f.tet = batch.tet[static_cast<std::size_t>(j)];
                std::copy_n(batch.bary.data() + 4 * static_cast<std::size_t>(j), 4, f.bary);
            }
            n = 0;
        };
        for (const CandidatePair& c : m_sinks[static_cast<std::size_t>(r)].pairs) {
            // A tet's own vertices are left out by the broad phases (broad_phase.hpp).
            assert([&] {
                const Index* tv = scene.tets + 4 * static_cast<std::size_t>(c.tet);
                return c.vertex != tv[0] && c.vertex != tv[1] && c.vertex != tv[2] && c.vertex != tv[3];
            }());
            const Index vo = vertex_object[c.vertex], to = tet_object[c.tet];
            if (vo == to && !flags.self_collision[static_cast<std::size_t>(to)]) continue;
            if (flags.is_static[static_cast<std::size_t>(to)] && flags.is_static[static_cast<std::size_t>(vo)])
                continue;
            batch.vertex[static_cast<std::size_t>(n)] = c.vertex;
            batch.tet[static_cast<std::size_t>(n)] = c.tet;
            if (++n == static_cast<std::int32_t>(batch_size)) flush();
        }
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
