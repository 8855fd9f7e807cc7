// The coarse space's factorisation in 3 × 3 blocks (src/sim/block_ldlt.hpp): it must solve the lattice's system as a
// dense factorisation does, on a lattice's pattern (every node coupled with its 26 neighbours, fill in the factor), as
// accurately as a scalar LDLᵀ on a stiff body's ill-conditioned lattice, and refuse a matrix with a singular pivot.
#include "../src/sim/block_ldlt.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

using namespace tethash::sim::detail;

namespace {

/// A symmetric positive definite matrix on the pattern of an n × n × n lattice (each node coupled with its 26
/// neighbours), its blocks listed in an order that is neither row- nor column-major, their values stored scattered
/// (each entry at a position given by `at`, as the coarse space's matrix holds them).
struct LatticeMatrix {
    std::int32_t nodes = 0;
    std::vector<std::pair<std::int32_t, std::int32_t>> blocks;
    std::vector<double> values;
    std::vector<std::int32_t> at;
    Eigen::MatrixXd dense;
};

/// The kinds of values lattice_matrix() puts on the pattern.
enum class Values {
    /// gᵀ g terms of every sign plus a mass: well conditioned.
    Generic,
    /// What a small stiff body's lattice holds (young 1e9 at 15 cm, 1/60): springs along the lattice's edges and
    /// diagonals, stiffness along them only (k u uᵀ, k = 1e9), and a mass of 1e-2 on the diagonal: the body's rigid
    /// motions held by the mass alone, so that a node's block spans eleven orders of magnitude and the last pivots are
    /// about 1e-10 of their block's scale.
    Stiff,
};

LatticeMatrix lattice_matrix(int n, Values kind = Values::Generic)
{
    LatticeMatrix a;
    a.nodes = n * n * n;
    const auto id = [n](int x, int y, int z) { return static_cast<std::int32_t>((z * n + y) * n + x); };
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x)
                for (int dz = -1; dz <= 1; ++dz)
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dx = -1; dx <= 1; ++dx) {
                            const int u = x + dx, v = y + dy, w = z + dz;
                            if (u < 0 || v < 0 || w < 0 || u >= n || v >= n || w >= n) continue;
                            a.blocks.emplace_back(id(u, v, w), id(x, y, z));
                        }
    // Listed from the last block backwards, pairs swapped two by two: no order the factorisation could rely on.
    std::reverse(a.blocks.begin(), a.blocks.end());
    for (size_t b = 0; b + 1 < a.blocks.size(); b += 2)
        std::swap(a.blocks[b], a.blocks[b + 1]);
    // Values: a sum of element-like terms gᵀ g (positive semidefinite) plus a mass on the diagonal, so positive
    // definite and with couplings of every sign.
    const Eigen::Index dofs = 3 * a.nodes;
    a.dense = Eigen::MatrixXd::Zero(dofs, dofs);
    const bool stiff = kind == Values::Stiff;
    for (std::int32_t i = 0; i < a.nodes; ++i)
        a.dense.block<3, 3>(3 * i, 3 * i) += (stiff ? 1e-2 : 0.5) * Eigen::Matrix3d::Identity();
    const auto place = [n](std::int32_t i) {
        return Eigen::Vector3d(i % n, (i / n) % n, i / (n * n)); // inverse of id()
    };
    for (const auto& [i, j] : a.blocks) {
        if (i >= j) continue;
        if (stiff) {
            const Eigen::Vector3d u = (place(j) - place(i)).normalized();
            const Eigen::Matrix3d k = 1e9 * u * u.transpose();
            a.dense.block<3, 3>(3 * i, 3 * i) += k;
            a.dense.block<3, 3>(3 * i, 3 * j) -= k;
            a.dense.block<3, 3>(3 * j, 3 * i) -= k;
            a.dense.block<3, 3>(3 * j, 3 * j) += k;
            continue;
        }
        Eigen::Matrix<double, 3, 6> g;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 6; ++c)
                g(r, c) = std::sin(0.7 * i + 1.3 * j + 0.9 * r + 2.1 * c);
        const Eigen::Matrix<double, 6, 6> k = g.transpose() * g;
        a.dense.block<3, 3>(3 * i, 3 * i) += k.block<3, 3>(0, 0);
        a.dense.block<3, 3>(3 * i, 3 * j) += k.block<3, 3>(0, 3);
        a.dense.block<3, 3>(3 * j, 3 * i) += k.block<3, 3>(3, 0);
        a.dense.block<3, 3>(3 * j, 3 * j) += k.block<3, 3>(3, 3);
    }
    const size_t entries = 9 * a.blocks.size();
    a.values.assign(entries, 0.0);
    a.at.resize(entries);
    for (size_t b = 0; b < a.blocks.size(); ++b)
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) {
                // Entry q of block b stored at (q · 7919 + b) mod entries... a scattered but one-to-one position.
                const size_t q = 9 * b + static_cast<size_t>(3 * r + c);
                const size_t pos = (q * 7919) % entries;
                a.at[q] = static_cast<std::int32_t>(pos);
                a.values[pos] = a.dense(3 * a.blocks[b].first + r, 3 * a.blocks[b].second + c);
            }
    return a;
}

} // namespace

TEST(SimBlockLdlt, SolvesAsADenseFactorisationDoes)
{
    const LatticeMatrix a = lattice_matrix(5); // 125 nodes: a small mesh's lattice
    ASSERT_NE(a.values.size() % 7919, 0u);
    BlockLdlt f;
    f.analyse(a.nodes, a.blocks);
    ASSERT_TRUE(f.factorise(a.values.data(), a.at.data()));
    EXPECT_TRUE(f.ok());
    // The ordering keeps the fill well below a dense factor's (125 · 124 / 2 blocks).
    EXPECT_LT(f.factor_blocks(), 125u * 124u / 2u / 2u);
    Eigen::VectorXd b(3 * a.nodes);
    for (Eigen::Index i = 0; i < b.size(); ++i)
        b[i] = std::cos(0.37 * static_cast<double>(i));
    Eigen::VectorXd x(b.size());
    f.solve(b.data(), x.data());
    const Eigen::VectorXd expected = a.dense.ldlt().solve(b);
    EXPECT_LT((x - expected).norm(), 1e-10 * expected.norm());
    EXPECT_LT((a.dense * x - b).norm(), 1e-10 * b.norm());
    // In place, and again after a second factorisation of other values on the same pattern.
    LatticeMatrix twice = a;
    for (double& v : twice.values)
        v *= 2;
    ASSERT_TRUE(f.factorise(twice.values.data(), twice.at.data()));
    Eigen::VectorXd y = b;
    f.solve(y.data(), y.data());
    EXPECT_LT((y - 0.5 * expected).norm(), 1e-10 * expected.norm());
}

TEST(SimBlockLdlt, RefusesASingularPivot)
{
    // A node whose blocks are all zero: its pivot is singular whatever the order.
    LatticeMatrix a = lattice_matrix(3);
    const std::int32_t dead = 13;
    for (size_t b = 0; b < a.blocks.size(); ++b)
        if (a.blocks[b].first == dead || a.blocks[b].second == dead)
            for (size_t q = 0; q < 9; ++q)
                a.values[static_cast<size_t>(a.at[9 * b + q])] = 0.0;
    BlockLdlt f;
    f.analyse(a.nodes, a.blocks);
    EXPECT_FALSE(f.factorise(a.values.data(), a.at.data()));
    EXPECT_FALSE(f.ok());
}

TEST(SimBlockLdlt, SolvesAStiffLatticeAsTheScalarLdltDoes)
{
    // A small stiff body's lattice (Values::Stiff): condition 1e12, each node's block spanning eleven orders of
    // magnitude, every pivot regular. The factorisation must take it (a pivot threshold relative to the block's scale
    // would refuse the last pivots and leave the body without its coarse correction) and solve it as accurately as
    // Eigen's scalar SimplicialLDLT, which it replaced. With each D_k inverted explicitly, its backward error was
    // 1.5e-9 against the scalar's 7e-17 and its forward error 0.8 against 3e-5.
    const LatticeMatrix a = lattice_matrix(4, Values::Stiff);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> spectrum(a.dense, Eigen::EigenvaluesOnly);
    const double condition = spectrum.eigenvalues().maxCoeff() / spectrum.eigenvalues().minCoeff();
    ASSERT_GT(spectrum.eigenvalues().minCoeff(), 0.0);
    ASSERT_GT(condition, 1e10); // the property that makes the two solutions differ
    BlockLdlt f;
    f.analyse(a.nodes, a.blocks);
    ASSERT_TRUE(f.factorise(a.values.data(), a.at.data()));
    Eigen::VectorXd b(3 * a.nodes);
    for (Eigen::Index i = 0; i < b.size(); ++i)
        b[i] = std::cos(0.37 * static_cast<double>(i));
    Eigen::VectorXd x(b.size());
    f.solve(b.data(), x.data());
    const Eigen::SparseMatrix<double> sparse = a.dense.sparseView();
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> scalar(sparse);
    ASSERT_EQ(scalar.info(), Eigen::Success);
    const Eigen::VectorXd xs = scalar.solve(b);
    // Backward error (the residual against |A| |x|): the block solve's within a few times the scalar one's.
    const double norm_a = a.dense.cwiseAbs().colwise().sum().maxCoeff();
    const double backward = (a.dense * x - b).norm() / (norm_a * x.norm());
    const double backward_scalar = (a.dense * xs - b).norm() / (norm_a * xs.norm());
    EXPECT_LT(backward, 4 * backward_scalar + 1e-16) << "condition " << condition;
    // Forward error: both within what the conditioning allows of the exact solution (the dense pivoted LDLT's).
    const Eigen::VectorXd exact = a.dense.ldlt().solve(b);
    const double allowed = 1e-14 * condition;
    EXPECT_LT((x - exact).norm(), allowed * exact.norm());
    EXPECT_LT((xs - exact).norm(), allowed * exact.norm());
}
