#pragma once
// LDLᵀ of a sparse symmetric matrix made of 3 × 3 blocks (private to tethash::sim): the coarse space's lattice matrix,
// three unknowns per node, every entry of a coupled pair of nodes present.
//
// Why not Eigen's SimplicialLDLT on the scalar matrix: it permutes the whole matrix into a copy at every
// factorisation and walks the elimination tree one scalar row at a time, each update an indexed scalar; on the
// lattices of small meshes (125-200 nodes) that was a third of the instructions of a step. Here the ordering (AMD on
// the nodes' graph), the elimination tree and the factor's pattern are computed once per pattern, and the numeric
// factorisation reads the blocks in place and updates 3 × 3 blocks: the same up-looking algorithm, a ninth of the
// index work; the octopus drop's factorisations went from 357M to 100M instructions (docs/simulator.md, "The small
// meshes against Bullet").
//
// A = Pᵀ L D Lᵀ P with L unit lower triangular in blocks and D block diagonal (each D_k a symmetric 3 × 3, kept as
// its own unpivoted LDLᵀ and applied by substitution, never inverted: on a stiff body's lattice a D_k's eigenvalues
// span ten orders of magnitude, and its explicit inverse made the solve's backward error 1e-9 where a scalar LDLᵀ's
// is 1e-16; docs/simulator.md). Serial, so the result is the same at any thread count.

#include <Eigen/Core>

#include <cstdint>
#include <utility>
#include <vector>

namespace tethash::sim::detail {

class BlockLdlt {
  public:
    /// The pattern: `nodes` block rows and columns, `blocks` the (row, column) of each 3 × 3 block present, a
    /// symmetric pattern (both (i, j) and (j, i)) with every diagonal block. Computes the ordering and the factor's
    /// pattern; factorise() then takes the blocks' values in this order.
    void analyse(std::int32_t nodes, const std::vector<std::pair<std::int32_t, std::int32_t>>& blocks);
    /// Factorises the matrix whose block b has the entry (r, c) at values[at[9 b + 3 r + c]]. False where a pivot
    /// (of a D_k's own LDLᵀ, as a scalar LDLᵀ's) is zero or not finite (solve() must not be called then).
    bool factorise(const double* values, const std::int32_t* at);
    /// x = A⁻¹ b (3 × nodes each; x and b may be the same).
    void solve(const double* b, double* x) const;
    std::int32_t nodes() const { return m_nodes; }
    /// Whether the last factorise() succeeded.
    bool ok() const { return m_ok; }
    /// Blocks of L below the diagonal (for the documentation of costs and for tests).
    size_t factor_blocks() const { return m_li.size(); }

  private:
    std::int32_t m_nodes = 0;
    bool m_ok = false;
    std::vector<std::int32_t> m_old; ///< per permuted node its node in A
    // Per permuted column k: its blocks above the diagonal (permuted row i < k, in increasing i) and the index in A of
    // each (A's block (old i, old k)), and its diagonal block's.
    std::vector<std::int32_t> m_upper_start, m_upper_row, m_upper_block;
    std::vector<std::int32_t> m_diag_block;
    std::vector<std::int32_t> m_parent;   ///< elimination tree
    std::vector<std::int32_t> m_li_start; ///< per column of L: the start of its blocks (rows below the diagonal)
    std::vector<std::int32_t> m_li;       ///< rows of L's blocks, column by column
    std::vector<Eigen::Matrix3d> m_lx;    ///< L's blocks
    std::vector<Eigen::Matrix3d> m_pivot; ///< D_k's LDLᵀ: multipliers below the diagonal, pivots' reciprocals on it
    // Scratch of factorise().
    std::vector<Eigen::Matrix3d> m_y;
    std::vector<std::int32_t> m_mark, m_pattern, m_fill;
    mutable std::vector<Eigen::Vector3d> m_z; ///< of solve()
};

} // namespace tethash::sim::detail
