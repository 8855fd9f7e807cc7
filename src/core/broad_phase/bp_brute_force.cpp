// Brute force as a broad phase: every vertex against every tet box, with the vertices sorted by x once per call so
// that each tet only looks at the vertices of its x-extent (the oracle's layout; still every pair that can touch).
#include "bp_common.hpp"

namespace tethash::detail {

namespace {

class BruteForce final : public BroadPhaseBase {
  private:
    bool build_phase(const PartitionScene& scene, int threads) override;
    void query_phase(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    std::int64_t structure_bytes() const override { return m_sorted.memory_bytes(); }

    VerticesByX m_sorted;
};

bool BruteForce::build_phase(const PartitionScene& s, int /*threads*/)
{
    m_sorted.build(s);
    return true;
}

void BruteForce::query_phase(const PartitionScene& s, std::vector<CandidateSink>& sinks)
{
    for_each_index(s.num_tets, 256, sinks, [&](Index t, std::vector<CandidatePair>& out) {
        Box b;
        tet_box(s, t, b.lo, b.hi);
        m_sorted.find(s, b, t, s.tet_static[t] != 0, m_static.data(), out);
    });
}

} // namespace

std::unique_ptr<BroadPhase> make_brute_force()
{
    return std::make_unique<BruteForce>();
}

} // namespace tethash::detail
