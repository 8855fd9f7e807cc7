#pragma once
// Pieces shared by the broad phases (private header): tet boxes of a whole scene, the cell coordinate every grid uses
// for points and box corners alike, per-vertex static flags, the vertices sorted by x, the parallel loops over
// vertices and tets that feed the threads' sinks, a timer.
#include "../hash/table_size.hpp"
#include "../team.hpp"
#include "../timing.hpp"
#include "broad_phase.hpp"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <vector>

namespace tethash::detail {

/// A closed axis-aligned box.
struct Box {
    double lo[3], hi[3];
};

/// boxes[t] = the closed bounding box of tet t, for every tet (parallel over `threads`).
void tet_boxes(const PartitionScene& s, std::vector<Box>& boxes, int threads);

/// The closed bounding box of the vertices (num_vertices ≥ 1). Every tet box lies in it.
Box vertex_box(const PartitionScene& s);

/// flags[v] = 1 for the vertices of static objects, 0 otherwise (size num_vertices).
void static_vertex_flags(const PartitionScene& s, std::vector<unsigned char>& flags);

/// Largest cell coordinate magnitude: coordinates are clamped to ±2^62 (monotone, so still exact; cells merge).
inline constexpr double max_cell = 4611686018427387904.0; // 2^62

/// Cell coordinate floor((x − origin) · inv) of a point or a box corner, clamped to ±2^62. The grids use this one
/// expression for points and for box corners: it is monotone in x (each operation rounds monotonically), so a point
/// p with lo ≤ p ≤ hi has cell(lo) ≤ cell(p) ≤ cell(hi), also on cell borders and far from the origin.
inline std::int64_t cell_coord(double x, double origin, double inv)
{
    double c = std::floor((x - origin) * inv);
    c = c < -max_cell ? -max_cell : (c > max_cell ? max_cell : c);
    return static_cast<std::int64_t>(c);
}

/// The vertices sorted by x (ties by id) with their x: the vertices in a box are in its x-range of the list.
struct VerticesByX {
    std::vector<Index> order;
    std::vector<double> xs;
    void build(const PartitionScene& s);
    /// Appends (v, t) for every vertex v in the closed box b, except static vertices when `skip_static`
    /// (`vertex_static`: per vertex, 1 for static).
    void find(const PartitionScene& s, const Box& b, Index t, bool skip_static, const unsigned char* vertex_static,
              std::vector<CandidatePair>& out) const;
    std::int64_t memory_bytes() const;
};

/// Whether v is one of tet t's own four vertices: never a contact, so no broad phase hands it on (a tet box holds its
/// own corners: left in, they would be most of the candidates).
inline bool own_vertex(const PartitionScene& s, Index v, Index t)
{
    const Index* tv = s.tets + 4 * static_cast<std::size_t>(t);
    return v == tv[0] || v == tv[1] || v == tv[2] || v == tv[3];
}

/// Appends the candidate (v, t) unless both are static (`tet_static`: tet t's flag; `vertex_static`: per vertex, 1
/// for static) or v is one of t's own vertices.
inline void add_candidate(const PartitionScene& s, Index v, Index t, bool tet_static,
                          const unsigned char* vertex_static, std::vector<CandidatePair>& out)
{
    if (!(tet_static && vertex_static[v]) && !own_vertex(s, v, t)) out.push_back({v, t});
}

/// Appends (v, items[k]) for each k in [first, last) whose box boxes[k] contains p, except static tets when
/// `vertex_static`, and the tets v belongs to: a vertex against the tets of a leaf or cell.
inline void find_in_boxes(const PartitionScene& s, const double* p, Index v, bool vertex_static, const Index* items,
                          const Box* boxes, Index first, Index last, std::vector<CandidatePair>& out)
{
    for (Index k = first; k < last; ++k) {
        if (!in_box(p, boxes[k].lo, boxes[k].hi)) continue;
        const Index t = items[k];
        if ((vertex_static && s.tet_static[t]) || own_vertex(s, v, t)) continue;
        out.push_back({v, t});
    }
}

/// Calls f(v, p, vertex_static, out) for every vertex v (position p) in parallel over the sinks' threads, out being
/// the calling thread's sink. Dynamic chunks: which thread finds a pair does not matter (the exact stage sorts).
template <class F>
void for_each_vertex(const PartitionScene& s, const std::vector<unsigned char>& vertex_static,
                     std::vector<CandidateSink>& sinks, F&& f)
{
    const int T = static_cast<int>(sinks.size());
#pragma omp parallel num_threads(T) if (T > 1)
    {
        std::vector<CandidatePair>& out = sinks[static_cast<std::size_t>(team_rank())].pairs;
#pragma omp for schedule(dynamic, 256)
        for (Index v = 0; v < s.num_vertices; ++v)
            f(v, s.positions + 3 * static_cast<std::size_t>(v), vertex_static[static_cast<std::size_t>(v)] != 0, out);
    }
}

/// Calls f(i, out) for i in [0, count) in parallel over the sinks' threads (dynamic chunks of `chunk`).
template <class F> void for_each_index(Index count, int chunk, std::vector<CandidateSink>& sinks, F&& f)
{
    const int T = static_cast<int>(sinks.size());
#pragma omp parallel num_threads(T) if (T > 1)
    {
        std::vector<CandidatePair>& out = sinks[static_cast<std::size_t>(team_rank())].pairs;
#pragma omp for schedule(dynamic, chunk)
        for (Index i = 0; i < count; ++i)
            f(i, out);
    }
}

/// Times a find() call's two phases: the build from construction to end_build(), the query from there to
/// end_query(), which returns both.
class PhaseTimer {
  public:
    void end_build()
    {
        m_times.ms_build = ms_since(m_start);
        m_start = std::chrono::steady_clock::now();
    }
    BroadPhaseTimes end_query()
    {
        m_times.ms_query = ms_since(m_start);
        return m_times;
    }

  private:
    std::chrono::steady_clock::time_point m_start = std::chrono::steady_clock::now();
    BroadPhaseTimes m_times;
};

/// Capacities of vectors in bytes, summed.
template <class... T> std::int64_t bytes_of(const std::vector<T>&... v)
{
    return (std::int64_t{0} + ... + static_cast<std::int64_t>(v.capacity() * sizeof(T)));
}

/// What every broad phase keeps besides its structure, and the frame of its find(): build_phase() makes (or updates)
/// the structure, the per-vertex static flags of the call follow (counted by memory_bytes() with the structure's own
/// bytes), then query_phase() fills the sinks; the two phases are timed apart (PhaseTimer).
class BroadPhaseBase : public BroadPhase {
  public:
    BroadPhaseTimes find(const PartitionScene& scene, std::vector<CandidateSink>& sinks) final;
    std::int64_t memory_bytes() const final { return structure_bytes() + bytes_of(m_static); }

  protected:
    /// Builds or updates the structure for the scene, `threads` being the sinks' count (the team of its parallel
    /// loops). False when there is nothing to find (no vertex or no tet): the call then returns zero times.
    virtual bool build_phase(const PartitionScene& scene, int threads) = 0;
    /// Appends the candidates to the sinks (BroadPhase::find), after a build that returned true.
    virtual void query_phase(const PartitionScene& scene, std::vector<CandidateSink>& sinks) = 0;
    /// Working memory of the structure itself.
    virtual std::int64_t structure_bytes() const = 0;

    std::vector<unsigned char> m_static; ///< per vertex: 1 for the vertices of static objects
};

} // namespace tethash::detail
