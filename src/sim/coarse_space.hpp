#pragma once
// A coarse space for the vbd sweeps (private to tethash::sim): a lattice over each dynamic object, its nodes
// carrying displacements that reach the vertices by trilinear interpolation at their start positions.
//
// Why: a Gauss–Seidel sweep moves information by about one ring of neighbours, while a backward-Euler step of an
// elastic body is a global problem whose stiffness relative to its inertia grows as (ω h)², ω = c / L̄ the
// material's frequency at the mean edge. At a fixed mesh ω grows as 1 / size: on small bodies the sweeps needed
// to carry an impact through the body grow far past a fixed count, which leaves the step unconverged (bodies
// sagging flat, energy growing; docs/simulator.md, "Convergence at every size", has the figures). The lattice carries
// the long waves the sweeps cannot: between sweeps the step's residual is projected on the lattice, the lattice's
// Newton step solved directly (the Galerkin matrix Pᵀ A P) and interpolated back (a two-level cycle: the sweeps smooth,
// the lattice corrects).
//
// The factorisation is kept from one substep to the next while the vertices touching the ground or a contact are
// nine tenths the same, no object turned by more than 0.05 rad since, and for at most 8 substeps: the line search along
// each correction (block_descent.cpp) makes a slightly stale matrix cost a little convergence, not correctness.
//
// The matrix: the springs' and volume terms' stiffness and damping and the masses at the start positions, Pᵀ (K +
// C / h + M / h²) P, kept per substep length h, the elements' part apart per lattice cell (the cell of each element's
// first vertex); at a factorisation each object's block is turned by the object's rotation since the start (polar
// decomposition of its positions against the start), the part of each cell that turned by more than 0.2 rad against
// its object (a leg, a tail) by the cell's own rotation instead, where ω h exceeds the cell in mean edges (with the
// object's rotation such a part had its stiffness across its springs), and the ground's and contacts' own terms at
// the current iterate are added, vertex by vertex (their diagonal blocks). Pinned vertices hold their lattice nodes by
// a stiff term. The lattice's cells are a sixth of the object's longest extent while ω h ≤ 4, finer
// as ω h grows (the waves a substep couples reach further), and at least two
// mean edges; an object gets at most a quarter as many nodes as it has vertices (125 for any) and at most 8 ω h
// between 200 and 400: the factorisation costs a few sweeps, and is worth more where ω h makes a substep need many.

#include "block_ldlt.hpp"

#include "tethash/sim/model.hpp"

#include <Eigen/Core>
#include <Eigen/Sparse>

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

namespace tethash::sim::detail {

class CoarseSpace {
  public:
    /// Lattices over the free vertices of each dynamic object at positions x (the start of the run); `damping` per
    /// object, the material's relative damping time (the sweeps damp volume terms by it, as springs); h the substep
    /// the scene asks for, which sets each lattice's cell: a sixth of the object's longest extent while ω h ≤ 4 (ω
    /// its material's frequency at the mean edge), finer as ω h grows (the waves a substep couples reach further in
    /// edges than the sweeps carry them), never below two mean edges.
    void build(const Model& model, const Positions& x, const std::vector<double>& damping, double h);
    bool empty() const { return m_nodes == 0; }
    /// Builds the start-state matrix of substep length h now (set-up), instead of at the first substep with that h.
    void set_up_for(double h)
    {
        if (m_nodes > 0) cached(h);
    }
    std::int32_t nodes() const { return m_nodes; }

    /// The coarse matrix of substep length h at positions x4 (stride 4): the cached start-state part turned by each
    /// object's rotation, plus per vertex the 3 × 3 block of `extra` (xx, yy, zz, xy, xz, yz per vertex, 6n) for the
    /// vertices listed in `with_extra`; factorised. False when the factorisation fails (the correction is then
    /// skipped).
    bool prepare(double h, const double* x4, const std::vector<double>& extra,
                 const std::vector<std::int32_t>& with_extra);

    /// Threads for the restriction, the prolongation and the matrix's refresh (the result is the same at any count).
    void set_threads(int threads) { m_threads = std::max(1, threads); }

    /// The start-state matrix Pᵀ (K + C/h + M/h²) P of substep length h (dense; for tests).
    Eigen::MatrixXd start_matrix(double h);
    /// P (3n × 3 nodes): the trilinear weights of each vertex in a lattice on its 8 nodes (for tests).
    Eigen::SparseMatrix<double> prolongation() const;
    /// The lattice cells the last prepare() that factorised turned by their own rotation, apart from their object's
    /// (for tests).
    size_t cells_turned_apart() const { return m_turned_cells.size(); }
    /// The matrix of the last prepare() that factorised (for tests).
    const Eigen::SparseMatrix<double>& matrix() const { return m_matrix; }

    /// The lattice's Newton step for the residual r (flat 3n, per vertex −∇G), interpolated to the vertices: dx
    /// (flat 3n; fixed vertices 0).
    void correct(const std::vector<double>& r, std::vector<double>& dx);

  private:
    struct Cached {
        double h;
        std::vector<double> values; ///< block values (9 per block, row-major 3 × 3) of Pᵀ (K + C/h + M/h²) P
        std::vector<std::int32_t> cell_start, cell_block; ///< per cell its entries (CSR): the block of each
        std::vector<double> cell_values;                  ///< 9 per entry: the cell's elements' part of its block
    };
    const Model* m_model = nullptr;
    Positions m_start;
    std::vector<double> m_damping;
    std::int32_t m_nodes = 0;
    // Per vertex: its 8 lattice nodes and trilinear weights (node −1: the vertex is not in a lattice).
    std::vector<std::int32_t> m_node;   ///< 8 n
    std::vector<double> m_weight;       ///< 8 n
    std::vector<std::int32_t> m_object; ///< per node: its object's index in m_objects
    struct Object {
        std::vector<std::int32_t> vertices;                ///< its vertices in a lattice
        Eigen::Vector3d centre0 = Eigen::Vector3d::Zero(); ///< mass centre at the start
        double mass = 0;
        /// Its cells turned by their own rotations where they turned against it: where a substep couples further
        /// than a cell (ω h above the cell in mean edges).
        bool cells_turn = false;
    };
    std::vector<Object> m_objects;
    // Block pattern (once per lattice): blocks (I, J) of the coarse matrix, the scalar positions of each in the CSR
    // matrix, found per object in a dense node × node table.
    std::vector<std::pair<std::int32_t, std::int32_t>> m_blocks;
    std::vector<std::int32_t> m_block_value;  ///< 9 per block: index into the matrix's value array
    std::vector<std::int32_t> m_object_first; ///< per object its first node (nodes of an object are consecutive); +1
    std::vector<size_t> m_local_offset;       ///< per object: start of its table in m_local_block; +1
    std::vector<std::int32_t> m_local_block;  ///< per object: (I − first) · count + (J − first) → block, or −1
    std::unordered_map<std::int64_t, std::int32_t> m_cross_block; ///< I · nodes + J → block, I and J of two objects
    // Per node the free vertices it interpolates, in vertex order, and their weights (the restriction Pᵀ r).
    std::vector<std::int32_t> m_node_start, m_node_vertex;
    std::vector<double> m_node_weight;
    int m_threads = 1;
    std::vector<std::int32_t> m_vertex_blocks; ///< 64 per vertex: the block of (node a, node b) of its 8 × 8
    Eigen::SparseMatrix<double> m_matrix;
    BlockLdlt m_factor; ///< of m_matrix, in its 3 × 3 blocks
    bool m_analysed = false;
    std::vector<Cached> m_cache;
    std::vector<Eigen::Matrix3d> m_rotation;          ///< per object, this substep
    std::vector<Eigen::Matrix3d> m_factored_rotation; ///< per object, at the last factorisation
    // Lattice cells (those holding a vertex): per vertex its cell, per cell its object, elements and free vertices.
    std::int32_t m_cells = 0;
    std::vector<std::int32_t> m_vertex_cell, m_cell_object;
    std::vector<std::int32_t> m_cell_spring_start, m_cell_spring, m_cell_tet_start, m_cell_tet;
    std::vector<std::int32_t> m_cell_vertex_start, m_cell_vertex;
    std::vector<Eigen::Matrix3d> m_cell_rotation; ///< per cell, this substep
    std::vector<double> m_turned; ///< 9 per cell entry: its block turned by its cell's rotation less by its object's
    std::vector<std::int32_t> m_turned_cells;   ///< the cells turned apart from their object, this substep
    std::vector<std::int32_t> m_factored_extra; ///< the vertices with ground or contact terms then
    double m_factored_h = 0;
    int m_factored_age = 0; ///< substeps since the last factorisation
    Eigen::VectorXd m_rc, m_dc;

    const Cached& cached(double h);
    void build_pattern();
    std::int32_t block_at(std::int32_t bi, std::int32_t bj) const; ///< −1: not in the pattern
};

} // namespace tethash::sim::detail
