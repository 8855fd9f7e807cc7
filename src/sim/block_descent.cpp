// Vertex Block Descent (Chen, Macklin et al., SIGGRAPH 2024), the default integrator. Backward Euler written as
// the minimisation of G(x) = Σ m/(2h²) |x − y|² + E(x), y = x + h v + h² g, is solved by Gauss–Seidel over
// vertices: each vertex in turn takes one Newton step on its own 3 coordinates with the others held, in the
// order of a colouring of the edge graph (vertices of one colour share no spring or tet, so a colour's
// updates are independent: parallel without atomics, and the result does not depend on the thread count).
//
// Per vertex i the local problem gathers: inertia (m/h²), its springs (Hessian with the transverse term clamped
// at 0 when compressed), its tets' volume terms (the volume is linear in x_i, so their local Hessian is exact),
// the ground (penalty, damping, friction), and the contacts in which it takes part (as the penetrating vertex or
// as a corner of the penetrated tet). Damping is relative: springs on their rate of length change, volume terms
// on the rate of volume change, contacts on the relative normal velocity; rigid motion is never damped.
//
// What makes it robust on real meshes (measured on hand.mesh; docs/simulator.md): the iterations start from y;
// each local Newton step is clamped to a fifth of the object's mean edge (without it the same settings gave 0 or
// ~1,700 inverted tets depending on round-off); contact terms use the contacts' relative displacement taken at
// the start of each iteration (Jacobi across the contact's five nodes), so no two threads ever read a position
// another one writes.
#include "integrator.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#ifdef TETHASH_HAVE_OPENMP
#include <omp.h>
#endif

namespace tethash::sim {

namespace {

/// A spring seen from one of its ends (32 bytes). Stored in the order the sweep visits the vertices, so a
/// sweep streams through these arrays.
struct VertexSpring {
    std::int32_t other; ///< the other end
    double k, rest;
    double length_t; ///< length at the start of the substep (relative damping)
};

/// A volume term seen from one of its corners i (40 bytes), in terms of W = 6V = (x_a − x_i) · N,
/// N = (x_b − x_a) × (x_c − x_a): energy ½ k36 (W − W0)², ∇_i W = −N (W is linear in x_i).
struct VertexTet {
    std::int32_t a, b, c;
    double k36; ///< k / (36 V0): the volume term's ½ (k/V0) (V − V0)² in W
    double w0;  ///< 6 V0
    double wt;  ///< 6 V at the start of the substep (relative damping)
};

/// One incidence of a vertex in a contact's stencil.
struct VertexContact {
    std::int32_t contact;
    double coef; ///< 1 for the penetrating vertex, −b_k for the tet's corner k
};

/// Symmetric 3 × 3 accumulated as six entries (xx, yy, zz, xy, xz, yz).
struct Sym3 {
    double xx = 0, yy = 0, zz = 0, xy = 0, xz = 0, yz = 0;
    void add_outer(double s, double ux, double uy, double uz)
    {
        xx += s * ux * ux;
        yy += s * uy * uy;
        zz += s * uz * uz;
        xy += s * ux * uy;
        xz += s * ux * uz;
        yz += s * uy * uz;
    }
    void add_identity(double s)
    {
        xx += s;
        yy += s;
        zz += s;
    }
    /// Solves H d = f by Cholesky; false when H is not positive definite.
    bool solve(const double f[3], double d[3]) const
    {
        const double l11 = xx;
        if (!(l11 > 0)) return false;
        const double r11 = std::sqrt(l11);
        const double l21 = xy / r11, l31 = xz / r11;
        const double l22sq = yy - l21 * l21;
        if (!(l22sq > 0)) return false;
        const double r22 = std::sqrt(l22sq);
        const double l32 = (yz - l31 * l21) / r22;
        const double l33sq = zz - l31 * l31 - l32 * l32;
        if (!(l33sq > 0)) return false;
        const double r33 = std::sqrt(l33sq);
        const double z1 = f[0] / r11;
        const double z2 = (f[1] - l21 * z1) / r22;
        const double z3 = (f[2] - l31 * z1 - l32 * z2) / r33;
        d[2] = z3 / r33;
        d[1] = (z2 - l32 * d[2]) / r22;
        d[0] = (z1 - l21 * d[1] - l31 * d[2]) / r11;
        return true;
    }
};

class BlockDescent final : public StepIntegrator {
  public:
    explicit BlockDescent(const StepContext& ctx) : m_ctx(ctx) { setup(); }

    int substep(Positions& x, Positions& v, double h) override;

  private:
    void setup();
    void start_substep(const Positions& x);
    void gather_contacts();
    /// One Newton step on the vertex at position k of the sweep order.
    /// Returns the step's length over the vertex's clamp length (0 … 1).
    double solve_vertex(std::int32_t k, double* x, double h) const;
    /// Chebyshev step after sweep n: x ← ω (x − x_{n−2}) + x_{n−2} on the free vertices.
    void accelerate(int n, double rho, double& omega, double* x);
    /// Newton steps on the vertices at positions [begin, end) of the sweep order, in order. (An x86-64-v3 clone
    /// with fused multiply-adds measured 7 % slower on the hand drop than this baseline build, interleaved runs.)
    double sweep(std::int32_t begin, std::int32_t end, double* x, double h) const
    {
        double largest = 0;
        for (std::int32_t k = begin; k < end; ++k)
            largest = std::max(largest, solve_vertex(k, x, h));
        return largest;
    }

    StepContext m_ctx;
    // Fixed set-up, built once. Everything per vertex is indexed by the vertex's position k in the sweep order
    // (free vertices grouped by colour), so that a sweep reads these arrays front to back.
    std::vector<std::int32_t> m_colour_start;              ///< positions k of each colour
    std::vector<std::int32_t> m_order;                     ///< k → vertex id
    std::vector<std::int32_t> m_spring_start, m_tet_start; ///< k → entries
    std::vector<VertexSpring> m_springs;
    std::vector<VertexTet> m_tets;
    std::vector<double> m_damping;  ///< k → its object's damping time (s)
    std::vector<double> m_max_step; ///< k → largest local step (a fifth of its object's mean edge)
    std::vector<double> m_ground_k, m_ground_c; ///< vertex id → ground penalty and damping
    int m_threads = 1;
    // Per-substep state, buffers reused.
    Positions m_xt;          ///< positions at the start of the substep
    std::vector<double> m_y; ///< inertial target, flat 3n
    std::vector<double> m_prev1, m_prev2; ///< the iterates of the two previous sweeps (Chebyshev acceleration)
    // Contacts of the substep: per contact depth, direction, weighted stiffness and damping, relative
    // displacement since the start (refreshed each iteration); per vertex its incidences.
    struct ActiveContact {
        double depth, n[3], k, c, rel[3];
        std::int32_t node[5];
        double coef[5];
    };
    std::vector<ActiveContact> m_contacts;
    std::vector<std::int32_t> m_vc_start; ///< vertex id → incidences
    std::vector<VertexContact> m_vc;
};

void BlockDescent::setup()
{
    const Model& model = m_ctx.model;
    const Index n = model.num_vertices();
    const size_t un = static_cast<size_t>(n);
    const Index ne = static_cast<Index>(model.springs.edges.rows());
    const Index nt = static_cast<Index>(model.volumes.tets.rows());

    // Vertex → springs (by id), then a greedy colouring of the free vertices over the edge graph (every pair of
    // vertices of a tet is an edge, so one colour shares no spring and no tet).
    std::vector<std::int32_t> adj_start(un + 1, 0), adj_spring(static_cast<size_t>(2 * ne));
    for (Index e = 0; e < ne; ++e)
        for (int s = 0; s < 2; ++s)
            ++adj_start[static_cast<size_t>(model.springs.edges(e, s)) + 1];
    for (size_t i = 0; i < un; ++i)
        adj_start[i + 1] += adj_start[i];
    std::vector<std::int32_t> fill(adj_start.begin(), adj_start.end() - 1);
    for (Index e = 0; e < ne; ++e)
        for (int s = 0; s < 2; ++s)
            adj_spring[static_cast<size_t>(fill[static_cast<size_t>(model.springs.edges(e, s))]++)] =
                static_cast<std::int32_t>(e);
    std::vector<std::int32_t> tet_adj_start(un + 1, 0), tet_adj(static_cast<size_t>(4 * nt));
    for (Index t = 0; t < nt; ++t)
        for (int a = 0; a < 4; ++a)
            ++tet_adj_start[static_cast<size_t>(model.volumes.tets(t, a)) + 1];
    for (size_t i = 0; i < un; ++i)
        tet_adj_start[i + 1] += tet_adj_start[i];
    fill.assign(tet_adj_start.begin(), tet_adj_start.end() - 1);
    for (Index t = 0; t < nt; ++t)
        for (int a = 0; a < 4; ++a)
            tet_adj[static_cast<size_t>(fill[static_cast<size_t>(model.volumes.tets(t, a))]++)] =
                static_cast<std::int32_t>(4 * t + a);

    std::vector<int> colour(un, -1);
    int colours = 0;
    std::vector<char> used;
    for (Index i = 0; i < n; ++i) {
        if (model.fixed[static_cast<size_t>(i)]) continue;
        used.assign(static_cast<size_t>(colours) + 1, 0);
        for (std::int32_t s = adj_start[static_cast<size_t>(i)]; s < adj_start[static_cast<size_t>(i) + 1]; ++s) {
            const Index e = adj_spring[static_cast<size_t>(s)];
            const Index j = model.springs.edges(e, 0) == i ? model.springs.edges(e, 1) : model.springs.edges(e, 0);
            const int c = colour[static_cast<size_t>(j)];
            if (c >= 0) used[static_cast<size_t>(c)] = 1;
        }
        int c = 0;
        while (used[static_cast<size_t>(c)])
            ++c;
        colour[static_cast<size_t>(i)] = c;
        colours = std::max(colours, c + 1);
    }
    m_colour_start.assign(static_cast<size_t>(colours) + 1, 0);
    for (Index i = 0; i < n; ++i)
        if (colour[static_cast<size_t>(i)] >= 0) ++m_colour_start[static_cast<size_t>(colour[static_cast<size_t>(i)]) + 1];
    for (int c = 0; c < colours; ++c)
        m_colour_start[static_cast<size_t>(c) + 1] += m_colour_start[static_cast<size_t>(c)];
    m_order.resize(static_cast<size_t>(m_colour_start.back()));
    fill.assign(m_colour_start.begin(), m_colour_start.end() - 1);
    for (Index i = 0; i < n; ++i)
        if (colour[static_cast<size_t>(i)] >= 0)
            m_order[static_cast<size_t>(fill[static_cast<size_t>(colour[static_cast<size_t>(i)])]++)] =
                static_cast<std::int32_t>(i);

    // Entries in sweep order. Volume terms: the other three corners in an order that keeps the orientation (even
    // permutations of (0, 1, 2, 3) starting with the corner).
    static constexpr int others[4][3] = {{1, 2, 3}, {0, 3, 2}, {3, 0, 1}, {2, 1, 0}};
    const size_t nk = m_order.size();
    m_spring_start.assign(nk + 1, 0);
    m_tet_start.assign(nk + 1, 0);
    m_springs.clear();
    m_tets.clear();
    m_damping.assign(nk, 0.0);
    m_max_step.assign(nk, 0.0);
    for (size_t k = 0; k < nk; ++k) {
        const Index i = m_order[k];
        for (std::int32_t s = adj_start[static_cast<size_t>(i)]; s < adj_start[static_cast<size_t>(i) + 1]; ++s) {
            const Index e = adj_spring[static_cast<size_t>(s)];
            const Index j = model.springs.edges(e, 0) == i ? model.springs.edges(e, 1) : model.springs.edges(e, 0);
            m_springs.push_back(VertexSpring{static_cast<std::int32_t>(j), model.springs.k[static_cast<size_t>(e)],
                                             model.springs.rest[static_cast<size_t>(e)], 0.0});
        }
        for (std::int32_t s = tet_adj_start[static_cast<size_t>(i)]; s < tet_adj_start[static_cast<size_t>(i) + 1]; ++s) {
            const Index t = tet_adj[static_cast<size_t>(s)] / 4;
            const int a = tet_adj[static_cast<size_t>(s)] % 4;
            const double v0 = model.volumes.rest[static_cast<size_t>(t)];
            VertexTet vt;
            vt.a = model.volumes.tets(t, others[a][0]);
            vt.b = model.volumes.tets(t, others[a][1]);
            vt.c = model.volumes.tets(t, others[a][2]);
            vt.k36 = model.volumes.k[static_cast<size_t>(t)] / v0 / 36.0;
            vt.w0 = 6.0 * v0;
            vt.wt = vt.w0;
            m_tets.push_back(vt);
        }
        m_spring_start[k + 1] = static_cast<std::int32_t>(m_springs.size());
        m_tet_start[k + 1] = static_cast<std::int32_t>(m_tets.size());
        const size_t o = static_cast<size_t>(model.vertex_object[static_cast<size_t>(i)]);
        m_damping[k] = o < m_ctx.scene.objects.size() ? m_ctx.scene.objects[o].material.damping : 0.0;
        const double edge = o < model.object_mean_edge.size() ? model.object_mean_edge[o] : 0.0;
        m_max_step[k] = edge > 0 ? 0.2 * edge : std::numeric_limits<double>::infinity();
    }
    if (model.ground.enabled) {
        m_ground_k.resize(un);
        m_ground_c.resize(un);
        for (Index i = 0; i < n; ++i) {
            m_ground_k[static_cast<size_t>(i)] = model.ground_k_at(i);
            m_ground_c[static_cast<size_t>(i)] = model.ground_c_at(i);
        }
    }
    m_threads = m_ctx.scene.detect.threads;
#ifdef TETHASH_HAVE_OPENMP
    if (m_threads <= 0) m_threads = omp_get_max_threads();
#else
    m_threads = 1;
#endif
}

void BlockDescent::start_substep(const Positions& x)
{
    // Lengths and volumes at the start of the substep, for the relative damping.
    const double* xp = x.data();
    const size_t nk = m_order.size();
    for (size_t k = 0; k < nk; ++k) {
        const double* xi = xp + 3 * static_cast<size_t>(m_order[k]);
        for (std::int32_t s = m_spring_start[k]; s < m_spring_start[k + 1]; ++s) {
            VertexSpring& sp = m_springs[static_cast<size_t>(s)];
            const double* xj = xp + 3 * static_cast<size_t>(sp.other);
            const double dx = xi[0] - xj[0], dy = xi[1] - xj[1], dz = xi[2] - xj[2];
            sp.length_t = std::sqrt(dx * dx + dy * dy + dz * dz);
        }
        for (std::int32_t s = m_tet_start[k]; s < m_tet_start[k + 1]; ++s) {
            VertexTet& t = m_tets[static_cast<size_t>(s)];
            const double* a = xp + 3 * static_cast<size_t>(t.a);
            const double* b = xp + 3 * static_cast<size_t>(t.b);
            const double* c = xp + 3 * static_cast<size_t>(t.c);
            const double bax = b[0] - a[0], bay = b[1] - a[1], baz = b[2] - a[2];
            const double cax = c[0] - a[0], cay = c[1] - a[1], caz = c[2] - a[2];
            const double nx = bay * caz - baz * cay, ny = baz * cax - bax * caz, nz = bax * cay - bay * cax;
            t.wt = (a[0] - xi[0]) * nx + (a[1] - xi[1]) * ny + (a[2] - xi[2]) * nz;
        }
    }
}

void BlockDescent::gather_contacts()
{
    const ContactResponse& cr = m_ctx.contacts;
    const Model& model = m_ctx.model;
    const std::vector<Contact>& contacts = cr.contacts();
    m_contacts.clear();
    const size_t un = model.mass.size();
    m_vc_start.assign(un + 1, 0);
    for (size_t q = 0; q < contacts.size(); ++q) {
        const Contact& c = contacts[q];
        if (!(c.depth > 0)) continue;
        ActiveContact a;
        a.depth = c.depth;
        for (int r = 0; r < 3; ++r) {
            a.n[r] = c.direction[r];
            a.rel[r] = 0;
        }
        a.k = cr.weight()[q] * cr.stiffness()[q];
        a.c = cr.weight()[q] * cr.damping()[q];
        Index node[5];
        cr.stencil(q, node, a.coef);
        for (int s = 0; s < 5; ++s) {
            a.node[s] = static_cast<std::int32_t>(node[s]);
            if (!model.fixed[static_cast<size_t>(node[s])]) ++m_vc_start[static_cast<size_t>(node[s]) + 1];
        }
        m_contacts.push_back(a);
    }
    for (size_t i = 0; i < un; ++i)
        m_vc_start[i + 1] += m_vc_start[i];
    m_vc.resize(static_cast<size_t>(m_vc_start.back()));
    std::vector<std::int32_t> fill(m_vc_start.begin(), m_vc_start.end() - 1);
    for (size_t q = 0; q < m_contacts.size(); ++q)
        for (int s = 0; s < 5; ++s) {
            const std::int32_t j = m_contacts[q].node[s];
            if (!model.fixed[static_cast<size_t>(j)])
                m_vc[static_cast<size_t>(fill[static_cast<size_t>(j)]++)] =
                    VertexContact{static_cast<std::int32_t>(q), m_contacts[q].coef[s]};
        }
}

inline __attribute__((always_inline)) double BlockDescent::solve_vertex(std::int32_t k, double* x, double h) const
{
    const Model& model = m_ctx.model;
    const size_t kk = static_cast<size_t>(k);
    const size_t u = static_cast<size_t>(m_order[kk]);
    const double inv_h = 1.0 / h;
    const double m_h2 = model.mass[u] * inv_h * inv_h;
    const double xi = x[3 * u], yi = x[3 * u + 1], zi = x[3 * u + 2];
    double f[3] = {m_h2 * (m_y[3 * u] - xi), m_h2 * (m_y[3 * u + 1] - yi), m_h2 * (m_y[3 * u + 2] - zi)};
    Sym3 H;
    H.add_identity(m_h2);
    const double damp_h = m_damping[kk] * inv_h; // dashpot c = damping · k, taken over the substep

    for (std::int32_t s = m_spring_start[kk]; s < m_spring_start[kk + 1]; ++s) {
        const VertexSpring& sp = m_springs[static_cast<size_t>(s)];
        const double* xj = x + 3 * static_cast<size_t>(sp.other);
        const double dx = xi - xj[0], dy = yi - xj[1], dz = zi - xj[2];
        const double len2 = dx * dx + dy * dy + dz * dz;
        if (!(len2 > 0)) continue;
        const double len = std::sqrt(len2), inv = 1.0 / len;
        const double ux = dx * inv, uy = dy * inv, uz = dz * inv;
        const double fs = sp.k * ((len - sp.rest) + damp_h * (len - sp.length_t));
        f[0] -= fs * ux;
        f[1] -= fs * uy;
        f[2] -= fs * uz;
        // k (uuᵀ + (1 − L0/l)(I − uuᵀ)) with the transverse part clamped at 0 when compressed, plus damping uuᵀ.
        const double tr = std::max(0.0, 1.0 - sp.rest * inv);
        H.add_identity(sp.k * tr);
        H.add_outer(sp.k * (1.0 - tr) + damp_h * sp.k, ux, uy, uz);
    }

    const double tet_scale = 1.0 + damp_h;
    for (std::int32_t s = m_tet_start[kk]; s < m_tet_start[kk + 1]; ++s) {
        const VertexTet& t = m_tets[static_cast<size_t>(s)];
        const double* a = x + 3 * static_cast<size_t>(t.a);
        const double* b = x + 3 * static_cast<size_t>(t.b);
        const double* c = x + 3 * static_cast<size_t>(t.c);
        const double bax = b[0] - a[0], bay = b[1] - a[1], baz = b[2] - a[2];
        const double cax = c[0] - a[0], cay = c[1] - a[1], caz = c[2] - a[2];
        const double nx = bay * caz - baz * cay, ny = baz * cax - bax * caz, nz = bax * cay - bay * cax;
        const double w = (a[0] - xi) * nx + (a[1] - yi) * ny + (a[2] - zi) * nz;
        // f = −∂E/∂x_i = k36 ((W − W0) + damping/h (W − W_t)) N, H = k36 (1 + damping/h) N Nᵀ.
        const double fs = t.k36 * ((w - t.w0) + damp_h * (w - t.wt));
        f[0] += fs * nx;
        f[1] += fs * ny;
        f[2] += fs * nz;
        H.add_outer(t.k36 * tet_scale, nx, ny, nz);
    }

    const double* xt = m_xt.data() + 3 * u;
    if (!m_ground_k.empty()) {
        const Ground& g = model.ground;
        const double gnx = g.normal.x(), gny = g.normal.y(), gnz = g.normal.z();
        const double pen = g.height - (gnx * xi + gny * yi + gnz * zi);
        if (pen > 0) {
            const double k = m_ground_k[u], c = m_ground_c[u];
            const double dx = xi - xt[0], dy = yi - xt[1], dz = zi - xt[2];
            const double dn = gnx * dx + gny * dy + gnz * dz; // normal displacement over the substep
            const double fn = k * pen - c * inv_h * dn;
            if (fn > 0) {
                f[0] += fn * gnx;
                f[1] += fn * gny;
                f[2] += fn * gnz;
                H.add_outer(k + c * inv_h, gnx, gny, gnz);
                if (g.friction > 0) {
                    // Coulomb friction on the tangential displacement, smoothed below 1 mm/s of sliding
                    // (lagged normal force: Hessian μ fn / max(|t|, ε) on the tangent plane).
                    const double tx = dx - dn * gnx, ty = dy - dn * gny, tz = dz - dn * gnz;
                    const double tl = std::sqrt(tx * tx + ty * ty + tz * tz);
                    const double s = g.friction * fn / std::max(tl, 1e-3 * h);
                    f[0] -= s * tx;
                    f[1] -= s * ty;
                    f[2] -= s * tz;
                    H.add_identity(s);
                    H.add_outer(-s, gnx, gny, gnz);
                }
            }
        }
    }

    const double mu = m_ctx.contacts.friction();
    for (std::int32_t s = m_vc_start[u]; s < m_vc_start[u + 1]; ++s) {
        const VertexContact& vc = m_vc[static_cast<size_t>(s)];
        const ActiveContact& c = m_contacts[static_cast<size_t>(vc.contact)];
        // Relative displacement since the start of the substep, with this vertex's share taken at its current
        // position (it has not moved since the relative displacement was refreshed: one update per iteration).
        const double rn = c.n[0] * c.rel[0] + c.n[1] * c.rel[1] + c.n[2] * c.rel[2];
        const double depth = c.depth - rn;
        const double fn = c.k * depth - c.c * inv_h * rn;
        if (!(depth > 0) || !(fn > 0)) continue;
        const double fc = vc.coef * fn;
        f[0] += fc * c.n[0];
        f[1] += fc * c.n[1];
        f[2] += fc * c.n[2];
        H.add_outer(vc.coef * vc.coef * (c.k + c.c * inv_h), c.n[0], c.n[1], c.n[2]);
        if (mu > 0) {
            const double tx = c.rel[0] - rn * c.n[0], ty = c.rel[1] - rn * c.n[1], tz = c.rel[2] - rn * c.n[2];
            const double tl = std::sqrt(tx * tx + ty * ty + tz * tz);
            const double sf = mu * fn / std::max(tl, 1e-3 * h);
            f[0] -= vc.coef * sf * tx;
            f[1] -= vc.coef * sf * ty;
            f[2] -= vc.coef * sf * tz;
            H.add_identity(vc.coef * vc.coef * sf);
            H.add_outer(-vc.coef * vc.coef * sf, c.n[0], c.n[1], c.n[2]);
        }
    }

    double d[3];
    if (!H.solve(f, d)) return 0;
    const double step2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    const double cap = m_max_step[kk];
    double scale = 1.0, relative = std::sqrt(step2) / cap;
    if (relative > 1) {
        scale = 1.0 / relative;
        relative = 1;
    }
    x[3 * u] = xi + scale * d[0];
    x[3 * u + 1] = yi + scale * d[1];
    x[3 * u + 2] = zi + scale * d[2];
    return relative;
}

void BlockDescent::accelerate(int n, double rho, double& omega, double* x)
{
    omega = n == 1 ? 1.0 : n == 2 ? 2.0 / (2.0 - rho * rho) : 4.0 / (4.0 - rho * rho * omega);
    const size_t nk = m_order.size();
    // Vertices touching the ground or in a contact are not extrapolated: their friction terms are lagged, and an
    // extrapolated tangential step overstated a sliding box's friction by 60 % (tests/test_sim_obstacles.cpp).
    const Ground& g = m_ctx.model.ground;
    const bool ground = !m_ground_k.empty();
    if (n >= 2)
        for (size_t k = 0; k < nk; ++k) {
            const size_t i = static_cast<size_t>(m_order[k]), u = 3 * i;
            if (m_vc_start[i + 1] > m_vc_start[i]) continue;
            if (ground && g.normal.x() * x[u] + g.normal.y() * x[u + 1] + g.normal.z() * x[u + 2] < g.height) continue;
            for (size_t r = u; r < u + 3; ++r)
                x[r] = omega * (x[r] - m_prev2[r]) + m_prev2[r];
        }
    m_prev2.swap(m_prev1);
    for (size_t k = 0; k < nk; ++k) {
        const size_t u = 3 * static_cast<size_t>(m_order[k]);
        for (size_t r = u; r < u + 3; ++r)
            m_prev1[r] = x[r];
    }
}

int BlockDescent::substep(Positions& x, Positions& v, double h)
{
    const Model& model = m_ctx.model;
    const Index n = x.rows();
    const size_t un = static_cast<size_t>(n);
    m_xt = x;
    start_substep(x);
    // Inertial target y = x + h v + h² g; the iterations start from it.
    m_y.resize(3 * un);
    const Eigen::Vector3d& g = model.gravity;
    for (size_t i = 0; i < un; ++i) {
        if (model.fixed[i]) {
            for (int r = 0; r < 3; ++r)
                m_y[3 * i + static_cast<size_t>(r)] = x(static_cast<Index>(i), r);
            continue;
        }
        for (int r = 0; r < 3; ++r) {
            const double yr = x(static_cast<Index>(i), r) + h * v(static_cast<Index>(i), r) + h * h * g[r];
            m_y[3 * i + static_cast<size_t>(r)] = yr;
            x(static_cast<Index>(i), r) = yr;
        }
    }
    gather_contacts();

    double* xp = x.data();
    const double* xtp = m_xt.data();
    const int colours = static_cast<int>(m_colour_start.size()) - 1;
    const int max_sweeps = std::max(1, m_ctx.scene.iterations);
    // Stop when no vertex moved more than this fraction of its clamp length (a fifth of its object's mean edge).
    const double stop = 5 * m_ctx.scene.sweep_tolerance;
    int sweeps = 0;
    const double rho = m_ctx.scene.acceleration;
    double omega = 1;
    if (rho > 0) {
        m_prev2.assign(xp, xp + 3 * un);
        m_prev1 = m_prev2;
    }
    while (sweeps < max_sweeps) {
        for (ActiveContact& c : m_contacts) {
            c.rel[0] = c.rel[1] = c.rel[2] = 0;
            for (int s = 0; s < 5; ++s) {
                const size_t j = static_cast<size_t>(c.node[s]);
                for (int r = 0; r < 3; ++r)
                    c.rel[r] += c.coef[s] * (xp[3 * j + static_cast<size_t>(r)] - xtp[3 * j + static_cast<size_t>(r)]);
            }
        }
        double largest = 0;
        for (int c = 0; c < colours; ++c) {
            const std::int32_t begin = m_colour_start[static_cast<size_t>(c)], end = m_colour_start[static_cast<size_t>(c) + 1];
#ifdef TETHASH_HAVE_OPENMP
            if (m_threads > 1 && end - begin > 256) {
                double colour_largest = 0;
#pragma omp parallel for num_threads(m_threads) schedule(static) reduction(max : colour_largest)
                for (std::int32_t k = begin; k < end; ++k)
                    colour_largest = std::max(colour_largest, solve_vertex(k, xp, h));
                largest = std::max(largest, colour_largest);
                continue;
            }
#endif
            largest = std::max(largest, sweep(begin, end, xp, h));
        }
        ++sweeps;
        if (rho > 0) accelerate(sweeps, rho, omega, xp);
        if (largest <= stop) break;
    }
    const double inv_h = 1.0 / h;
    for (size_t i = 0; i < un; ++i) {
        if (model.fixed[i]) continue;
        for (int r = 0; r < 3; ++r)
            v(static_cast<Index>(i), r) = (x(static_cast<Index>(i), r) - m_xt(static_cast<Index>(i), r)) * inv_h;
    }
    return sweeps;
}

} // namespace

std::unique_ptr<StepIntegrator> make_block_descent(const StepContext& ctx)
{
    return std::make_unique<BlockDescent>(ctx);
}

} // namespace tethash::sim
