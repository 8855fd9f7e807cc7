#pragma once
// The hierarchical hash grid of Mirtich 1998 as a broad phase (private header; docs/partitions.md): levels of doubling
// cell size from the detector's cell size, each tet on the finest level where its box spans at most two cells per
// axis, stored once under the cell of its box's min corner in one hash table keyed by (level, cell); each vertex looks
// up, on every occupied level, the 2 × 2 × 2 cells at and below its own.
#include "bp_common.hpp"

namespace tethash::detail {

class HierarchicalGrid final : public BroadPhase {
  public:
    BroadPhaseTimes find(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    std::int64_t memory_bytes() const override;
    /// Occupied levels (plus one when some tets exceed the top level).
    std::int64_t nodes() const override { return m_nodes; }

    static constexpr int max_levels = 32;

  private:
    /// A tet in the table: its box, level and min-corner cell, so that a scan compares the exact cell.
    struct Entry {
        Box box;
        std::int64_t cell[3];
        Index tet;
        std::int32_t level;
    };
    std::int64_t m_nodes = 0;
    std::vector<Box> m_boxes;
    std::vector<std::int32_t> m_level;   // per tet: its level, or -1 when it exceeds the top level
    std::vector<std::uint64_t> m_bucket; // per tet: its bucket
    std::vector<std::int64_t> m_cell;    // per tet: its min-corner cell (3)
    std::vector<Index> m_start;          // buckets + 1
    std::vector<Entry> m_entries;        // by bucket
    std::vector<Index> m_big;            // tets exceeding the top level
    VerticesByX m_sorted;                // with tets beyond the top level: the vertices by x
    std::vector<unsigned char> m_static;
};

} // namespace tethash::detail
