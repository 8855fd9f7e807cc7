// Work-precision study of the simulator: integrator × dt × substeps against a reference run of the same
// scene with a much smaller time step.
#include "measure.hpp"
#include "plan.hpp"
#include "value_list.hpp"

#include "tethash/error.hpp"
#include "tethash/sim/scene.hpp"
#include "tethash/sim/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>

namespace tethash::study {

struct SimPoint {
    sim::Integrator integrator = sim::Integrator::implicit_euler;
    double dt = 1e-3;
    int substeps = 1;
};

struct SimPlan {
    sim::Scene scene;
    std::string scene_name;
    std::vector<SimPoint> points;
    double duration = 0;
    std::vector<double> sample_times; ///< where positions are compared (s)
    double ref_dt = 0;
    // The reference run, computed at the first point that needs it.
    std::optional<std::vector<Positions>> ref_samples;
    std::string ref_integrator;
    double ref_energy_drift = 0;
    double ref_max_penetration = 0;
    double size = 0; ///< the scene's extent (longest side of the reference's first sample's box): errors relative to it
};

void SimPlanDeleter::operator()(SimPlan* p) const
{
    delete p;
}

namespace {

const std::vector<std::string> k_sim_columns = {
    "point",
    "repeat",
    "scene",
    "sweep",
    "integrator",
    "dt",
    "substeps",
    "steps",
    "duration",
    "vertices",
    "tets",
    "status",
    "err_rms",
    "err_max",
    "err_rms_rel",
    "max_penetration",
    "final_contacts",
    "energy_start",
    "energy_end",
    "energy_drift",
    "energy_drift_rel",
    "ref_integrator",
    "ref_dt",
    "ref_energy_drift",
    "ref_max_penetration",
    "ms_wall",
    "wall_s_per_sim_s",
    "ms_detect",
    "ms_response",
    "ms_integrate",
};

/// Result of one simulated run.
struct RunOutcome {
    std::string status = "ok";
    std::vector<Positions> samples; ///< positions at plan.sample_times (fewer when it failed)
    std::int64_t steps = 0;
    double wall_ms = 0, ms_detect = 0, ms_response = 0, ms_integrate = 0;
    double e0 = 0, e1 = 0, max_pen = 0;
    std::int64_t contacts = 0;
    Index vertices = 0, tets = 0;
};

RunOutcome simulate(const SimPlan& plan, const SimPoint& pt, const std::atomic<bool>* stop)
{
    sim::Scene sc = plan.scene;
    sc.integrator = pt.integrator;
    sc.dt = pt.dt;
    sc.substeps = pt.substeps;
    sc.steps = static_cast<int>(std::ceil(plan.duration / pt.dt - 1e-9));
    sc.output.every = 0;
    RunOutcome out;
    const auto t0 = now_ns();
    sim::Simulation s(sc);
    out.e0 = s.energy().total();
    out.vertices = s.mesh().num_vertices();
    out.tets = s.mesh().num_tets();
    Positions prev = s.positions();
    double t_prev = s.time();
    std::size_t next = 0;
    try {
        while (next < plan.sample_times.size()) {
            if (stop && stop->load()) {
                out.status = "interrupted";
                break;
            }
            s.step();
            ++out.steps;
            const auto& st = s.last_stats();
            out.ms_detect += st.ms_detect;
            out.ms_response += st.ms_response;
            out.ms_integrate += st.ms_integrate;
            const double t = s.time();
            while (next < plan.sample_times.size() && plan.sample_times[next] <= t + 1e-12 * plan.duration) {
                const double w =
                    t > t_prev ? std::clamp((plan.sample_times[next] - t_prev) / (t - t_prev), 0.0, 1.0) : 1.0;
                out.samples.push_back(prev + w * (s.positions() - prev));
                ++next;
            }
            prev = s.positions();
            t_prev = t;
        }
    } catch (const RunFailure& e) {
        out.status = std::string("diverged: ") + e.what();
    } catch (const Error& e) {
        // The scene was valid at the start (the constructor checked it): input errors raised while stepping
        // (for example positions beyond the detector's grid range) mean the run blew up.
        out.status = std::string("diverged: ") + e.what();
    }
    out.wall_ms = elapsed_ms(t0);
    out.e1 = s.energy().total();
    out.max_pen = s.max_penetration();
    out.contacts = static_cast<std::int64_t>(s.contacts().size());
    return out;
}

} // namespace

void plan_sim_study(StudyPlan& plan)
{
    const StudyOptions& o = plan.options;
    auto sp = std::unique_ptr<SimPlan, SimPlanDeleter>(new SimPlan);
    // Validate the value lists before loading anything.
    const auto integ_items = o.integrator.empty() ? std::vector<std::string>{"all"} : o.integrator;
    std::vector<sim::Integrator> integrators;
    for (const auto& spec : integ_items) {
        std::size_t start = 0;
        while (start <= spec.size()) {
            const auto comma = spec.find(',', start);
            const std::string it = spec.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
            if (it.empty()) throw Error("--integrator: empty value in '" + spec + "'");
            if (it == "all") {
                integrators.insert(integrators.end(), {sim::Integrator::symplectic_euler,
                                                       sim::Integrator::implicit_euler, sim::Integrator::vbd});
            } else {
                integrators.push_back(sim::parse_integrator(it));
            }
            if (comma == std::string::npos) break;
            start = comma + 1;
        }
    }
    const auto substeps = parse_int_list(o.substeps.empty() ? std::vector<std::string>{"1"} : o.substeps, "--substeps");
    if (o.duration < 0 || !std::isfinite(o.duration)) throw Error("--duration: must be > 0");
    if (o.samples < 1) throw Error("--samples: must be >= 1, found " + std::to_string(o.samples));
    if (!(o.reference_factor >= 2)) throw Error("--reference-factor: must be >= 2");
    // Syntax check of --dt with a unit scale (x factors are relative to the scene's dt).
    (void)parse_real_list(o.dt.empty() ? std::vector<std::string>{"x1"} : o.dt, "--dt", 1.0, true);

    if (!o.scene_file.empty()) {
        if (!std::filesystem::exists(o.scene_file)) throw Error("--scene: file not found: " + o.scene_file);
        if (std::filesystem::is_directory(o.scene_file))
            throw Error("--scene: " + o.scene_file + ": is a directory, expected a scene file (.toml)");
        sp->scene = sim::load_scene(o.scene_file);
        sp->scene_name = std::filesystem::path(o.scene_file).stem().string();
    } else {
        sp->scene = sim::default_scene();
        sp->scene_name = "default";
    }
    const auto dts =
        parse_real_list(o.dt.empty() ? std::vector<std::string>{"x0.25:x4:5"} : o.dt, "--dt", sp->scene.dt, true);
    sp->duration = o.duration > 0 ? o.duration : std::min(0.5, sp->scene.dt * sp->scene.steps);
    if (!(sp->duration > 0)) throw Error("--duration: the scene has no duration; give --duration SECONDS");
    for (int k = 1; k <= o.samples; ++k)
        sp->sample_times.push_back(sp->duration * k / o.samples);
    sp->ref_dt = *std::min_element(dts.begin(), dts.end()) / o.reference_factor;

    plan.columns = k_sim_columns;
    for (auto integ : integrators)
        for (int sub : substeps)
            for (double dt : dts) {
                PointInfo info;
                info.index = static_cast<std::int64_t>(plan.points.size());
                info.scene = sp->scene_name;
                info.params = {
                    {"integrator", sim::to_string(integ)}, {"dt", fmt_double(dt)}, {"substeps", std::to_string(sub)}};
                plan.points.push_back(std::move(info));
                sp->points.push_back({integ, dt, sub});
            }
    plan.sim = std::move(sp);
}

std::vector<Row> run_sim_point(StudyPlan& plan, std::int64_t index, const RunHooks& hooks)
{
    SimPlan& sp = *plan.sim;
    const StudyOptions& o = plan.options;
    if (!sp.ref_samples) {
        // Reference: symplectic Euler when its step is well inside the explicit stability limit, else implicit Euler.
        SimPoint ref{sim::Integrator::symplectic_euler, sp.ref_dt, 1};
        {
            sim::Scene probe_scene = sp.scene;
            probe_scene.dt = sp.ref_dt;
            probe_scene.substeps = 1;
            sim::Simulation probe(probe_scene);
            if (!(sp.ref_dt < 0.5 * probe.explicit_dt_limit())) ref.integrator = sim::Integrator::implicit_euler;
        }
        if (hooks.on_note)
            hooks.on_note("reference run: " + std::string(sim::to_string(ref.integrator)) + " dt " +
                          fmt_double(sp.ref_dt) + " s for " + fmt_double(sp.duration) + " s");
        RunOutcome r = simulate(sp, ref, hooks.stop);
        if (r.status == "interrupted") return {};
        if (r.status != "ok")
            throw RunFailure("reference run (" + std::string(sim::to_string(ref.integrator)) + ", dt " +
                             fmt_double(sp.ref_dt) + "): " + r.status);
        sp.ref_samples = std::move(r.samples);
        if (!sp.ref_samples->empty()) {
            const auto [lo, hi] = bounding_box(sp.ref_samples->front());
            sp.size = (hi - lo).maxCoeff();
        }
        sp.ref_integrator = sim::to_string(ref.integrator);
        sp.ref_energy_drift = r.e1 - r.e0;
        sp.ref_max_penetration = r.max_pen;
        plan.notes.push_back("reference run: " + sp.ref_integrator + " dt " + fmt_double(sp.ref_dt) + " s, " +
                             fmt_double(r.wall_ms / 1000) + " s wall");
    }
    const SimPoint& pt = sp.points[static_cast<std::size_t>(index)];
    std::vector<Row> rows;
    for (int r = -o.warmup; r < o.repeat; ++r) {
        if (hooks.stop && hooks.stop->load()) break;
        RunOutcome out = simulate(sp, pt, hooks.stop);
        if (out.status == "interrupted") break;
        if (r < 0) continue;
        std::string err_rms, err_max, err_rel;
        if (out.samples.size() == sp.ref_samples->size()) {
            double sum = 0, mx = 0;
            std::int64_t count = 0;
            for (std::size_t k = 0; k < out.samples.size(); ++k) {
                const Positions d = out.samples[k] - (*sp.ref_samples)[k];
                for (Eigen::Index v = 0; v < d.rows(); ++v) {
                    const double e2 = d.row(v).squaredNorm();
                    sum += e2;
                    mx = std::max(mx, e2);
                    ++count;
                }
            }
            const double rms = count ? std::sqrt(sum / static_cast<double>(count)) : 0.0;
            err_rms = fmt_double(rms);
            if (sp.size > 0) err_rel = fmt_double(rms / sp.size);
            err_max = fmt_double(std::sqrt(mx));
        }
        const double drift = out.e1 - out.e0;
        rows.push_back({std::to_string(index),
                        std::to_string(r),
                        sp.scene_name,
                        "integrator",
                        sim::to_string(pt.integrator),
                        fmt_double(pt.dt),
                        std::to_string(pt.substeps),
                        std::to_string(out.steps),
                        fmt_double(sp.duration),
                        std::to_string(out.vertices),
                        std::to_string(out.tets),
                        out.status,
                        err_rms,
                        err_max,
                        err_rel,
                        fmt_double(out.max_pen),
                        std::to_string(out.contacts),
                        fmt_double(out.e0),
                        fmt_double(out.e1),
                        fmt_double(drift),
                        out.e0 != 0 ? fmt_double(drift / std::abs(out.e0)) : "",
                        sp.ref_integrator,
                        fmt_double(sp.ref_dt),
                        fmt_double(sp.ref_energy_drift),
                        fmt_double(sp.ref_max_penetration),
                        fmt_double(out.wall_ms),
                        fmt_double(out.wall_ms / 1000.0 / sp.duration),
                        fmt_double(out.ms_detect),
                        fmt_double(out.ms_response),
                        fmt_double(out.ms_integrate)});
    }
    return rows;
}

} // namespace tethash::study
