#pragma once
// The dense uniform grid as a broad phase (private header; docs/partitions.md): an array of cells over the
// vertices' bounding box, the vertices counting-sorted into it, each tet box enumerating the cells it overlaps.
#include "bp_common.hpp"

namespace tethash::detail {

class UniformGrid final : public BroadPhase {
  public:
    /// Throws Error when the grid would need more than max_cells cells or max_bytes bytes.
    BroadPhaseTimes find(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    std::int64_t memory_bytes() const override;
    std::int64_t nodes() const override { return m_cells; }

    static constexpr std::int64_t max_cells = std::int64_t{1} << 28;
    static constexpr std::int64_t max_bytes = std::int64_t{1} << 31;

  private:
    std::int64_t m_cells = 0;
    std::int64_t m_dims[3] = {0, 0, 0};
    std::vector<Index> m_start;       // cells + 1: the vertices of cell c are m_ids[m_start[c], m_start[c + 1])
    std::vector<Index> m_ids;         // vertices by cell (z fastest, then y, then x)
    std::vector<double> m_xyz;        // their positions in that order (3 per vertex)
    std::vector<std::int32_t> m_cell; // per vertex: its cell
    std::vector<unsigned char> m_static;
};

} // namespace tethash::detail
