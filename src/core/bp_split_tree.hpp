#pragma once
// The splitting-plane trees as broad phases (private header; docs/partitions.md): the region and point octree, the
// region and point k-d tree and the two BSP rules are one SplitTree (split_tree.hpp) over the vertices as points,
// queried with every tet's box.
#include "bp_common.hpp"
#include "tethash/split_tree.hpp"

namespace tethash::detail {

class SplitTreeBroadPhase final : public BroadPhase {
  public:
    explicit SplitTreeBroadPhase(SplitRule rule) : m_rule(rule) {}
    BroadPhaseTimes find(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    std::int64_t memory_bytes() const override;
    std::int64_t nodes() const override { return m_nodes; }

  private:
    SplitRule m_rule;
    SplitTree m_tree;
    std::vector<SplitBox> m_points;               // per vertex: its position as a box
    std::vector<unsigned char> m_static;          // per vertex: 1 for static objects
    std::vector<std::vector<std::uint32_t>> m_found; // per thread: query output
    std::vector<SplitTreeScratch> m_scratch;      // per thread
    std::int64_t m_nodes = 0;
};

} // namespace tethash::detail
