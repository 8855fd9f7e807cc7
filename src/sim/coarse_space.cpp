#include "coarse_space.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

#ifdef TETHASH_HAVE_OPENMP
#include <omp.h>
#endif

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

/// A cell's rotation (prepare) is the polar factor of its vertices' moment Σ m (x − c)(x0 − c0)ᵀ plus this fraction of
/// their Σ m |x0 − c0|² times the object's rotation: the object's rotation fills the directions a cell's vertices leave
/// open (along a line, in a plane, few of them), as lattice nodes turned by their own vertices' rotation did not: those
/// whose vertices lay nearly along a line got rotations 0.1-0.9 rad off a stiff body that does not bend, which then
/// swept ten times as much. The raptor at 15 cm and 1/60 swept 1,012 times in its 30 steps with 0, 763 with 0.1, 965
/// with 0.3 (1,356 with the object's rotation alone; docs/simulator.md, "Where a 15 cm step's extra work goes").
constexpr double cell_rotation_hold = 0.1;
/// A cell turned by less than this (rad) against its object takes the object's rotation: only the parts that turned
/// against the body (a leg, a tail) are turned apart, which costs a pass over their entries at a factorisation.
constexpr double cell_own_rotation = 0.2;

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
    m_vertex_cell.assign(un, -1);
    m_cell_object.clear();
    m_cells = 0;
    m_object.clear();
    m_objects.clear();
    m_nodes = 0;
    m_cache.clear();
    m_blocks.clear();
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
        std::vector<std::int32_t> cell_ids(id.size(), -1);
        Object obj;
        // Cells turned apart only where a substep couples further than a cell: below (P1's struts collapsing at 1 m
        // and 1/60, ω h 2.5 against cells of 3.2 mean edges) the sweeps carry a cell's waves, and the cells' own
        // rotations made the collapse enter its own struts within a step (refined steps).
        obj.cells_turn = omega_h > cell / model.object_mean_edge[o];
        for (const std::int32_t i : vs) {
            int c[3];
            double t[3];
            for (int r = 0; r < 3; ++r) {
                const double q = (x(i, r) - lo[r]) / cell;
                c[r] = std::clamp(static_cast<int>(std::floor(q)), 0, dims[r] - 2);
                t[r] = std::clamp(q - c[r], 0.0, 1.0);
            }
            {
                const size_t key = static_cast<size_t>((c[2] * dims[1] + c[1]) * dims[0] + c[0]);
                if (cell_ids[key] < 0) {
                    cell_ids[key] = m_cells++;
                    m_cell_object.push_back(static_cast<std::int32_t>(m_objects.size()));
                }
                m_vertex_cell[static_cast<size_t>(i)] = cell_ids[key];
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
    if (m_nodes > 0) build_pattern();
}

std::int32_t CoarseSpace::block_at(std::int32_t bi, std::int32_t bj) const
{
    const size_t o = static_cast<size_t>(m_object[static_cast<size_t>(bi)]);
    if (o == static_cast<size_t>(m_object[static_cast<size_t>(bj)])) {
        const std::int32_t first = m_object_first[o], count = m_object_first[o + 1] - first;
        return m_local_block[m_local_offset[o] + static_cast<size_t>(bi - first) * static_cast<size_t>(count) +
                             static_cast<size_t>(bj - first)];
    }
    const auto it = m_cross_block.find(static_cast<std::int64_t>(bi) * m_nodes + bj);
    return it == m_cross_block.end() ? -1 : it->second;
}

void CoarseSpace::build_pattern()
{
    const Model& model = *m_model;
    const size_t un = model.mass.size();
    // Per object a dense table node × node → block (its nodes are numbered one after the other), an object's at most
    // 400 nodes; pairs across objects (an element joining two objects) in a map.
    const size_t objects = m_objects.size();
    m_object_first.assign(objects + 1, m_nodes);
    for (std::int32_t node = m_nodes - 1; node >= 0; --node)
        m_object_first[static_cast<size_t>(m_object[static_cast<size_t>(node)])] = node;
    m_local_offset.assign(objects + 1, 0);
    for (size_t o = 0; o < objects; ++o) {
        const size_t count = static_cast<size_t>(m_object_first[o + 1] - m_object_first[o]);
        m_local_offset[o + 1] = m_local_offset[o] + count * count;
    }
    m_local_block.assign(m_local_offset[objects], -1);
    m_cross_block.clear();
    m_blocks.clear();
    auto add = [&](std::int32_t bi, std::int32_t bj) {
        const size_t o = static_cast<size_t>(m_object[static_cast<size_t>(bi)]);
        std::int32_t* slot = nullptr;
        if (o == static_cast<size_t>(m_object[static_cast<size_t>(bj)])) {
            const std::int32_t first = m_object_first[o], count = m_object_first[o + 1] - first;
            slot = &m_local_block[m_local_offset[o] + static_cast<size_t>(bi - first) * static_cast<size_t>(count) +
                                  static_cast<size_t>(bj - first)];
        } else {
            slot = &m_cross_block.emplace(static_cast<std::int64_t>(bi) * m_nodes + bj, -1).first->second;
        }
        if (*slot < 0) {
            *slot = static_cast<std::int32_t>(m_blocks.size());
            m_blocks.emplace_back(bi, bj);
        }
    };
    for (std::int32_t node = 0; node < m_nodes; ++node)
        add(node, node);
    // Every pair of nodes an element (spring, tet) or a vertex couples: the blocks Pᵀ A P can touch.
    std::vector<std::int32_t> nodes;
    auto couple = [&](const Index* vs, int count) {
        nodes.clear();
        for (int a = 0; a < count; ++a) {
            const size_t u = static_cast<size_t>(vs[a]);
            if (m_node[8 * u] < 0) continue;
            for (size_t k = 0; k < 8; ++k)
                if (std::find(nodes.begin(), nodes.end(), m_node[8 * u + k]) == nodes.end())
                    nodes.push_back(m_node[8 * u + k]);
        }
        for (const std::int32_t bi : nodes)
            for (const std::int32_t bj : nodes)
                add(bi, bj);
    };
    for (Index e = 0; e < model.springs.edges.rows(); ++e) {
        const Index vs[2] = {model.springs.edges(e, 0), model.springs.edges(e, 1)};
        couple(vs, 2);
    }
    for (Index t = 0; t < model.volumes.tets.rows(); ++t) {
        const Index vs[4] = {model.volumes.tets(t, 0), model.volumes.tets(t, 1), model.volumes.tets(t, 2),
                             model.volumes.tets(t, 3)};
        couple(vs, 4);
    }
    for (size_t i = 0; i < un; ++i) {
        const Index v = static_cast<Index>(i);
        couple(&v, 1);
    }
    // Per cell the elements whose first vertex in a lattice lies in it (their stiffness is turned by its rotation),
    // and its free vertices (which give the rotation).
    auto element_cell = [&](const Index* vs, int count) {
        for (int a = 0; a < count; ++a)
            if (m_vertex_cell[static_cast<size_t>(vs[a])] >= 0) return m_vertex_cell[static_cast<size_t>(vs[a])];
        return std::int32_t{-1};
    };
    auto bucket = [&](std::vector<std::int32_t>& start, std::vector<std::int32_t>& items, Index count, auto cell_of) {
        start.assign(static_cast<size_t>(m_cells) + 1, 0);
        for (Index e = 0; e < count; ++e) {
            const std::int32_t c = cell_of(e);
            if (c >= 0) ++start[static_cast<size_t>(c) + 1];
        }
        for (size_t c = 0; c < static_cast<size_t>(m_cells); ++c)
            start[c + 1] += start[c];
        items.resize(static_cast<size_t>(start.back()));
        std::vector<std::int32_t> fill(start.begin(), start.end() - 1);
        for (Index e = 0; e < count; ++e) {
            const std::int32_t c = cell_of(e);
            if (c >= 0) items[static_cast<size_t>(fill[static_cast<size_t>(c)]++)] = static_cast<std::int32_t>(e);
        }
    };
    bucket(m_cell_spring_start, m_cell_spring, model.springs.edges.rows(), [&](Index e) {
        const Index vs[2] = {model.springs.edges(e, 0), model.springs.edges(e, 1)};
        return element_cell(vs, 2);
    });
    bucket(m_cell_tet_start, m_cell_tet, model.volumes.tets.rows(), [&](Index t) {
        const Index vs[4] = {model.volumes.tets(t, 0), model.volumes.tets(t, 1), model.volumes.tets(t, 2),
                             model.volumes.tets(t, 3)};
        return element_cell(vs, 4);
    });
    bucket(m_cell_vertex_start, m_cell_vertex, static_cast<Index>(un), [&](Index i) {
        return model.fixed[static_cast<size_t>(i)] ? std::int32_t{-1} : m_vertex_cell[static_cast<size_t>(i)];
    });
    m_vertex_blocks.assign(64 * un, -1);
    for (size_t i = 0; i < un; ++i)
        if (m_node[8 * i] >= 0)
            for (size_t s = 0; s < 8; ++s)
                for (size_t t = 0; t < 8; ++t)
                    m_vertex_blocks[64 * i + 8 * s + t] = block_at(m_node[8 * i + s], m_node[8 * i + t]);
    // The matrix's CSR pattern (column-major, rows sorted in each column) and each block's 9 positions in it.
    std::vector<std::int32_t> column_count(3 * static_cast<size_t>(m_nodes), 0);
    for (const auto& b : m_blocks)
        for (int c = 0; c < 3; ++c)
            column_count[3 * static_cast<size_t>(b.second) + static_cast<size_t>(c)] += 3;
    m_matrix.resize(3 * m_nodes, 3 * m_nodes);
    m_matrix.reserve(Eigen::Map<const Eigen::VectorXi>(column_count.data(), 3 * m_nodes));
    std::vector<size_t> order(m_blocks.size());
    for (size_t b = 0; b < order.size(); ++b)
        order[b] = b;
    std::sort(order.begin(), order.end(), [&](size_t p, size_t q) {
        return std::make_pair(m_blocks[p].second, m_blocks[p].first) <
               std::make_pair(m_blocks[q].second, m_blocks[q].first);
    });
    for (const size_t b : order)
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r)
                m_matrix.insert(3 * m_blocks[b].first + r, 3 * m_blocks[b].second + c) = 0.0;
    m_matrix.makeCompressed();
    m_block_value.assign(9 * m_blocks.size(), -1);
    for (size_t b = 0; b < m_blocks.size(); ++b) {
        const std::int32_t bi = m_blocks[b].first, bj = m_blocks[b].second;
        for (int c = 0; c < 3; ++c) {
            const Index col = 3 * bj + c;
            const int* rows = m_matrix.innerIndexPtr() + m_matrix.outerIndexPtr()[col];
            const int* rows_end = m_matrix.innerIndexPtr() + m_matrix.outerIndexPtr()[col + 1];
            const int* at = std::lower_bound(rows, rows_end, 3 * bi);
            for (int r = 0; r < 3; ++r)
                m_block_value[9 * b + static_cast<size_t>(3 * r + c)] =
                    static_cast<std::int32_t>(at + r - m_matrix.innerIndexPtr());
        }
    }
    // Per node the (vertex, weight) pairs of the free vertices it interpolates, in vertex order: the restriction
    // Pᵀ r gathered node by node sums in the order a pass over the vertices would.
    m_node_start.assign(static_cast<size_t>(m_nodes) + 1, 0);
    for (size_t i = 0; i < un; ++i)
        if (m_node[8 * i] >= 0 && !model.fixed[i])
            for (size_t k = 0; k < 8; ++k)
                ++m_node_start[static_cast<size_t>(m_node[8 * i + k]) + 1];
    for (size_t node = 0; node < static_cast<size_t>(m_nodes); ++node)
        m_node_start[node + 1] += m_node_start[node];
    m_node_vertex.resize(static_cast<size_t>(m_node_start.back()));
    m_node_weight.resize(m_node_vertex.size());
    std::vector<std::int32_t> fill(m_node_start.begin(), m_node_start.end() - 1);
    for (size_t i = 0; i < un; ++i)
        if (m_node[8 * i] >= 0 && !model.fixed[i])
            for (size_t k = 0; k < 8; ++k) {
                const size_t at = static_cast<size_t>(fill[static_cast<size_t>(m_node[8 * i + k])]++);
                m_node_vertex[at] = static_cast<std::int32_t>(i);
                m_node_weight[at] = m_weight[8 * i + k];
            }
}

const CoarseSpace::Cached& CoarseSpace::cached(double h)
{
    for (const Cached& c : m_cache)
        if (c.h == h) return c;
    const Model& model = *m_model;
    const size_t un = model.mass.size();
    // Pᵀ (K + C / h + M / h²) P at the start positions, assembled element by element on the lattice: an element's
    // fine matrix is Dᵀ B D (a spring: D = [I, −I] on its two vertices, B its 3 × 3 block; a tet: D the 4 gradients
    // gᵀ, B = s I), so its coarse part is (P D)ᵀ B (P D) with P D gathered on the element's few distinct nodes
    // (its vertices share most of their cell corners). Pinned vertices drop out of D (their rows and columns of the
    // fine matrix are empty) and get a stiff hold on their mass; the ground is added per substep.
    Cached out{h, std::vector<double>(9 * m_blocks.size(), 0.0), {}, {}, {}};
    double* values = out.values.data();
    // The elements' part also cell by cell (the cell of each element's first vertex), each cell's blocks apart, to
    // be turned by the cell's own rotation (prepare).
    std::vector<std::int32_t> cell_slot(m_blocks.size(), -1);
    auto add_block = [&](std::int32_t bi, std::int32_t bj, const Eigen::Matrix3d& b) {
        const std::int32_t block = block_at(bi, bj);
        double* v = values + 9 * static_cast<size_t>(block);
        std::int32_t& at = cell_slot[static_cast<size_t>(block)];
        if (at < 0) {
            at = static_cast<std::int32_t>(out.cell_block.size());
            out.cell_block.push_back(block);
            out.cell_values.resize(out.cell_values.size() + 9, 0.0);
        }
        double* w = out.cell_values.data() + 9 * static_cast<size_t>(at);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) {
                v[3 * r + c] += b(r, c);
                w[3 * r + c] += b(r, c);
            }
    };
    // An element's distinct nodes and per node its row of P D (a weight per vertex times the vertex's D).
    std::vector<std::int32_t> nodes;
    std::vector<Eigen::Vector3d> rows; // tets: Σ w g per node
    std::vector<double> weights;       // springs: Σ ± w per node
    auto slot = [&](std::int32_t node) {
        const auto it = std::find(nodes.begin(), nodes.end(), node);
        if (it != nodes.end()) return static_cast<size_t>(it - nodes.begin());
        nodes.push_back(node);
        rows.emplace_back(Eigen::Vector3d::Zero());
        weights.push_back(0.0);
        return nodes.size() - 1;
    };
    auto in_play = [&](Index v) {
        return m_node[8 * static_cast<size_t>(v)] >= 0 && !model.fixed[static_cast<size_t>(v)];
    };
    auto spring_part = [&](Index e) {
        const Index i = model.springs.edges(e, 0), j = model.springs.edges(e, 1);
        const Eigen::Vector3d d = (m_start.row(i) - m_start.row(j)).transpose();
        const double len = d.norm();
        if (!(len > 0)) return;
        const Eigen::Vector3d u = d / len;
        const Eigen::Matrix3d uu = u * u.transpose();
        const size_t ue = static_cast<size_t>(e);
        // −∂f/∂x of the spring, its transverse term clamped at 0 (as Model::add_matrix_triplets), and its damping.
        const double tr = std::max(0.0, 1.0 - model.springs.rest[ue] / len);
        const Eigen::Matrix3d b =
            model.springs.k[ue] * (uu + tr * (Eigen::Matrix3d::Identity() - uu)) + model.springs.c[ue] / h * uu;
        nodes.clear();
        rows.clear();
        weights.clear();
        for (const auto& [v, sign] : {std::pair{i, 1.0}, std::pair{j, -1.0}})
            if (in_play(v))
                for (size_t k = 0; k < 8; ++k) {
                    const size_t at = slot(m_node[8 * static_cast<size_t>(v) + k]);
                    weights[at] += sign * m_weight[8 * static_cast<size_t>(v) + k];
                }
        for (size_t p = 0; p < nodes.size(); ++p)
            for (size_t q = 0; q < nodes.size(); ++q)
                add_block(nodes[p], nodes[q], (weights[p] * weights[q]) * b);
    };
    // The volume terms: k / 6V0 (g gᵀ) with the relative damping the sweeps give them (k (1 + damping / h); the
    // model's matrix damps the springs only).
    const Tets& tets = model.volumes.tets;
    auto tet_part = [&](Index t) {
        const size_t o = static_cast<size_t>(model.vertex_object[static_cast<size_t>(tets(t, 0))]);
        const double dh = (o < m_damping.size() ? m_damping[o] : 0.0) / h;
        const Eigen::Vector3d a = m_start.row(tets(t, 0)).transpose(), b = m_start.row(tets(t, 1)).transpose(),
                              c = m_start.row(tets(t, 2)).transpose(), d = m_start.row(tets(t, 3)).transpose();
        const Eigen::Vector3d ba = b - a, ca = c - a, da = d - a;
        Eigen::Vector3d g[4];
        g[1] = ca.cross(da) / 6.0;
        g[2] = da.cross(ba) / 6.0;
        g[3] = ba.cross(ca) / 6.0;
        g[0] = -(g[1] + g[2] + g[3]);
        const double k_v = model.volumes.k[static_cast<size_t>(t)] / model.volumes.rest[static_cast<size_t>(t)];
        const double s = dh > 0 ? k_v + dh * k_v : k_v;
        nodes.clear();
        rows.clear();
        weights.clear();
        for (int p = 0; p < 4; ++p) {
            const Index v = tets(t, p);
            if (!in_play(v)) continue;
            for (size_t k = 0; k < 8; ++k) {
                const size_t at = slot(m_node[8 * static_cast<size_t>(v) + k]);
                rows[at] += m_weight[8 * static_cast<size_t>(v) + k] * g[p];
            }
        }
        for (size_t p = 0; p < nodes.size(); ++p) {
            const Eigen::Vector3d sp = s * rows[p];
            for (size_t q = 0; q < nodes.size(); ++q)
                add_block(nodes[p], nodes[q], sp * rows[q].transpose());
        }
    };
    out.cell_start.assign(1, 0);
    for (size_t c = 0; c < static_cast<size_t>(m_cells); ++c) {
        for (std::int32_t at = m_cell_spring_start[c]; at < m_cell_spring_start[c + 1]; ++at)
            spring_part(m_cell_spring[static_cast<size_t>(at)]);
        for (std::int32_t at = m_cell_tet_start[c]; at < m_cell_tet_start[c + 1]; ++at)
            tet_part(m_cell_tet[static_cast<size_t>(at)]);
        for (size_t at = static_cast<size_t>(out.cell_start.back()); at < out.cell_block.size(); ++at)
            cell_slot[static_cast<size_t>(out.cell_block[at])] = -1;
        out.cell_start.push_back(static_cast<std::int32_t>(out.cell_block.size()));
    }
    // The masses / h² (pinned vertices of the dynamic objects held by 10⁴ times theirs).
    double mass_sum = 0;
    for (size_t u = 0; u < un; ++u) {
        if (m_node[8 * u] < 0) continue;
        const double m = model.mass[u] / (h * h);
        mass_sum += model.mass[u];
        const double mh = model.fixed[u] ? 1e4 * m : m;
        for (size_t p = 0; p < 8; ++p)
            for (size_t q = 0; q < 8; ++q) {
                double* v = values + 9 * static_cast<size_t>(m_vertex_blocks[64 * u + 8 * p + q]);
                const double w = mh * m_weight[8 * u + p] * m_weight[8 * u + q];
                v[0] += w;
                v[4] += w;
                v[8] += w;
            }
    }
    // A node that only vertices far in its cell reach has a tiny diagonal: a small mass term on every node keeps
    // the coarse matrix well conditioned.
    const double floor = 1e-6 * mass_sum / (h * h) / std::max<std::int32_t>(1, m_nodes);
    for (std::int32_t node = 0; node < m_nodes; ++node) {
        double* v = values + 9 * static_cast<size_t>(block_at(node, node));
        v[0] += floor;
        v[4] += floor;
        v[8] += floor;
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
    bool same = m_analysed && m_factor.ok() && m_factored_h == h && m_factored_age < 8 &&
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
    // Each cell's rotation since the start: the polar factor of its free vertices' Σ m (x − c)(x0 − c0)ᵀ plus
    // cell_rotation_hold times their Σ m |x0 − c0|² times the object's rotation (a cell whose vertices lie along a
    // line or in a plane, or hold little mass, takes the object's rotation about what they leave open), the object's
    // where that is no rotation (an inverted cell) or within cell_own_rotation of it.
    m_cell_rotation.resize(static_cast<size_t>(m_cells));
    m_turned_cells.clear();
    for (size_t cell = 0; cell < static_cast<size_t>(m_cells); ++cell) {
        const Eigen::Matrix3d& ro = m_rotation[static_cast<size_t>(m_cell_object[cell])];
        if (!m_objects[static_cast<size_t>(m_cell_object[cell])].cells_turn) {
            m_cell_rotation[cell] = ro;
            continue;
        }
        double mass = 0;
        Eigen::Vector3d c = Eigen::Vector3d::Zero(), c0 = Eigen::Vector3d::Zero();
        for (std::int32_t at = m_cell_vertex_start[cell]; at < m_cell_vertex_start[cell + 1]; ++at) {
            const size_t v = static_cast<size_t>(m_cell_vertex[static_cast<size_t>(at)]);
            mass += model.mass[v];
            c += model.mass[v] * Eigen::Vector3d(x4[4 * v], x4[4 * v + 1], x4[4 * v + 2]);
            c0 += model.mass[v] * m_start.row(static_cast<Index>(v)).transpose();
        }
        if (!(mass > 0)) {
            m_cell_rotation[cell] = ro;
            continue;
        }
        c /= mass;
        c0 /= mass;
        Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
        double spread = 0;
        for (std::int32_t at = m_cell_vertex_start[cell]; at < m_cell_vertex_start[cell + 1]; ++at) {
            const size_t v = static_cast<size_t>(m_cell_vertex[static_cast<size_t>(at)]);
            const Eigen::Vector3d q0 = m_start.row(static_cast<Index>(v)).transpose() - c0;
            s += model.mass[v] * (Eigen::Vector3d(x4[4 * v], x4[4 * v + 1], x4[4 * v + 2]) - c) * q0.transpose();
            spread += model.mass[v] * q0.squaredNorm();
        }
        s += cell_rotation_hold * spread * ro;
        m_cell_rotation[cell] = s.determinant() > 0 ? closest_rotation(s) : ro;
        if (std::abs(Eigen::AngleAxisd(m_cell_rotation[cell] * ro.transpose()).angle()) < cell_own_rotation)
            m_cell_rotation[cell] = ro;
        else
            m_turned_cells.push_back(static_cast<std::int32_t>(cell));
    }
    double* values = m_matrix.valuePtr();
    // Each thread owns the blocks of a range of the matrix's block rows: it turns them, then adds the ground's and
    // contacts' terms that fall in them, vertex by vertex (every entry sums in vertex order at any thread count).
    const bool parallel = m_threads > 1 && m_blocks.size() > 2048;
#ifdef TETHASH_HAVE_OPENMP
#pragma omp parallel num_threads(m_threads) if (parallel)
#endif
    {
        std::int32_t lo = 0, hi = m_nodes;
#ifdef TETHASH_HAVE_OPENMP
        const std::int32_t part = omp_get_thread_num(), parts = omp_get_num_threads();
        lo = static_cast<std::int32_t>(static_cast<std::int64_t>(m_nodes) * part / parts);
        hi = static_cast<std::int32_t>(static_cast<std::int64_t>(m_nodes) * (part + 1) / parts);
#endif
        for (size_t b = 0; b < m_blocks.size(); ++b) {
            const std::int32_t row = m_blocks[b].first;
            if (row < lo || row >= hi) continue;
            const Eigen::Matrix3d& r = m_rotation[static_cast<size_t>(m_object[static_cast<size_t>(row)])];
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
            for (size_t s = 0; s < 8; ++s) {
                const std::int32_t row = m_node[8 * u + s];
                if (row < lo || row >= hi) continue;
                for (size_t t = 0; t < 8; ++t) {
                    const double w = m_weight[8 * u + s] * m_weight[8 * u + t];
                    if (w == 0) continue;
                    const size_t b = static_cast<size_t>(m_vertex_blocks[64 * u + 8 * s + t]);
                    for (size_t q = 0; q < 9; ++q)
                        values[m_block_value[9 * b + q]] += w * blk[q];
                }
            }
        }
    }
    if (!m_turned_cells.empty()) {
        // The cells turned apart from their object: their part turned by their own rotation instead of the object's
        // (the differences in parallel, each entry apart; summed in entry order, the same at any thread count).
        m_turned.resize(base.cell_values.size());
        const std::int32_t count = static_cast<std::int32_t>(m_turned_cells.size());
#ifdef TETHASH_HAVE_OPENMP
#pragma omp parallel for num_threads(m_threads) schedule(static) if (m_threads > 1 && count > 16)
#endif
        for (std::int32_t k = 0; k < count; ++k) {
            const size_t cell = static_cast<size_t>(m_turned_cells[static_cast<size_t>(k)]);
            const Eigen::Matrix3d& rc = m_cell_rotation[cell];
            const Eigen::Matrix3d& ro = m_rotation[static_cast<size_t>(m_cell_object[cell])];
            for (std::int32_t at = base.cell_start[cell]; at < base.cell_start[cell + 1]; ++at) {
                const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> b0(base.cell_values.data() +
                                                                                        9 * static_cast<size_t>(at));
                Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m_turned.data() +
                                                                         9 * static_cast<size_t>(at)) =
                    rc * b0 * rc.transpose() - ro * b0 * ro.transpose();
            }
        }
        for (const std::int32_t cell : m_turned_cells)
            for (std::int32_t at = base.cell_start[static_cast<size_t>(cell)];
                 at < base.cell_start[static_cast<size_t>(cell) + 1]; ++at) {
                const size_t b = static_cast<size_t>(base.cell_block[static_cast<size_t>(at)]);
                for (size_t q = 0; q < 9; ++q)
                    values[m_block_value[9 * b + q]] += m_turned[9 * static_cast<size_t>(at) + q];
            }
    }
    if (!m_analysed) {
        m_factor.analyse(m_nodes, m_blocks);
        m_analysed = true;
    }
    return m_factor.factorise(m_matrix.valuePtr(), m_block_value.data());
}

Eigen::MatrixXd CoarseSpace::start_matrix(double h)
{
    Eigen::MatrixXd out = Eigen::MatrixXd::Zero(3 * m_nodes, 3 * m_nodes);
    if (m_nodes == 0) return out;
    const Cached& base = cached(h);
    for (size_t b = 0; b < m_blocks.size(); ++b)
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                out(3 * m_blocks[b].first + r, 3 * m_blocks[b].second + c) =
                    base.values[9 * b + static_cast<size_t>(3 * r + c)];
    return out;
}

Eigen::SparseMatrix<double> CoarseSpace::prolongation() const
{
    const size_t un = m_node.size() / 8;
    std::vector<Eigen::Triplet<double>> trip;
    for (size_t i = 0; i < un; ++i)
        for (size_t k = 0; k < 8; ++k)
            if (m_node[8 * i + k] >= 0)
                for (int r = 0; r < 3; ++r)
                    trip.emplace_back(static_cast<Index>(3 * i) + r, 3 * m_node[8 * i + k] + r, m_weight[8 * i + k]);
    Eigen::SparseMatrix<double> p(static_cast<Index>(3 * un), 3 * m_nodes);
    p.setFromTriplets(trip.begin(), trip.end());
    return p;
}

void CoarseSpace::correct(const std::vector<double>& r, std::vector<double>& dx)
{
    const Model& model = *m_model;
    const size_t un = model.mass.size();
    // Restriction Pᵀ r node by node (each node's sum over its vertices in vertex order, whatever the threads), the
    // lattice's solve, then the prolongation P dc vertex by vertex (each vertex's 8 nodes in order).
    m_rc.resize(3 * m_nodes);
    m_dc.resize(3 * m_nodes);
    dx.resize(3 * un);
    const std::int32_t nodes = m_nodes;
    const std::int64_t vertices = static_cast<std::int64_t>(un);
    const bool parallel = m_threads > 1 && un > 4096;
    double* rc = m_rc.data();
#ifdef TETHASH_HAVE_OPENMP
#pragma omp parallel for num_threads(m_threads) schedule(static) if (parallel)
#endif
    for (std::int32_t node = 0; node < nodes; ++node) {
        double s[3] = {0.0, 0.0, 0.0};
        for (std::int32_t at = m_node_start[static_cast<size_t>(node)];
             at < m_node_start[static_cast<size_t>(node) + 1]; ++at) {
            const size_t v = 3 * static_cast<size_t>(m_node_vertex[static_cast<size_t>(at)]);
            const double w = m_node_weight[static_cast<size_t>(at)];
            for (size_t q = 0; q < 3; ++q)
                s[q] += w * r[v + q];
        }
        for (size_t q = 0; q < 3; ++q)
            rc[3 * static_cast<size_t>(node) + q] = s[q];
    }
    m_factor.solve(m_rc.data(), m_dc.data());
    const double* dc = m_dc.data();
#ifdef TETHASH_HAVE_OPENMP
#pragma omp parallel for num_threads(m_threads) schedule(static) if (parallel)
#endif
    for (std::int64_t iv = 0; iv < vertices; ++iv) {
        const size_t i = static_cast<size_t>(iv);
        double s[3] = {0.0, 0.0, 0.0};
        if (m_node[8 * i] >= 0 && !model.fixed[i])
            for (size_t k = 0; k < 8; ++k) {
                const size_t node = 3 * static_cast<size_t>(m_node[8 * i + k]);
                const double w = m_weight[8 * i + k];
                for (size_t q = 0; q < 3; ++q)
                    s[q] += w * dc[node + q];
            }
        for (size_t q = 0; q < 3; ++q)
            dx[3 * i + q] = s[q];
    }
}

} // namespace tethash::sim::detail
