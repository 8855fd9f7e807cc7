// The loose octree over the tets as a broad phase (docs/partitions.md): cubic cells enlarged by a
// looseness factor, each tet stored in one cell (the deepest on its path whose loose box contains its box), each
// vertex descending through the cells whose loose box contains it. Rebuilt
// every call.
//
// The root cell is the cube around the union of the tet boxes; its loose box also covers that union exactly. A cell
// of half edge h and centre c has the loose box c ± looseness·h, its children the centres c ± h/2. A tet descends from
// the root, each time to the child whose octant holds its box centre, as long as that child's loose box (computed
// once, stored in the node) contains its box and the depth is below max_depth; it is stored where it stops. A vertex
// visits a node only when the node's stored loose box contains it; a tet's box lies in the stored loose box of every
// node on its path (each step checked it), so a vertex in the box reaches the tet's node: no pair is missed whatever
// the rounding and the looseness (≥ 1). Each tet is in one node and each node is visited once per vertex, so each
// pair is found once. Subtrees without tets are not entered.
#include "bp_common.hpp"

#include <algorithm>

namespace tethash::detail {

namespace {

class LooseOctree final : public BroadPhaseBase {
  public:
    std::int64_t nodes() const override { return static_cast<std::int64_t>(m_nodes.size()); }

    static constexpr int default_max_depth = 10;
    static constexpr double default_looseness = 2;

  private:
    bool build_phase(const PartitionScene& scene, int threads) override;
    void query_phase(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    struct Node {
        Box loose;                  ///< the cell's box enlarged by the looseness (the root's: also every tet box)
        double centre[3], half;     ///< the cell itself: centre ± half
        Index children = -1;        ///< first of 8 consecutive children, -1 while none
        Index first = 0, count = 0; ///< its tets: m_items[first, first + count)
        Index below = 0;            ///< tets in its subtree
    };
    /// Appends the 8 children of node i.
    void split(Index i, double looseness);
    std::int64_t structure_bytes() const override
    {
        return bytes_of(m_nodes, m_boxes, m_node_of, m_items, m_item_boxes);
    }

    std::vector<Node> m_nodes;
    std::vector<Box> m_boxes;      // per tet
    std::vector<Index> m_node_of;  // per tet: its node
    std::vector<Index> m_items;    // tets by node
    std::vector<Box> m_item_boxes; // their boxes
};

bool contains(const Box& outer, const Box& inner)
{
    return outer.lo[0] <= inner.lo[0] && outer.lo[1] <= inner.lo[1] && outer.lo[2] <= inner.lo[2] &&
           outer.hi[0] >= inner.hi[0] && outer.hi[1] >= inner.hi[1] && outer.hi[2] >= inner.hi[2];
}

void LooseOctree::split(Index i, double looseness)
{
    const Index first = static_cast<Index>(m_nodes.size());
    m_nodes[static_cast<std::size_t>(i)].children = first;
    const Node parent = m_nodes[static_cast<std::size_t>(i)];
    const double h = 0.5 * parent.half;
    for (int k = 0; k < 8; ++k) {
        Node child;
        child.half = h;
        for (int a = 0; a < 3; ++a) {
            child.centre[a] = parent.centre[a] + ((k >> a & 1) ? h : -h);
            child.loose.lo[a] = child.centre[a] - looseness * h;
            child.loose.hi[a] = child.centre[a] + looseness * h;
        }
        m_nodes.push_back(child);
    }
}

bool LooseOctree::build_phase(const PartitionScene& s, int threads)
{
    const Index n = s.num_vertices, m = s.num_tets;
    m_nodes.clear();
    if (n == 0 || m == 0) return false;
    const double looseness = s.params.looseness > 0 ? s.params.looseness : default_looseness;
    const int max_depth = s.params.max_depth > 0 ? s.params.max_depth : default_max_depth;

    tet_boxes(s, m_boxes, threads);
    Node root;
    root.loose = m_boxes[0];
    for (const Box& b : m_boxes)
        for (int a = 0; a < 3; ++a) {
            root.loose.lo[a] = std::min(root.loose.lo[a], b.lo[a]);
            root.loose.hi[a] = std::max(root.loose.hi[a], b.hi[a]);
        }
    root.half = 0;
    for (int a = 0; a < 3; ++a) {
        root.centre[a] = 0.5 * (root.loose.lo[a] + root.loose.hi[a]);
        root.half = std::max(root.half, 0.5 * (root.loose.hi[a] - root.loose.lo[a]));
    }
    for (int a = 0; a < 3; ++a) { // the loose cube, and never less than the union of the boxes
        root.loose.lo[a] = std::min(root.loose.lo[a], root.centre[a] - looseness * root.half);
        root.loose.hi[a] = std::max(root.loose.hi[a], root.centre[a] + looseness * root.half);
    }
    m_nodes.push_back(root);

    // Insertion (serial: it grows the tree).
    m_node_of.resize(static_cast<std::size_t>(m));
    for (Index t = 0; t < m; ++t) {
        const Box& b = m_boxes[static_cast<std::size_t>(t)];
        const double mid[3] = {0.5 * (b.lo[0] + b.hi[0]), 0.5 * (b.lo[1] + b.hi[1]), 0.5 * (b.lo[2] + b.hi[2])};
        Index node = 0;
        for (int depth = 0; depth < max_depth; ++depth) {
            const Node cur = m_nodes[static_cast<std::size_t>(node)];
            const int k = (mid[0] >= cur.centre[0] ? 1 : 0) | (mid[1] >= cur.centre[1] ? 2 : 0) |
                          (mid[2] >= cur.centre[2] ? 4 : 0);
            // The child's loose box before creating the children: creating them for a tet that does not fit
            // would grow the tree where nothing is stored.
            const double h = 0.5 * cur.half;
            Box loose;
            for (int a = 0; a < 3; ++a) {
                const double c = cur.centre[a] + ((k >> a & 1) ? h : -h);
                loose.lo[a] = c - looseness * h;
                loose.hi[a] = c + looseness * h;
            }
            if (!contains(loose, b)) break;
            if (cur.children < 0) split(node, looseness);
            const Index child = m_nodes[static_cast<std::size_t>(node)].children + k;
            // What the queries use is the stored box: checked again (the same expression, but the compiler may
            // contract it differently in the two places).
            if (!contains(m_nodes[static_cast<std::size_t>(child)].loose, b)) break;
            node = child;
        }
        m_node_of[static_cast<std::size_t>(t)] = node;
        ++m_nodes[static_cast<std::size_t>(node)].count;
    }
    // The tets by node (counting sort), and the subtree counts (children come after their parent).
    Index offset = 0;
    for (Node& node : m_nodes) {
        node.first = offset;
        offset += node.count;
        node.count = 0;
    }
    m_items.resize(static_cast<std::size_t>(m));
    m_item_boxes.resize(static_cast<std::size_t>(m));
    for (Index t = 0; t < m; ++t) {
        Node& node = m_nodes[static_cast<std::size_t>(m_node_of[static_cast<std::size_t>(t)])];
        const Index i = node.first + node.count++;
        m_items[static_cast<std::size_t>(i)] = t;
        m_item_boxes[static_cast<std::size_t>(i)] = m_boxes[static_cast<std::size_t>(t)];
    }
    for (std::size_t i = m_nodes.size(); i-- > 0;) {
        Node& node = m_nodes[i];
        node.below = node.count;
        if (node.children >= 0)
            for (int k = 0; k < 8; ++k)
                node.below += m_nodes[static_cast<std::size_t>(node.children + k)].below;
    }
    return true;
}

void LooseOctree::query_phase(const PartitionScene& s, std::vector<CandidateSink>& sinks)
{
    const Node* nodes = m_nodes.data();
    for_each_vertex(s, m_static, sinks, [&](Index v, const double* p, bool vertex_static, auto& out) {
        Index stack[8 * (40 + 1)]; // depth ≤ 40: at most 7 pending siblings per level
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& node = nodes[stack[--top]];
            if (node.below == 0 || !in_box(p, node.loose.lo, node.loose.hi)) continue;
            find_in_boxes(s, p, v, vertex_static, m_items.data(), m_item_boxes.data(), node.first,
                          node.first + node.count, out);
            if (node.children >= 0)
                for (int k = 0; k < 8; ++k)
                    stack[top++] = node.children + k;
        }
    });
}

} // namespace

std::unique_ptr<BroadPhase> make_loose_octree()
{
    return std::make_unique<LooseOctree>();
}

} // namespace tethash::detail
