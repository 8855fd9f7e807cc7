#pragma once
// The loose octree over the tets as a broad phase (private header; docs/partitions.md): cubic cells enlarged by a
// looseness factor, each tet stored in one cell (the deepest on its path whose loose box contains its box), each
// vertex descending through the cells whose loose box contains it.
#include "bp_common.hpp"

namespace tethash::detail {

class LooseOctree final : public BroadPhase {
  public:
    BroadPhaseTimes find(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    std::int64_t memory_bytes() const override;
    std::int64_t nodes() const override { return static_cast<std::int64_t>(m_nodes.size()); }

    static constexpr int default_max_depth = 10;
    static constexpr double default_looseness = 2;

  private:
    struct Node {
        Box loose;                  ///< the cell's box enlarged by the looseness (the root's: also every tet box)
        double centre[3], half;     ///< the cell itself: centre ± half
        Index children = -1;        ///< first of 8 consecutive children, -1 while none
        Index first = 0, count = 0; ///< its tets: m_items[first, first + count)
        Index below = 0;            ///< tets in its subtree
    };
    /// Appends the 8 children of node i.
    void split(Index i, double looseness);

    std::vector<Node> m_nodes;
    std::vector<Box> m_boxes;      // per tet
    std::vector<Index> m_node_of;  // per tet: its node
    std::vector<Index> m_items;    // tets by node
    std::vector<Box> m_item_boxes; // their boxes
    std::vector<unsigned char> m_static;
};

} // namespace tethash::detail
