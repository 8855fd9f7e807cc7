#include "block_ldlt.hpp"

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>

namespace tethash::sim::detail {

namespace {

/// D_k's own LDLᵀ, in place (no pivoting, x, y, z in order, as a scalar factorisation eliminates a node's three
/// unknowns): the multipliers below the diagonal, the pivots' reciprocals on it. False where a pivot is zero or not
/// finite. Reads the lower triangle of d only.
bool factorise_pivot(Eigen::Matrix3d& d)
{
    const double d0 = d(0, 0);
    if (!std::isfinite(d0) || d0 == 0) return false;
    const double l10 = d(1, 0) / d0, l20 = d(2, 0) / d0;
    const double d1 = d(1, 1) - l10 * d(1, 0);
    if (!std::isfinite(d1) || d1 == 0) return false;
    const double l21 = (d(2, 1) - l20 * d(1, 0)) / d1;
    const double d2 = d(2, 2) - l20 * d(2, 0) - l21 * (d(2, 1) - l20 * d(1, 0));
    if (!std::isfinite(d2) || d2 == 0) return false;
    d.setZero();
    d(1, 0) = l10;
    d(2, 0) = l20;
    d(2, 1) = l21;
    d(0, 0) = 1 / d0;
    d(1, 1) = 1 / d1;
    d(2, 2) = 1 / d2;
    return true;
}

/// v = D⁻¹ v for each column of v, D given by factorise_pivot()'s f: forward, scaled, backward.
template <typename M> void apply_pivot_inverse(const Eigen::Matrix3d& f, M& v)
{
    v.row(1) -= f(1, 0) * v.row(0);
    v.row(2) -= f(2, 0) * v.row(0) + f(2, 1) * v.row(1);
    v.row(0) *= f(0, 0);
    v.row(1) *= f(1, 1);
    v.row(2) *= f(2, 2);
    v.row(1) -= f(2, 1) * v.row(2);
    v.row(0) -= f(1, 0) * v.row(1) + f(2, 0) * v.row(2);
}

} // namespace

void BlockLdlt::analyse(std::int32_t nodes, const std::vector<std::pair<std::int32_t, std::int32_t>>& blocks)
{
    m_nodes = nodes;
    const size_t m = static_cast<size_t>(nodes);
    // The fill-reducing order of the nodes: AMD on the nodes' graph (the permutation's indices give, per new position,
    // the old node, as Eigen's simplicial factorisations use it).
    std::vector<Eigen::Triplet<double, int>> pattern;
    pattern.reserve(blocks.size());
    for (const auto& [i, j] : blocks)
        pattern.emplace_back(i, j, 1.0);
    Eigen::SparseMatrix<double, Eigen::ColMajor, int> graph(nodes, nodes);
    graph.setFromTriplets(pattern.begin(), pattern.end());
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> order;
    Eigen::AMDOrdering<int>()(graph, order);
    m_old.assign(order.indices().data(), order.indices().data() + order.indices().size());
    std::vector<std::int32_t> now(m);
    for (size_t k = 0; k < m; ++k)
        now[static_cast<size_t>(m_old[k])] = static_cast<std::int32_t>(k);

    // Per permuted column its blocks above the diagonal, rows increasing, and its diagonal block.
    std::vector<std::pair<std::int32_t, std::int32_t>> upper; // (permuted column, block)
    m_diag_block.assign(m, -1);
    for (size_t b = 0; b < blocks.size(); ++b) {
        const std::int32_t i = now[static_cast<size_t>(blocks[b].first)],
                           k = now[static_cast<size_t>(blocks[b].second)];
        if (i == k)
            m_diag_block[static_cast<size_t>(k)] = static_cast<std::int32_t>(b);
        else if (i < k)
            upper.emplace_back(k, static_cast<std::int32_t>(b));
    }
    std::sort(upper.begin(), upper.end(), [&](const auto& p, const auto& q) {
        const std::int32_t pi = now[static_cast<size_t>(blocks[static_cast<size_t>(p.second)].first)];
        const std::int32_t qi = now[static_cast<size_t>(blocks[static_cast<size_t>(q.second)].first)];
        return p.first < q.first || (p.first == q.first && pi < qi);
    });
    m_upper_start.assign(m + 1, 0);
    m_upper_row.resize(upper.size());
    m_upper_block.resize(upper.size());
    for (size_t u = 0; u < upper.size(); ++u) {
        ++m_upper_start[static_cast<size_t>(upper[u].first) + 1];
        m_upper_block[u] = upper[u].second;
        m_upper_row[u] = now[static_cast<size_t>(blocks[static_cast<size_t>(upper[u].second)].first)];
    }
    for (size_t k = 0; k < m; ++k)
        m_upper_start[k + 1] += m_upper_start[k];

    // The elimination tree and the blocks of each column of L (Liu's algorithm, row by row).
    m_parent.assign(m, -1);
    m_mark.assign(m, -1);
    std::vector<std::int32_t> count(m, 0);
    for (size_t k = 0; k < m; ++k) {
        m_mark[k] = static_cast<std::int32_t>(k);
        for (std::int32_t u = m_upper_start[k]; u < m_upper_start[k + 1]; ++u)
            for (std::int32_t i = m_upper_row[static_cast<size_t>(u)];
                 m_mark[static_cast<size_t>(i)] != static_cast<std::int32_t>(k); i = m_parent[static_cast<size_t>(i)]) {
                if (m_parent[static_cast<size_t>(i)] < 0)
                    m_parent[static_cast<size_t>(i)] = static_cast<std::int32_t>(k);
                ++count[static_cast<size_t>(i)];
                m_mark[static_cast<size_t>(i)] = static_cast<std::int32_t>(k);
            }
    }
    m_li_start.assign(m + 1, 0);
    for (size_t k = 0; k < m; ++k)
        m_li_start[k + 1] = m_li_start[k] + count[k];
    m_li.assign(static_cast<size_t>(m_li_start[m]), 0);
    m_lx.assign(m_li.size(), Eigen::Matrix3d::Zero());
    m_pivot.assign(m, Eigen::Matrix3d::Zero());
    m_y.assign(m, Eigen::Matrix3d::Zero());
    m_pattern.assign(m, 0);
    m_fill.assign(m, 0);
}

bool BlockLdlt::factorise(const double* values, const std::int32_t* at)
{
    const size_t m = static_cast<size_t>(m_nodes);
    const auto block = [&](std::int32_t b) {
        Eigen::Matrix3d out;
        const std::int32_t* p = at + 9 * static_cast<size_t>(b);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                out(r, c) = values[p[3 * r + c]];
        return out;
    };
    m_ok = false;
    std::fill(m_mark.begin(), m_mark.end(), -1);
    for (size_t k = 0; k < m; ++k)
        m_fill[k] = m_li_start[k];
    // Up-looking: row k of L solves L(0:k, 0:k) W = A(0:k, k) over the rows the elimination tree reaches (W's block i
    // is D_i L(k, i)ᵀ), then D_k = A(k, k) − Σ L(k, i) W_i.
    for (size_t k = 0; k < m; ++k) {
        const std::int32_t kk = static_cast<std::int32_t>(k);
        size_t top = m;
        m_mark[k] = kk;
        for (std::int32_t u = m_upper_start[k]; u < m_upper_start[k + 1]; ++u) {
            std::int32_t i = m_upper_row[static_cast<size_t>(u)];
            m_y[static_cast<size_t>(i)] = block(m_upper_block[static_cast<size_t>(u)]);
            size_t len = 0;
            for (; m_mark[static_cast<size_t>(i)] != kk; i = m_parent[static_cast<size_t>(i)]) {
                m_pattern[len++] = i;
                m_mark[static_cast<size_t>(i)] = kk;
            }
            while (len > 0)
                m_pattern[--top] = m_pattern[--len];
        }
        Eigen::Matrix3d d = block(m_diag_block[k]);
        for (size_t p = top; p < m; ++p) {
            const size_t i = static_cast<size_t>(m_pattern[p]);
            const Eigen::Matrix3d w = m_y[i];
            m_y[i].setZero();
            for (std::int32_t q = m_li_start[i]; q < m_fill[i]; ++q)
                m_y[static_cast<size_t>(m_li[static_cast<size_t>(q)])].noalias() -= m_lx[static_cast<size_t>(q)] * w;
            Eigen::Matrix3d t = w;
            apply_pivot_inverse(m_pivot[i], t);
            const Eigen::Matrix3d l = t.transpose();
            d.noalias() -= l * w;
            const size_t q = static_cast<size_t>(m_fill[i]++);
            m_li[q] = kk;
            m_lx[q] = l;
        }
        if (!factorise_pivot(d)) return false;
        m_pivot[k] = d;
    }
    m_ok = true;
    return true;
}

void BlockLdlt::solve(const double* b, double* x) const
{
    const size_t m = static_cast<size_t>(m_nodes);
    std::vector<Eigen::Vector3d>& z = m_z;
    z.resize(m);
    for (size_t k = 0; k < m; ++k)
        z[k] = Eigen::Vector3d::Map(b + 3 * static_cast<size_t>(m_old[k]));
    for (size_t i = 0; i < m; ++i)
        for (std::int32_t q = m_li_start[i]; q < m_li_start[i + 1]; ++q)
            z[static_cast<size_t>(m_li[static_cast<size_t>(q)])].noalias() -= m_lx[static_cast<size_t>(q)] * z[i];
    for (size_t i = 0; i < m; ++i)
        apply_pivot_inverse(m_pivot[i], z[i]);
    for (size_t i = m; i-- > 0;)
        for (std::int32_t q = m_li_start[i]; q < m_li_start[i + 1]; ++q)
            z[i].noalias() -=
                m_lx[static_cast<size_t>(q)].transpose() * z[static_cast<size_t>(m_li[static_cast<size_t>(q)])];
    for (size_t k = 0; k < m; ++k)
        Eigen::Vector3d::Map(x + 3 * static_cast<size_t>(m_old[k])) = z[k];
}

} // namespace tethash::sim::detail
