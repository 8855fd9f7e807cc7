// fem_contact SCENE [--steps N] [--dt H] [--skin F] [--threads T] [--stiffness K] [--trace]
// Runs a scene of the FEM code with tethash as its contact module and checks what must hold:
//   block:   a soft block pressed onto another by its weight and a load on its top face. No far penetration; at
//            vertical rest the contact force on the upper block balances weight plus load; the contact spreads
//            over the face with its pressure highest at the rim (a flat punch); the energy (kinetic + elastic +
//            penalty − work potential) never rises above its start.
//   hairpin: a U-shaped beam clamped along its lower arm, the tip of its upper arm pushed down: the arm bends onto
//            the lower arm (self-contact, one object). No far penetration, the tip stopped by the lower arm,
//            energy bounded.
// Prints the per-Newton-iteration cost of tethash (median over the run); --threads 0 lets the detector use every
// hardware thread (the default here is 1: these meshes are a few hundred tets). Exit status: 0 when every check holds,
// 1 when one fails, 2 on bad arguments.
#include "simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

using fem::Vec;

namespace {

struct Options {
    std::string scene;
    int steps = 0; ///< 0: the scene's own
    double dt = 0;
    double skin = 0.2;
    int threads = 1;      ///< detector threads: 1, the scenes are small (see docs/embedding.md)
    double stiffness = 0; ///< penalty k; 0: the scene's own
    bool trace = false;   ///< a line per step
};

int failures = 0;

void check(bool ok, const char* what, double value, double limit)
{
    std::printf("  %-58s %12.6g (limit %.6g)  %s\n", what, value, limit, ok ? "ok" : "FAILED");
    if (!ok) ++failures;
}

double median(std::vector<double> v)
{
    if (v.empty()) return 0;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
}

/// Runs the steps, tracking the largest exact penetration and the energy; prints the Newton cost.
struct RunResult {
    double max_exact_depth = 0, max_energy_rise = 0, energy_start = 0, energy_end = 0;
    int max_self_contacts = 0;
    double max_residual = 0; ///< largest relative Newton residual left at the end of a step
};

RunResult run(fem::Simulation& sim, int steps, const char* name, bool trace)
{
    RunResult r;
    r.energy_start = sim.energy();
    double peak = r.energy_start;
    int iterations = 0, worst = 0, unconverged = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (int s = 0; s < steps; ++s) {
        const int it = sim.step();
        iterations += it;
        worst = std::max(worst, it);
        if (!sim.converged()) ++unconverged;
        r.max_residual = std::max(r.max_residual, sim.residual());
        for (double d : sim.exact_depths())
            r.max_exact_depth = std::max(r.max_exact_depth, d);
        peak = std::max(peak, sim.energy());
        if (trace)
            std::printf("step %d it %d conv %d res %g energy %g penalty %g contacts %d maxdepth %g\n", s, it,
                        sim.converged(), sim.residual(), sim.energy(), sim.contact().energy, sim.contact().contacts,
                        sim.contact().max_depth);
        r.max_self_contacts = std::max(r.max_self_contacts, sim.contact().self_contacts);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.energy_end = sim.energy();
    r.max_energy_rise = peak - r.energy_start;
    std::vector<double> total, teth;
    int reused = 0, evaluations = 0;
    for (const auto& t : sim.timings()) {
        evaluations += t.evaluations;
        total.push_back(t.ms_total);
        teth.push_back(t.ms_tethash);
        reused += t.reused ? 1 : 0;
    }
    const double mt = median(total), mh = median(teth);
    std::printf("%s: %d nodes, %d tets, %d steps, %d Newton iterations (at most %d per step, %d steps unconverged), "
                "%.2f s\n",
                name, sim.mesh().nodes(), sim.mesh().elements(), steps, iterations, worst, unconverged, seconds);
    std::printf("Newton residual left at the end of a step, largest / largest nodal load: %.3g\n", r.max_residual);
    std::printf("per Newton iteration (median): total %.3f ms, tethash (detect + penetration) %.3f ms = %.1f %%; "
                "skin reuse in %.0f %% of the iterations; %.2f detections per iteration (line search)\n",
                mt, mh, mt > 0 ? 100 * mh / mt : 0.0,
                total.empty() ? 0.0 : 100.0 * reused / static_cast<double>(total.size()),
                total.empty() ? 0.0 : evaluations / static_cast<double>(total.size()));
    return r;
}

fem::ContactSettings contact_settings(const Options& o, double stiffness)
{
    fem::ContactSettings c;
    c.stiffness = o.stiffness > 0 ? o.stiffness : stiffness;
    c.skin = o.skin;
    c.threads = o.threads;
    return c;
}

/// The scenes' material (density 1000 kg/m³, Poisson ratio 0.3) of Young's modulus `young` [Pa].
fem::Material material(double young)
{
    fem::Material m;
    m.young = young;
    m.poisson = 0.3;
    m.density = 1e3;
    return m;
}

/// The time step of --dt (0.01 s by default) and a damping α [1/s].
fem::SimulationSettings settings(const Options& o, double damping)
{
    fem::SimulationSettings s;
    s.dt = o.dt > 0 ? o.dt : 0.01;
    s.damping = damping;
    return s;
}

int block(const Options& o)
{
    const double gap = 0.005, load = 2000;
    fem::Mesh mesh = fem::lattice(
        4, 4, 2, 0.25, {0, 0, 0}, [](int, int, int) { return true; }, 0);
    fem::append(mesh, fem::lattice(
                          3, 3, 3, 1.0 / 6, {0.25, 0.25, 0.5 + gap}, [](int, int, int) { return true; }, 1));
    fem::SimulationSettings ss = settings(o, 20);
    ss.gravity = {0, 0, -9.81};
    fem::Simulation sim(mesh, material(1e5), contact_settings(o, 1e6), ss);
    Vec f = Vec::Zero(mesh.rest.size());
    std::vector<int> top;
    for (int i = 0; i < mesh.nodes(); ++i) {
        if (mesh.rest[3 * i + 2] == 0) sim.fix(i);
        if (mesh.node_object[static_cast<size_t>(i)] == 1 && mesh.rest[3 * i + 2] > 1.0 + gap - 1e-9) top.push_back(i);
    }
    for (int i : top)
        f[3 * i + 2] = -load / static_cast<double>(top.size());
    sim.set_load(f);
    double weight = 0;
    for (int i = 0; i < mesh.nodes(); ++i)
        if (mesh.node_object[static_cast<size_t>(i)] == 1) weight += sim.elasticity().mass()[3 * i] * 9.81;

    const RunResult r = run(sim, o.steps > 0 ? o.steps : 100, "block", o.trace);
    const double h = sim.elasticity().smallest_edge();
    const double support = sim.contact().force[3 * 1 + 2];
    std::printf("checks (smallest edge %.4g m, weight %.1f N + load %.1f N):\n", h, weight, load);
    check(r.max_exact_depth < 0.1 * h, "largest exact penetration depth over the run [m]", r.max_exact_depth, 0.1 * h);
    check(std::abs(support - (weight + load)) < 0.05 * (weight + load),
          "contact force on the upper block at the end [N]", support, weight + load);
    Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
    double mass = 0;
    for (int i = 0; i < mesh.nodes(); ++i)
        if (mesh.node_object[static_cast<size_t>(i)] == 1) {
            momentum += sim.elasticity().mass()[3 * i] * sim.v().segment<3>(3 * i);
            mass += sim.elasticity().mass()[3 * i];
        }
    // Vertical rest; sideways the contact is frictionless, so a small tangential component of the estimated
    // directions lets the block drift slowly (printed, not checked).
    check(std::abs(momentum.z()) / mass < 1e-3, "upper block's vertical centre-of-mass speed at the end [m/s]",
          std::abs(momentum.z()) / mass, 1e-3);
    std::printf("  (its sideways drift at the end: %.3g m/s, frictionless contact)\n",
                momentum.head<2>().norm() / mass);
    const double tol = 1e-3 * std::abs(r.energy_end - r.energy_start);
    check(r.max_energy_rise <= tol, "largest energy rise above the start [J]", r.max_energy_rise, tol);
    // Pressure of a flat punch on an elastic foundation peaks at the punch's rim (Boussinesq): the mean pressure
    // (penalty force over the node's share of the face: ½ on an edge, ¼ at a corner) of the upper block's bottom
    // nodes on the rim of its footprint against the nodes inside it.
    double rim = 0, inner = 0, area_rim = 0, area_inner = 0;
    const double cell = 1.0 / 6;
    for (const tethash::Contact& c : sim.contact().pairs) {
        if (c.vertex_object != 1) continue;
        const double x = mesh.rest[3 * c.vertex], y = mesh.rest[3 * c.vertex + 1];
        const bool rim_x = std::abs(x - 0.25) < 1e-9 || std::abs(x - 0.75) < 1e-9;
        const bool rim_y = std::abs(y - 0.25) < 1e-9 || std::abs(y - 0.75) < 1e-9;
        const double area = (rim_x ? 0.5 : 1.0) * (rim_y ? 0.5 : 1.0) * cell * cell;
        ((rim_x || rim_y) ? rim : inner) += sim.contact().stiffness * c.depth;
        ((rim_x || rim_y) ? area_rim : area_inner) += area;
    }
    const double p_rim = area_rim > 0 ? rim / area_rim : 0, p_inner = area_inner > 0 ? inner / area_inner : 0;
    std::printf("  (mean contact pressure under the upper block: rim %.0f Pa, inside %.0f Pa; load / footprint %.0f "
                "Pa)\n",
                p_rim, p_inner, (weight + load) / 0.25);
    check(p_inner > 0 && p_rim > p_inner, "contact pressure at the footprint's rim / inside it (punch: > 1)",
          p_inner > 0 ? p_rim / p_inner : 0.0, 1);
    check(sim.contact().contacts >= 9, "contacting nodes at the end (spread over the face)", sim.contact().contacts, 9);
    return failures ? 1 : 0;
}

int hairpin(const Options& o)
{
    const double h = 0.1, load = 400;
    // 8 × 2 × 5 cubes minus the slot k = 2, i ≥ 1: lower arm z ∈ [0, 0.2], gap [0.2, 0.3], upper arm [0.3, 0.5].
    fem::Mesh mesh = fem::lattice(
        8, 2, 5, h, {0, 0, 0}, [](int i, int, int k) { return !(k == 2 && i >= 1); }, 0);
    fem::Simulation sim(mesh, material(1e6), contact_settings(o, 1e6), settings(o, 5));
    Vec f = Vec::Zero(mesh.rest.size());
    std::vector<int> tip;
    int tip_bottom = -1;
    for (int i = 0; i < mesh.nodes(); ++i) {
        const double x = mesh.rest[3 * i], y = mesh.rest[3 * i + 1], z = mesh.rest[3 * i + 2];
        if (z == 0) sim.fix(i);
        if (x > 0.8 - 1e-9 && z > 0.3 - 1e-9) tip.push_back(i);
        if (x > 0.8 - 1e-9 && std::abs(z - 0.3) < 1e-9 && std::abs(y - 0.1) < 1e-9) tip_bottom = i;
    }
    for (int i : tip)
        f[3 * i + 2] = -load / static_cast<double>(tip.size());
    sim.set_load(f);

    const RunResult r = run(sim, o.steps > 0 ? o.steps : 100, "hairpin", o.trace);
    const double e = sim.elasticity().smallest_edge();
    const double z_tip = sim.x()[3 * tip_bottom + 2];
    std::printf("checks (smallest edge %.4g m, tip load %.1f N; free cantilever would deflect ~0.5 m):\n", e, load);
    check(r.max_self_contacts > 0, "self-contacts seen (nodes of the object inside its own tets)", r.max_self_contacts,
          1);
    check(sim.contact().self_contacts > 0, "self-contacts at the end (the arm rests on itself)",
          sim.contact().self_contacts, 1);
    check(r.max_exact_depth < 0.1 * e, "largest exact penetration depth over the run [m]", r.max_exact_depth, 0.1 * e);
    check(z_tip > 0.2 - 0.1 * e, "tip height at the end, above the lower arm's top 0.2 [m]", z_tip, 0.2 - 0.1 * e);
    check(z_tip < 0.25, "tip height at the end, the gap closed [m]", z_tip, 0.25);
    const double tol = 1e-3 * std::abs(r.energy_end - r.energy_start);
    check(r.max_energy_rise <= tol, "largest energy rise above the start [J]", r.max_energy_rise, tol);
    return failures ? 1 : 0;
}

const char* const usage_text =
    "usage: fem_contact block|hairpin [--steps N] [--dt H] [--skin F] [--threads T] [--stiffness K] [--trace]\n"
    "Runs a scene of a small FEM code with tethash as its contact module and checks its physics:\n"
    "  block    a soft block pressed onto another by its weight and a load\n"
    "  hairpin  a U-shaped beam bent onto itself (self-contact)\n"
    "  --steps N      time steps (default: the scene's, 100)\n"
    "  --dt H         time step [s] (default 0.01)\n"
    "  --skin F       the detector's skin, a factor of its cell size (default 0.2; 0: no candidate reuse)\n"
    "  --threads T    the detector's threads (default 1; 0: every hardware thread)\n"
    "  --stiffness K  contact penalty [N/m] (default: the scene's)\n"
    "  --trace        a line per step\n"
    "Exit status: 0 when every check holds, 1 when one fails, 2 on bad arguments.\n";

int usage(const char* why)
{
    std::fprintf(stderr, "fem_contact: %s\n%s", why, usage_text);
    return 2;
}

} // namespace

int main(int argc, char** argv)
{
    Options o;
    for (int a = 1; a < argc; ++a) {
        const std::string arg = argv[a];
        auto value = [&](const char* name) -> const char* {
            if (a + 1 >= argc) return nullptr;
            (void)name;
            return argv[++a];
        };
        char* end = nullptr;
        if (arg == "--help" || arg == "-h") {
            std::fputs(usage_text, stdout);
            return 0;
        }
        if (arg == "--trace") {
            o.trace = true;
        } else if (arg == "--steps" || arg == "--threads") {
            const char* v = value(arg.c_str());
            if (!v) return usage((arg + " needs a value").c_str());
            const long n = std::strtol(v, &end, 10);
            if (*end || n < 0 || n > 1000000) return usage((arg + ": expected a count, found '" + v + "'").c_str());
            (arg == "--steps" ? o.steps : o.threads) = static_cast<int>(n);
        } else if (arg == "--dt" || arg == "--skin" || arg == "--stiffness") {
            const char* v = value(arg.c_str());
            if (!v) return usage((arg + " needs a value").c_str());
            const double x = std::strtod(v, &end);
            if (*end || !(x >= 0) || x > 1e12)
                return usage((arg + ": expected a number ≥ 0, found '" + v + "'").c_str());
            (arg == "--dt" ? o.dt : arg == "--skin" ? o.skin : o.stiffness) = x;
        } else if (o.scene.empty() && arg[0] != '-') {
            o.scene = arg;
        } else {
            return usage(("unknown argument '" + arg + "'").c_str());
        }
    }
    try {
        if (o.scene == "block") return block(o);
        if (o.scene == "hairpin") return hairpin(o);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "fem_contact: %s\n", e.what());
        return 1;
    }
    return usage(o.scene.empty() ? "no scene given" : ("unknown scene '" + o.scene + "'").c_str());
}
