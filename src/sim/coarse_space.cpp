#include "coarse_space.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace tethash::sim::detail {

namespace {

/// The most lattice nodes one object gets (each carries three unknowns of the factorised system): nodes_per_omega_h
/// times its ω h, between min_nodes_cap and max_nodes_per_object. The lattice is factorised again at most substeps
/// (the ground's and contacts' terms change), and its factorisation grows faster than the square of its nodes (cells
/// of two to three mean edges: a node couples with up to 125 others). Where ω h is a few tens a substep converges in
/// about six sweeps and the factorisation is the larger cost: at 400 nodes the 15 cm hand (ω h 12.6 at 1/240) spent
/// 5 ms a step factorising (395 nodes, 156k entries in the factor) where the 1 m hand (115 nodes) spent 0.6 ms; 200
/// made the 15 cm steps 0.62-0.93 of their cost (hand, raptor, octocat, two armadillos). Where ω h is larger the
/// sweeps a substep needs grow and the finer lattice saves more than it costs: at 200 nodes the hand of young 1e9 at
/// 15 cm and 1/60 (ω h 5,000) took 369 sweeps a step against 112, and octocat at 1/60 (ω h 62) 12 a step against
/// 5 (docs/simulator.md, "A small body no dearer than a big one").
constexpr size_t max_nodes_per_object = 400;
constexpr size_t min_nodes_cap = 200;
constexpr double nodes_per_omega_h = 8.0;

/// The weight-to-bending number ρ g L³ / (E t²) above which a thin sheet's weight folds it (no lattice, below).
constexpr double sheet_folds = 10.0;
/// The ω h up to which a sheet that folds converges with the sweeps alone. Above it the sweeps cannot carry the
/// sheet's long waves (a small mat landing on its edge stayed standing, buckled, its springs holding several times
/// the drop's energy: docs/simulator.md), and the lattice's corrections are what makes the step converge.
constexpr double sheet_sweeps_alone = 20.0;

/// The rotation closest to the 3 × 3 matrix s (its polar factor; a reflection turned into a rotation).
Eigen::Matrix3d closest_rotation(const Eigen::Matrix3d& s)
{
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(s, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d u = svd.matrixU();
    const Eigen::Matrix3d& v = svd.matrixV();
    if ((u * v.transpose()).determinant() < 0) u.col(2) = -u.col(2);
    return u * v.transpose();
}

} // namespace

void CoarseSpace::build(const Model& model, const Positions& x, const std::vector<double>& damping, double h)
{
    m_model = &model;
    m_damping = damping;
    m_start = x;
    const Index n = model.num_vertices();
    const size_t un = static_cast<size_t>(n);
    m_node.assign(8 * un, -1);
    m_weight.assign(8 * un, 0.0);
    m_object.clear();
    m_objects.clear();
    m_nodes = 0;
    m_cache.clear();
    m_blocks.clear();
    m_block_index.clear();
    m_analysed = false;
    const size_t objects = model.object_mean_edge.size();
    std::vector<std::vector<std::int32_t>> members(objects);
    for (Index i = 0; i < n; ++i) {
        const size_t o = static_cast<size_t>(model.vertex_object[static_cast<size_t>(i)]);
        if (o < objects && model.object_mean_edge[o] > 0) members[o].push_back(static_cast<std::int32_t>(i));
    }
    for (size_t o = 0; o < objects; ++o) {
        const std::vector<std::int32_t>& vs = members[o];
        if (vs.empty()) continue;
        Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
        for (const std::int32_t i : vs) {
            lo = lo.cwiseMin(x.row(i).transpose());
            hi = hi.cwiseMax(x.row(i).transpose());
        }
        // A sheet thinner than half a cell (one tet layer) that its weight folds gets no lattice: the cells span its
        // folds, and the start state's matrix points nowhere useful once it crumples (its corrections slowed the
        // sweeps). Its weight folds it where ρ g L³ / (E t²) (L its extent, t its thickness; E / ρ = ω² L̄²) is
        // large. A stiff sheet keeps its lattice: without it, the sweeps alone let its drop gain energy many times
        // over (docs/simulator.md, "Figures behind the code's constants"). So does a sheet whose ω h the sweeps alone
        // cannot converge (sheet_sweeps_alone: the mat below 1 m landing on its edge stayed standing, buckled).
        const Eigen::Vector3d extent3 = hi - lo;
        const double omega_h = std::sqrt(model.object_frequency_sq[o]) * h;
        if (extent3.minCoeff() < 0.5 * std::max(2.0 * model.object_mean_edge[o], extent3.maxCoeff() / 6.0)) {
            const double stiffness = model.object_frequency_sq[o] * model.object_mean_edge[o] *
                                     model.object_mean_edge[o] * extent3.minCoeff() * extent3.minCoeff();
            const double weight = model.gravity.norm() * std::pow(extent3.maxCoeff(), 3);
            if (!(weight <= sheet_folds * stiffness) && omega_h <= sheet_sweeps_alone) continue;
        }
        const double cells_per_extent = 6.0 * std::max(1.0, omega_h / 4.0);
        const double extent = (hi - lo).maxCoeff();
        double cell = std::max(2.0 * model.object_mean_edge[o], extent / cells_per_extent);
        // At most a quarter as many nodes as the object has vertices (125 for any object), and at most 8 ω h between
        // 200 and 400 (above: the factorisation's cost against the sweeps it saves).
        const size_t most =
            static_cast<size_t>(std::clamp(nodes_per_omega_h * omega_h, static_cast<double>(min_nodes_cap),
                                           static_cast<double>(max_nodes_per_object)));
        const size_t cap = std::min<size_t>(most, std::max<size_t>(125, vs.size() / 4));
        Eigen::Array3i dims;
        std::vector<std::int32_t> id;
        for (;;) {
            for (int r = 0; r < 3; ++r)
                dims[r] = static_cast<int>(std::floor((hi[r] - lo[r]) / cell)) + 2;
            id.assign(static_cast<size_t>(dims.prod()), -1);
            size_t used = 0;
            for (const std::int32_t i : vs) {
                int c[3];
                for (int r = 0; r < 3; ++r)
                    c[r] = std::clamp(static_cast<int>(std::floor((x(i, r) - lo[r]) / cell)), 0, dims[r] - 2);
                for (int k = 0; k < 8; ++k) {
                    const size_t cell_id = static_cast<size_t>(
                        ((c[2] + ((k >> 2) & 1)) * dims[1] + (c[1] + ((k >> 1) & 1))) * dims[0] + (c[0] + (k & 1)));
                    if (id[cell_id] < 0) {
                        id[cell_id] = 0;
                        ++used;
                    }
                }
            }
            if (used <= cap || cell > extent) break;
            cell *= 1.25;
        }
        id.assign(id.size(), -1);
        Object obj;
        for (const std::int32_t i : vs) {
            int c[3];
            double t[3];
            for (int r = 0; r < 3; ++r) {
                const double q = (x(i, r) - lo[r]) / cell;
                c[r] = std::clamp(static_cast<int>(std::floor(q)), 0, dims[r] - 2);
                t[r] = std::clamp(q - c[r], 0.0, 1.0);
            }
            for (int k = 0; k < 8; ++k) {
                const int a = k & 1, b = (k >> 1) & 1, d = (k >> 2) & 1;
                const double w = (a ? t[0] : 1 - t[0]) * (b ? t[1] : 1 - t[1]) * (d ? t[2] : 1 - t[2]);
                const size_t cell_id = static_cast<size_t>(((c[2] + d) * dims[1] + (c[1] + b)) * dims[0] + (c[0] + a));
                if (id[cell_id] < 0) {
                    id[cell_id] = m_nodes++;
                    m_object.push_back(static_cast<std::int32_t>(m_objects.size()));
                }
                m_node[8 * static_cast<size_t>(i) + static_cast<size_t>(k)] = id[cell_id];
                m_weight[8 * static_cast<size_t>(i) + static_cast<size_t>(k)] = w;
            }
            if (!model.fixed[static_cast<size_t>(i)]) {
                const double m = model.mass[static_cast<size_t>(i)];
                obj.vertices.push_back(i);
                obj.centre0 += m * x.row(i).transpose();
                obj.mass += m;
            }
        }
        obj.centre0 = obj.mass > 0 ? Eigen::Vector3d(obj.centre0 / obj.mass) : Eigen::Vector3d::Zero();
        m_objects.push_back(std::move(obj));
    }
    m_rotation.assign(m_objects.size(), Eigen::Matrix3d::Identity());
    m_factored_rotation = m_rotation;
    m_factored_extra.clear();
    m_factored_h = 0;
    m_factored_age = 0;
}

const CoarseSpace::Cached& CoarseSpace::cached(double h)
{
    for (const Cached& c : m_cache)
        if (c.h == h) return c;
    const Model& model = *m_model;
    const Index n = model.num_vertices();
    const size_t un = static_cast<size_t>(n);
    // The fine matrix at the start positions: springs and volume terms (K + C / h; the ground is added per
    // substep), masses / h², and a stiff hold on the pinned vertices of the dynamic objects.
    Model elastic = model;
    elastic.ground.enabled = false;
    std::vector<Eigen::Triplet<double>> trip;
    elastic.add_matrix_triplets(m_start, 1.0, 1.0 / h, trip);
    // The volume terms' relative damping (the sweeps' Hessian has k (1 + damping / h) on them; the model's matrix
    // damps the springs only).
    const Tets& tets = model.volumes.tets;
    for (Index t = 0; t < tets.rows(); ++t) {
        const size_t o = static_cast<size_t>(model.vertex_object[static_cast<size_t>(tets(t, 0))]);
        const double dh = (o < m_damping.size() ? m_damping[o] : 0.0) / h;
        if (!(dh > 0)) continue;
        const Eigen::Vector3d a = m_start.row(tets(t, 0)).transpose(), b = m_start.row(tets(t, 1)).transpose(),
                              c = m_start.row(tets(t, 2)).transpose(), d = m_start.row(tets(t, 3)).transpose();
        Eigen::Matrix<double, 4, 3> g;
        g.row(1) = ((c - a).cross(d - a) / 6).transpose();
        g.row(2) = ((d - a).cross(b - a) / 6).transpose();
        g.row(3) = ((b - a).cross(c - a) / 6).transpose();
        g.row(0) = -(g.row(1) + g.row(2) + g.row(3));
        const double s = dh * model.volumes.k[static_cast<size_t>(t)] / model.volumes.rest[static_cast<size_t>(t)];
        for (int p = 0; p < 4; ++p)
            for (int q = 0; q < 4; ++q) {
                const Index vp = tets(t, p), vq = tets(t, q);
                if (model.fixed[static_cast<size_t>(vp)] || model.fixed[static_cast<size_t>(vq)]) continue;
                for (int r = 0; r < 3; ++r)
                    for (int cc = 0; cc < 3; ++cc)
                        trip.emplace_back(3 * vp + r, 3 * vq + cc, s * g(p, r) * g(q, cc));
            }
    }
    double mass_sum = 0;
    for (Index i = 0; i < n; ++i) {
        const size_t u = static_cast<size_t>(i);
        if (m_node[8 * u] < 0) continue;
        const double m = model.mass[u] / (h * h);
        mass_sum += model.mass[u];
        for (int r = 0; r < 3; ++r)
            trip.emplace_back(3 * i + r, 3 * i + r, model.fixed[u] ? 1e4 * m : m);
    }
    Eigen::SparseMatrix<double> a(3 * n, 3 * n);
    a.setFromTriplets(trip.begin(), trip.end());
    std::vector<Eigen::Triplet<double>> ptrip;
    for (size_t i = 0; i < un; ++i)
        for (size_t k = 0; k < 8; ++k) {
            const std::int32_t node = m_node[8 * i + k];
            if (node < 0 || !(m_weight[8 * i + k] > 0)) continue;
            for (int r = 0; r < 3; ++r)
                ptrip.emplace_back(static_cast<Index>(3 * i) + r, 3 * node + r, m_weight[8 * i + k]);
        }
    Eigen::SparseMatrix<double> p(3 * n, 3 * m_nodes);
    p.setFromTriplets(ptrip.begin(), ptrip.end());
    Eigen::SparseMatrix<double> ac = p.transpose() * (a * p);
    // A node that only vertices far in its cell reach has a tiny diagonal: a small mass term on every node keeps
    // the coarse matrix well conditioned.
    const double floor = 1e-6 * mass_sum / (h * h) / std::max<std::int32_t>(1, m_nodes);

    if (m_blocks.empty()) {
        // The block pattern, once: every 3 × 3 block the product touches, and the 8 × 8 blocks of each vertex.
        auto block_of = [&](std::int32_t bi, std::int32_t bj) {
            const std::int64_t key = static_cast<std::int64_t>(bi) * m_nodes + bj;
            auto [it, inserted] = m_block_index.emplace(key, static_cast<std::int32_t>(m_blocks.size()));
            if (inserted) m_blocks.emplace_back(bi, bj);
            return it->second;
        };
        for (std::int32_t node = 0; node < m_nodes; ++node)
            block_of(node, node);
        for (int c = 0; c < ac.outerSize(); ++c)
            for (Eigen::SparseMatrix<double>::InnerIterator it(ac, c); it; ++it)
                block_of(static_cast<std::int32_t>(it.row() / 3), static_cast<std::int32_t>(it.col() / 3));
        m_vertex_blocks.assign(64 * un, -1);
        for (size_t i = 0; i < un; ++i)
            if (m_node[8 * i] >= 0)
                for (size_t s = 0; s < 8; ++s)
                    for (size_t t = 0; t < 8; ++t)
                        m_vertex_blocks[64 * i + 8 * s + t] = block_of(m_node[8 * i + s], m_node[8 * i + t]);
        std::vector<Eigen::Triplet<double>> pattern;
        for (const auto& [bi, bj] : m_blocks)
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c)
                    pattern.emplace_back(3 * bi + r, 3 * bj + c, 1.0);
        m_matrix.resize(3 * m_nodes, 3 * m_nodes);
        m_matrix.setFromTriplets(pattern.begin(), pattern.end());
        m_matrix.makeCompressed();
        m_block_value.assign(9 * m_blocks.size(), -1);
        std::unordered_map<std::int64_t, std::int32_t> position;
        for (int c = 0; c < m_matrix.outerSize(); ++c)
            for (Eigen::SparseMatrix<double>::InnerIterator it(m_matrix, c); it; ++it)
                position.emplace(static_cast<std::int64_t>(it.row()) * 3 * m_nodes + it.col(),
                                 static_cast<std::int32_t>(&it.value() - m_matrix.valuePtr()));
        for (size_t b = 0; b < m_blocks.size(); ++b)
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c)
                    m_block_value[9 * b + static_cast<size_t>(3 * r + c)] =
                        position.at(static_cast<std::int64_t>(3 * m_blocks[b].first + r) * 3 * m_nodes +
                                    3 * m_blocks[b].second + c);
    }
    Cached out{h, std::vector<double>(9 * m_blocks.size(), 0.0)};
    {
        const auto& index = m_block_index;
        for (int c = 0; c < ac.outerSize(); ++c)
            for (Eigen::SparseMatrix<double>::InnerIterator it(ac, c); it; ++it) {
                const std::int32_t b = index.at(static_cast<std::int64_t>(it.row() / 3) * m_nodes + it.col() / 3);
                out.values[9 * static_cast<size_t>(b) + static_cast<size_t>(3 * (it.row() % 3) + it.col() % 3)] +=
                    it.value();
            }
        for (std::int32_t node = 0; node < m_nodes; ++node) {
            const size_t b = static_cast<size_t>(index.at(static_cast<std::int64_t>(node) * m_nodes + node));
            for (int r = 0; r < 3; ++r)
                out.values[9 * b + static_cast<size_t>(4 * r)] += floor;
        }
    }
    m_cache.push_back(std::move(out));
    return m_cache.back();
}

bool CoarseSpace::prepare(double h, const double* x4, const std::vector<double>& extra,
                          const std::vector<std::int32_t>& with_extra)
{
    if (m_nodes == 0) return false;
    const Cached& base = cached(h);
    const Model& model = *m_model;
    // Each object's rotation since the start: the polar factor of Σ m (x − c)(x0 − c0)ᵀ.
    for (size_t o = 0; o < m_objects.size(); ++o) {
        const Object& obj = m_objects[o];
        if (!(obj.mass > 0)) continue;
        Eigen::Vector3d c = Eigen::Vector3d::Zero();
        for (const std::int32_t i : obj.vertices)
            c += model.mass[static_cast<size_t>(i)] * Eigen::Vector3d(x4[4 * static_cast<size_t>(i)],
                                                                      x4[4 * static_cast<size_t>(i) + 1],
                                                                      x4[4 * static_cast<size_t>(i) + 2]);
        c /= obj.mass;
        Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
        for (const std::int32_t i : obj.vertices) {
            const size_t u = static_cast<size_t>(i);
            const Eigen::Vector3d p = Eigen::Vector3d(x4[4 * u], x4[4 * u + 1], x4[4 * u + 2]) - c;
            s += model.mass[u] * p * (m_start.row(i).transpose() - obj.centre0).transpose();
        }
        m_rotation[o] = closest_rotation(s);
    }
    // The factorisation of a previous substep serves while the contact set and the rotations are the same.
    // (The vertices with ground or contact terms, sorted: counted apart from the last factorisation's, a tenth of them
    // may differ.)
    size_t differ = 0;
    {
        size_t a = 0, b = 0;
        while (a < with_extra.size() || b < m_factored_extra.size()) {
            if (b == m_factored_extra.size() || (a < with_extra.size() && with_extra[a] < m_factored_extra[b])) {
                ++differ;
                ++a;
            } else if (a == with_extra.size() || m_factored_extra[b] < with_extra[a]) {
                ++differ;
                ++b;
            } else {
                ++a;
                ++b;
            }
        }
    }
    bool same = m_analysed && m_factored_h == h && m_factored_age < 8 &&
                10 * differ <= std::max(with_extra.size(), m_factored_extra.size());
    for (size_t o = 0; same && o < m_objects.size(); ++o) {
        const Eigen::AngleAxisd turn(m_rotation[o] * m_factored_rotation[o].transpose());
        same = std::abs(turn.angle()) < 0.05;
    }
    if (same) {
        ++m_factored_age;
        return true;
    }
    m_factored_age = 0;
    m_factored_h = h;
    m_factored_extra = with_extra;
    m_factored_rotation = m_rotation;
    double* values = m_matrix.valuePtr();
    for (size_t b = 0; b < m_blocks.size(); ++b) {
        const Eigen::Matrix3d& r = m_rotation[static_cast<size_t>(m_object[static_cast<size_t>(m_blocks[b].first)])];
        const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> b0(base.values.data() + 9 * b);
        const Eigen::Matrix3d turned = r * b0 * r.transpose();
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                values[m_block_value[9 * b + static_cast<size_t>(3 * i + j)]] = turned(i, j);
    }
    for (const std::int32_t v : with_extra) {
        const size_t u = static_cast<size_t>(v);
        if (m_node[8 * u] < 0) continue;
        const double* e = extra.data() + 6 * u;
        const double blk[9] = {e[0], e[3], e[4], e[3], e[1], e[5], e[4], e[5], e[2]};
        for (size_t s = 0; s < 8; ++s)
            for (size_t t = 0; t < 8; ++t) {
                const double w = m_weight[8 * u + s] * m_weight[8 * u + t];
                if (w == 0) continue;
                const size_t b = static_cast<size_t>(m_vertex_blocks[64 * u + 8 * s + t]);
                for (size_t q = 0; q < 9; ++q)
                    values[m_block_value[9 * b + q]] += w * blk[q];
            }
    }
    if (!m_analysed) {
        m_solver.analyzePattern(m_matrix);
        m_analysed = true;
    }
    m_solver.factorize(m_matrix);
    return m_solver.info() == Eigen::Success;
}

void CoarseSpace::correct(const std::vector<double>& r, std::vector<double>& dx)
{
    const Model& model = *m_model;
    const size_t un = model.mass.size();
    // Each free vertex in a lattice with each of its 8 nodes and weights: restriction Pᵀ r, then prolongation P dc.
    auto each_weight = [&](auto f) {
        for (size_t i = 0; i < un; ++i)
            if (m_node[8 * i] >= 0 && !model.fixed[i])
                for (size_t k = 0; k < 8; ++k)
                    f(3 * i, 3 * static_cast<Index>(m_node[8 * i + k]), m_weight[8 * i + k]);
    };
    m_rc.setZero(3 * m_nodes);
    each_weight([&](size_t v, Index node, double w) {
        for (Index q = 0; q < 3; ++q)
            m_rc[node + q] += w * r[v + static_cast<size_t>(q)];
    });
    m_dc = m_solver.solve(m_rc);
    dx.assign(3 * un, 0.0);
    each_weight([&](size_t v, Index node, double w) {
        for (Index q = 0; q < 3; ++q)
            dx[v + static_cast<size_t>(q)] += w * m_dc[node + q];
    });
}

} // namespace tethash::sim::detail
