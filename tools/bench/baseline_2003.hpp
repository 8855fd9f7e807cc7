#pragma once
// The baseline of tethash_bench: Teschner et al. 2003 as the paper describes it, a second detector kept apart
// from the library so that the comparison measures the paper's algorithm, not ours.
#include "tethash/detect.hpp"
#include "tethash/mesh.hpp"

#include <cstdint>
#include <utility>
#include <vector>

namespace tethash::bench {

/// Hash table of per-bucket vertex lists, stamped with the step instead of cleared; each tet looks up every cell
/// its box touches (xor-prime hash mod a prime), checks box and own vertices, and computes barycentric
/// coordinates in double (no exactness). Pairs found through several cells sharing a bucket are filtered by
/// comparing the vertex's cell with the visited cell. Keeps its buffers across runs; the table size is chosen
/// (the prime after twice the vertex count) at the first run.
class Baseline2003 {
  public:
    /// All (vertex, tet) pairs with the vertex inside the tet, for cell size `l`.
    void run(const TetMesh& m, double l, std::vector<std::pair<Index, Index>>& out);

  private:
    std::size_t m_table = 0;
    std::vector<std::vector<Index>> m_buckets;
    std::vector<std::uint32_t> m_stamp;
    std::uint32_t m_step = 0;
    std::vector<std::int32_t> m_cell;
};

/// Whether the baseline's pairs (any order) are the (vertex, tet) pairs of `contacts` (the detector's or the
/// oracle's, sorted by vertex then tet): the benchmark checks the baseline against them as it checks every method,
/// so that it compares times of equal answers.
bool same_pairs(std::vector<std::pair<Index, Index>> pairs, const std::vector<Contact>& contacts);

} // namespace tethash::bench
