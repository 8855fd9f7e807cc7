// The splitting-plane trees as broad phases: a new tree over the vertices per call (as the comparison of octree,
// k-d and BSP trees builds them), then every tet box queried in parallel, each thread with its own output and stamp.
#include "bp_common.hpp"
#include "split_tree.hpp"

namespace tethash::detail {

namespace {

class SplitTreeBroadPhase final : public BroadPhaseBase {
  public:
    explicit SplitTreeBroadPhase(SplitRule rule) : m_rule(rule) {}
    std::int64_t nodes() const override { return m_nodes; }

  private:
    bool build_phase(const PartitionScene& scene, int threads) override;
    void query_phase(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    std::int64_t structure_bytes() const override;

    SplitRule m_rule;
    SplitTree m_tree;
    std::vector<SplitBox> m_points;                  // per vertex: its position as a box
    std::vector<std::vector<std::uint32_t>> m_found; // per thread: query output
    std::vector<SplitTreeScratch> m_scratch;         // per thread
    std::int64_t m_nodes = 0;
};

bool SplitTreeBroadPhase::build_phase(const PartitionScene& s, int /*threads*/)
{
    SplitTreeParams params;
    params.rule = m_rule;
    params.max_depth = s.params.max_depth > 0 ? s.params.max_depth : -1;
    params.leaf_size = s.params.leaf_size > 0 ? s.params.leaf_size : 8;
    m_tree.set_params(params);
    m_points.resize(static_cast<std::size_t>(s.num_vertices));
    for (Index v = 0; v < s.num_vertices; ++v) {
        SplitBox& b = m_points[static_cast<std::size_t>(v)];
        for (int a = 0; a < 3; ++a)
            b.lo[static_cast<std::size_t>(a)] = b.hi[static_cast<std::size_t>(a)] =
                s.positions[3 * static_cast<std::size_t>(v) + static_cast<std::size_t>(a)];
    }
    m_tree.build(m_points);
    m_nodes = m_tree.stats().nodes;
    return true;
}

void SplitTreeBroadPhase::query_phase(const PartitionScene& s, std::vector<CandidateSink>& sinks)
{
    m_found.resize(sinks.size());
    m_scratch.resize(sinks.size());
    for_each_index(s.num_tets, 64, sinks, [&](Index t, std::vector<CandidatePair>& out) {
        const auto r = static_cast<std::size_t>(team_rank());
        std::vector<std::uint32_t>& found = m_found[r];
        found.clear();
        SplitBox q;
        tet_box(s, t, q.lo.data(), q.hi.data());
        m_tree.query(q, found, m_scratch[r]);
        const bool tet_static = s.tet_static[t] != 0;
        for (std::uint32_t v : found)
            add_candidate(s, static_cast<Index>(v), t, tet_static, m_static.data(), out);
    });
}

std::int64_t SplitTreeBroadPhase::structure_bytes() const
{
    std::int64_t m = m_tree.stats().bytes + bytes_of(m_points);
    for (const auto& f : m_found)
        m += bytes_of(f);
    for (const SplitTreeScratch& sc : m_scratch)
        m += bytes_of(sc.stamp);
    return m;
}

} // namespace

std::unique_ptr<BroadPhase> make_split_tree_broad_phase(Method method)
{
    static constexpr std::pair<Method, SplitRule> rules[] = {
        {Method::octree, SplitRule::region_octree}, {Method::octree_point, SplitRule::point_octree},
        {Method::kd_tree, SplitRule::region_kd},    {Method::kd_tree_point, SplitRule::point_kd},
        {Method::bsp_tree, SplitRule::bsp},         {Method::bsp_tree_balanced, SplitRule::bsp_balanced},
    };
    for (const auto& [m, rule] : rules)
        if (m == method) return std::make_unique<SplitTreeBroadPhase>(rule);
    return nullptr;
}

} // namespace tethash::detail
