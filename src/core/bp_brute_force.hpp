#pragma once
// Brute force as a broad phase (private header): the vertices sorted by x, each tet box against its x-extent.
#include "broad_phase.hpp"

namespace tethash::detail {

class BruteForce final : public BroadPhase {
  public:
    BroadPhaseTimes find(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    std::int64_t memory_bytes() const override;
    std::int64_t nodes() const override { return 0; }

  private:
    std::vector<Index> m_order; // vertices by increasing x (ties by id)
    std::vector<double> m_xs;   // their x
    std::vector<unsigned char> m_static;
};

} // namespace tethash::detail
