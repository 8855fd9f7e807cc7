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
// What makes it robust on real meshes (docs/simulator.md): each local Newton step is clamped to a fifth of the
// object's mean edge (without it the same settings gave no inverted tets or a crumpled body depending on
// round-off); contact terms use the contacts' relative displacement taken at the start of each iteration (Jacobi
// across the contact's five nodes), so no two threads ever read a position another one writes.
//
// What makes it right at every size (docs/simulator.md, "Convergence"): the sweeps needed grow with ω h (ω the
// material's frequency at the mean edge, which grows as the body shrinks), so a fixed count left small bodies
// unconverged: they sagged flat and ended drops with many times their start energy. Now
// - every third sweep a coarse space (a lattice over each object, coarse_space.hpp) corrects the long waves that
//   sweeps carry one ring of vertices at a time, its length chosen by a line search (from a first trial whose
//   longest vertex move is a fifth of a mean edge, on to the lattice's whole correction while the energy still falls);
// - sweeps run until converged: the last sweep's moves, measured in the local Hessians' norm (twice the energy
//   they take out), are below `convergence` of the largest sweep's and below energy_tolerance of the energy the
//   scene has to spend, or stalled in a cycle of contact switches below it; at most max_iterations, counted
//   unconverged otherwise;
// - the iterations start from x + h v + h² ã (ã the vertex's last acceleration along gravity, clamped to [0, g]),
//   not from y: a resting body does not start each substep pressed g h² into the ground;
// - a vertex that stepped into a contact within the substep and steps out of one goes half the way to its surface
//   (leaving_fraction): the contacts' damping jumps at the surface, and the sweeps flipped resting vertices across it
//   for ever.
//
// After each step (finish_step), the tets it left inverted are turned back corner by corner, positions only, in
// moves of at most a twentieth of the mean edge that press no other tet of the corner towards inversion
// (inversion_guard.hpp): slivers pressed flat on the ground, the odd tet of an impact. The refinement of steps and
// the crumple check read the count before it, so a crumpling body is still refined or stopped. Without it, drops
// end with inverted slivers on the ground, and a crumpling sheet with hundreds (docs/simulator.md, "Figures behind
// the code's constants", has the counts and what it leaves).
//
// With `inversion_guard`, no tet ends a substep inverted where it can be helped: a vertex's step never lowers one of
// its tets (slivers aside) below a tenth of its rest volume, or further once there (the inversion guard, exact since
// the volume is linear in the vertex; vertex_stencils.hpp), and the sweeps start from a state that inverts no such
// tet (corners taken back to where the substep started); but squeezed regions are held back
// (Scene::inversion_guard says what it costs).
#include "coarse_space.hpp"
#include "incidences.hpp"
#include "integrator.hpp"
#include "inversion_guard.hpp"
#include "vertex_stencils.hpp"

#include "core/team.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <vector>

#ifdef TETHASH_HAVE_OPENMP
#include <omp.h>
#endif

namespace tethash::sim {

namespace {

using detail::LaneGroup;
using detail::LaneTerms;
using detail::SpringLanes;
using detail::TetLanes;

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
};

/// Sweeps between two corrections of the coarse space (coarse_space.hpp): every second sweep cost more than it saved
/// (two residual passes per correction), every fourth converged in more sweeps (docs/simulator.md, "Figures behind
/// the code's constants").
constexpr int sweeps_per_correction = 3;
/// An automatic substep has converged when, besides `convergence`, its last sweep took out less than this fraction of
/// the energy the scene has to spend (energy_scale). On small bodies the relative test alone stopped drops that ended
/// with several times their start energy (the sweeps' remaining error is stiff: it stores (ω h)² times the energy its
/// length suggests); 1e-3 ends them below their start, 1e-4 costs twice as much (docs/simulator.md, "Figures behind
/// the code's constants").
constexpr double energy_tolerance = 1e-3;
/// The coarse correction's first trial moves no vertex further than this many times its sweep clamp (a fifth of its
/// object's mean edge), the whole correction shortened alike; its length along that direction is then the line
/// search's, up to the whole correction.
constexpr double coarse_reach = 1.0;
/// Sweeps an automatic substep takes at least: one, so that a body in free fall (its start is the answer) pays one
/// sweep, not three (the same end state at a lower cost; docs/simulator.md, "Figures behind the code's constants").
constexpr int min_sweeps_automatic = 1;
/// Times a step that gained energy is taken again, each with the convergence tests ten times tighter.
constexpr int max_tighter = 2;

class BlockDescent final : public StepIntegrator {
  public:
    explicit BlockDescent(const StepContext& ctx) : m_ctx(ctx), m_inversions(ctx.model) { setup(); }

    int substep(Positions& x, Positions& v, double h) override;
    bool converged() const override { return m_converged; }
    void finish_step(Positions& x, const std::vector<std::int32_t>& inverted) override;
    bool tighten() override
    {
        if (m_ctx.scene.iterations > 0 || m_tighter >= max_tighter) return false;
        ++m_tighter;
        return true;
    }
    void relax() override
    {
        m_tighter = 0;
        m_resumable = false;
    }
    bool resumable() const override { return m_resumable; }
    int resume(Positions& x, Positions& v, double h) override;
    void set_threads(int threads) override
    {
#ifdef TETHASH_HAVE_OPENMP
        m_threads = std::max(1, threads);
#else
        (void)threads;
#endif
    }

  private:
    void setup();
    /// A greedy colouring of the free vertices over the edge graph (every pair of vertices of a tet is an edge, so one
    /// colour shares no spring and no tet): m_order the free vertices colour by colour; returns each colour's
    /// start in m_order (and the end).
    std::vector<std::int32_t> colour_vertices(const detail::Incidences& springs_at);
    /// Each colour's vertices in groups of four lanes, their springs and tets lane-interleaved (m_groups, m_springs,
    /// m_tets, m_colour_start), and each vertex's clamp length (m_max_step).
    void pack_lanes(const std::vector<std::int32_t>& colour_start, const detail::Incidences& springs_at,
                    const detail::Incidences& tets_at);
    /// Lane l of group g: its vertex's springs and tets into the group's entries (padding beyond them).
    void pack_lane(LaneGroup& g, int l, const detail::Incidences& springs_at, const detail::Incidences& tets_at);
    void start_substep(const double* x4);
    void gather_contacts();
    /// One Newton step on each real lane of group g (its elastic terms gathered four lanes at a time, then
    /// inertia, ground and contacts lane by lane). Returns the largest step over its lane's clamp length (0 … 1);
    /// adds Σ dᵀ H d of its lanes' moves to `moved` (d the move, H the vertex's local Hessian).
    double solve_group(std::int32_t g, double* x4, double h, double& moved) const;
    /// One Gauss–Seidel sweep over the colours (each colour's groups in parallel). The size of its moves (Σ dᵀ H d)
    /// is summed per group, then in group order, so it is the same at any thread count.
    struct Sweep {
        double largest = 0; ///< largest step over its vertex's clamp length
        double moved = 0;   ///< Σ dᵀ H d over the sweep's moves: twice the energy they took out (to second order)
    };
    Sweep sweep(double* x4, double h);
    /// The energy the scene has at (x, v) to spend: kinetic, plus every free mass falling over the free vertices'
    /// extent along gravity (and to the ground where there is one); a sweep whose moves, as velocities, carry a
    /// small part of it has not much left to change.
    double energy_scale(const Positions& x, const Positions& v) const;
    /// Contacts' relative displacements since the start of the substep, at x4 (once per sweep: Jacobi across them).
    void refresh_contacts(const double* x4);
    /// The lattice's correction (coarse_space.hpp) at x4: the residual −∇G and the ground's and contacts' own
    /// Hessian blocks per vertex, the coarse Newton step (the matrix factorised on the first call of a substep),
    /// added to x4 (shortened so that no vertex moves more than its clamp length). Returns the energy it took out (to
    /// second order along its direction), or a negative number if it could not be made.
    double coarse_correction(double* x4, double h, bool first);
    /// r (3n) = −∇G at x4 over the free vertices; with `extra`, m_extra the ground's and contacts' Hessian blocks.
    void residual(const double* x4, double h, std::vector<double>& r, bool extra);
    /// The fraction of the step ds of vertex u that leaves none of its pressing contacts (ground or contact) for
    /// more than half the way to the surface: 1 when no step leaves one.
    double leaving_fraction(size_t u, const double* x4, const double* ds) const;
    /// Adds lane l's inertia, ground and contact terms to its elastic ones.
    void add_lane_terms(const LaneGroup& grp, int lane, LaneTerms& terms, const double* x4, double h) const;
    /// Chebyshev step after sweep n: x ← ω (x − x_{n−2}) + x_{n−2} on the free vertices (stride 4).
    void accelerate(int n, double rho, double& omega, double* x);
    /// Chebyshev acceleration's ρ: the scene's, or automatic: none with the coarse space (its corrections carry the
    /// long waves the acceleration was for), 0.9 without.
    double acceleration_rho() const
    {
        return m_ctx.scene.acceleration >= 0 ? m_ctx.scene.acceleration : (m_coarse.empty() ? 0.9 : 0.0);
    }
    /// The substep's sweeps on m_x4, from where m_run left them, until converged (the tolerances m_tighter's) or the
    /// substep has swept `max_iterations` times in all; returns the sweeps taken now.
    int iterate(double h);
    /// The sweeps' end into x and v (v, the substep's start velocities on entry: from the start m_xt, and the
    /// acceleration against the start velocities).
    void end_substep(Positions& x, Positions& v, double h);

    StepContext m_ctx;
    // Fixed set-up, built once: the free vertices of each colour in groups of four lanes (vertex_stencils.hpp),
    // the groups' entries stored in sweep order, so that a sweep reads them front to back.
    std::vector<std::int32_t> m_colour_start; ///< groups of each colour
    /// Prefix sums of the groups' gather costs (group_cost), to split a range of groups over a team in equal work.
    std::vector<std::int64_t> m_cost_prefix;
    /// Groups [begin, end) split over `parts` threads by cost: part `part`'s contiguous range.
    std::pair<std::int32_t, std::int32_t> balanced_part(std::int32_t begin, std::int32_t end, int part,
                                                        int parts) const;
    std::vector<LaneGroup> m_groups;
    std::vector<SpringLanes> m_springs;
    std::vector<TetLanes> m_tets;
    std::vector<std::int32_t> m_order; ///< the free vertices
    std::vector<double> m_max_step;    ///< vertex id → largest local step (a fifth of its object's mean edge)
    std::vector<double> m_ground_k, m_ground_c; ///< vertex id → ground penalty and damping
    detail::GatherFn m_gather = nullptr;
    detail::StartFn m_start = nullptr;
    detail::SolveFn m_solve = nullptr;
    int m_threads = 1;
    // Per-substep state, buffers reused.
    Positions m_xt; ///< positions at the start of the substep
    struct alignas(32) Point4 {
        double c[4];
    };
    std::vector<Point4> m_x4;             ///< the positions the sweeps work on (stride 4: aligned row loads)
    std::vector<double> m_y;              ///< inertial target, flat 3n
    std::vector<double> m_accel;          ///< per vertex, flat 3n: its acceleration over the last substep
    std::vector<double> m_prev1, m_prev2; ///< the iterates of the two previous sweeps (Chebyshev acceleration)
    std::vector<double> m_group_moved;    ///< per group: Σ dᵀ H d of the current sweep
    std::vector<double> m_moved_history;  ///< Σ dᵀ H d of each sweep of the substep
    /// Where the substep's sweeps stand, kept so that a retake for energy continues them (resume): the sweeps taken,
    /// the largest sweep's moves (the convergence test's reference), the Chebyshev weight, the coarse space's use.
    struct SweepRun {
        int sweeps = 0;
        double omega = 1, moved_max = 0;
        bool use_coarse = false, first_coarse = true;
    };
    SweepRun m_run;
    bool m_resumable = false; ///< the last substep's state is intact: resume may continue it
    bool m_converged = true;  ///< the last substep's sweeps met the tolerance
    int m_tighter = 0; ///< times the step is being taken again for energy it gained (tighten): tolerances / 10 each
    mutable std::vector<char> m_entered; ///< vertex id → it stepped into a contact in this substep (leaving_fraction)
    double m_energy_ref = 0;             ///< the energy the scene has to spend (energy_scale at the first substep)
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
    detail::CoarseSpace m_coarse;
    std::vector<double> m_residual, m_residual_end, m_extra, m_dx; ///< per vertex: −∇G (3) at x and x + dx, ground
                                                                   ///< and contact Hessian (6), the lattice's step (3)
    std::vector<std::int32_t> m_with_extra;
    InversionGuard m_inversions; ///< whole-state checks of the inversion guard (inversion_guard.hpp)
};

/// The number of entries of vertex i in `at`.
std::int32_t count_of(const detail::Incidences& at, std::int32_t i)
{
    return at.start[static_cast<size_t>(i) + 1] - at.start[static_cast<size_t>(i)];
}

void BlockDescent::setup()
{
    const Model& model = m_ctx.model;
    const Index n = model.num_vertices();
    const size_t un = static_cast<size_t>(n);

    // Vertex → springs (by id) and tets (by id and corner): the colouring and the lanes' entries.
    const detail::Incidences springs_at = detail::incidences(model.springs.edges, un, false);
    const detail::Incidences tets_at = detail::incidences(model.volumes.tets, un, true);
    pack_lanes(colour_vertices(springs_at), springs_at, tets_at);

    std::vector<double> damping;
    for (const ObjectSpec& o : m_ctx.scene.objects)
        damping.push_back(o.material.damping);
    if (m_ctx.scene.coarse_space) {
        const double h = m_ctx.scene.dt / std::max(1, m_ctx.scene.substeps);
        m_coarse.build(model, m_ctx.mesh.positions, damping, h);
        m_coarse.set_up_for(h);
    }
    m_gather = detail::choose_gather(m_ctx.scene.inversion_guard);
    m_start = detail::choose_start(m_gather);
    m_solve = detail::choose_solve(m_gather);
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
    m_coarse.set_threads(m_threads);
}

std::vector<std::int32_t> BlockDescent::colour_vertices(const detail::Incidences& springs_at)
{
    const Model& model = m_ctx.model;
    const Index n = model.num_vertices();
    const std::vector<std::int32_t>& adj_start = springs_at.start;
    const std::vector<std::int32_t>& adj_spring = springs_at.entries;
    std::vector<int> colour(static_cast<size_t>(n), -1);
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
    std::vector<std::int32_t> colour_start(static_cast<size_t>(colours) + 1, 0); // positions in m_order
    for (Index i = 0; i < n; ++i)
        if (colour[static_cast<size_t>(i)] >= 0)
            ++colour_start[static_cast<size_t>(colour[static_cast<size_t>(i)]) + 1];
    for (int c = 0; c < colours; ++c)
        colour_start[static_cast<size_t>(c) + 1] += colour_start[static_cast<size_t>(c)];
    m_order.resize(static_cast<size_t>(colour_start.back()));
    std::vector<std::int32_t> fill(colour_start.begin(), colour_start.end() - 1);
    for (Index i = 0; i < n; ++i)
        if (colour[static_cast<size_t>(i)] >= 0)
            m_order[static_cast<size_t>(fill[static_cast<size_t>(colour[static_cast<size_t>(i)])]++)] =
                static_cast<std::int32_t>(i);
    return colour_start;
}

void BlockDescent::pack_lanes(const std::vector<std::int32_t>& colour_start, const detail::Incidences& springs_at,
                              const detail::Incidences& tets_at)
{
    // Within a colour the order does not change the result (its vertices are independent), so each colour's
    // vertices are sorted by their number of tets and springs and grouped by four, which keeps the padding of the
    // lane-interleaved entries small.
    const int colours = static_cast<int>(colour_start.size()) - 1;
    m_colour_start.assign(1, 0);
    m_groups.clear();
    m_springs.clear();
    m_tets.clear();
    m_max_step.assign(static_cast<size_t>(m_ctx.model.num_vertices()), std::numeric_limits<double>::infinity());
    for (int c = 0; c < colours; ++c) {
        std::vector<std::int32_t> members(m_order.begin() + colour_start[static_cast<size_t>(c)],
                                          m_order.begin() + colour_start[static_cast<size_t>(c) + 1]);
        std::stable_sort(members.begin(), members.end(), [&](std::int32_t p, std::int32_t q) {
            const std::int32_t tp = count_of(tets_at, p), tq = count_of(tets_at, q);
            if (tp != tq) return tp > tq;
            return count_of(springs_at, p) > count_of(springs_at, q);
        });
        for (size_t first = 0; first < members.size(); first += 4) {
            LaneGroup g{};
            g.lanes = static_cast<std::int32_t>(std::min<size_t>(4, members.size() - first));
            std::int32_t springs = 0, tets = 0;
            for (int l = 0; l < 4; ++l) {
                const std::int32_t i = members[first + static_cast<size_t>(std::min(l, g.lanes - 1))];
                g.vertex[l] = l < g.lanes ? i : members[first];
                springs = std::max(springs, count_of(springs_at, i));
                tets = std::max(tets, count_of(tets_at, i));
            }
            g.spring_begin = static_cast<std::int32_t>(m_springs.size());
            g.spring_end = g.spring_begin + springs;
            g.tet_begin = static_cast<std::int32_t>(m_tets.size());
            g.tet_end = g.tet_begin + tets;
            m_springs.resize(static_cast<size_t>(g.spring_end));
            m_tets.resize(static_cast<size_t>(g.tet_end));
            for (int l = 0; l < 4; ++l)
                pack_lane(g, l, springs_at, tets_at);
            m_groups.push_back(g);
        }
        m_colour_start.push_back(static_cast<std::int32_t>(m_groups.size()));
    }
    // A group's gather cost: its entries (a tet entry about twice a spring's work) and its solve. Colours are sorted
    // by their vertices' tet counts, most first, so equal counts of groups would be unequal work.
    m_cost_prefix.assign(1, 0);
    for (const LaneGroup& g : m_groups)
        m_cost_prefix.push_back(m_cost_prefix.back() + 2 * (g.tet_end - g.tet_begin) + (g.spring_end - g.spring_begin) +
                                4);
}

std::pair<std::int32_t, std::int32_t> BlockDescent::balanced_part(std::int32_t begin, std::int32_t end, int part,
                                                                  int parts) const
{
    const std::int64_t* P = m_cost_prefix.data();
    const std::int64_t total = P[end] - P[begin];
    const auto cut = [&](int k) {
        if (k <= 0) return begin;
        if (k >= parts) return end;
        const std::int64_t target = P[begin] + total * k / parts;
        return static_cast<std::int32_t>(std::lower_bound(P + begin, P + end, target) - P);
    };
    return {cut(part), cut(part + 1)};
}

void BlockDescent::pack_lane(LaneGroup& g, int l, const detail::Incidences& springs_at,
                             const detail::Incidences& tets_at)
{
    // Volume terms: the other three corners in an order that keeps the orientation (even permutations of
    // (0, 1, 2, 3) starting with the corner).
    static constexpr int others[4][3] = {{1, 2, 3}, {0, 3, 2}, {3, 0, 1}, {2, 1, 0}};
    const Model& model = m_ctx.model;
    const std::int32_t i = g.vertex[l];
    const bool real = l < g.lanes;
    const size_t o = static_cast<size_t>(model.vertex_object[static_cast<size_t>(i)]);
    g.damping[l] = o < m_ctx.scene.objects.size() ? m_ctx.scene.objects[o].material.damping : 0.0;
    const double edge = o < model.object_mean_edge.size() ? model.object_mean_edge[o] : 0.0;
    if (edge > 0) m_max_step[static_cast<size_t>(i)] = 0.2 * edge;
    // Padding (a padding lane, or a lane's entries beyond its own): zero stiffness on the lane's own vertex, which
    // contributes nothing.
    for (std::int32_t e = 0; e < g.spring_end - g.spring_begin; ++e) {
        SpringLanes& sl = m_springs[static_cast<size_t>(g.spring_begin + e)];
        sl.other[l] = i;
        sl.rest[l] = 0;
        sl.k[l] = sl.stretch_t[l] = 0;
        if (!real || e >= count_of(springs_at, i)) continue;
        const Index edge_id = springs_at.entries[static_cast<size_t>(springs_at.start[static_cast<size_t>(i)] + e)];
        const Index j =
            model.springs.edges(edge_id, 0) == i ? model.springs.edges(edge_id, 1) : model.springs.edges(edge_id, 0);
        sl.other[l] = static_cast<std::int32_t>(j);
        sl.k[l] = static_cast<float>(model.springs.k[static_cast<size_t>(edge_id)]);
        sl.rest[l] = model.springs.rest[static_cast<size_t>(edge_id)];
    }
    for (std::int32_t e = 0; e < g.tet_end - g.tet_begin; ++e) {
        TetLanes& tl = m_tets[static_cast<size_t>(g.tet_begin + e)];
        tl.a[l] = tl.b[l] = tl.c[l] = i;
        tl.w0[l] = 0;
        tl.k36[l] = tl.excess_t[l] = 0;
        tl.guard[l] = 0;
        if (!real || e >= count_of(tets_at, i)) continue;
        const std::int32_t entry = tets_at.entries[static_cast<size_t>(tets_at.start[static_cast<size_t>(i)] + e)];
        const Index t = entry / 4;
        const int a = entry % 4;
        const double v0 = model.volumes.rest[static_cast<size_t>(t)];
        tl.a[l] = static_cast<std::int32_t>(model.volumes.tets(t, others[a][0]));
        tl.b[l] = static_cast<std::int32_t>(model.volumes.tets(t, others[a][1]));
        tl.c[l] = static_cast<std::int32_t>(model.volumes.tets(t, others[a][2]));
        tl.k36[l] = static_cast<float>(model.volumes.k[static_cast<size_t>(t)] / v0 / 36.0);
        tl.w0[l] = 6.0 * v0;
        tl.guard[l] = !m_ctx.scene.inversion_guard || model.volumes.sliver[static_cast<size_t>(t)]
                          ? 0.0F
                          : static_cast<float>(detail::guard_fraction * 6.0 * v0);
    }
}

void BlockDescent::start_substep(const double* x4)
{
    // Lengths and volumes at the start of the substep, for the relative damping: each group writes its own lane
    // entries only, so the groups split over the threads.
    const std::int32_t groups = static_cast<std::int32_t>(m_groups.size());
#ifdef TETHASH_HAVE_OPENMP
#pragma omp parallel num_threads(m_threads) if (m_threads > 1 && groups > 64)
#endif
    {
        const auto [first, last] = balanced_part(0, groups, tethash::detail::team_rank(), tethash::detail::team_size());
        for (std::int32_t g = first; g < last; ++g)
            m_start(m_groups[static_cast<size_t>(g)], m_springs.data(), m_tets.data(), x4);
    }
}

void BlockDescent::gather_contacts()
{
    const ContactResponse& cr = m_ctx.contacts;
    const Model& model = m_ctx.model;
    const std::vector<Contact>& contacts = cr.active();
    m_contacts.clear();
    const size_t un = model.mass.size();
    m_vc_start.assign(un + 1, 0);
    for (size_t q = 0; q < contacts.size(); ++q) {
        const Contact& c = contacts[q];
        // Speculative margin contacts (depth ≤ 0, proximity.hpp) come in too: they push only if the gap closes
        // within the substep's iterations.
        if (!(c.depth > 0) && !cr.is_margin(q)) continue;
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

double BlockDescent::solve_group(std::int32_t gi, double* x, double h, double& moved) const
{
    const LaneGroup& grp = m_groups[static_cast<size_t>(gi)];
    assert(grp.lanes >= 1 && grp.lanes <= 4 && grp.spring_end <= static_cast<std::int32_t>(m_springs.size()) &&
           grp.tet_end <= static_cast<std::int32_t>(m_tets.size()));
    LaneTerms terms;
    const double inv_h = 1.0 / h;
    m_gather(grp, m_springs.data(), m_tets.data(), x, inv_h, terms);
    for (int l = 0; l < grp.lanes; ++l)
        add_lane_terms(grp, l, terms, x, h);
    double d[3][4];
    const int solved = m_solve(terms, d);
    double largest = 0;
    for (int l = 0; l < grp.lanes; ++l) {
        if (!(solved >> l & 1)) continue; // not positive definite: the vertex stays
        const size_t u = static_cast<size_t>(grp.vertex[l]);
        const double step = std::sqrt(d[0][l] * d[0][l] + d[1][l] * d[1][l] + d[2][l] * d[2][l]);
        double scale = 1.0, relative = step / m_max_step[u];
        if (relative > 1) {
            scale = 1.0 / relative;
            relative = 1;
        }
        // The inversion guard (vertex_stencils.hpp): a step that could bring one of the vertex's tets near zero
        // volume is shortened so that none crosses it.
        if (scale * scale * (step * step) > 0.81 * terms.reach2[l]) {
            const double ds[3] = {scale * d[0][l], scale * d[1][l], scale * d[2][l]};
            scale *= detail::guarded_fraction(grp, m_tets.data(), l, x, ds);
        }
        {
            const double ds[3] = {scale * d[0][l], scale * d[1][l], scale * d[2][l]};
            scale *= leaving_fraction(u, x, ds);
        }
        for (size_t r = 0; r < 3; ++r)
            x[4 * u + r] += scale * d[r][l];
        {
            // The move in the local Hessian's norm, dᵀ H d: twice the energy the local step takes out (the
            // mass-weighted length undercounts it by 1 + (ω h)², the stiffness's share, which is what grows on small
            // bodies).
            const double a = d[0][l], b = d[1][l], c = d[2][l];
            const double dhd = terms.H[0][l] * a * a + terms.H[1][l] * b * b + terms.H[2][l] * c * c +
                               2 * (terms.H[3][l] * a * b + terms.H[4][l] * a * c + terms.H[5][l] * b * c);
            moved += scale * scale * dhd;
        }
        largest = std::max(largest, relative);
    }
    return largest;
}

double BlockDescent::leaving_fraction(size_t u, const double* x, const double* ds) const
{
    // A contact's damping pushes while the vertex is inside and stops at the surface: its force jumps there, and a
    // Newton step from inside that takes the vertex out meets no force on the other side, so the next one takes it
    // back in: the sweeps flip a resting vertex across the surface for ever (measured on the shared meshes: the
    // same move every second sweep, and the velocity the substep ends with is what the flip left). So a vertex that
    // entered a contact within this substep and then steps out of one goes half the way to the surface instead: it
    // settles at the surface and the sweeps converge. A vertex that did not enter in this substep leaves freely.
    double t = 1.0;
    bool entered = false;
    const bool flipping = m_entered[u] != 0;
    auto cut = [&](double before, double after) {
        if (before > 0 && after < 0 && flipping) t = std::min(t, 0.5 * before / (before - after));
        if (before <= 0 && after > 0) entered = true;
    };
    if (!m_ground_k.empty()) {
        const Ground& g = m_ctx.model.ground;
        const double pen =
            g.height - (g.normal.x() * x[4 * u] + g.normal.y() * x[4 * u + 1] + g.normal.z() * x[4 * u + 2]);
        cut(pen, pen - (g.normal.x() * ds[0] + g.normal.y() * ds[1] + g.normal.z() * ds[2]));
    }
    for (std::int32_t s = m_vc_start[u]; s < m_vc_start[u + 1]; ++s) {
        const VertexContact& vc = m_vc[static_cast<size_t>(s)];
        const ActiveContact& c = m_contacts[static_cast<size_t>(vc.contact)];
        const double depth = c.depth - (c.n[0] * c.rel[0] + c.n[1] * c.rel[1] + c.n[2] * c.rel[2]);
        cut(depth, depth - vc.coef * (c.n[0] * ds[0] + c.n[1] * ds[1] + c.n[2] * ds[2]));
    }
    if (entered) m_entered[u] = 1;
    return t;
}

void BlockDescent::add_lane_terms(const LaneGroup& grp, int l, LaneTerms& terms, const double* x, double h) const
{
    const Model& model = m_ctx.model;
    const size_t u = static_cast<size_t>(grp.vertex[l]);
    const double inv_h = 1.0 / h;
    const double m_h2 = model.mass[u] * inv_h * inv_h;
    const double xi = x[4 * u], yi = x[4 * u + 1], zi = x[4 * u + 2];
    double f[3] = {m_h2 * (m_y[3 * u] - xi) + terms.f[0][l], m_h2 * (m_y[3 * u + 1] - yi) + terms.f[1][l],
                   m_h2 * (m_y[3 * u + 2] - zi) + terms.f[2][l]};
    Sym3 H;
    H.xx = terms.H[0][l] + m_h2;
    H.yy = terms.H[1][l] + m_h2;
    H.zz = terms.H[2][l] + m_h2;
    H.xy = terms.H[3][l];
    H.xz = terms.H[4][l];
    H.yz = terms.H[5][l];

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
                    // Coulomb friction on the tangential displacement, smoothed below Model::friction_speed
                    // (lagged normal force: Hessian μ fn / max(|t|, ε) on the tangent plane).
                    const double tx = dx - dn * gnx, ty = dy - dn * gny, tz = dz - dn * gnz;
                    const double tl = std::sqrt(tx * tx + ty * ty + tz * tz);
                    const double s = g.friction * fn / std::max(tl, model.friction_speed[u] * h);
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
            const double sf = mu * fn / std::max(tl, model.friction_speed[u] * h);
            f[0] -= vc.coef * sf * tx;
            f[1] -= vc.coef * sf * ty;
            f[2] -= vc.coef * sf * tz;
            H.add_identity(vc.coef * vc.coef * sf);
            H.add_outer(-vc.coef * vc.coef * sf, c.n[0], c.n[1], c.n[2]);
        }
    }

    for (int r = 0; r < 3; ++r)
        terms.f[r][l] = f[r];
    terms.H[0][l] = H.xx;
    terms.H[1][l] = H.yy;
    terms.H[2][l] = H.zz;
    terms.H[3][l] = H.xy;
    terms.H[4][l] = H.xz;
    terms.H[5][l] = H.yz;
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
            const size_t i = static_cast<size_t>(m_order[k]), u = 4 * i;
            if (m_vc_start[i + 1] > m_vc_start[i]) continue;
            if (ground && g.normal.x() * x[u] + g.normal.y() * x[u + 1] + g.normal.z() * x[u + 2] < g.height) continue;
            for (size_t r = u; r < u + 3; ++r)
                x[r] = omega * (x[r] - m_prev2[r]) + m_prev2[r];
        }
    m_prev2.swap(m_prev1);
    for (size_t k = 0; k < nk; ++k) {
        const size_t u = 4 * static_cast<size_t>(m_order[k]);
        for (size_t r = u; r < u + 3; ++r)
            m_prev1[r] = x[r];
    }
}

double BlockDescent::energy_scale(const Positions& x, const Positions& v) const
{
    const Model& model = m_ctx.model;
    const double g = model.gravity.norm();
    const Eigen::Vector3d down = g > 0 ? Eigen::Vector3d(model.gravity / g) : Eigen::Vector3d::Zero();
    double kinetic = 0, mass = 0, lo = INFINITY, hi = -INFINITY;
    for (const std::int32_t i : m_order) {
        const size_t u = static_cast<size_t>(i);
        kinetic += 0.5 * model.mass[u] * v.row(i).squaredNorm();
        mass += model.mass[u];
        const double along = down.dot(x.row(i).transpose());
        lo = std::min(lo, along);
        hi = std::max(hi, along);
    }
    double drop = hi > lo ? hi - lo : 0.0;
    if (model.ground.enabled && g > 0) {
        // The ground's plane, along gravity: how far a free vertex (the first of the order; not necessarily the lowest,
        // which the run's health measures: FailureCheck::energy_available) is above it. Measuring from the lowest
        // made the energy test stricter and left the screw dropped at 1/60 with a tet inverted.
        const double above =
            model.ground.normal.dot(-down) > 0.1
                ? (model.ground.height - model.ground.normal.dot(x.row(m_order.empty() ? 0 : m_order[0]).transpose()))
                : 0.0;
        drop += std::max(0.0, -above);
    }
    const double e = kinetic + mass * g * drop;
    return e > 0 ? e : std::max(1e-300, mass * 1e-12);
}

void BlockDescent::refresh_contacts(const double* xp)
{
    const double* xtp = m_xt.data();
    for (ActiveContact& c : m_contacts) {
        c.rel[0] = c.rel[1] = c.rel[2] = 0;
        for (int s = 0; s < 5; ++s) {
            const size_t j = static_cast<size_t>(c.node[s]);
            for (int r = 0; r < 3; ++r)
                c.rel[r] += c.coef[s] * (xp[4 * j + static_cast<size_t>(r)] - xtp[3 * j + static_cast<size_t>(r)]);
        }
    }
}

void BlockDescent::residual(const double* xp, double h, std::vector<double>& r, bool extra)
{
    const Model& model = m_ctx.model;
    const size_t un = model.mass.size();
    r.assign(3 * un, 0.0);
    if (extra) m_extra.assign(6 * un, 0.0);
    const double inv_h2 = 1.0 / (h * h);
    const std::int32_t groups = static_cast<std::int32_t>(m_groups.size());
    // Every group's terms at x4, none moved: the residual and, if asked, the blocks the ground and the contacts add
    // to the vertex's Hessian (its total less the elastic part and the inertia).
#ifdef TETHASH_HAVE_OPENMP
#pragma omp parallel num_threads(m_threads) if (m_threads > 1)
#endif
    {
        const auto [first, last] = balanced_part(0, groups, tethash::detail::team_rank(), tethash::detail::team_size());
        for (std::int32_t gi = first; gi < last; ++gi) {
            const LaneGroup& grp = m_groups[static_cast<size_t>(gi)];
            LaneTerms terms;
            m_gather(grp, m_springs.data(), m_tets.data(), xp, 1.0 / h, terms);
            double elastic[6][4];
            for (int q = 0; q < 6; ++q)
                for (int l = 0; l < 4; ++l)
                    elastic[q][l] = terms.H[q][l];
            for (int l = 0; l < grp.lanes; ++l) {
                add_lane_terms(grp, l, terms, xp, h);
                const size_t u = static_cast<size_t>(grp.vertex[l]);
                for (size_t q = 0; q < 3; ++q)
                    r[3 * u + q] = terms.f[q][l];
                if (!extra) continue;
                const double m_h2 = model.mass[u] * inv_h2;
                // What the ground and the contacts added (0 where they add nothing: the sum less its parts leaves
                // round-off, which would list every vertex).
                bool any = false;
                double e[6];
                for (size_t q = 0; q < 6; ++q) {
                    const double base = elastic[q][l] + (q < 3 ? m_h2 : 0.0);
                    e[q] = terms.H[q][l] - base;
                    any = any || std::abs(e[q]) > 1e-9 * (std::abs(base) + m_h2);
                }
                for (size_t q = 0; q < 6; ++q)
                    m_extra[6 * u + q] = any ? e[q] : 0.0;
            }
        }
    }
}

double BlockDescent::coarse_correction(double* xp, double h, bool first)
{
    const size_t un = m_ctx.model.mass.size();
    refresh_contacts(xp);
    residual(xp, h, m_residual, first);
    if (first) {
        m_with_extra.clear();
        for (size_t i = 0; i < un; ++i)
            if (m_extra[6 * i] != 0 || m_extra[6 * i + 1] != 0 || m_extra[6 * i + 2] != 0)
                m_with_extra.push_back(static_cast<std::int32_t>(i));
        if (!m_coarse.prepare(h, xp, m_extra, m_with_extra)) return -1;
    }
    m_coarse.correct(m_residual, m_dx);
    double over = 1.0;
    for (const std::int32_t i : m_order) {
        const size_t u = static_cast<size_t>(i);
        const double len2 =
            m_dx[3 * u] * m_dx[3 * u] + m_dx[3 * u + 1] * m_dx[3 * u + 1] + m_dx[3 * u + 2] * m_dx[3 * u + 2];
        over = std::max(over, std::sqrt(len2) / (coarse_reach * m_max_step[u]));
    }
    if (!std::isfinite(over)) return -1;
    // The lattice's matrix is the start state's, turned: not the exact Hessian of the state (compressed springs,
    // friction, contacts that came or went). The step's length along its direction is the secant minimum of G
    // between x and x + dx (exact for a quadratic), so the correction never undoes what the sweeps did.
    double slope0 = 0;
    for (const std::int32_t i : m_order) {
        const size_t u = static_cast<size_t>(i);
        for (size_t q = 0; q < 3; ++q) {
            m_dx[3 * u + q] /= over;
            slope0 += m_residual[3 * u + q] * m_dx[3 * u + q];
        }
    }
    if (!(slope0 > 0)) return 0; // not a descent direction here: no correction this time
    // xp moved by `by` times the correction; the correction's slope where xp is (the residual along it: the energy
    // still falls where it is positive).
    const auto move = [&](double by) {
        for (const std::int32_t i : m_order)
            for (size_t q = 0; q < 3; ++q)
                xp[4 * static_cast<size_t>(i) + q] += by * m_dx[3 * static_cast<size_t>(i) + q];
    };
    const auto slope_here = [&] {
        refresh_contacts(xp);
        residual(xp, h, m_residual_end, false);
        double slope = 0;
        for (const std::int32_t i : m_order)
            for (size_t q = 0; q < 3; ++q)
                slope += m_residual_end[3 * static_cast<size_t>(i) + q] * m_dx[3 * static_cast<size_t>(i) + q];
        return slope;
    };
    move(1.0);
    const double slope1 = slope_here();
    double alpha = slope0 > slope1 ? std::min(1.0, slope0 / (slope0 - slope1)) : 1.0;
    // Still going down at the clamp's end (slope1 > 0): the secant's minimum further along, within the lattice's
    // whole correction (over times the clamped one), and where the slope there says it went past, the secant between
    // the two ends. The clamp sets how far the first trial reaches, not how far the correction may go: it shortened
    // the small raptor's corrections five times (docs/simulator.md, "Where a 15 cm step's extra work goes").
    if (slope1 > 0 && alpha >= 1.0 && over > 1.0) {
        const double reach = slope0 > slope1 ? std::min(over, slope0 / (slope0 - slope1)) : over;
        if (reach > 1.0) {
            move(reach - 1.0);
            const double slope2 = slope_here();
            alpha = slope2 < 0 ? 1.0 + (reach - 1.0) * slope1 / (slope1 - slope2) : reach;
            if (alpha < reach) move(-(reach - alpha));
            return 0.5 * alpha * slope0;
        }
    }
    if (alpha < 1.0) move(-(1.0 - alpha));
    return 0.5 * alpha * slope0;
}

BlockDescent::Sweep BlockDescent::sweep(double* xp, double h)
{
    const int colours = static_cast<int>(m_colour_start.size()) - 1;
    m_group_moved.assign(m_groups.size(), 0.0);
    double* moved = m_group_moved.data();
    Sweep out;
#ifdef TETHASH_HAVE_OPENMP
    if (m_threads > 1 && m_groups.size() > 64) {
        // One team for the whole sweep: a colour's groups split over it (a colour of a few groups taken by one
        // thread), the colours one after the other with a barrier between (the one synchronisation Gauss-Seidel
        // needs), rather than a parallel region per colour and the colours under 64 groups on one thread: the hand
        // drop's step 0.95x, its integration 0.92x at two threads (docs/simulator.md).
        double largest = 0;
#pragma omp parallel num_threads(m_threads) reduction(max : largest)
        for (int c = 0; c < colours; ++c) {
            const std::int32_t begin = m_colour_start[static_cast<size_t>(c)],
                               end = m_colour_start[static_cast<size_t>(c) + 1];
            if (end - begin > 8) {
                // Each thread a contiguous range of equal cost (the groups are sorted dearest first).
                const auto [first, last] =
                    balanced_part(begin, end, tethash::detail::team_rank(), tethash::detail::team_size());
                for (std::int32_t g = first; g < last; ++g)
                    largest = std::max(largest, solve_group(g, xp, h, moved[g]));
#pragma omp barrier
            } else {
#pragma omp single
                for (std::int32_t g = begin; g < end; ++g)
                    largest = std::max(largest, solve_group(g, xp, h, moved[g]));
            }
        }
        out.largest = largest;
    } else
#endif
    {
        for (int c = 0; c < colours; ++c)
            for (std::int32_t g = m_colour_start[static_cast<size_t>(c)];
                 g < m_colour_start[static_cast<size_t>(c) + 1]; ++g)
                out.largest = std::max(out.largest, solve_group(g, xp, h, moved[g]));
    }
    for (double m : m_group_moved)
        out.moved += m;
    return out;
}

int BlockDescent::substep(Positions& x, Positions& v, double h)
{
    const Model& model = m_ctx.model;
    const Index n = x.rows();
    const size_t un = static_cast<size_t>(n);
    m_xt = x;
    // The sweeps work on a copy with a stride of 4 doubles (vertex_stencils.hpp), written back at the end.
    m_x4.resize(un);
    for (size_t i = 0; i < un; ++i)
        m_x4[i] = {x(static_cast<Index>(i), 0), x(static_cast<Index>(i), 1), x(static_cast<Index>(i), 2), 0.0};
    double* xp = m_x4.data()->c;
    start_substep(xp);
    m_y.resize(3 * un);
    const bool automatic = m_ctx.scene.iterations <= 0;
    if (!(m_energy_ref > 0)) m_energy_ref = energy_scale(x, v);
    const double rho = acceleration_rho();
    // Inertial target y = x + h v + h² g. The iterations start from x + h v + h² ã, ã the part of the vertex's
    // acceleration over the previous substep along gravity, clamped to [0, |g|] (the VBD paper's adaptive start, per
    // vertex; g at the first substep): y in free fall, x + h v for a body at rest. Starting from y, a resting body
    // began every substep g h² lower, pressed into the ground (at 1/60 that is 2.7 mm: an edge of a 5 cm body), and
    // the sweeps spent themselves lifting it back. The clamp matters: the whole last acceleration extrapolated an
    // impact's rebound into the next start, and where the sweeps stopped short that bias put energy in (small bodies
    // ended drops with tens of times their start energy; docs/simulator.md, "Figures behind the code's constants").
    const Eigen::Vector3d& g = model.gravity;
    const double g_norm = g.norm();
    const Eigen::Vector3d down = g_norm > 0 ? Eigen::Vector3d(g / g_norm) : Eigen::Vector3d::Zero();
    const bool first = m_accel.size() != 3 * un;
    if (first) m_accel.assign(3 * un, 0.0);
    for (size_t i = 0; i < un; ++i) {
        if (model.fixed[i]) {
            for (int r = 0; r < 3; ++r)
                m_y[3 * i + static_cast<size_t>(r)] = x(static_cast<Index>(i), r);
            continue;
        }
        if (first)
            for (size_t r = 0; r < 3; ++r)
                m_accel[3 * i + r] = g[static_cast<Index>(r)];
        const double along = std::clamp(
            down.x() * m_accel[3 * i] + down.y() * m_accel[3 * i + 1] + down.z() * m_accel[3 * i + 2], 0.0, g_norm);
        for (size_t r = 0; r < 3; ++r) {
            const Index ri = static_cast<Index>(r);
            const double xr = x(static_cast<Index>(i), ri) + h * v(static_cast<Index>(i), ri);
            m_y[3 * i + r] = xr + h * h * g[ri];
            xp[4 * i + r] = automatic ? xr + h * h * along * down[ri] : m_y[3 * i + r];
        }
    }
    if (m_ctx.scene.inversion_guard) m_inversions.start_without_inversions(xp, m_xt);
    gather_contacts();
    m_entered.assign(un, 0);

    m_run = SweepRun{};
    m_run.use_coarse = !m_coarse.empty();
    m_moved_history.clear();
    if (rho > 0) {
        m_prev2.assign(xp, xp + 4 * un);
        m_prev1 = m_prev2;
    }
    const int sweeps = iterate(h);
    if (m_ctx.scene.inversion_guard) m_inversions.restore_in_substep(xp);
    end_substep(x, v, h);
    // Continued only where nothing changes the iterate between its end and the sweeps (the inversion guard's
    // restoration does, and an interrupted substep is rolled back) and sweeps are left below the cap (a capped
    // substep is started over, with the cap's sweeps again).
    m_resumable =
        automatic && !m_ctx.scene.inversion_guard && !m_ctx.interrupted() && m_run.sweeps < m_ctx.scene.max_iterations;
    return sweeps;
}

int BlockDescent::resume(Positions& x, Positions& v, double h)
{
    assert(m_resumable && x.rows() == m_xt.rows());
    // The same substep, from the same start (x = m_xt and v, as the caller gives them back), continued from where
    // its sweeps stopped: the same inertial target m_y, contacts
    // (gathered at its start), vertices that entered a contact (m_entered), convergence reference (the largest
    // sweep's moves and the moves' history), Chebyshev iterates and coarse factorisation; only the tolerances are
    // tighter (m_tighter). The acceleration m_accel is taken against the start velocity v, as a retake from the
    // start leaves it. A retake from the start swept again from its predictor: the small raptor at 1/60 took 57.6
    // sweeps a step that way, 45.2 continued (docs/simulator.md, "Where a 15 cm step's extra work goes").
    const int sweeps = iterate(h);
    end_substep(x, v, h);
    m_resumable = !m_ctx.interrupted() && m_run.sweeps < m_ctx.scene.max_iterations;
    return sweeps;
}

int BlockDescent::iterate(double h)
{
    double* xp = m_x4.data()->c;
    const bool automatic = m_ctx.scene.iterations <= 0;
    const double rho = acceleration_rho();

    // Automatic: sweep until a sweep's moves (Σ dᵀ H d) are below `convergence` of the largest sweep's of the substep
    // and below energy_tolerance of the scene's energy, or they hardly move at all; at least min_sweeps, at most
    // max_iterations (then the substep is reported unconverged). A fixed `iterations` sweeps that many times.
    const int min_sweeps =
        automatic ? std::min(min_sweeps_automatic, m_ctx.scene.max_iterations) : m_ctx.scene.iterations;
    const int max_sweeps = automatic ? m_ctx.scene.max_iterations : m_ctx.scene.iterations;
    const double tighter = std::pow(0.1, m_tighter);
    const double tol2 = m_ctx.scene.convergence * m_ctx.scene.convergence * tighter;
    // Stop when no vertex moved more than this fraction of its clamp length (a fifth of its object's mean edge).
    const double stop = 5 * m_ctx.scene.sweep_tolerance;
    // A step refined into k times the scene's substeps gives each a k-th of the energy tolerance, so that what a
    // step may leave unconverged does not grow with its refinement (a small stiff body taken in a hundred substeps a
    // step ended its drop with several times its start energy, every substep converged; docs/simulator.md, "Figures
    // behind the code's constants").
    const double refined_share = tighter * std::min(1.0, h * m_ctx.scene.substeps / m_ctx.scene.dt);
    // A continued substep (resume) counts its sweeps on from the first attempt's (the coarse corrections keep their
    // rhythm, the stall test its history, the cap is the substep's): what a retake from the start would have swept.
    int& sweeps = m_run.sweeps;
    const int first_sweep = sweeps;
    double& moved_max = m_run.moved_max;
    m_converged = !automatic;
    bool met_base = false;
    while (sweeps < max_sweeps) {
        if (m_ctx.interrupted()) break; // Ctrl-C: the simulation rolls the step back
        refresh_contacts(xp);
        const Sweep sw = sweep(xp, h);
        ++sweeps;
        if (rho > 0) accelerate(sweeps, rho, m_run.omega, xp);
        if (sw.largest <= stop) break;
        moved_max = std::max(moved_max, sw.moved);
        const double energy_limit = energy_tolerance * refined_share * m_energy_ref;
        const bool small_energy = 0.5 * sw.moved <= energy_limit;
        // A contact or friction that switches between sweeps and corrections can hold the moves in a cycle (seen
        // at 1 m: the same six moves over and over, each far below the energy tolerance): once the moves stop
        // shrinking over a cycle of corrections, more sweeps change nothing.
        constexpr size_t cycle = 2 * sweeps_per_correction;
        m_moved_history.push_back(sw.moved);
        const bool stalled =
            m_moved_history.size() > cycle && sw.moved >= 0.9 * m_moved_history[m_moved_history.size() - 1 - cycle];
        if (automatic && sweeps >= min_sweeps &&
            (((sw.moved <= tol2 * moved_max || stalled) && small_energy) || 0.5 * sw.moved <= 1e-14 * m_energy_ref)) {
            m_converged = true;
            break;
        }
        // Taken again with tighter tolerances (tighten): reaching the cap after meeting the scene's own counts as
        // converged.
        met_base = m_tighter > 0 && (sw.moved <= tol2 / tighter * moved_max || stalled) &&
                   0.5 * sw.moved <= energy_limit / tighter;
        if (m_run.use_coarse && sweeps % sweeps_per_correction == 0 && sweeps < max_sweeps) {
            m_run.use_coarse = coarse_correction(xp, h, m_run.first_coarse) >= 0;
            m_run.first_coarse = false;
        }
    }
    if (!m_converged && met_base) m_converged = true;
    return sweeps - first_sweep;
}

void BlockDescent::end_substep(Positions& x, Positions& v, double h)
{
    const Model& model = m_ctx.model;
    const size_t un = m_x4.size();
    const double* xp = m_x4.data()->c;
    const double inv_h = 1.0 / h;
    for (size_t i = 0; i < un; ++i) {
        if (model.fixed[i]) continue;
        for (int r = 0; r < 3; ++r) {
            const double v_old = v(static_cast<Index>(i), r);
            x(static_cast<Index>(i), r) = xp[4 * i + static_cast<size_t>(r)];
            v(static_cast<Index>(i), r) = (x(static_cast<Index>(i), r) - m_xt(static_cast<Index>(i), r)) * inv_h;
            m_accel[3 * i + static_cast<size_t>(r)] = (v(static_cast<Index>(i), r) - v_old) * inv_h;
        }
    }
}

void BlockDescent::finish_step(Positions& x, const std::vector<std::int32_t>& inverted)
{
    // With the guard each substep ended with restore_in_substep (its slivers may stay inverted: turned back here
    // too, its pressed struts at 1/60 ended with a non-sliver inverted).
    m_resumable = false;
    if (inverted.empty() || m_ctx.scene.inversion_guard) return;
    // Positions only: the velocities keep what the step gave them, so the moves add no kinetic energy.
    const size_t un = static_cast<size_t>(x.rows());
    m_x4.resize(un);
    for (size_t i = 0; i < un; ++i)
        m_x4[i] = {x(static_cast<Index>(i), 0), x(static_cast<Index>(i), 1), x(static_cast<Index>(i), 2), 0.0};
    m_inversions.restore_after_step(m_x4.data()->c, inverted);
    for (size_t i = 0; i < un; ++i)
        for (int r = 0; r < 3; ++r)
            x(static_cast<Index>(i), r) = m_x4[i].c[r];
}

} // namespace

std::unique_ptr<StepIntegrator> make_block_descent(const StepContext& ctx)
{
    return std::make_unique<BlockDescent>(ctx);
}

} // namespace tethash::sim
