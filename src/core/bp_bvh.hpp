#pragma once
// A bounding-volume hierarchy over the tet boxes as a broad phase (private header; docs/partitions.md): binned
// surface-area-heuristic build, point queries per vertex. One class for both methods: `bvh` rebuilds every call,
// `bvh_refit` builds on the first call and then refits the boxes bottom-up, rebuilding when refitting has degraded
// the tree (its summed node surface area, relative to the root's, more than twice that of the last build).
#include "bp_common.hpp"

namespace tethash::detail {

class Bvh final : public BroadPhase {
  public:
    explicit Bvh(bool refit) : m_refit(refit) {}
    BroadPhaseTimes find(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    std::int64_t memory_bytes() const override;
    std::int64_t nodes() const override { return static_cast<std::int64_t>(m_nodes.size()); }

    static constexpr int default_leaf_size = 4;
    static constexpr int default_max_depth = 40;
    /// Refitted trees are rebuilt when quality() exceeds this factor times its value after the last build.
    static constexpr double degradation = 2.0;

    /// Builds (the first call's included) and refits since the object was made.
    std::int64_t builds() const { return m_builds; }
    std::int64_t refits() const { return m_refits; }
    /// Summed surface area of the nodes over the root's: the surface-area heuristic's measure of the nodes a query
    /// visits (lower is better; grows as refitted boxes swell and overlap).
    double quality() const;

  private:
    struct Node {
        Box box;
        Index right; ///< internal: the right child (the left one is the next node)
        Index first; ///< leaf: its first item
        Index count; ///< leaf: its items (> 0); internal: 0
    };
    void build(const PartitionScene& s);
    Index build_node(Index begin, Index end, int depth);
    void refit();

    bool m_refit;
    int m_leaf_size = default_leaf_size, m_max_depth = default_max_depth;
    std::int64_t m_builds = 0, m_refits = 0;
    double m_built_quality = 0;
    std::vector<Node> m_nodes;       // depth-first order: children after their parent
    std::vector<Index> m_items;      // tets by leaf
    std::vector<Box> m_boxes;        // per tet
    std::vector<Box> m_item_boxes;   // per item (leaf order)
    std::vector<double> m_centroids; // per tet (3), during the build
    std::vector<unsigned char> m_static;
};

} // namespace tethash::detail
