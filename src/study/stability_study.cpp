// Stability sweep of the simulator: two copies of a mesh thrown into each other above the ground, for every
// integrator × young × dt × mass ratio × body size. Each cell either completes with a finite, uncrumpled body
// (inverted tets ≤ 1 % at the end) or stops with the simulator's message (step and likely cause); a cell that
// completes crumpled is the failure this sweep exists to find ("crumpled" in the verdict column), and one that
// completes with a problem of its run's health (energy gained, volume lost, iterations unconverged; RunHealth) is
// "untrusted": finite is not yet right.
#include "measure.hpp"
#include "plan.hpp"
#include "value_list.hpp"

#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/sim/quality.hpp"
#include "tethash/sim/scene.hpp"
#include "tethash/sim/simulation.hpp"

#include <cmath>
#include <filesystem>

namespace tethash::study {

struct StabilityPoint {
    std::size_t mesh = 0;
    sim::Integrator integrator = sim::Integrator::vbd;
    double young = 1e5, dt = 1e-3, mass_ratio = 1, size = 1;
};

struct StabilityPlan {
    std::vector<std::string> names;
    std::vector<TetMesh> meshes;
    std::vector<StabilityPoint> points;
    double duration = 0.5;
};

void StabilityPlanDeleter::operator()(StabilityPlan* p) const
{
    delete p;
}

namespace {

const std::vector<std::string> k_stability_columns = {
    "point",
    "repeat",
    "scene",
    "sweep",
    "integrator",
    "young",
    "dt",
    "mass_ratio",
    "vertices",
    "tets",
    "steps",
    "duration",
    "verdict",
    "status",
    "inverted",
    "inverted_fraction",
    "far_self",
    "max_penetration",
    "ms_per_step",
    "size",
    "energy_growth",
    "volume_ratio",
    "unconverged_substeps",
    "refined_steps",
    "problems",
};

/// Two copies of `mesh`, each scaled to `size` (its longest extent), 0.3 sizes above the ground and 1.4 sizes apart,
/// moving towards each other at 1 m/s each (2 m/s closing speed); the first has density 1000, the second
/// `mass_ratio` times less (a heavier second body would only measure whether it carries its own weight).
sim::Scene collision_scene(const TetMesh& mesh, const StabilityPoint& p, double duration)
{
    const auto [lo, hi] = bounding_box(mesh.positions);
    const double s = p.size / (hi - lo).maxCoeff();
    sim::Scene scene;
    for (int k = 0; k < 2; ++k) {
        sim::ObjectSpec o;
        o.name = k == 0 ? "left" : "right";
        o.data = mesh;
        o.scale = Eigen::Vector3d::Constant(s);
        o.translate = Eigen::Vector3d(-s * 0.5 * (lo.x() + hi.x()) + (k == 0 ? -0.7 : 0.7) * p.size,
                                      -s * 0.5 * (lo.y() + hi.y()), 0.3 * p.size - s * lo.z());
        o.velocity = Eigen::Vector3d(k == 0 ? 1.0 : -1.0, 0, 0);
        o.material.young = p.young;
        o.material.density = 1000 / (k == 0 ? 1.0 : p.mass_ratio);
        scene.objects.push_back(std::move(o));
    }
    scene.ground.enabled = true;
    scene.integrator = p.integrator;
    scene.dt = p.dt;
    scene.steps = static_cast<int>(std::ceil(duration / p.dt - 1e-9));
    scene.output.every = 0;
    return scene;
}

} // namespace

void plan_stability_study(StudyPlan& plan)
{
    const StudyOptions& o = plan.options;
    if (o.meshes.empty()) throw Error("stability sweep: give --mesh FILE (each mesh is one scene of two copies)");
    if (!o.scene_file.empty()) throw Error("--scene: the stability sweep builds its own scene from --mesh");
    auto sp = std::unique_ptr<StabilityPlan, StabilityPlanDeleter>(new StabilityPlan);
    std::vector<sim::Integrator> integrators;
    for (const std::string& it : o.integrator.empty() ? std::vector<std::string>{"all"} : o.integrator) {
        if (it == "all")
            integrators.insert(integrators.end(), {sim::Integrator::vbd, sim::Integrator::implicit_euler,
                                                   sim::Integrator::symplectic_euler});
        else
            integrators.push_back(sim::parse_integrator(it));
    }
    const auto youngs =
        parse_real_list(o.young.empty() ? std::vector<std::string>{"1e3,1e5,1e7,1e9"} : o.young, "--young", 1.0, true);
    const auto dts =
        parse_real_list(o.dt.empty() ? std::vector<std::string>{"1e-3,1/240,1/60"} : o.dt, "--dt", 1.0 / 240, true);
    const auto ratios = parse_real_list(o.mass_ratio.empty() ? std::vector<std::string>{"1,1e3,1e6"} : o.mass_ratio,
                                        "--mass-ratio", 1.0, true);
    const auto sizes = parse_real_list(o.size.empty() ? std::vector<std::string>{"1"} : o.size, "--size", 1.0, true);
    if (o.duration < 0 || !std::isfinite(o.duration)) throw Error("--duration: must be > 0");
    sp->duration = o.duration > 0 ? o.duration : 0.5;
    for (const std::string& file : o.meshes) {
        if (file.find('+') != std::string::npos)
            throw Error("stability sweep: --mesh takes one file per scene, found '" + file + "'");
        sp->meshes.push_back(io::read_mesh(file));
        sp->names.push_back(std::filesystem::path(file).stem().string());
    }
    plan.columns = k_stability_columns;
    for (std::size_t m = 0; m < sp->meshes.size(); ++m)
        for (sim::Integrator integ : integrators)
            for (double young : youngs)
                for (double dt : dts)
                    for (double ratio : ratios)
                        for (double size : sizes) {
                            PointInfo info;
                            info.index = static_cast<std::int64_t>(plan.points.size());
                            info.scene = sp->names[m];
                            info.params = {{"integrator", sim::to_string(integ)},
                                           {"young", fmt_double(young)},
                                           {"dt", fmt_double(dt)},
                                           {"mass_ratio", fmt_double(ratio)},
                                           {"size", fmt_double(size)}};
                            plan.points.push_back(std::move(info));
                            sp->points.push_back({m, integ, young, dt, ratio, size});
                        }
    plan.stability = std::move(sp);
}

std::vector<Row> run_stability_point(StudyPlan& plan, std::int64_t index, const RunHooks& hooks)
{
    const StabilityPlan& sp = *plan.stability;
    const StabilityPoint& p = sp.points[static_cast<std::size_t>(index)];
    std::vector<Row> rows;
    for (int r = -plan.options.warmup; r < plan.options.repeat; ++r) {
        if (hooks.stop && hooks.stop->load()) break;
        sim::Simulation s(collision_scene(sp.meshes[p.mesh], p, sp.duration));
        const Positions start = s.positions();
        std::string status = "ok";
        std::int64_t steps = 0;
        const auto t0 = now_ns();
        try {
            while (s.time() < sp.duration - 1e-9 * sp.duration) {
                if (hooks.stop && hooks.stop->load()) {
                    status = "interrupted";
                    break;
                }
                s.step();
                ++steps;
            }
        } catch (const RunFailure& e) {
            status = std::string("stopped: ") + e.what();
        } catch (const Error& e) {
            status = std::string("stopped: ") + e.what();
        }
        const double ms = elapsed_ms(t0);
        if (status == "interrupted") break;
        if (r < 0) continue;
        const bool finite = s.positions().allFinite();
        const std::int64_t inv = finite ? sim::count_inverted(s.mesh(), start) : -1;
        const std::int64_t far = finite ? sim::count_far_self_penetrations(s.mesh(), start) : -1;
        const std::int64_t tets = s.mesh().num_tets();
        const sim::RunHealth& health = s.health();
        std::string problems;
        for (const std::string& q : health.problems())
            problems += (problems.empty() ? "" : "; ") + q;
        std::string verdict = "ok";
        if (status != "ok")
            verdict = "stopped";
        else if (!finite || inv * 100 > tets)
            verdict = "crumpled";
        else if (!problems.empty())
            verdict = "untrusted";
        rows.push_back({std::to_string(index),
                        std::to_string(r),
                        sp.names[p.mesh],
                        "stability",
                        sim::to_string(p.integrator),
                        fmt_double(p.young),
                        fmt_double(p.dt),
                        fmt_double(p.mass_ratio),
                        std::to_string(s.mesh().num_vertices()),
                        std::to_string(tets),
                        std::to_string(steps),
                        fmt_double(sp.duration),
                        verdict,
                        status,
                        std::to_string(inv),
                        inv >= 0 ? fmt_double(static_cast<double>(inv) / static_cast<double>(tets)) : "",
                        std::to_string(far),
                        fmt_double(s.max_penetration()),
                        fmt_double(steps > 0 ? ms / static_cast<double>(steps) : 0.0),
                        fmt_double(p.size),
                        fmt_double(health.energy_growth),
                        fmt_double(health.volume_ratio),
                        std::to_string(health.unconverged_substeps),
                        std::to_string(health.refined_steps),
                        problems});
    }
    return rows;
}

} // namespace tethash::study
