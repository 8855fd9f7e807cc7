#pragma once
// Sort and sweep as a broad phase (private header; docs/partitions.md): the vertices and the tet boxes sorted on the
// axis of largest variance, the orders kept across calls and repaired by insertion sort (temporal coherence).
#include "bp_common.hpp"

namespace tethash::detail {

class SortSweep final : public BroadPhase {
  public:
    BroadPhaseTimes find(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    std::int64_t memory_bytes() const override;
    std::int64_t nodes() const override { return 0; }

    /// Calls whose orders were repaired by insertion sort, and calls that sorted from scratch (first call, new
    /// axis, or an insertion sort that exceeded its budget of moves).
    std::int64_t incremental_sorts() const { return m_incremental; }
    std::int64_t full_sorts() const { return m_full; }

  private:
    struct Key {
        double x;
        Index id;
    };
    int m_axis = -1;
    std::int64_t m_incremental = 0, m_full = 0;
    std::vector<Key> m_points; // vertices by their coordinate on the axis
    std::vector<Key> m_tets;   // tets by their box's low end on the axis
    std::vector<Box> m_boxes;
    std::vector<double> m_xyz; // the vertices' positions in the sorted order
    std::vector<unsigned char> m_static;
};

} // namespace tethash::detail
