// The running simulation: the fixed set-up (objects, model, contacts, integrator) built once, then per step and
// substep detection → penetration depth → contact response → integration → blow-up checks.
#include "tethash/sim/simulation.hpp"

#include "contact_response.hpp"
#include "failure.hpp"
#include "integrator.hpp"
#include "objects.hpp"
#include "obstacles.hpp"
#include "sweep_check.hpp"
#include "thread_choice.hpp"

#include "core/timing.hpp"

#include "tethash/error.hpp"
#include "tethash/sim/quality.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

namespace tethash::sim {

namespace {

using tethash::detail::Clock;
using tethash::detail::ms_since;

/// Explicit stability limit of the model with, per vertex, the stiffer of its stiffest possible contact and the
/// ground (with their damping). A contact's effective mass is at most the vertex's own.
double estimate_dt_limit(const Scene& scene, const Model& model, const TetMesh& mesh, const ContactResponse& contacts)
{
    const Index n = mesh.num_vertices();
    std::vector<double> extra_k(static_cast<size_t>(n), 0.0), extra_c(static_cast<size_t>(n), 0.0);
    // Per object the partner giving the stiffest contact (the stiffness grows with the effective mass in the same
    // way for every partner, so one partner per object serves all its vertices); -1: it touches nothing.
    const Index nobj = static_cast<Index>(scene.objects.size());
    std::vector<Index> partner(static_cast<size_t>(nobj), -1);
    if (contacts.enabled())
        for (Index a = 0; a < nobj; ++a)
            for (Index b = 0; b < nobj; ++b)
                if ((a != b || scene.objects[static_cast<size_t>(a)].self_collision) &&
                    !(scene.objects[static_cast<size_t>(a)].is_static &&
                      scene.objects[static_cast<size_t>(b)].is_static)) {
                    Index& best = partner[static_cast<size_t>(a)];
                    if (best < 0 || contacts.pair_stiffness(a, b, 1.0) > contacts.pair_stiffness(a, best, 1.0))
                        best = b;
                }
    for (Index i = 0; i < n; ++i) {
        const size_t u = static_cast<size_t>(i);
        const Index a = model.vertex_object[u];
        const Index b = static_cast<size_t>(a) < partner.size() ? partner[static_cast<size_t>(a)] : -1;
        double k = b >= 0 ? contacts.pair_stiffness(a, b, model.mass[u]) : 0.0;
        if (model.ground.enabled) k = std::max(k, model.ground_k_at(i));
        extra_k[u] = k;
        extra_c[u] =
            scene.contact.damping > 0 && !model.ground.enabled ? scene.contact.damping : std::sqrt(k * model.mass[u]);
    }
    return model.explicit_dt_limit(mesh.positions, extra_k, extra_c);
}

} // namespace

class SimulationImpl {
  public:
    Scene scene; // without its collider = "bsp" objects (in obstacles)
    SceneObstacles obstacles;
    SceneObjects objects; // objects.mesh.positions = current positions
    Positions v;
    Model model;
    ContactResponse contacts;
    std::unique_ptr<StepIntegrator> integrator;
    FailureCheck failure;
    StepStats stats;
    std::vector<std::string> warnings;
    std::int64_t steps_done = 0;
    double t = 0;
    double dt_limit = std::numeric_limits<double>::infinity();
    Positions x_save, v_save;                // last good step (rollback on failure)
    std::int64_t inverted = 0;               // inverted dynamic tets after the last step
    std::vector<std::int32_t> inverted_tets; // which (scratch of each step)
    Model::TetScan tet_scan;                 // the step's pass over the tets (with its energy)
    int refined = 1;                         // substeps of the last refined step, kept until refined_until
    int auto_max_substeps = 8;               // vbd's automatic max_substeps (set_auto_max_substeps)
    double refined_until = 0;
    RunHealth health;
    double volume0 = 0;        // volume of the dynamic tets at the start
    std::vector<double> sizes; // per object: the longest extent of its box at the start
    const volatile std::sig_atomic_t* interrupt = nullptr;
    // threads = 0: the count chosen step by step (thread_choice.hpp); `threads_now` the count set in the stages.
    detail::ThreadChoice thread_choice;
    bool choose_threads = false;
    int threads_now = 1;
    // Scene::crossing_check: the (vertex, object) pairs the contacts of the last update watched (penetrations and
    // margin contacts, sorted), and whether the contacts are those of the state the last step ended in (for a substep
    // of h_end), which the next step's first substep then reuses. Only step() changes the state: it clears the flag
    // wherever it takes the state back (a refinement, a failure) after that update.
    std::vector<std::pair<Index, Index>> watched;
    bool contacts_at_end = false;
    double h_end = 0;
    // Scene::continuous_check: the sweep of each substep, and the substep's start positions.
    SweepCheck sweep;
    Positions x_substep;

    explicit SimulationImpl(const Scene& s);
    std::string object_name(size_t k) const
    {
        return scene.objects[k].name.empty() ? "object " + std::to_string(k) : "'" + scene.objects[k].name + "'";
    }
    /// Set-up warnings: sizes that look like a wrong unit or scale, objects below the ground or inside others.
    void check_placement();
    /// The health figures that do not change during the run.
    void start_health();
    /// Throws Error for a dt far beyond the scene's own time scale.
    void check_time_step();
    /// vbd's automatic max_substeps from the stiffest object's ω h.
    void set_auto_max_substeps();
    /// The substeps (scene.substeps times a power of two, at most `most`) in which no two objects whose swept boxes
    /// meet during the step close by more than approach_reach of their mean edge per substep.
    int approach_substeps(int most) const;
    /// Contacts at positions x for a substep h; the step's end update is reused when nothing moved since.
    void update_contacts(const Positions& x, double h, StepStats& st);
    /// Whether a vertex is inside a tet of an object that the last watch did not watch it against (a far part
    /// entered within a substep unseen); then sets `watched` to what the current contacts watch.
    bool entered_unseen();
    TetMesh& mesh() { return objects.mesh; }
    const TetMesh& mesh() const { return objects.mesh; }
    void automatic_ground();
};

SimulationImpl::SimulationImpl(const Scene& s) : scene(s)
{
    if (!(scene.dt > 0) || !std::isfinite(scene.dt))
        throw Error("dt must be positive, found " + short_number(scene.dt));
    if (scene.substeps < 1) throw Error("substeps must be ≥ 1, found " + std::to_string(scene.substeps));
    if (scene.max_substeps < 0)
        throw Error("max_substeps must be ≥ 1 (or 0: automatic), found " + std::to_string(scene.max_substeps));
    if (scene.iterations < 0)
        throw Error("iterations must be ≥ 1 (or 0: automatic), found " + std::to_string(scene.iterations));
    obstacles = take_obstacles(scene);
    objects = load_objects(scene);
    const Index n = mesh().num_vertices();
    model = Model::build(mesh(), objects.materials, objects.is_static);
    model.gravity = scene.gravity;
    for (std::string& w : apply_pins(scene, objects, model))
        warnings.push_back(std::move(w));

    v = Positions::Zero(n, 3);
    for (size_t k = 0; k < scene.objects.size(); ++k)
        for (Index i = objects.vertices[k].first; i < objects.vertices[k].first + objects.vertices[k].second; ++i)
            if (!model.fixed[static_cast<size_t>(i)]) v.row(i) = scene.objects[k].velocity.transpose();

    contacts.setup(scene, mesh(), model, objects.options, &obstacles);
    model.ground = scene.ground;
    automatic_ground();

    dt_limit = estimate_dt_limit(scene, model, mesh(), contacts);
    const double h = scene.dt / scene.substeps;
    if (scene.integrator == Integrator::symplectic_euler && h > dt_limit)
        warnings.push_back("time step " + short_number(h) + " s (dt/substeps) exceeds the explicit stability limit ≈ " +
                           short_number(dt_limit) +
                           " s estimated from the largest stiffness/mass ratio; symplectic_euler "
                           "will likely blow up: use more substeps, a smaller dt, or vbd");

    StepStats first;
    contacts.update(mesh().positions, v, scene.dt / scene.substeps, first);
    failure.setup(model, mesh().positions, v, contacts.energy());
    inverted = find_inverted_tets(model, mesh().positions, inverted_tets, &volume0);
    integrator = make_integrator(StepContext{scene, mesh(), model, contacts, &interrupt});
    for (const auto& [first, count] : objects.vertices) {
        const auto box = bounding_box(mesh().positions.middleRows(first, count));
        sizes.push_back(count > 0 ? (box.second - box.first).maxCoeff() : 0.0);
    }
    check_placement();
    start_health();
    check_time_step();
    set_auto_max_substeps();
    threads_now = scene.detect.threads > 0 ? scene.detect.threads : detail::ThreadChoice::every_core();
    choose_threads = scene.detect.threads == 0 && threads_now > 1;
    if (scene.continuous_check && contacts.enabled())
        sweep.setup(mesh(), model, objects.options, objects.vertices, ContactResponse::local_contact_edges,
                    scene.contact.margin);
    if (choose_threads) thread_choice = detail::ThreadChoice(threads_now);
}

void SimulationImpl::set_auto_max_substeps()
{
    // vbd refines a step whose substeps do not converge (or invert tets, or blow up) into up to 8 × substeps, and
    // more for a stiff material at a long step: the sweeps and the coarse space converge while ω h (ω the material's
    // frequency at the mean edge, h the substep) stays within a few hundred, and a young 1e9 body of 5 cm at 1/60 has
    // ω h ≈ 5,000. The cap lets the refined substep reach ω h ≈ stiff_omega_h: each doubling is paid only by the steps
    // that need it.
    constexpr double stiff_omega_h = 100;
    constexpr int most = 256;
    double omega = 0;
    for (size_t o = 0; o < model.object_frequency_sq.size(); ++o)
        omega = std::max(omega, std::sqrt(model.object_frequency_sq[o]));
    const double omega_h = omega * scene.dt / scene.substeps;
    int factor = 1;
    while (factor < most / 8 && omega_h / factor > stiff_omega_h)
        factor *= 2;
    auto_max_substeps = 8 * factor * scene.substeps;
}

/// A step may gain this fraction of the energy the scene has to spend (RunHealth::energy_scale) before it is taken
/// again with tighter tolerances.
constexpr double energy_step_slack = 1e-3;

/// The continuous check takes a step again in more substeps at most this many times (each doubling them, within
/// max_substeps): a crumpling body, whose far parts meet in most substeps however short, could otherwise be retaken
/// up to max_substeps at every step (256 × the substeps for a stiff material at a long step). Past the cap the
/// substeps are still swept, and an impact left is reported (StepStats::continuous_unresolved,
/// RunHealth::continuous_unresolved_steps).
constexpr int max_sweep_retakes = 2;

int SimulationImpl::approach_substeps(int most) const
{
    // Contacts are found at the start of each substep, and margin and speculative contacts reach a quarter of a
    // mean edge ahead: two objects that close by more than that within a substep can enter each other deeply before
    // a contact sees them, and a penalty pushing out of a deep penetration puts energy in (small stiff bodies thrown
    // into each other flew apart with hundreds of times the scene's energy; docs/simulator.md, "At the sizes users
    // have").
    // Per object: its box and its rigid motion (the velocity of its centre of mass, and its rotation times its
    // radius); objects whose boxes, grown by what they may move in the step, meet get substeps in which their rigid
    // motions close by at most the reach. (Their vibrations are left out: counted as a speed of approach, a soft
    // body's kept the substeps of its impact as long as it touched the other.)
    constexpr double approach_reach = 0.25;
    const size_t nobj = objects.vertices.size();
    if (nobj < 2 || scene.integrator != Integrator::vbd) return scene.substeps;
    const Positions& x = mesh().positions;
    struct Body {
        Eigen::Vector3d lo, hi, mean_v;
        double spread = 0, edge = 0;
        size_t k = 0;
    };
    std::vector<Body> bodies;
    const double g = model.gravity.norm();
    for (size_t k = 0; k < nobj; ++k) {
        const auto [first, count] = objects.vertices[k];
        if (objects.is_static[k] || count == 0 || !(model.object_mean_edge[k] > 0)) continue;
        Body b;
        b.k = k;
        b.edge = model.object_mean_edge[k];
        b.lo = Eigen::Vector3d::Constant(INFINITY);
        b.hi = -b.lo;
        double mass = 0;
        Eigen::Vector3d centre = Eigen::Vector3d::Zero(), momentum = Eigen::Vector3d::Zero();
        for (Index i = first; i < first + count; ++i) {
            const double m = model.mass[static_cast<size_t>(i)];
            b.lo = b.lo.cwiseMin(x.row(i).transpose());
            b.hi = b.hi.cwiseMax(x.row(i).transpose());
            mass += m;
            centre += m * x.row(i).transpose();
            momentum += m * v.row(i).transpose();
        }
        if (!(mass > 0)) continue;
        centre /= mass;
        b.mean_v = momentum / mass;
        Eigen::Vector3d angular = Eigen::Vector3d::Zero();
        Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
        double radius = 0;
        for (Index i = first; i < first + count; ++i) {
            const double m = model.mass[static_cast<size_t>(i)];
            const Eigen::Vector3d r = x.row(i).transpose() - centre;
            angular += m * r.cross(v.row(i).transpose() - b.mean_v);
            inertia += m * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
            radius = std::max(radius, r.norm());
        }
        const Eigen::Vector3d omega = inertia.ldlt().solve(angular);
        b.spread = omega.allFinite() ? omega.norm() * radius : 0.0;
        const double reach = (b.mean_v.norm() + b.spread) * scene.dt + g * scene.dt * scene.dt;
        b.lo.array() -= reach;
        b.hi.array() += reach;
        bodies.push_back(b);
    }
    // Sweep and prune along x: pairs whose grown boxes meet.
    std::sort(bodies.begin(), bodies.end(),
              [](const Body& a, const Body& b) { return a.lo.x() < b.lo.x() || (a.lo.x() == b.lo.x() && a.k < b.k); });
    double closing = 0; // largest closing distance per step over reach, over the pairs that meet
    for (size_t a = 0; a < bodies.size(); ++a)
        for (size_t b = a + 1; b < bodies.size() && bodies[b].lo.x() <= bodies[a].hi.x(); ++b) {
            const Body &p = bodies[a], &q = bodies[b];
            if ((p.lo.array() > q.hi.array()).any() || (q.lo.array() > p.hi.array()).any()) continue;
            const double speed = (p.mean_v - q.mean_v).norm() + p.spread + q.spread;
            closing = std::max(closing, speed * scene.dt / (approach_reach * std::min(p.edge, q.edge)));
        }
    int substeps = scene.substeps;
    while (substeps < most && closing > substeps)
        substeps *= 2;
    return std::min(substeps, most);
}

void SimulationImpl::update_contacts(const Positions& x, double h, StepStats& st)
{
    if (contacts_at_end && h == h_end) {
        contacts_at_end = false;
        return;
    }
    contacts_at_end = false;
    contacts.update(x, v, h, st);
}

bool SimulationImpl::entered_unseen()
{
    bool unseen = false;
    for (const Contact& c : contacts.contacts())
        if (c.tet >= 0 && !std::binary_search(watched.begin(), watched.end(), std::pair(c.vertex, c.tet_object))) {
            unseen = true;
            break;
        }
    watched.clear();
    for (const Contact& c : contacts.contacts())
        if (c.tet >= 0) watched.emplace_back(c.vertex, c.tet_object);
    for (const Contact& c : contacts.margin_contacts())
        watched.emplace_back(c.vertex, c.tet_object);
    std::sort(watched.begin(), watched.end());
    return unseen;
}

void SimulationImpl::check_time_step()
{
    // A step far longer than the scene's own time: the smallest dynamic object falls its own size under gravity in
    // sqrt(2 L / g) (or crosses it at its speed). Ten times that is refused: such a step cannot show the motion it
    // skips, and its iterations would only converge at great cost (a user's dt = 1e9 asked for a million sweeps).
    const double g = model.gravity.norm();
    double shortest = INFINITY, size_of = 0;
    for (size_t k = 0; k < objects.vertices.size(); ++k) {
        const auto [first, count] = objects.vertices[k];
        if (objects.is_static[k] || count == 0) continue;
        const double size = sizes[k];
        double speed = 0;
        for (Index i = first; i < first + count; ++i)
            speed = std::max(speed, v.row(i).norm());
        double t_own = INFINITY;
        if (g > 0) t_own = std::sqrt(2 * size / g);
        if (speed > 0) t_own = std::min(t_own, size / speed);
        if (t_own < shortest) {
            shortest = t_own;
            size_of = size;
        }
    }
    if (std::isfinite(shortest) && shortest > 0 && scene.dt > 10 * shortest)
        throw Error("dt " + short_number(scene.dt) + " s is far beyond what this scene can show: its smallest moving " +
                    "object (" + short_number(size_of) + " m) falls or moves its own size in " +
                    short_number(shortest) + " s, and a step of more than 10 times that (" +
                    short_number(10 * shortest) + " s) is refused; use a dt of at most that, or substeps");
}

void SimulationImpl::check_placement()
{
    const Positions& x = mesh().positions;
    const Ground& g = model.ground;
    const size_t nobj = objects.vertices.size();
    std::vector<std::int64_t> inside(nobj * nobj, 0);
    for (const Contact& c : contacts.contacts())
        if (c.vertex_object != c.tet_object && static_cast<size_t>(c.vertex_object) < nobj &&
            static_cast<size_t>(c.tet_object) < nobj)
            ++inside[static_cast<size_t>(c.vertex_object) * nobj + static_cast<size_t>(c.tet_object)];
    for (size_t k = 0; k < nobj; ++k) {
        const auto [first, count] = objects.vertices[k];
        if (count == 0) continue;
        const double size = sizes[k];
        if (size > 20.0)
            warnings.push_back(object_name(k) + " is " + short_number(size) +
                               " m across: if its mesh is in millimetres, give it scale = 0.001 (scene sizes are in "
                               "metres; the material's stiffness and the contacts are set for them)");
        else if (size < 5e-3)
            warnings.push_back(object_name(k) + " is " + short_number(1e3 * size) +
                               " mm across: check its scale (scene sizes are in metres)");
        if (g.enabled && !objects.is_static[k]) {
            double deepest = 0;
            for (Index i = first; i < first + count; ++i)
                deepest = std::max(deepest, g.height - g.normal.dot(x.row(i).transpose()));
            if (deepest > 1e-9 * std::max(1.0, size))
                warnings.push_back(object_name(k) + " starts " + short_number(deepest) +
                                   " m below the ground: the ground pushes it out at the first step");
        }
        for (size_t o = 0; o < nobj; ++o)
            if (const std::int64_t n = inside[k * nobj + o]; n > 0)
                warnings.push_back(object_name(k) + " starts with " + std::to_string(n) +
                                   (n == 1 ? " vertex inside " : " vertices inside ") + object_name(o) +
                                   ": the contacts push them apart at the first step");
    }
}

void SimulationImpl::start_health()
{
    health = RunHealth{};
    const Energy e = model.energy(mesh().positions, v);
    health.energy_start = e.total() + contacts.energy();
    health.energy_end = health.energy_start;
    health.energy_scale = failure.energy_available();
    health.tets = static_cast<std::int64_t>(model.volumes.tets.rows());
    health.inverted_end = inverted;
    // What each object's weight squeezes: density · g · height / young (a strain).
    const double gn = model.gravity.norm();
    for (size_t k = 0; k < objects.vertices.size(); ++k) {
        const auto [first, count] = objects.vertices[k];
        if (objects.is_static[k] || count == 0 || !(gn > 0)) continue;
        double lo = INFINITY, hi = -INFINITY;
        for (Index i = first; i < first + count; ++i) {
            const double z = -model.gravity.dot(mesh().positions.row(i).transpose()) / gn;
            lo = std::min(lo, z);
            hi = std::max(hi, z);
        }
        const Material& m = objects.materials[k];
        const double young = m.stiffness > 0 && k < model.object_mean_edge.size() && model.object_mean_edge[k] > 0
                                 ? m.stiffness / model.object_mean_edge[k]
                                 : m.young;
        if (young > 0) health.weight_strain = std::max(health.weight_strain, m.density * gn * (hi - lo) / young);
    }
}

void SimulationImpl::automatic_ground()
{
    // Automatic ground stiffness per vertex = a contact of its object with itself whose effective mass is the
    // vertex's (contact_rate_factor ω² m), automatic damping per vertex sqrt(k m) (half critical).
    const Index n = mesh().num_vertices();
    if (!model.ground.enabled || (model.ground.stiffness > 0 && model.ground.damping > 0)) return;
    model.ground_k.assign(static_cast<size_t>(n), model.ground.stiffness);
    model.ground_c.assign(static_cast<size_t>(n), model.ground.damping);
    for (Index i = 0; i < n; ++i) {
        const Index o = model.vertex_object[static_cast<size_t>(i)];
        double& k = model.ground_k[static_cast<size_t>(i)];
        if (!(k > 0)) k = contacts.pair_stiffness(o, o, model.mass[static_cast<size_t>(i)]);
        double& c = model.ground_c[static_cast<size_t>(i)];
        if (!(c > 0)) c = std::sqrt(k * model.mass[static_cast<size_t>(i)]);
    }
    if (model.ground.stiffness > 0) model.ground_k.clear();
    if (model.ground.damping > 0) model.ground_c.clear();
}

// ---- Simulation ----------------------------------------------------------------------------------

Simulation::Simulation(const Scene& scene) : m_impl(std::make_unique<SimulationImpl>(scene)) {}
Simulation::~Simulation() = default;
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;

void Simulation::step()
{
    SimulationImpl& s = *m_impl;
    const auto t_step = Clock::now();
    if (s.choose_threads && s.thread_choice.threads() != s.threads_now) {
        s.threads_now = s.thread_choice.threads();
        // Every core as the scene asked (0: the detector keeps one thread for small scenes), or one.
        s.contacts.set_threads(s.threads_now == detail::ThreadChoice::every_core() ? 0 : s.threads_now);
        s.integrator->set_threads(s.threads_now);
    }
    Positions& x = s.mesh().positions;
    s.x_save = x;
    s.v_save = s.v;
    StepStats st;
    const std::int64_t step_no = s.steps_done + 1;
    int substeps = s.scene.substeps;
    int sub = 0;
    auto fail = [&](const std::string& what, bool with_cause = true) {
        s.contacts_at_end = false;
        x = s.x_save;
        s.v = s.v_save;
        const double h = s.scene.dt / substeps;
        const std::string where = substeps > 1 && sub < substeps
                                      ? ", substep " + std::to_string(sub + 1) + "/" + std::to_string(substeps)
                                      : std::string();
        throw RunFailure("simulation " + std::string(with_cause ? "blew up" : "failed") + " at step " +
                         std::to_string(step_no) + where +
                         " (t = " + short_number(s.t + (sub < substeps ? sub + 1 : substeps) * h) + " s): " + what +
                         (with_cause ? "; likely cause: " + s.failure.likely_cause(s.scene, h, s.dt_limit, s.contacts)
                                     : std::string()));
    };
    // A step that leaves more than 1 % of the tets inverted, and more than it started with, is taken again in
    // twice as many substeps, up to max_substeps (a step that blows up or whose energy explodes likewise): the time
    // step a user picks stays the frame step, and the work grows only where the material or a contact needs it. A
    // refined step count is kept for 0.05 s of simulated time, then halved, so a body that needs it does not pay for a
    // failed attempt every step. (A lower threshold also refines the transient inversions of impacts that recover by
    // themselves, at a high cost and with no fewer inverted tets at the end; docs/simulator.md.)
    const int max_substeps = std::max(substeps, s.scene.max_substeps > 0                ? s.scene.max_substeps
                                                : s.scene.integrator == Integrator::vbd ? s.auto_max_substeps
                                                                                        : substeps);
    if (s.refined > substeps && s.t >= s.refined_until) {
        s.refined /= 2;
        s.refined_until = s.t + 0.05;
    }
    substeps = std::min(max_substeps, std::max(substeps, s.refined));
    // Objects that approach each other fast get the substeps that let their contacts see them coming (not counted
    // as refined: the step is not taken again).
    const int approach = s.approach_substeps(max_substeps);
    substeps = std::max(substeps, approach);
    const std::int64_t allowed = std::max(s.inverted, static_cast<std::int64_t>(s.model.volumes.tets.rows()) / 100);
    // Back to the step's start with twice the substeps, while max_substeps allows.
    const bool sweeping = s.scene.continuous_check && s.contacts.enabled();
    auto refine = [&] {
        if (substeps * 2 > max_substeps) return false;
        s.contacts_at_end = false;
        x = s.x_save;
        s.v = s.v_save;
        substeps *= 2;
        st.unconverged = 0; // the attempt's own; its iterations and times stay counted
        st.continuous_unresolved = 0;
        return true;
    };
    double energy_now = 0, volume_now = 0;
    // The step's one substep is continued rather than taken again from the step's start (a retake for energy).
    bool resuming = false;
    for (;;) {
        const double h = s.scene.dt / substeps;
        std::string bad;
        bool crossed = false, swept = false;
        for (sub = 0; sub < substeps; ++sub) {
            // A continued substep keeps its contacts, watched pairs and start (x_substep).
            if (!resuming) {
                try {
                    s.update_contacts(x, h, st);
                } catch (const Error& e) {
                    // The input was checked at construction: a detector error now comes from the state (a vertex
                    // flung far away, a tet stretched over millions of cells), i.e. from a diverging run.
                    bad = std::string("collision detection failed (") + e.what() + ")";
                    break;
                }
                // A far part entered within the last substep, unseen by its contacts: the step again in more
                // substeps. (entered_unseen also refreshes the watched pairs, which the sweep reads.)
                const bool unseen = (s.scene.crossing_check || sweeping) && s.entered_unseen();
                if (unseen && s.scene.crossing_check && sub > 0 && substeps * 2 <= max_substeps) {
                    crossed = true;
                    break;
                }
                if (sweeping) s.x_substep = x;
            }
            const auto t0 = Clock::now();
            st.solver_iterations += resuming ? s.integrator->resume(x, s.v, h) : s.integrator->substep(x, s.v, h);
            resuming = false;
            if (!s.integrator->converged()) ++st.unconverged;
            st.ms_integrate += ms_since(t0);
            if (s.interrupt && *s.interrupt) {
                x = s.x_save;
                s.v = s.v_save;
                throw Interrupted("interrupted during step " + std::to_string(step_no) + " (t = " + short_number(s.t) +
                                  " s); the state is that of the step's start");
            }
            bad = s.failure.check_substep(s.model, x, s.v, s.t + (sub + 1) * h);
            if (!bad.empty()) break;
            // A far pair met within the substep, unwatched (passing through, or an edge through a face): the step
            // again in more substeps, within the sweep's cap; past it (once the sweep has retaken this step) the
            // substeps are still swept until one is found that no retake may remove, and the step says so.
            const bool may_retake = st.continuous_crossings < max_sweep_retakes && substeps * 2 <= max_substeps;
            if (sweeping && st.continuous_unresolved == 0 && (may_retake || st.continuous_crossings > 0)) {
                const auto t1 = Clock::now();
                const bool met = s.sweep.crossed(s.x_substep, x, s.watched, s.threads_now);
                st.ms_continuous += ms_since(t1);
                if (met && may_retake) {
                    crossed = swept = true;
                    break;
                }
                if (met) st.continuous_unresolved = 1;
            }
        }
        if (crossed && refine()) {
            ++st.crossings;
            if (swept) ++st.continuous_crossings;
            continue;
        }
        // The energy, and in the same pass over the tets the inverted ones and the volume (read below).
        if (bad.empty()) {
            const Energy e = s.model.energy(x, s.v, s.threads_now, &s.tet_scan);
            bad = s.failure.check_energy(e.internal() + s.contacts.energy());
            energy_now = e.total() + s.contacts.energy();
        }
        if (!bad.empty()) {
            if (refine()) continue;
            fail(bad);
        }
        // A passive scene's step cannot gain energy: one that did stopped its iterations short (slow convergence
        // where contacts switch: a stiff body's bounce) and is taken again with tighter tolerances, then, if it still
        // gains, in more substeps (a small sheet falling over at 1/60 folds onto itself faster than its contacts see).
        // A step of one substep continues its iterations from where they stopped (Scene::resume_retakes); one of
        // several starts over.
        if (energy_now > s.health.energy_end + energy_step_slack * s.health.energy_scale) {
            if (s.integrator->tighten()) {
                x = s.x_save;
                s.v = s.v_save;
                resuming = substeps == 1 && s.scene.resume_retakes && s.integrator->resumable();
                st.unconverged = 0;
                ++st.tightened;
                continue;
            }
            // Not with the inversion guard: the corners it holds back are not the step's minimum, and its runs keep
            // single substeps (P1's guarded drop at 1/60 gains a little where its struts are held).
            if (!s.scene.inversion_guard && refine()) {
                s.integrator->relax();
                continue;
            }
        }
        s.inverted_tets.swap(s.tet_scan.inverted);
        s.inverted = static_cast<std::int64_t>(s.inverted_tets.size());
        volume_now = s.tet_scan.volume;
        if (s.inverted > allowed && refine()) continue;
        // A substep whose iterations reached their cap is a step too long for them to converge in (an impact of a
        // stiff body, which can gain the scene a tenth of its energy in one such substep; docs/simulator.md): taken
        // again in more substeps, like a blow-up.
        if (st.unconverged > 0 && refine()) continue;
        // vbd turns back what the step left inverted (positions only); the count above, which the refinement and
        // the crumple check read, is the step's own.
        s.integrator->finish_step(x, s.inverted_tets);
        // The step's end as it stays, detected for the crossing check (and reused by the next step's first substep).
        if (s.scene.crossing_check) {
            try {
                s.contacts.update(x, s.v, h, st);
            } catch (const Error& e) {
                if (refine()) continue;
                fail(std::string("collision detection failed (") + e.what() + ")");
            }
            s.contacts_at_end = true;
            s.h_end = h;
            if (s.entered_unseen() && refine()) {
                ++st.crossings;
                continue;
            }
        }
        break;
    }
    s.integrator->relax();
    if (substeps > s.refined && substeps > approach) {
        s.refined = substeps;
        s.refined_until = s.t + 0.05;
    }
    st.substeps = substeps;
    const std::string crumpled =
        s.failure.check_inverted(s.model, s.scene, s.inverted, s.scene.dt / substeps, s.t + s.scene.dt, s.dt_limit);
    if (!crumpled.empty()) fail(crumpled, false);
    st.contacts = static_cast<std::int64_t>(s.contacts.contacts().size());
    st.ignored_local = s.contacts.ignored_local();
    double sum = 0;
    for (const Contact& c : s.contacts.contacts()) {
        const double d = c.depth > 0 ? c.depth : 0.0;
        st.max_depth = std::max(st.max_depth, d);
        sum += d;
    }
    st.mean_depth = st.contacts == 0 ? 0.0 : sum / static_cast<double>(st.contacts);
    st.threads = s.threads_now;
    st.ms_step = ms_since(t_step);
    if (s.choose_threads) s.thread_choice.record(st.ms_step / substeps);
    s.stats = st;
    RunHealth& hl = s.health;
    ++hl.steps;
    hl.substeps += substeps;
    if (substeps > std::max(s.scene.substeps, approach)) ++hl.refined_steps;
    if (st.crossings > 0) ++hl.crossing_steps;
    hl.continuous_unresolved_steps += st.continuous_unresolved;
    hl.unconverged_substeps += st.unconverged;
    hl.energy_end = energy_now;
    if (hl.energy_scale > 0)
        hl.energy_growth = std::max(hl.energy_growth, (energy_now - hl.energy_start) / hl.energy_scale);
    if (s.volume0 > 0) {
        hl.volume_end = volume_now / s.volume0;
        hl.volume_ratio = std::min(hl.volume_ratio, hl.volume_end);
    }
    hl.inverted_end = s.inverted;
    ++s.steps_done;
    s.t += s.scene.dt;
}

const Scene& Simulation::scene() const
{
    return m_impl->scene;
}
std::int64_t Simulation::step_index() const
{
    return m_impl->steps_done;
}
double Simulation::time() const
{
    return m_impl->t;
}
const TetMesh& Simulation::mesh() const
{
    return m_impl->mesh();
}
const Positions& Simulation::positions() const
{
    return m_impl->mesh().positions;
}
const Positions& Simulation::velocities() const
{
    return m_impl->v;
}
const Model& Simulation::model() const
{
    return m_impl->model;
}
std::pair<Index, Index> Simulation::object_vertices(int k) const
{
    return m_impl->objects.vertices.at(static_cast<size_t>(k));
}
std::pair<Index, Index> Simulation::object_tets(int k) const
{
    return m_impl->objects.tets.at(static_cast<size_t>(k));
}

Energy Simulation::energy() const
{
    Energy e = m_impl->model.energy(m_impl->mesh().positions, m_impl->v);
    e.contact = m_impl->contacts.energy();
    return e;
}

Eigen::Vector3d Simulation::momentum() const
{
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (Index i = 0; i < m_impl->mesh().num_vertices(); ++i)
        if (!m_impl->model.fixed[static_cast<size_t>(i)])
            p += m_impl->model.mass[static_cast<size_t>(i)] * m_impl->v.row(i).transpose();
    return p;
}

const std::vector<Contact>& Simulation::contacts() const
{
    return m_impl->contacts.contacts();
}

const std::vector<Contact>& Simulation::margin_contacts() const
{
    return m_impl->contacts.margin_contacts();
}

double Simulation::max_penetration() const
{
    return m_impl->contacts.max_depth();
}

double Simulation::mean_penetration() const
{
    const std::vector<Contact>& cs = m_impl->contacts.contacts();
    if (cs.empty()) return 0;
    double s = 0;
    for (const Contact& c : cs)
        s += c.depth > 0 ? c.depth : 0.0;
    return s / static_cast<double>(cs.size());
}

std::vector<double> Simulation::exact_depths() const
{
    return m_impl->contacts.exact_depths(m_impl->mesh().positions);
}

void Simulation::refresh_contacts()
{
    StepStats st;
    m_impl->contacts_at_end = false;
    m_impl->contacts.update(m_impl->mesh().positions, m_impl->v, m_impl->scene.dt / m_impl->scene.substeps, st);
}

double Simulation::contact_stiffness(int a, int b, double effective_mass) const
{
    const int n = static_cast<int>(m_impl->scene.objects.size());
    if (a < 0 || a >= n || b < 0 || b >= n)
        throw Error("contact_stiffness: object index out of range (" + std::to_string(a) + ", " + std::to_string(b) +
                    "; " + std::to_string(n) + " objects)");
    if (!(effective_mass >= 0) || !std::isfinite(effective_mass))
        throw Error("contact_stiffness: effective mass must be finite and ≥ 0, got " + std::to_string(effective_mass));
    return m_impl->contacts.pair_stiffness(a, b, effective_mass);
}

const StepStats& Simulation::last_stats() const
{
    return m_impl->stats;
}
double Simulation::explicit_dt_limit() const
{
    return m_impl->dt_limit;
}
const std::vector<std::string>& Simulation::warnings() const
{
    return m_impl->warnings;
}

std::vector<double> Simulation::object_sizes() const
{
    return m_impl->sizes;
}

const RunHealth& Simulation::health() const
{
    return m_impl->health;
}

void Simulation::set_interrupt_flag(const volatile std::sig_atomic_t* flag)
{
    m_impl->interrupt = flag;
}

std::vector<std::string> RunHealth::problems() const
{
    std::vector<std::string> out;
    auto percent = [](double f) { return short_number(100 * f) + " %"; };
    if (energy_growth > energy_slack)
        out.push_back("the energy rose " + percent(energy_growth) +
                      " of what the scene had to spend above its start (a passive scene must lose energy): the "
                      "steps were not converged; lower `convergence` or dt");
    if (volume_ratio < 1 - volume_slack && weight_strain < volume_slack)
        out.push_back("the bodies lost " + percent(1 - volume_ratio) +
                      " of their volume at the worst step (their weight squeezes them by " + percent(weight_strain) +
                      " only)");
    if (unconverged_substeps > 0)
        out.push_back(std::to_string(unconverged_substeps) + " of " + std::to_string(substeps) +
                      " substeps stopped at max_iterations unconverged: raise max_iterations or lower dt");
    if (refined_steps > 0)
        out.push_back(std::to_string(refined_steps) + " of " + std::to_string(steps) +
                      " steps were taken again in more substeps (tets inverted, a blow-up, iterations unconverged, "
                      "energy gained" +
                      (crossing_steps > 0 ? ", far parts entered unseen in " + std::to_string(crossing_steps) : "") +
                      " at dt): dt is large for the material or the impacts");
    if (continuous_unresolved_steps > 0)
        out.push_back(std::to_string(continuous_unresolved_steps) + " of " + std::to_string(steps) +
                      " steps kept a far pair met unwatched within a substep, the continuous check's retakes at their "
                      "cap (two, or max_substeps): far parts passed into or through each other; lower dt");
    if (tets > 0 && inverted_end * 1000 > tets)
        out.push_back(std::to_string(inverted_end) + " of " + std::to_string(tets) + " tets (" +
                      percent(static_cast<double>(inverted_end) / static_cast<double>(tets)) + ") end inverted");
    return out;
}

StaticSurface Simulation::static_surface() const
{
    const SimulationImpl& s = *m_impl;
    StaticSurface out;
    Index nv = 0, nt = 0;
    for (const meshing::SurfaceMesh& m : s.obstacles.surfaces) {
        nv += static_cast<Index>(m.vertices.rows());
        nt += static_cast<Index>(m.triangles.rows());
    }
    const Ground& g = s.model.ground;
    if (g.enabled) nv += 4, nt += 2;
    out.surface.vertices.resize(nv, 3);
    out.surface.triangles.resize(nt, 3);
    Index v0 = 0, t0 = 0;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (std::size_t k = 0; k < s.obstacles.surfaces.size(); ++k) {
        const meshing::SurfaceMesh& m = s.obstacles.surfaces[k];
        out.surface.vertices.middleRows(v0, m.vertices.rows()) = m.vertices;
        out.surface.triangles.middleRows(t0, m.triangles.rows()) = m.triangles.array() + v0;
        out.triangle_object.insert(out.triangle_object.end(), static_cast<std::size_t>(m.triangles.rows()),
                                   s.obstacles.first_object + static_cast<Index>(k));
        for (Index i = 0; i < m.vertices.rows(); ++i) {
            lo = lo.cwiseMin(m.vertices.row(i).transpose());
            hi = hi.cwiseMax(m.vertices.row(i).transpose());
        }
        v0 += static_cast<Index>(m.vertices.rows());
        t0 += static_cast<Index>(m.triangles.rows());
    }
    if (g.enabled) {
        for (Index i = 0; i < s.mesh().num_vertices(); ++i) {
            lo = lo.cwiseMin(s.mesh().positions.row(i).transpose());
            hi = hi.cwiseMax(s.mesh().positions.row(i).transpose());
        }
        if (!(lo.array() <= hi.array()).all()) lo = hi = Eigen::Vector3d::Zero();
        const Eigen::Vector3d n = g.normal.normalized();
        Eigen::Vector3d centre = 0.5 * (lo + hi);
        centre -= (n.dot(centre) - g.height) * n; // onto the plane n·x = height
        const double half = std::max(0.5, 2 * (hi - lo).norm());
        // Two directions in the plane: e1 orthogonal to n (from the axis least along n), e2 = n × e1.
        Eigen::Index least = 0;
        n.cwiseAbs().minCoeff(&least);
        const Eigen::Vector3d e1 = n.cross(Eigen::Vector3d::Unit(least)).normalized(), e2 = n.cross(e1);
        const double corner[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
        for (int c = 0; c < 4; ++c)
            out.surface.vertices.row(v0 + c) = (centre + half * (corner[c][0] * e1 + corner[c][1] * e2)).transpose();
        // Counter-clockwise seen from the side n points to (e1, e2, n right-handed): the normal is n.
        out.surface.triangles.row(t0) << v0, v0 + 1, v0 + 2;
        out.surface.triangles.row(t0 + 1) << v0, v0 + 2, v0 + 3;
        out.triangle_object.insert(out.triangle_object.end(), 2, -1);
    }
    return out;
}

io::Fields Simulation::output_fields() const
{
    const SimulationImpl& s = *m_impl;
    const Index n = s.mesh().num_vertices();
    auto wanted = [&](const char* name) {
        return std::find(s.scene.output.fields.begin(), s.scene.output.fields.end(), name) !=
               s.scene.output.fields.end();
    };
    io::Fields f;
    if (wanted("velocity")) {
        io::Field fl{"velocity", 3, {}};
        fl.values.assign(s.v.data(), s.v.data() + 3 * n);
        f.point.push_back(std::move(fl));
    }
    if (wanted("contact") || wanted("depth")) {
        std::vector<double> flag(static_cast<size_t>(n), 0.0), depth(static_cast<size_t>(n), 0.0);
        for (const Contact& c : s.contacts.contacts()) {
            flag[static_cast<size_t>(c.vertex)] = 1.0;
            if (c.depth > depth[static_cast<size_t>(c.vertex)]) depth[static_cast<size_t>(c.vertex)] = c.depth;
        }
        if (wanted("contact")) f.point.push_back(io::Field{"contact", 1, std::move(flag)});
        if (wanted("depth")) f.point.push_back(io::Field{"penetration_depth", 1, std::move(depth)});
    }
    if (wanted("object")) {
        io::Field fl{"object", 1, {}};
        for (Index t : s.mesh().tet_object)
            fl.values.push_back(static_cast<double>(t));
        f.cell.push_back(std::move(fl));
    }
    return f;
}

} // namespace tethash::sim
