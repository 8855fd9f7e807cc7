#include "tethash/sim/model.hpp"

#include "block_sum.hpp"

#include "tethash/error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace tethash::sim {

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

Vec3 row(const Positions& x, Index i)
{
    return x.row(i).transpose();
}

/// Signed volume and its gradient with respect to the four vertices (rows of g).
double volume_and_gradient(const Positions& x, const Index* t, Eigen::Matrix<double, 4, 3>& g)
{
    const Vec3 a = row(x, t[0]), b = row(x, t[1]), c = row(x, t[2]), d = row(x, t[3]);
    const Vec3 ba = b - a, ca = c - a, da = d - a;
    const Vec3 gb = ca.cross(da) / 6.0, gc = da.cross(ba) / 6.0, gd = ba.cross(ca) / 6.0;
    g.row(1) = gb.transpose();
    g.row(2) = gc.transpose();
    g.row(3) = gd.transpose();
    g.row(0) = -(gb + gc + gd).transpose();
    return ba.dot(ca.cross(da)) / 6.0;
}

/// Volume of the regular tet of edge length l: l³ / (6 √2).
double regular_tet_volume(double l)
{
    return l * l * l / (6.0 * std::sqrt(2.0));
}

/// Per-vertex Gershgorin sums of the stiffness (Σ |K_ij| over the block row) and damping.
void gershgorin(const Model& m, const Positions& x, std::vector<double>& ksum, std::vector<double>& csum)
{
    const size_t n = m.mass.size();
    ksum.assign(n, 0.0);
    csum.assign(n, 0.0);
    for (Index e = 0; e < m.springs.edges.rows(); ++e) {
        for (int s = 0; s < 2; ++s) {
            ksum[static_cast<size_t>(m.springs.edges(e, s))] += 2 * m.springs.k[static_cast<size_t>(e)];
            csum[static_cast<size_t>(m.springs.edges(e, s))] += 2 * m.springs.c[static_cast<size_t>(e)];
        }
    }
    Eigen::Matrix<double, 4, 3> g;
    for (Index t = 0; t < m.volumes.tets.rows(); ++t) {
        volume_and_gradient(x, &m.volumes.tets(t, 0), g);
        const double s = m.volumes.k[static_cast<size_t>(t)] / m.volumes.rest[static_cast<size_t>(t)];
        double total = 0;
        for (int a = 0; a < 4; ++a)
            total += g.row(a).norm();
        for (int a = 0; a < 4; ++a)
            ksum[static_cast<size_t>(m.volumes.tets(t, a))] += s * g.row(a).norm() * total;
    }
}

} // namespace

namespace {

/// Per vertex: friction_smoothing × the largest side of its object's rest bounding box.
std::vector<double> friction_speeds(const Positions& rest, const std::vector<Index>& vertex_object, size_t objects)
{
    std::vector<Vec3> lo(objects, Vec3::Constant(std::numeric_limits<double>::infinity()));
    std::vector<Vec3> hi(objects, Vec3::Constant(-std::numeric_limits<double>::infinity()));
    for (Index i = 0; i < rest.rows(); ++i) {
        const size_t o = static_cast<size_t>(vertex_object[static_cast<size_t>(i)]);
        lo[o] = lo[o].cwiseMin(row(rest, i));
        hi[o] = hi[o].cwiseMax(row(rest, i));
    }
    std::vector<double> speed(static_cast<size_t>(rest.rows()));
    for (Index i = 0; i < rest.rows(); ++i) {
        const size_t o = static_cast<size_t>(vertex_object[static_cast<size_t>(i)]);
        speed[static_cast<size_t>(i)] = friction_smoothing * (hi[o] - lo[o]).maxCoeff();
    }
    return speed;
}

/// Per spring: the rest volume of the tets around its edge (per vertex a sorted list of (other end, edge), then
/// every tet's six edges).
std::vector<double> edge_volumes(const Edges& edges, const Tets& tets, const std::vector<double>& rest_volume, Index n)
{
    const Index ne = static_cast<Index>(edges.rows());
    std::vector<double> edge_volume(static_cast<size_t>(ne), 0.0);
    std::vector<Index> start(static_cast<size_t>(n + 1), 0);
    for (Index e = 0; e < ne; ++e)
        ++start[static_cast<size_t>(edges(e, 0) + 1)];
    for (Index i = 0; i < n; ++i)
        start[static_cast<size_t>(i + 1)] += start[static_cast<size_t>(i)];
    std::vector<Index> other(static_cast<size_t>(ne)), id(static_cast<size_t>(ne));
    std::vector<Index> fill(start.begin(), start.end() - 1);
    for (Index e = 0; e < ne; ++e) {
        const size_t k = static_cast<size_t>(fill[static_cast<size_t>(edges(e, 0))]++);
        other[k] = edges(e, 1);
        id[k] = e;
    }
    auto find_edge = [&](Index a, Index b) {
        if (a > b) std::swap(a, b);
        for (Index k = start[static_cast<size_t>(a)]; k < start[static_cast<size_t>(a + 1)]; ++k)
            if (other[static_cast<size_t>(k)] == b) return id[static_cast<size_t>(k)];
        return Index{-1};
    };
    for (Index q = 0; q < tets.rows(); ++q)
        for (int a = 0; a < 4; ++a)
            for (int b = a + 1; b < 4; ++b) {
                const Index e = find_edge(tets(q, a), tets(q, b));
                if (e >= 0) edge_volume[static_cast<size_t>(e)] += rest_volume[static_cast<size_t>(q)];
            }
    return edge_volume;
}

/// The mass floor of Model::build (free vertices with edges): at least the mass that keeps each vertex's Gershgorin
/// bound of stiffness / mass at (2 / h_m)², the mass added taken back from the vertices above the floor.
void floor_masses(Model& m, const Positions& rest, const std::vector<double>& vertex_edge_count, size_t objects)
{
    const Index n = m.num_vertices();
    std::vector<double> ksum, csum;
    gershgorin(m, rest, ksum, csum);
    std::vector<double> total(static_cast<size_t>(objects), 0.0), floored(static_cast<size_t>(objects), 0.0);
    std::vector<double> above(static_cast<size_t>(objects), 0.0);
    std::vector<char> at_floor(static_cast<size_t>(n), 0);
    for (Index i = 0; i < n; ++i) {
        const size_t u = static_cast<size_t>(i);
        const size_t o = static_cast<size_t>(m.vertex_object[u]);
        if (m.fixed[u] || !(vertex_edge_count[u] > 0)) continue;
        total[o] += m.mass[u];
        const double floor = ksum[u] * material_courant * material_courant / (4 * m.object_frequency_sq[o]);
        if (floor > m.mass[u]) {
            m.mass[u] = floor;
            at_floor[u] = 1;
            floored[o] += floor;
        } else {
            above[o] += m.mass[u];
        }
    }
    for (Index i = 0; i < n; ++i) {
        const size_t u = static_cast<size_t>(i);
        const size_t o = static_cast<size_t>(m.vertex_object[u]);
        if (m.fixed[u] || !(vertex_edge_count[u] > 0) || at_floor[u]) continue;
        // Floors holding more than 90 % of an object's mass (none on the shared meshes) add mass instead.
        if (above[o] > 0 && total[o] - floored[o] > 0.1 * total[o]) m.mass[u] *= (total[o] - floored[o]) / above[o];
    }
}

} // namespace

Model Model::build(const TetMesh& mesh, const std::vector<Material>& materials, const std::vector<char>& object_static)
{
    Model m;
    const Index n = mesh.num_vertices();
    const Positions& rest = mesh.rest();
    auto tet_obj = [&](Index t) { return mesh.tet_object.empty() ? 0 : mesh.tet_object[static_cast<size_t>(t)]; };
    auto is_static = [&](Index o) {
        return static_cast<size_t>(o) < object_static.size() && object_static[static_cast<size_t>(o)];
    };
    auto material = [&](Index o) -> const Material& {
        if (static_cast<size_t>(o) >= materials.size())
            throw Error("model: no material for object " + std::to_string(o));
        return materials[static_cast<size_t>(o)];
    };
    Index objects = 0;
    m.vertex_object.assign(static_cast<size_t>(n), 0);
    for (Index i = 0; i < n; ++i) {
        m.vertex_object[static_cast<size_t>(i)] =
            mesh.vertex_object.empty() ? 0 : mesh.vertex_object[static_cast<size_t>(i)];
        objects = std::max(objects, m.vertex_object[static_cast<size_t>(i)] + 1);
    }
    objects = std::max<Index>(objects, static_cast<Index>(materials.size()));

    m.mass.assign(static_cast<size_t>(n), 0.0);
    m.fixed.assign(static_cast<size_t>(n), 0);
    for (Index i = 0; i < n; ++i)
        if (is_static(m.vertex_object[static_cast<size_t>(i)])) m.fixed[static_cast<size_t>(i)] = 1;

    // Dynamic tets: rest volumes (oriented positive), lumped masses, volume terms.
    std::vector<Index> dyn;
    for (Index t = 0; t < mesh.num_tets(); ++t)
        if (!is_static(tet_obj(t))) dyn.push_back(t);
    m.volumes.tets.resize(static_cast<Index>(dyn.size()), 4);
    m.volumes.rest.resize(dyn.size());
    m.volumes.k.resize(dyn.size());
    m.volumes.sliver.resize(dyn.size());
    Eigen::Matrix<double, 4, 3> g;
    for (size_t q = 0; q < dyn.size(); ++q) {
        const Index t = dyn[q];
        Index v[4] = {mesh.tets(t, 0), mesh.tets(t, 1), mesh.tets(t, 2), mesh.tets(t, 3)};
        double vol = volume_and_gradient(rest, v, g);
        double lmean = 0;
        for (int a = 0; a < 4; ++a)
            for (int b = a + 1; b < 4; ++b)
                lmean += (row(rest, v[a]) - row(rest, v[b])).norm() / 6.0;
        if (!(std::abs(vol) > 1e-12 * lmean * lmean * lmean) || !std::isfinite(vol))
            throw Error("model: tet " + std::to_string(t) + " has zero volume in the rest state (volume " +
                        std::to_string(vol) + "); fix the mesh (tethash info reports such tets)");
        if (vol < 0) { // inverted at rest: orient the volume term so that its rest volume is positive
            std::swap(v[2], v[3]);
            vol = -vol;
        }
        const Material& mat = material(tet_obj(t));
        for (int a = 0; a < 4; ++a)
            m.mass[static_cast<size_t>(v[a])] += mat.density * vol / 4.0;
        const double young = mat.stiffness > 0 ? mat.stiffness / lmean : mat.young;
        for (int a = 0; a < 4; ++a)
            m.volumes.tets(static_cast<Index>(q), a) = v[a];
        // Energy ½ (volume_stiffness · young / V̂) (V − V0)² with V̂ = max(V0, 0.1 × the volume of the regular
        // tet of this tet's mean edge): a sliver's volume term is no stiffer than a tenth-size regular tet's,
        // so slivers neither dominate the stiffness-to-mass ratios nor get crushed. Stored as k with
        // k / V0 = volume_stiffness · young / V̂.
        const double vhat = std::max(vol, 0.1 * regular_tet_volume(lmean));
        m.volumes.rest[q] = vol;
        m.volumes.k[q] = mat.volume_stiffness * young * vol / vhat;
        m.volumes.sliver[q] = vhat > vol ? 1 : 0;
    }

    // Springs: unique edges of the dynamic tets, Van Gelder stiffness k = young · ΣV_adjacent / L0².
    Tets dyn_tets(static_cast<Index>(dyn.size()), 4);
    for (size_t q = 0; q < dyn.size(); ++q)
        dyn_tets.row(static_cast<Index>(q)) = m.volumes.tets.row(static_cast<Index>(q));
    m.springs.edges = unique_edges(dyn_tets);
    const Index ne = static_cast<Index>(m.springs.edges.rows());
    const std::vector<double> edge_volume = edge_volumes(m.springs.edges, m.volumes.tets, m.volumes.rest, n);
    m.springs.rest.resize(static_cast<size_t>(ne));
    m.springs.k.resize(static_cast<size_t>(ne));
    m.springs.c.resize(static_cast<size_t>(ne));
    m.object_mean_edge.assign(static_cast<size_t>(objects), 0.0);
    std::vector<double> edge_count(static_cast<size_t>(objects), 0.0);
    std::vector<double> vertex_edge_count(static_cast<size_t>(n), 0.0);
    for (Index e = 0; e < ne; ++e) {
        const Index i = m.springs.edges(e, 0), j = m.springs.edges(e, 1);
        const double len = (row(rest, i) - row(rest, j)).norm();
        if (!(len > 0))
            throw Error("model: edge (" + std::to_string(i) + ", " + std::to_string(j) + ") has zero rest length");
        const Index o = m.vertex_object[static_cast<size_t>(i)];
        const Material& mat = material(o);
        const double k =
            mat.stiffness > 0 ? mat.stiffness : mat.young * edge_volume[static_cast<size_t>(e)] / (len * len);
        m.springs.rest[static_cast<size_t>(e)] = len;
        m.springs.k[static_cast<size_t>(e)] = k;
        m.springs.c[static_cast<size_t>(e)] = mat.damping * k;
        m.object_mean_edge[static_cast<size_t>(o)] += len;
        edge_count[static_cast<size_t>(o)] += 1;
        for (Index v : {i, j})
            vertex_edge_count[static_cast<size_t>(v)] += 1;
    }
    for (size_t o = 0; o < m.object_mean_edge.size(); ++o)
        if (edge_count[o] > 0) m.object_mean_edge[o] /= edge_count[o];

    // Mass floor at the material's step: a vertex whose tets are all slivers lumps almost no mass while its
    // springs and volume terms are ordinary; it would then set the explicit limit and condition the solvers.
    // Each object has a wave speed c = sqrt(young / density) and a frequency ω = c / L̄ at its mean edge L̄
    // (object_frequency_sq); every free vertex gets at least the mass that keeps its Gershgorin bound of
    // stiffness / mass at (2 / h_m)², h_m = material_courant / ω, so no vertex's explicit limit falls below
    // h_m whatever the tets' shapes. The mass the floor adds (a small fraction of a real mesh's, on its slivers'
    // vertices; docs/simulator.md) is taken back from the vertices above the floor, so each object keeps
    // density × volume.
    m.object_frequency_sq.assign(static_cast<size_t>(objects), 0.0);
    for (Index o = 0; o < objects; ++o) {
        const double lbar = m.object_mean_edge[static_cast<size_t>(o)];
        if (is_static(o) || !(lbar > 0)) continue;
        const Material& mat = material(o);
        const double young = mat.stiffness > 0 ? mat.stiffness / lbar : mat.young;
        m.object_frequency_sq[static_cast<size_t>(o)] = young / (mat.density * lbar * lbar);
    }
    floor_masses(m, rest, vertex_edge_count, static_cast<size_t>(objects));
    for (Index i = 0; i < n; ++i)
        if (!m.fixed[static_cast<size_t>(i)] && !(m.mass[static_cast<size_t>(i)] > 0))
            m.fixed[static_cast<size_t>(i)] = 1; // unreferenced vertex: nothing moves it
    m.friction_speed = friction_speeds(rest, m.vertex_object, static_cast<size_t>(objects));
    return m;
}

void Model::add_forces(const Positions& x, const Positions& v, Positions& f, const ForceOptions& opt) const
{
    const Index n = num_vertices();
    const bool do_k = opt.parts & ForceOptions::springs, do_c = opt.parts & ForceOptions::damping;
    const Index ne = (do_k || do_c) ? static_cast<Index>(springs.edges.rows()) : 0;
    for (Index e = 0; e < ne; ++e) {
        const Index i = springs.edges(e, 0), j = springs.edges(e, 1);
        const Vec3 d = row(x, i) - row(x, j);
        const double len = d.norm();
        if (!(len > 0)) continue;
        const Vec3 u = d / len;
        double mag = 0;
        if (do_k) mag += springs.k[static_cast<size_t>(e)] * (len - springs.rest[static_cast<size_t>(e)]);
        if (do_c) mag += springs.c[static_cast<size_t>(e)] * (row(v, i) - row(v, j)).dot(u);
        f.row(i) -= mag * u.transpose();
        f.row(j) += mag * u.transpose();
    }
    if (opt.parts & ForceOptions::volume) {
        Eigen::Matrix<double, 4, 3> g;
        for (Index t = 0; t < volumes.tets.rows(); ++t) {
            const double vol = volume_and_gradient(x, &volumes.tets(t, 0), g);
            const double v0 = volumes.rest[static_cast<size_t>(t)];
            const double s = -opt.volume_scale * volumes.k[static_cast<size_t>(t)] * (vol - v0) / v0;
            for (int a = 0; a < 4; ++a)
                f.row(volumes.tets(t, a)) += s * g.row(a);
        }
    }
    if ((opt.parts & ForceOptions::gravity) && gravity.squaredNorm() > 0)
        for (Index i = 0; i < n; ++i)
            f.row(i) += mass[static_cast<size_t>(i)] * gravity.transpose();
    if ((opt.parts & ForceOptions::ground) && ground.enabled) {
        const Vec3& nrm = ground.normal;
        for (Index i = 0; i < n; ++i) {
            const double pen = ground.height - nrm.dot(row(x, i));
            if (pen <= 0) continue;
            const Vec3 vi = row(v, i);
            const double vn = nrm.dot(vi);
            const double fn = std::max(0.0, opt.ground_scale * (ground_k_at(i) * pen - ground_c_at(i) * vn));
            Vec3 force = fn * nrm;
            if (ground.friction > 0) {
                const Vec3 vt = vi - vn * nrm;
                const double speed = vt.norm();
                double ft = ground.friction * fn; // Coulomb, smoothed below the object's friction_speed
                ft *= speed / std::max(speed, friction_speed[static_cast<size_t>(i)]);
                if (opt.h > 0) ft = std::min(ft, mass[static_cast<size_t>(i)] * speed / opt.h);
                if (speed > 0) force -= ft * vt / speed;
            }
            f.row(i) += force.transpose();
        }
    }
}

namespace {

struct VertexSums {
    double kinetic = 0, gravity = 0, ground = 0;
    VertexSums& operator+=(const VertexSums& o)
    {
        kinetic += o.kinetic;
        gravity += o.gravity;
        ground += o.ground;
        return *this;
    }
};

} // namespace

Energy Model::energy(const Positions& x, const Positions& v, int threads, TetScan* tets) const
{
    using detail::block_sum;
    Energy en;
    const VertexSums vs = block_sum<VertexSums>(num_vertices(), threads, [&](Index begin, Index end) {
        VertexSums p;
        for (Index i = begin; i < end; ++i) {
            if (fixed[static_cast<size_t>(i)]) continue;
            p.kinetic += 0.5 * mass[static_cast<size_t>(i)] * v.row(i).squaredNorm();
            p.gravity -= mass[static_cast<size_t>(i)] * gravity.dot(row(x, i));
            if (ground.enabled) {
                const double pen = ground.height - ground.normal.dot(row(x, i));
                if (pen > 0) p.ground += 0.5 * ground_k_at(i) * pen * pen;
            }
        }
        return p;
    });
    en.kinetic = vs.kinetic;
    en.gravity = vs.gravity;
    en.ground = vs.ground;
    en.spring = block_sum<double>(static_cast<Index>(springs.edges.rows()), threads, [&](Index begin, Index end) {
        double sum = 0;
        for (Index e = begin; e < end; ++e) {
            const double len = (row(x, springs.edges(e, 0)) - row(x, springs.edges(e, 1))).norm();
            const double s = len - springs.rest[static_cast<size_t>(e)];
            sum += 0.5 * springs.k[static_cast<size_t>(e)] * s * s;
        }
        return sum;
    });
    // The tets: their energy, and with `tets` the inverted ones and the volume, in one pass (each sum in the blocks'
    // order, so each the same bits as a pass of its own: signed_volume's and find_inverted_tets's products).
    struct TetSums {
        double energy = 0, six_volume = 0;
        std::vector<std::int32_t> inverted;
        TetSums& operator+=(const TetSums& o)
        {
            energy += o.energy;
            six_volume += o.six_volume;
            inverted.insert(inverted.end(), o.inverted.begin(), o.inverted.end());
            return *this;
        }
    };
    const bool scan = tets != nullptr;
    TetSums ts = block_sum<TetSums>(static_cast<Index>(volumes.tets.rows()), threads, [&](Index begin, Index end) {
        TetSums part;
        for (Index t = begin; t < end; ++t) {
            const Vec3 a = row(x, volumes.tets(t, 0));
            const double w = (row(x, volumes.tets(t, 1)) - a)
                                 .dot((row(x, volumes.tets(t, 2)) - a).cross(row(x, volumes.tets(t, 3)) - a));
            const double vol = w / 6.0;
            const double v0 = volumes.rest[static_cast<size_t>(t)];
            part.energy += 0.5 * volumes.k[static_cast<size_t>(t)] * (vol - v0) * (vol - v0) / v0;
            if (scan) {
                part.six_volume += w;
                if (!(w > 0)) part.inverted.push_back(static_cast<std::int32_t>(t));
            }
        }
        return part;
    });
    en.volume = ts.energy;
    if (scan) {
        tets->inverted.swap(ts.inverted);
        tets->volume = ts.six_volume / 6;
    }
    return en;
}

double Model::omega_max_sq(const Positions& x) const
{
    std::vector<double> ksum, csum;
    gershgorin(*this, x, ksum, csum);
    double w2 = 0;
    for (size_t i = 0; i < mass.size(); ++i)
        if (!fixed[i]) w2 = std::max(w2, ksum[i] / mass[i]);
    return w2;
}

double Model::explicit_dt_limit(const Positions& x, const std::vector<double>& extra_k,
                                const std::vector<double>& extra_c) const
{
    std::vector<double> ksum, csum;
    gershgorin(*this, x, ksum, csum);
    double limit = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < mass.size(); ++i) {
        if (fixed[i]) continue;
        const double w2 = (ksum[i] + 2 * (i < extra_k.size() ? extra_k[i] : 0.0)) / mass[i];
        const double gam = (csum[i] + 2 * (i < extra_c.size() ? extra_c[i] : 0.0)) / mass[i];
        if (w2 <= 0 && gam <= 0) continue;
        const double h = w2 > 0 ? (-gam + std::sqrt(gam * gam + 4 * w2)) / w2 : 2.0 / gam;
        limit = std::min(limit, h);
    }
    return limit;
}

void Model::add_matrix_triplets(const Positions& x, double scale_k, double scale_c,
                                std::vector<Eigen::Triplet<double>>& out) const
{
    auto add_block = [&](Index bi, Index bj, const Mat3& b) {
        if (fixed[static_cast<size_t>(bi)] || fixed[static_cast<size_t>(bj)]) return;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                if (b(r, c) != 0) out.emplace_back(3 * bi + r, 3 * bj + c, b(r, c));
    };
    for (Index e = 0; e < springs.edges.rows(); ++e) {
        const Index i = springs.edges(e, 0), j = springs.edges(e, 1);
        const Vec3 d = row(x, i) - row(x, j);
        const double len = d.norm();
        if (!(len > 0)) continue;
        const Vec3 u = d / len;
        const Mat3 uu = u * u.transpose();
        const double k = springs.k[static_cast<size_t>(e)];
        // −∂f/∂x of a spring, with the transverse term clamped at 0 (compressed springs) to stay semi-definite.
        const double tr = std::max(0.0, 1.0 - springs.rest[static_cast<size_t>(e)] / len);
        const Mat3 b =
            scale_k * k * (uu + tr * (Mat3::Identity() - uu)) + scale_c * springs.c[static_cast<size_t>(e)] * uu;
        add_block(i, i, b);
        add_block(j, j, b);
        add_block(i, j, -b);
        add_block(j, i, -b);
    }
    Eigen::Matrix<double, 4, 3> g;
    for (Index t = 0; t < volumes.tets.rows(); ++t) {
        volume_and_gradient(x, &volumes.tets(t, 0), g);
        const double s = scale_k * volumes.k[static_cast<size_t>(t)] / volumes.rest[static_cast<size_t>(t)];
        for (int a = 0; a < 4; ++a)
            for (int b = 0; b < 4; ++b)
                add_block(volumes.tets(t, a), volumes.tets(t, b), s * g.row(a).transpose() * g.row(b));
    }
    if (ground.enabled) {
        const Mat3 nn = ground.normal * ground.normal.transpose();
        for (Index i = 0; i < num_vertices(); ++i)
            if (ground.height - ground.normal.dot(row(x, i)) > 0)
                add_block(i, i, (scale_k * ground_k_at(i) + scale_c * ground_c_at(i)) * nn);
    }
}

namespace {
/// Spring block scale_k·K_e + scale_c·C_e of edge e at x (zero for a zero-length edge).
Mat3 spring_block_at(const Model& m, const Positions& x, Index e, double scale_k, double scale_c)
{
    const Vec3 d = row(x, m.springs.edges(e, 0)) - row(x, m.springs.edges(e, 1));
    const double len = d.norm();
    if (!(len > 0)) return Mat3::Zero();
    const Vec3 u = d / len;
    const Mat3 uu = u * u.transpose();
    const double tr = std::max(0.0, 1.0 - m.springs.rest[static_cast<size_t>(e)] / len);
    return scale_k * m.springs.k[static_cast<size_t>(e)] * (uu + tr * (Mat3::Identity() - uu)) +
           scale_c * m.springs.c[static_cast<size_t>(e)] * uu;
}
} // namespace

void Model::apply_matrix(const Positions& x, double scale_k, double scale_c, const Eigen::VectorXd& p,
                         Eigen::VectorXd& out) const
{
    auto free = [&](Index i) { return !fixed[static_cast<size_t>(i)]; };
    auto pv = [&](Index i) -> Vec3 { return free(i) ? Vec3(p.segment<3>(3 * i)) : Vec3::Zero(); };
    for (Index e = 0; e < springs.edges.rows(); ++e) {
        const Index i = springs.edges(e, 0), j = springs.edges(e, 1);
        if (!free(i) && !free(j)) continue;
        const Vec3 y = spring_block_at(*this, x, e, scale_k, scale_c) * (pv(i) - pv(j));
        if (free(i)) out.segment<3>(3 * i) += y;
        if (free(j)) out.segment<3>(3 * j) -= y;
    }
    if (scale_k != 0) {
        Eigen::Matrix<double, 4, 3> g;
        for (Index t = 0; t < volumes.tets.rows(); ++t) {
            volume_and_gradient(x, &volumes.tets(t, 0), g);
            const double s = scale_k * volumes.k[static_cast<size_t>(t)] / volumes.rest[static_cast<size_t>(t)];
            double gp = 0;
            for (int a = 0; a < 4; ++a)
                gp += g.row(a).dot(pv(volumes.tets(t, a)));
            for (int a = 0; a < 4; ++a)
                if (free(volumes.tets(t, a))) out.segment<3>(3 * volumes.tets(t, a)) += s * gp * g.row(a).transpose();
        }
    }
    if (ground.enabled) {
        for (Index i = 0; i < num_vertices(); ++i)
            if (free(i) && ground.height - ground.normal.dot(row(x, i)) > 0)
                out.segment<3>(3 * i) +=
                    (scale_k * ground_k_at(i) + scale_c * ground_c_at(i)) * ground.normal * ground.normal.dot(pv(i));
    }
}

Model::Linearised Model::linearise(const Positions& x, double scale_k, double scale_c) const
{
    Linearised lin;
    lin.update(*this, x, scale_k, scale_c);
    return lin;
}

void Model::Linearised::update(const Model& m, const Positions& x, double scale_k, double scale_c)
{
    const Index n = m.num_vertices();
    const Index ne = static_cast<Index>(m.springs.edges.rows());
    const Index nt = static_cast<Index>(m.volumes.tets.rows());
    if (model != &m || static_cast<Index>(spring_start.size()) != n + 1 ||
        static_cast<Index>(spring_id.size()) != 2 * ne || static_cast<Index>(tet_slot.size()) != 4 * nt) {
        // CSR adjacency by counting.
        spring_start.assign(static_cast<size_t>(n + 1), 0);
        tet_start.assign(static_cast<size_t>(n + 1), 0);
        for (Index e = 0; e < ne; ++e)
            for (int s = 0; s < 2; ++s)
                ++spring_start[static_cast<size_t>(m.springs.edges(e, s) + 1)];
        for (Index t = 0; t < nt; ++t)
            for (int a = 0; a < 4; ++a)
                ++tet_start[static_cast<size_t>(m.volumes.tets(t, a) + 1)];
        for (Index i = 0; i < n; ++i) {
            spring_start[static_cast<size_t>(i + 1)] += spring_start[static_cast<size_t>(i)];
            tet_start[static_cast<size_t>(i + 1)] += tet_start[static_cast<size_t>(i)];
        }
        spring_other.assign(static_cast<size_t>(2 * ne), 0);
        spring_id.assign(static_cast<size_t>(2 * ne), 0);
        tet_slot.assign(static_cast<size_t>(4 * nt), 0);
        std::vector<Index> fill(spring_start.begin(), spring_start.end() - 1);
        for (Index e = 0; e < ne; ++e)
            for (int s = 0; s < 2; ++s) {
                const size_t k = static_cast<size_t>(fill[static_cast<size_t>(m.springs.edges(e, s))]++);
                spring_other[k] = m.springs.edges(e, 1 - s);
                spring_id[k] = e;
            }
        fill.assign(tet_start.begin(), tet_start.end() - 1);
        for (Index t = 0; t < nt; ++t)
            for (int a = 0; a < 4; ++a)
                tet_slot[static_cast<size_t>(fill[static_cast<size_t>(m.volumes.tets(t, a))]++)] = 4 * t + a;
    }
    model = &m;
    spring_block.resize(static_cast<size_t>(ne));
    for (Index e = 0; e < ne; ++e)
        spring_block[static_cast<size_t>(e)] = spring_block_at(m, x, e, scale_k, scale_c);
    grad.resize(scale_k != 0 ? static_cast<size_t>(nt) : 0);
    tet_dot.resize(grad.size());
    for (Index t = 0; t < static_cast<Index>(grad.size()); ++t) {
        Eigen::Matrix<double, 4, 3>& g = grad[static_cast<size_t>(t)];
        volume_and_gradient(x, &m.volumes.tets(t, 0), g);
        // The Gauss–Newton block s ∇V ∇Vᵀ with s ≥ 0 (scale_k ≥ 0 in every use) as (√s ∇V)(√s ∇V)ᵀ.
        g *= std::sqrt(
            std::max(0.0, scale_k * m.volumes.k[static_cast<size_t>(t)] / m.volumes.rest[static_cast<size_t>(t)]));
    }
    ground.assign(m.ground.enabled ? static_cast<size_t>(n) : 0, 0.0);
    if (m.ground.enabled)
        for (Index i = 0; i < n; ++i)
            if (!m.fixed[static_cast<size_t>(i)] && m.ground.height - m.ground.normal.dot(row(x, i)) > 0)
                ground[static_cast<size_t>(i)] = scale_k * m.ground_k_at(i) + scale_c * m.ground_c_at(i);
}

void Model::Linearised::apply(const Eigen::VectorXd& p, Eigen::VectorXd& out) const
{
    const Model& m = *model;
    const std::vector<char>& fixed = m.fixed;
    const Index n = m.num_vertices();
    auto pv = [&](Index i) -> Vec3 { return fixed[static_cast<size_t>(i)] ? Vec3::Zero() : Vec3(p.segment<3>(3 * i)); };
    const Index nt = static_cast<Index>(grad.size());
    const Vec3& nrm = m.ground.normal;
    {
        for (Index t = 0; t < nt; ++t) {
            const Eigen::Matrix<double, 4, 3>& g = grad[static_cast<size_t>(t)];
            const Index* v = &m.volumes.tets(t, 0);
            double gp = 0;
            for (int a = 0; a < 4; ++a)
                gp += g.row(a).dot(pv(v[a]));
            tet_dot[static_cast<size_t>(t)] = gp;
        }
        for (Index i = 0; i < n; ++i) {
            if (fixed[static_cast<size_t>(i)]) continue;
            const Vec3 pi = p.segment<3>(3 * i);
            Vec3 acc = Vec3::Zero();
            for (Index k = spring_start[static_cast<size_t>(i)]; k < spring_start[static_cast<size_t>(i + 1)]; ++k)
                acc += spring_block[static_cast<size_t>(spring_id[static_cast<size_t>(k)])] *
                       (pi - pv(spring_other[static_cast<size_t>(k)]));
            if (nt)
                for (Index k = tet_start[static_cast<size_t>(i)]; k < tet_start[static_cast<size_t>(i + 1)]; ++k) {
                    const Index slot = tet_slot[static_cast<size_t>(k)];
                    acc += tet_dot[static_cast<size_t>(slot / 4)] *
                           grad[static_cast<size_t>(slot / 4)].row(slot % 4).transpose();
                }
            if (!ground.empty() && ground[static_cast<size_t>(i)] != 0)
                acc += ground[static_cast<size_t>(i)] * nrm * nrm.dot(pi);
            out.segment<3>(3 * i) += acc;
        }
    }
}

void Model::Linearised::add_diagonal(Eigen::VectorXd& diag) const
{
    const Model& m = *model;
    for (size_t e = 0; e < spring_block.size(); ++e) {
        const Vec3 dg = spring_block[e].diagonal();
        for (int s = 0; s < 2; ++s) {
            const Index v = m.springs.edges(static_cast<Index>(e), s);
            if (!m.fixed[static_cast<size_t>(v)]) diag.segment<3>(3 * v) += dg;
        }
    }
    for (size_t t = 0; t < grad.size(); ++t)
        for (int a = 0; a < 4; ++a) {
            const Index v = m.volumes.tets(static_cast<Index>(t), a);
            if (!m.fixed[static_cast<size_t>(v)]) diag.segment<3>(3 * v) += grad[t].row(a).transpose().cwiseAbs2();
        }
    for (size_t i = 0; i < ground.size(); ++i)
        if (ground[i] != 0) diag.segment<3>(3 * static_cast<Index>(i)) += ground[i] * m.ground.normal.cwiseAbs2();
}

void Model::add_matrix_diagonal(const Positions& x, double scale_k, double scale_c, Eigen::VectorXd& diag) const
{
    auto free = [&](Index i) { return !fixed[static_cast<size_t>(i)]; };
    for (Index e = 0; e < springs.edges.rows(); ++e) {
        const Vec3 dg = spring_block_at(*this, x, e, scale_k, scale_c).diagonal();
        for (int s = 0; s < 2; ++s)
            if (free(springs.edges(e, s))) diag.segment<3>(3 * springs.edges(e, s)) += dg;
    }
    if (scale_k != 0) {
        Eigen::Matrix<double, 4, 3> g;
        for (Index t = 0; t < volumes.tets.rows(); ++t) {
            volume_and_gradient(x, &volumes.tets(t, 0), g);
            const double s = scale_k * volumes.k[static_cast<size_t>(t)] / volumes.rest[static_cast<size_t>(t)];
            for (int a = 0; a < 4; ++a)
                if (free(volumes.tets(t, a)))
                    diag.segment<3>(3 * volumes.tets(t, a)) +=
                        s * g.row(a).transpose().cwiseProduct(g.row(a).transpose());
        }
    }
    if (ground.enabled) {
        for (Index i = 0; i < num_vertices(); ++i)
            if (free(i) && ground.height - ground.normal.dot(row(x, i)) > 0)
                diag.segment<3>(3 * i) +=
                    (scale_k * ground_k_at(i) + scale_c * ground_c_at(i)) * ground.normal.cwiseProduct(ground.normal);
    }
}

} // namespace tethash::sim
