#pragma once
// Brute force as a broad phase (private header): the vertices sorted by x, each tet box against its x-extent.
#include "bp_common.hpp"

namespace tethash::detail {

class BruteForce final : public BroadPhase {
  public:
    BroadPhaseTimes find(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    std::int64_t memory_bytes() const override;
    std::int64_t nodes() const override { return 0; }

  private:
    VerticesByX m_sorted;
    std::vector<unsigned char> m_static;
};

} // namespace tethash::detail
