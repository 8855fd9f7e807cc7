// The splitting-plane tree: octree, k-d tree and BSP tree as one structure (split_tree.hpp, docs/partitions.md).
#include "split_tree.hpp"

#include "../enum_names.hpp"
#include "tethash/error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tethash {

namespace {

using Vec = std::array<double, 3>;

/// Relative error bound of the plane expression n.x - d over a box corner (3 products, 3 sums, |n| <= 1 per
/// axis): a few units in the last place of the sum of absolute terms; 1e-14 leaves a wide safety factor.
constexpr double kPlaneEps = 1e-14;

double dot(const Vec& a, const Vec& b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

double norm1(const Vec& a)
{
    return std::abs(a[0]) + std::abs(a[1]) + std::abs(a[2]);
}

Vec centre(const SplitBox& b)
{
    return {0.5 * (b.lo[0] + b.hi[0]), 0.5 * (b.lo[1] + b.hi[1]), 0.5 * (b.lo[2] + b.hi[2])};
}

/// Computed min and max of n.x - d over the box (corner chosen per sign of n).
void plane_range(const SplitBox& b, const Vec& n, double d, double& lo, double& hi)
{
    Vec a, z;
    for (int k = 0; k < 3; ++k) {
        const auto u = static_cast<std::size_t>(k);
        a[u] = n[u] >= 0 ? b.lo[u] : b.hi[u];
        z[u] = n[u] >= 0 ? b.hi[u] : b.lo[u];
    }
    lo = dot(n, a) - d;
    hi = dot(n, z) - d;
}

double max_abs(const SplitBox& b)
{
    double m = 0;
    for (int k = 0; k < 3; ++k) {
        const auto u = static_cast<std::size_t>(k);
        m = std::max({m, std::abs(b.lo[u]), std::abs(b.hi[u])});
    }
    return m;
}

bool overlaps(const SplitBox& a, const SplitBox& b)
{
    return a.lo[0] <= b.hi[0] && a.hi[0] >= b.lo[0] && a.lo[1] <= b.hi[1] && a.hi[1] >= b.lo[1] && a.lo[2] <= b.hi[2] &&
           a.hi[2] >= b.lo[2];
}

Vec unit_axis(int a)
{
    Vec v{0, 0, 0};
    v[static_cast<std::size_t>(a)] = 1;
    return v;
}

bool is_region_rule(SplitRule r)
{
    return r == SplitRule::region_octree || r == SplitRule::region_kd;
}

constexpr detail::EnumName<SplitRule> k_split_rule_names[] = {{SplitRule::region_octree, "octree"},
                                                              {SplitRule::point_octree, "octree-point"},
                                                              {SplitRule::region_kd, "kd"},
                                                              {SplitRule::point_kd, "kd-point"},
                                                              {SplitRule::bsp, "bsp"},
                                                              {SplitRule::bsp_balanced, "bsp-balanced"}};

} // namespace

std::string_view split_rule_name(SplitRule rule)
{
    return detail::name_of(k_split_rule_names, rule);
}

std::optional<SplitRule> parse_split_rule(std::string_view name)
{
    return detail::value_named(k_split_rule_names, name);
}

int default_split_depth(SplitRule rule)
{
    return rule == SplitRule::region_octree || rule == SplitRule::point_octree ? 5 : 12;
}

SplitTree::SplitTree(SplitTreeParams params)
{
    set_params(params);
}

void SplitTree::set_params(SplitTreeParams params)
{
    if (params.max_depth < -1 || params.max_depth > 30)
        throw Error("split tree: max_depth must be -1 (default) or 0..30, found " + std::to_string(params.max_depth));
    if (params.leaf_size < 1)
        throw Error("split tree: leaf_size must be >= 1, found " + std::to_string(params.leaf_size));
    m_params = params;
    m_depth_limit = params.max_depth < 0 ? default_split_depth(params.rule) : params.max_depth;
}

void SplitTree::build(std::span<const SplitBox> boxes)
{
    if (boxes.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
        throw Error("split tree: more than 2^31 - 1 items (" + std::to_string(boxes.size()) + ")");
    m_depth_limit = m_params.max_depth < 0 ? default_split_depth(m_params.rule) : m_params.max_depth;
    const std::size_t n = boxes.size();
    m_boxes.assign(boxes.begin(), boxes.end());
    m_is_point.resize(n);
    SplitBox root;
    m_scale = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const SplitBox& b = boxes[i];
        bool point = true;
        for (std::size_t a = 0; a < 3; ++a) {
            if (!std::isfinite(b.lo[a]) || !std::isfinite(b.hi[a]))
                throw Error("split tree: item " + std::to_string(i) + " has a non-finite coordinate");
            if (b.lo[a] > b.hi[a])
                throw Error("split tree: item " + std::to_string(i) + " has lo > hi on axis " + std::to_string(a));
            point = point && b.lo[a] == b.hi[a];
            root.lo[a] = i == 0 ? b.lo[a] : std::min(root.lo[a], b.lo[a]);
            root.hi[a] = i == 0 ? b.hi[a] : std::max(root.hi[a], b.hi[a]);
        }
        m_is_point[i] = point ? 1 : 0;
        m_scale = std::max(m_scale, max_abs(b));
    }
    m_nodes.clear();
    m_items.clear();
    m_leaves.clear();
    m_work.resize(n);
    for (std::size_t i = 0; i < n; ++i)
        m_work[i] = static_cast<std::uint32_t>(i);
    m_reached = 0;
    m_duplicates = false;
    m_nodes.emplace_back();
    build_node(0, 0, n, 0, root, Vec{0, 0, 0}, false);
    m_duplicates = m_items.size() > n;
}

void SplitTree::make_leaf(std::uint32_t node, std::size_t begin, std::size_t end, int depth)
{
    Node& nd = m_nodes[node];
    nd.kind = 0;
    nd.depth = static_cast<std::uint8_t>(depth);
    nd.first = static_cast<std::uint32_t>(m_items.size());
    nd.count = static_cast<std::uint32_t>(end - begin);
    m_items.insert(m_items.end(), m_work.begin() + static_cast<std::ptrdiff_t>(begin),
                   m_work.begin() + static_cast<std::ptrdiff_t>(end));
    m_leaves.push_back(node);
    m_reached = std::max(m_reached, depth);
}

/// Median of the item centres projected on `dir` over m_work[begin, end). With `separate`, a value that leaves
/// at least one centre strictly below it when the centres are not all equal (the lower median may be the
/// minimum when many centres coincide: then the next larger value).
double SplitTree::median(std::size_t begin, std::size_t end, const Vec& dir, bool separate)
{
    const std::size_t n = end - begin;
    m_values.resize(n);
    for (std::size_t i = 0; i < n; ++i)
        m_values[i] = dot(dir, centre(m_boxes[m_work[begin + i]]));
    const auto mid = m_values.begin() + static_cast<std::ptrdiff_t>(n / 2);
    std::nth_element(m_values.begin(), mid, m_values.end());
    const double m = *mid;
    if (!separate) return m;
    if (std::any_of(m_values.begin(), mid, [m](double v) { return v < m; })) return m;
    double next = std::numeric_limits<double>::infinity();
    for (double v : m_values)
        if (v > m) next = std::min(next, v);
    return std::isfinite(next) ? next : m;
}

void SplitTree::build_node(std::uint32_t node, std::size_t begin, std::size_t end, int depth, const SplitBox& region,
                           const Vec& parent_ref, bool has_parent_ref)
{
    const std::size_t n = end - begin;
    if (n <= static_cast<std::size_t>(m_params.leaf_size) || depth >= m_depth_limit) {
        make_leaf(node, begin, end, depth);
        return;
    }
    const SplitRule rule = m_params.rule;
    Node split;
    split.depth = static_cast<std::uint8_t>(depth);
    Vec ref{0, 0, 0}; // the plane's reference point (BSP: the median point), handed to the children
    switch (rule) {
    case SplitRule::region_octree:
        split.kind = 2;
        for (std::size_t a = 0; a < 3; ++a)
            split.value[a] = 0.5 * (region.lo[a] + region.hi[a]);
        break;
    case SplitRule::point_octree:
        split.kind = 2;
        for (int a = 0; a < 3; ++a)
            split.value[static_cast<std::size_t>(a)] = median(begin, end, unit_axis(a), true);
        break;
    case SplitRule::region_kd:
    case SplitRule::point_kd: {
        split.kind = 1;
        split.axis = static_cast<std::uint8_t>(depth % 3);
        const std::size_t a = split.axis;
        split.value[a] = rule == SplitRule::region_kd ? 0.5 * (region.lo[a] + region.hi[a])
                                                      : median(begin, end, unit_axis(split.axis), true);
        break;
    }
    case SplitRule::bsp:
    case SplitRule::bsp_balanced: {
        split.kind = 3;
        for (int a = 0; a < 3; ++a)
            ref[static_cast<std::size_t>(a)] = median(begin, end, unit_axis(a), false);
        // The paper's normal: from the median point to the parent's reference point, rotated by 90 degrees
        // about x, then y, then z. Rz(90) Ry(90) Rx(90) maps (a, b, c) to (c, b, -a).
        Vec normal{0, 0, 0};
        const Vec d{parent_ref[0] - ref[0], parent_ref[1] - ref[1], parent_ref[2] - ref[2]};
        const double len = std::sqrt(dot(d, d));
        if (has_parent_ref && len > 1e-12 * std::max(m_scale, 1e-300)) {
            normal = {d[2] / len, d[1] / len, -d[0] / len};
        } else if (!has_parent_ref) {
            // Root: the axis of largest extent of the items.
            int best = 0;
            for (int a = 1; a < 3; ++a) {
                const auto u = static_cast<std::size_t>(a);
                const auto b = static_cast<std::size_t>(best);
                if (region.hi[u] - region.lo[u] > region.hi[b] - region.lo[b]) best = a;
            }
            normal = unit_axis(best);
        } else {
            normal = unit_axis(depth % 3); // median point on the parent's: no direction
        }
        if (rule == SplitRule::bsp) {
            split.value = normal;
            split.offset = dot(normal, ref);
        } else {
            // Balance heuristic: the paper's normal, the 3 axes and the 3 face diagonals, each with the plane at
            // the median of the projected centres; the one whose larger side (straddlers counted) is smallest.
            const double r = 1 / std::sqrt(2.0);
            const std::array<Vec, 7> candidates{normal,       unit_axis(0), unit_axis(1), unit_axis(2),
                                                Vec{r, r, 0}, Vec{r, 0, r}, Vec{0, r, r}};
            std::size_t best_cost = std::numeric_limits<std::size_t>::max();
            for (const Vec& c : candidates) {
                const double off = median(begin, end, c, true);
                const double margin = kPlaneEps * (norm1(c) * m_scale + std::abs(off));
                std::size_t low = 0, high = 0;
                for (std::size_t i = begin; i < end; ++i) {
                    const std::uint32_t id = m_work[i];
                    double lo, hi;
                    if (m_is_point[id]) {
                        lo = hi = dot(c, m_boxes[id].lo) - off;
                        low += lo < 0 ? 1 : 0;
                        high += lo < 0 ? 0 : 1;
                    } else {
                        plane_range(m_boxes[id], c, off, lo, hi);
                        low += lo <= margin ? 1 : 0;
                        high += hi >= -margin ? 1 : 0;
                    }
                }
                const std::size_t cost = std::max(low, high);
                if (cost < best_cost) {
                    best_cost = cost;
                    split.value = c;
                    split.offset = off;
                }
            }
        }
        split.margin = kPlaneEps * (norm1(split.value) * m_scale + std::abs(split.offset));
        break;
    }
    }

    // Children's item lists, appended to m_work after [begin, end). A split that separates nothing ends the
    // descent: a point rule (or BSP) whose plane leaves every item on one side, or any rule where every item
    // straddles (two children holding all). A region rule may put all items in one child: its region still
    // shrinks, and the next split may separate them. A BSP plane through the median point may still leave
    // every item on one side (the median point of a curved cloud): then the axis-median planes are tried, the
    // depth's axis first.
    const std::size_t children = split.kind == 2 ? 8 : 2;
    std::array<std::size_t, 9> bounds{};
    const bool bsp_rule = split.kind == 3;
    for (int attempt = 0;; ++attempt) {
        if (attempt > 0) {
            if (!bsp_rule || attempt > 3) {
                make_leaf(node, begin, end, depth);
                return;
            }
            split.kind = 1;
            split.axis = static_cast<std::uint8_t>((depth + attempt - 1) % 3);
            split.value = {0, 0, 0};
            split.value[split.axis] = median(begin, end, unit_axis(split.axis), true);
        }
        if (partition(split, begin, end, children, bounds)) break;
    }
    const auto first = static_cast<std::uint32_t>(m_nodes.size());
    split.first = first;
    split.count = static_cast<std::uint32_t>(children);
    m_nodes[node] = split;
    m_nodes.resize(m_nodes.size() + children);
    for (std::size_t k = 0; k < children; ++k) {
        SplitBox sub = region;
        if (split.kind == 2) {
            for (std::size_t a = 0; a < 3; ++a)
                ((k >> a) & 1U ? sub.lo[a] : sub.hi[a]) = std::clamp(split.value[a], region.lo[a], region.hi[a]);
        } else if (split.kind == 1) {
            const std::size_t a = split.axis;
            (k == 1 ? sub.lo[a] : sub.hi[a]) = std::clamp(split.value[a], region.lo[a], region.hi[a]);
        }
        build_node(first + static_cast<std::uint32_t>(k), bounds[k], bounds[k + 1], depth + 1, sub, ref, bsp_rule);
    }
    m_work.resize(bounds[0]);
}

/// Appends the children's item lists of `split` to m_work; bounds[k] .. bounds[k + 1] is child k's. Returns
/// false (m_work restored) when the split separates nothing (see build_node).
bool SplitTree::partition(const Node& split, std::size_t begin, std::size_t end, std::size_t children,
                          std::array<std::size_t, 9>& bounds)
{
    const std::size_t n = end - begin;
    bounds[0] = m_work.size(); // the children's lists go after every list on the path
    // One pass classifies every item (bits 0-2: reaches the lower side of plane 0-2; bits 3-5: the upper side;
    // one plane uses bit 0 and bit 3, bits 1-2 set), then each child collects the items reaching all its sides.
    m_sides.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t id = m_work[begin + i];
        const SplitBox& b = m_boxes[id];
        unsigned low = 0, high = 0;
        if (split.kind == 2) {
            for (std::size_t a = 0; a < 3; ++a) {
                low |= b.lo[a] < split.value[a] ? 1U << a : 0U;
                high |= b.hi[a] >= split.value[a] ? 1U << a : 0U;
            }
        } else if (split.kind == 1) {
            const std::size_t a = split.axis;
            low = (b.lo[a] < split.value[a] ? 1U : 0U) | 6U;
            high = b.hi[a] >= split.value[a] ? 1U : 0U;
        } else if (m_is_point[id]) {
            const double f = dot(split.value, b.lo) - split.offset;
            low = (f < 0 ? 1U : 0U) | 6U;
            high = f < 0 ? 0U : 1U;
        } else {
            double lo, hi;
            plane_range(b, split.value, split.offset, lo, hi);
            low = (lo <= split.margin ? 1U : 0U) | 6U;
            high = hi >= -split.margin ? 1U : 0U;
        }
        m_sides[i] = static_cast<std::uint8_t>(low | high << 3);
    }
    std::size_t full = 0;
    for (unsigned k = 0; k < children; ++k) {
        for (std::size_t i = 0; i < n; ++i) {
            const unsigned low = m_sides[i] & 7U, high = m_sides[i] >> 3;
            if (((k & ~high) | (~k & 7U & ~low)) != 0) continue;
            const std::uint32_t id = m_work[begin + i];
            m_work.push_back(id);
        }
        bounds[k + 1] = m_work.size();
        full += bounds[k + 1] - bounds[k] == n ? 1 : 0;
    }
    if (full >= 2 || (full == 1 && !is_region_rule(m_params.rule))) {
        m_work.resize(bounds[0]);
        return false;
    }
    return true;
}

template <class Emit> void SplitTree::walk(std::uint32_t node, const SplitBox& q, double q_scale, Emit& emit) const
{
    const Node& nd = m_nodes[node];
    switch (nd.kind) {
    case 0:
        for (std::uint32_t i = nd.first, e = nd.first + nd.count; i < e; ++i) {
            const std::uint32_t id = m_items[i];
            if (overlaps(m_boxes[id], q)) emit(id);
        }
        return;
    case 1: {
        const std::size_t a = nd.axis;
        if (q.lo[a] < nd.value[a]) walk(nd.first, q, q_scale, emit);
        if (q.hi[a] >= nd.value[a]) walk(nd.first + 1, q, q_scale, emit);
        return;
    }
    case 2: {
        unsigned low = 0, high = 0; // bit a: the query reaches the lower / upper side of plane a
        for (std::size_t a = 0; a < 3; ++a) {
            low |= q.lo[a] < nd.value[a] ? 1U << a : 0U;
            high |= q.hi[a] >= nd.value[a] ? 1U << a : 0U;
        }
        for (unsigned k = 0; k < 8; ++k) {
            if (((k & ~high) | (~k & 7U & ~low)) != 0) continue; // some axis side not reached
            const std::uint32_t c = nd.first + k;
            if (m_nodes[c].kind == 0 && m_nodes[c].count == 0) continue;
            walk(c, q, q_scale, emit);
        }
        return;
    }
    default: {
        // Conservative side test of a general plane. A point item is on the upper side when the computed
        // n.p - d >= 0, a box item on each side its computed range reaches within the node's margin. The
        // computed values err by at most kPlaneEps x (|n|_1 max|x| + |d|) for the items (node margin) and for
        // the query (its own scale), so widening the query's range by both margins visits every side holding
        // an item that touches the query: a point exactly on the plane, or a box touching it, is never lost
        // to rounding. The price is a few needless visits of planes within ~1e-14 relative of the query.
        double lo, hi;
        plane_range(q, nd.value, nd.offset, lo, hi);
        const double m = nd.margin + kPlaneEps * (norm1(nd.value) * q_scale + std::abs(nd.offset));
        if (lo <= m) walk(nd.first, q, q_scale, emit);
        if (hi >= -m) walk(nd.first + 1, q, q_scale, emit);
        return;
    }
    }
}

void SplitTree::query(const SplitBox& q, std::vector<std::uint32_t>& out, SplitTreeScratch& scratch) const
{
    if (m_nodes.empty() || m_boxes.empty()) return;
    const double q_scale = max_abs(q);
    if (!m_duplicates) {
        auto emit = [&out](std::uint32_t id) { out.push_back(id); };
        walk(0, q, q_scale, emit);
        return;
    }
    if (scratch.stamp.size() < m_boxes.size()) {
        scratch.stamp.assign(m_boxes.size(), 0);
        scratch.round = 0;
    }
    if (++scratch.round == 0) {
        std::fill(scratch.stamp.begin(), scratch.stamp.end(), 0U);
        scratch.round = 1;
    }
    const std::uint32_t round = scratch.round;
    auto emit = [&out, &scratch, round](std::uint32_t id) {
        if (scratch.stamp[id] == round) return;
        scratch.stamp[id] = round;
        out.push_back(id);
    };
    walk(0, q, q_scale, emit);
}

void SplitTree::query(const SplitBox& q, std::vector<std::uint32_t>& out) const
{
    if (m_nodes.empty() || m_boxes.empty()) return;
    const std::size_t start = out.size();
    auto emit = [&out](std::uint32_t id) { out.push_back(id); };
    walk(0, q, max_abs(q), emit);
    if (m_duplicates) {
        std::sort(out.begin() + static_cast<std::ptrdiff_t>(start), out.end());
        out.erase(std::unique(out.begin() + static_cast<std::ptrdiff_t>(start), out.end()), out.end());
    }
}

std::span<const std::uint32_t> SplitTree::leaf_items(std::size_t k) const
{
    const Node& nd = m_nodes[m_leaves.at(k)];
    return {m_items.data() + nd.first, nd.count};
}

int SplitTree::leaf_depth(std::size_t k) const
{
    return m_nodes[m_leaves.at(k)].depth;
}

SplitTreeStats SplitTree::stats() const
{
    SplitTreeStats s;
    s.nodes = static_cast<std::int64_t>(m_nodes.size());
    s.leaves = static_cast<std::int64_t>(m_leaves.size());
    s.max_depth = m_reached;
    s.items = static_cast<std::int64_t>(m_boxes.size());
    s.items_stored = static_cast<std::int64_t>(m_items.size());
    s.bytes =
        static_cast<std::int64_t>(m_nodes.capacity() * sizeof(Node) + m_items.capacity() * 4 + m_leaves.capacity() * 4 +
                                  m_boxes.capacity() * sizeof(SplitBox) + m_is_point.capacity());
    return s;
}

} // namespace tethash
