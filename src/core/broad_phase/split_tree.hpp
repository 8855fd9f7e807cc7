#pragma once
/// \file split_tree.hpp
/// One splitting-plane tree over axis-aligned boxes, parameterised by its splitting rule: the region and
/// point octree, the region and point k-d tree and the BSP tree (as compared experimentally in the literature
/// the project reproduces, docs/partitions.md) are the same structure with different planes. A point is a box
/// with lo == hi.
///
/// Exact broad phase: `query` reports every item whose closed box intersects the closed query box, each
/// once, and nothing else. Items straddling a plane are stored in both children; point items never
/// straddle (a point on a plane goes to its upper side), so point items are stored once.
///
/// Build is serial and deterministic; `query` is const and may run from several threads at once (each
/// thread passes its own `SplitTreeScratch`). Buffers are kept across builds.
///
/// Internal to tethash (the tree broad phases and the spheres study), not installed.

#include "tethash/error.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tethash {

/// Closed axis-aligned box, lo <= hi per axis (a point when lo == hi).
struct SplitBox {
    std::array<double, 3> lo{0, 0, 0};
    std::array<double, 3> hi{0, 0, 0};
};

/// How a node chooses its plane(s).
enum class SplitRule : std::uint8_t {
    region_octree, ///< 3 axis planes through the centre of the node's region (8 children)
    point_octree,  ///< 3 axis planes through the per-axis median of the item centres (8 children)
    region_kd,     ///< one axis plane at the mid-plane of the node's region, axis x, y, z cycling with depth
    point_kd,      ///< one axis plane at the median of the item centres, axis cycling with depth
    bsp,           ///< the comparison paper's plane: through the median point, normal rotated (see docs/partitions.md)
    bsp_balanced,  ///< among 7 candidate normals, the median plane with the fewest items in its larger side
};

/// "octree", "octree-point", "kd", "kd-point", "bsp", "bsp-balanced".
std::string_view split_rule_name(SplitRule rule);
/// The rule of a name of `split_rule_name`; nullopt for any other text.
std::optional<SplitRule> parse_split_rule(std::string_view name);
/// Default maximum depth: 5 for the octrees (8^5 = 32768 leaves at most), 12 for k-d and BSP (4096 leaves).
int default_split_depth(SplitRule rule);

struct SplitTreeParams {
    SplitRule rule = SplitRule::point_kd;
    int max_depth = -1; ///< root has depth 0; -1 = default_split_depth(rule); 0..30
    int leaf_size = 8;  ///< a node with <= leaf_size items is a leaf; >= 1
};

struct SplitTreeStats {
    std::int64_t nodes = 0;        ///< all nodes, leaves included
    std::int64_t leaves = 0;       ///< nodes without children (empty octree children included)
    int max_depth = 0;             ///< deepest node reached (root = 0)
    std::int64_t items = 0;        ///< items built over
    std::int64_t items_stored = 0; ///< item ids in the leaves (straddlers counted once per leaf)
    std::int64_t bytes = 0;        ///< memory of nodes, leaf lists and item boxes (capacity)
};

/// Per-caller query state: a stamp per item, so that an item stored in several leaves is reported once.
/// Needed only when the tree stores duplicates (`SplitTree::stores_duplicates`); one per thread.
struct SplitTreeScratch {
    std::vector<std::uint32_t> stamp;
    std::uint32_t round = 0;
};

class SplitTree {
  public:
    SplitTree() = default;
    explicit SplitTree(SplitTreeParams params);

    /// Sets the parameters of the next builds. Throws Error on max_depth outside -1..30 or leaf_size < 1.
    void set_params(SplitTreeParams params);
    const SplitTreeParams& params() const { return m_params; }

    /// Builds over `boxes` (item id = index). Throws Error on a non-finite coordinate or lo > hi (naming the
    /// item), or on more than 2^31 - 1 items. An empty span gives an empty tree.
    void build(std::span<const SplitBox> boxes);

    /// Appends to `out` every item whose closed box intersects the closed box `q`, each once, in an order
    /// fixed by the tree (not sorted). `scratch` is used only when `stores_duplicates()`.
    void query(const SplitBox& q, std::vector<std::uint32_t>& out, SplitTreeScratch& scratch) const;
    /// Same, without a scratch: sorts and deduplicates the appended ids when the tree stores duplicates
    /// (ascending order then; otherwise the tree's order).
    void query(const SplitBox& q, std::vector<std::uint32_t>& out) const;

    /// True when some item is stored in more than one leaf.
    bool stores_duplicates() const { return m_duplicates; }
    std::size_t size() const { return m_boxes.size(); }

    /// Number of leaves, and the ids of leaf `k` (ascending); empty leaves included.
    std::size_t leaf_count() const { return m_leaves.size(); }
    std::span<const std::uint32_t> leaf_items(std::size_t k) const;
    /// Depth of leaf `k` (root = 0).
    int leaf_depth(std::size_t k) const;

    SplitTreeStats stats() const;

  private:
    struct Node {
        /// kind 0: leaf; 1: one axis plane (axis, value[axis]); 2: three axis planes (value[0..2]), 8 children;
        /// 3: general plane normal (value[0..2]) and offset `offset`, margin in `margin`.
        std::array<double, 3> value{0, 0, 0};
        double offset = 0;
        double margin = 0;
        std::uint32_t first = 0; ///< leaf: first id in m_items; inner: first child node
        std::uint32_t count = 0; ///< leaf: ids; inner: children (2 or 8)
        std::uint8_t kind = 0;
        std::uint8_t axis = 0;
        std::uint8_t depth = 0;
    };
    void build_node(std::uint32_t node, std::size_t begin, std::size_t end, int depth, const SplitBox& region,
                    const std::array<double, 3>& parent_ref, bool has_parent_ref);
    bool partition(const Node& split, std::size_t begin, std::size_t end, std::size_t children,
                   std::array<std::size_t, 9>& bounds);
    void make_leaf(std::uint32_t node, std::size_t begin, std::size_t end, int depth);
    template <class Emit> void walk(std::uint32_t node, const SplitBox& q, double q_scale, Emit& emit) const;
    double median(std::size_t begin, std::size_t end, const std::array<double, 3>& dir, bool separate);

    SplitTreeParams m_params;
    int m_depth_limit = 12;
    std::vector<SplitBox> m_boxes;
    std::vector<std::uint8_t> m_is_point;
    std::vector<Node> m_nodes;
    std::vector<std::uint32_t> m_items;  ///< leaf lists, concatenated
    std::vector<std::uint32_t> m_leaves; ///< node index of each leaf
    std::vector<std::uint32_t> m_work;   ///< build: item lists of the nodes on the current path
    std::vector<double> m_values;        ///< build: median selection
    std::vector<std::uint8_t> m_sides;   ///< build: sides each item of a node reaches
    double m_scale = 0;                  ///< max |coordinate| of the items (plane margins)
    int m_reached = 0;
    bool m_duplicates = false;
};

} // namespace tethash
