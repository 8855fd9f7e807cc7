// A bounding-volume hierarchy over the tet boxes as a broad phase (docs/partitions.md): binned
// surface-area-heuristic build, point queries per vertex. One class for both methods: `bvh` rebuilds every call,
// `bvh_refit` builds on the first call and then refits the boxes bottom-up, rebuilding when refitting has degraded
// the tree (its summed node surface area, relative to the root's, more than twice that of the last build).
//
// Build: top-down; a node's items are split on the axis of the largest extent of their box centres into 16 bins,
// at the bin border of least surface-area cost (area × items on either side); items whose centres all fall in one bin
// are split at the median centre, coincident centres at the middle of the list. A node becomes a leaf at leaf_size
// items (default 4) or max_depth (default 40). The tree is stored depth first (the left child follows its parent),
// so a refit is one backward pass. Query: every vertex descends the nodes whose closed box contains it and tests the
// boxes of the tets in the leaves it reaches (parallel over vertices). Each tet is in one leaf and a vertex reaches a
// leaf at most once, so each pair is found once; a box contains the boxes below it (unions, no rounding), so a vertex
// in a tet's box reaches its leaf.
#include "bp_common.hpp"

#include <algorithm>
#include <cmath>

namespace tethash::detail {

namespace {

class Bvh final : public BroadPhaseBase {
  public:
    explicit Bvh(bool refit) : m_refit(refit) {}
    std::int64_t nodes() const override { return static_cast<std::int64_t>(m_nodes.size()); }

    static constexpr int default_leaf_size = 4;
    static constexpr int default_max_depth = 40;
    /// Refitted trees are rebuilt when quality() exceeds this factor times its value after the last build.
    static constexpr double degradation = 2.0;

    /// Builds (the first call's included) and refits since the object was made.
    BroadPhaseCounts counts() const override { return {m_builds, m_refits}; }
    /// Summed surface area of the nodes over the root's: the surface-area heuristic's measure of the nodes a query
    /// visits (lower is better; grows as refitted boxes swell and overlap).
    double quality() const;

  private:
    bool build_phase(const PartitionScene& scene, int threads) override;
    void query_phase(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    struct Node {
        Box box;
        Index right; ///< internal: the right child (the left one is the next node)
        Index first; ///< leaf: its first item
        Index count; ///< leaf: its items (> 0); internal: 0
    };
    void build(const PartitionScene& s);
    Index build_node(Index begin, Index end, int depth);
    void refit();
    std::int64_t structure_bytes() const override
    {
        return bytes_of(m_nodes, m_items, m_boxes, m_item_boxes, m_centroids);
    }

    bool m_refit;
    int m_leaf_size = default_leaf_size, m_max_depth = default_max_depth;
    std::int64_t m_builds = 0, m_refits = 0;
    double m_built_quality = 0;
    std::vector<Node> m_nodes;       // depth-first order: children after their parent
    std::vector<Index> m_items;      // tets by leaf
    std::vector<Box> m_boxes;        // per tet
    std::vector<Box> m_item_boxes;   // per item (leaf order)
    std::vector<double> m_centroids; // per tet (3), during the build
};

constexpr int bins = 16;

void grow(Box& b, const Box& o)
{
    for (int a = 0; a < 3; ++a) {
        b.lo[a] = std::min(b.lo[a], o.lo[a]);
        b.hi[a] = std::max(b.hi[a], o.hi[a]);
    }
}

Box empty_box()
{
    Box b;
    for (int a = 0; a < 3; ++a) {
        b.lo[a] = HUGE_VAL;
        b.hi[a] = -HUGE_VAL;
    }
    return b;
}

double area(const Box& b)
{
    const double x = b.hi[0] - b.lo[0], y = b.hi[1] - b.lo[1], z = b.hi[2] - b.lo[2];
    return x < 0 ? 0 : 2 * (x * y + y * z + z * x);
}

double Bvh::quality() const
{
    if (m_nodes.empty()) return 0;
    double sum = 0;
    for (const Node& n : m_nodes)
        sum += area(n.box);
    const double root = area(m_nodes[0].box);
    return root > 0 ? sum / root : 0;
}

Index Bvh::build_node(Index begin, Index end, int depth)
{
    const Index self = static_cast<Index>(m_nodes.size());
    m_nodes.push_back({empty_box(), -1, begin, end - begin});
    Box box = empty_box(), centres = empty_box();
    for (Index i = begin; i < end; ++i) {
        const Index t = m_items[static_cast<std::size_t>(i)];
        grow(box, m_boxes[static_cast<std::size_t>(t)]);
        const double* c = m_centroids.data() + 3 * static_cast<std::size_t>(t);
        grow(centres, Box{{c[0], c[1], c[2]}, {c[0], c[1], c[2]}});
    }
    m_nodes[static_cast<std::size_t>(self)].box = box;
    const Index count = end - begin;
    if (count <= m_leaf_size || depth >= m_max_depth) return self;

    int axis = 0;
    for (int a = 1; a < 3; ++a)
        if (centres.hi[a] - centres.lo[a] > centres.hi[axis] - centres.lo[axis]) axis = a;
    const double lo = centres.lo[axis], extent = centres.hi[axis] - centres.lo[axis];
    auto centre = [&](Index t) {
        return m_centroids[3 * static_cast<std::size_t>(t) + static_cast<std::size_t>(axis)];
    };
    Index* items = m_items.data();
    Index mid = begin + count / 2; // coincident centres: the middle of the list
    if (extent > 0) {
        // (c − lo) / extent ∈ [0, 1] also for tiny extents (bins / extent could overflow).
        auto bin_of = [&](Index t) { return std::min(bins - 1, static_cast<int>((centre(t) - lo) / extent * bins)); };
        Box bin_box[bins];
        Index bin_count[bins] = {};
        for (Box& b : bin_box)
            b = empty_box();
        for (Index i = begin; i < end; ++i) {
            const Index t = items[i];
            const int k = bin_of(t);
            grow(bin_box[k], m_boxes[static_cast<std::size_t>(t)]);
            ++bin_count[k];
        }
        // Cost of splitting after bin k: left area × left items + right area × right items.
        double right_cost[bins];
        Box acc = empty_box();
        Index acc_count = 0;
        for (int k = bins - 1; k > 0; --k) {
            grow(acc, bin_box[k]);
            acc_count += bin_count[k];
            right_cost[k] = area(acc) * acc_count;
        }
        acc = empty_box();
        acc_count = 0;
        int best = -1;
        double best_cost = HUGE_VAL;
        for (int k = 0; k < bins - 1; ++k) {
            grow(acc, bin_box[k]);
            acc_count += bin_count[k];
            if (acc_count == 0 || acc_count == count) continue;
            const double cost = area(acc) * acc_count + right_cost[k + 1];
            if (cost < best_cost) {
                best_cost = cost;
                best = k;
            }
        }
        if (best >= 0) {
            mid = static_cast<Index>(
                std::partition(items + begin, items + end, [&](Index t) { return bin_of(t) <= best; }) - items);
        } else { // every centre in one bin: the median centre
            std::nth_element(items + begin, items + mid, items + end, [&](Index a, Index b) {
                return centre(a) < centre(b) || (centre(a) == centre(b) && a < b);
            });
        }
    }
    m_nodes[static_cast<std::size_t>(self)].count = 0;
    build_node(begin, mid, depth + 1);
    const Index right = build_node(mid, end, depth + 1);
    m_nodes[static_cast<std::size_t>(self)].right = right;
    return self;
}

void Bvh::build(const PartitionScene& s)
{
    const Index m = s.num_tets;
    m_leaf_size = s.params.leaf_size > 0 ? s.params.leaf_size : default_leaf_size;
    m_max_depth = s.params.max_depth > 0 ? s.params.max_depth : default_max_depth;
    m_centroids.resize(3 * static_cast<std::size_t>(m));
    m_items.resize(static_cast<std::size_t>(m));
    for (Index t = 0; t < m; ++t) {
        const Box& b = m_boxes[static_cast<std::size_t>(t)];
        for (int a = 0; a < 3; ++a)
            m_centroids[3 * static_cast<std::size_t>(t) + static_cast<std::size_t>(a)] = 0.5 * (b.lo[a] + b.hi[a]);
        m_items[static_cast<std::size_t>(t)] = t;
    }
    m_nodes.clear();
    build_node(0, m, 0);
    m_item_boxes.resize(static_cast<std::size_t>(m));
    for (Index i = 0; i < m; ++i)
        m_item_boxes[static_cast<std::size_t>(i)] =
            m_boxes[static_cast<std::size_t>(m_items[static_cast<std::size_t>(i)])];
    m_built_quality = quality();
    ++m_builds;
}

void Bvh::refit()
{
    for (std::size_t i = 0; i < m_items.size(); ++i)
        m_item_boxes[i] = m_boxes[static_cast<std::size_t>(m_items[i])];
    for (std::size_t i = m_nodes.size(); i-- > 0;) {
        Node& n = m_nodes[i];
        if (n.count > 0) {
            n.box = m_item_boxes[static_cast<std::size_t>(n.first)];
            for (Index k = 1; k < n.count; ++k)
                grow(n.box, m_item_boxes[static_cast<std::size_t>(n.first + k)]);
        } else {
            n.box = m_nodes[i + 1].box;
            grow(n.box, m_nodes[static_cast<std::size_t>(n.right)].box);
        }
    }
    ++m_refits;
}

bool Bvh::build_phase(const PartitionScene& s, int threads)
{
    const Index n = s.num_vertices, m = s.num_tets;
    if (n == 0 || m == 0) {
        m_nodes.clear();
        return false;
    }
    tet_boxes(s, m_boxes, threads);
    if (!m_refit || s.first || m_items.size() != static_cast<std::size_t>(m)) {
        build(s);
    } else {
        refit();
        if (quality() > degradation * m_built_quality) build(s);
    }
    return true;
}

void Bvh::query_phase(const PartitionScene& s, std::vector<CandidateSink>& sinks)
{
    const Node* nodes = m_nodes.data();
    for_each_vertex(s, m_static, sinks, [&](Index v, const double* p, bool vertex_static, auto& out) {
        Index stack[2 * default_max_depth + 8]; // depth ≤ 40: at most one pending sibling per level
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Index i = stack[--top];
            const Node& node = nodes[i];
            if (!in_box(p, node.box.lo, node.box.hi)) continue;
            if (node.count > 0) {
                find_in_boxes(s, p, v, vertex_static, m_items.data(), m_item_boxes.data(), node.first,
                              node.first + node.count, out);
                continue;
            }
            stack[top++] = node.right;
            stack[top++] = i + 1;
        }
    });
}

} // namespace

std::unique_ptr<BroadPhase> make_bvh(bool refit)
{
    return std::make_unique<Bvh>(refit);
}

} // namespace tethash::detail
