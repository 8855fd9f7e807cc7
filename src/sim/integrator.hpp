#pragma once
// One interface for the time integrators (private to tethash::sim); one file per integrator.

#include "contact_response.hpp"

#include "tethash/sim/model.hpp"
#include "tethash/sim/scene.hpp"

#include <csignal>
#include <cstdint>
#include <memory>
#include <vector>

namespace tethash::sim {

/// What an integrator reads: the scene's settings, the mesh (tets, rest state), the fixed model and the contacts
/// of the current substep (updated by the caller before each substep). All outlive the integrator.
struct StepContext {
    const Scene& scene;
    const TetMesh& mesh;
    const Model& model;
    const ContactResponse& contacts;
    /// The simulation's interrupt flag (Simulation::set_interrupt_flag; may point to nullptr): iterative
    /// integrators stop iterating once it is set, and the step is rolled back.
    const volatile std::sig_atomic_t* const* interrupt = nullptr;
    bool interrupted() const { return interrupt && *interrupt && **interrupt; }
};

class StepIntegrator {
  public:
    virtual ~StepIntegrator() = default;
    /// Advances positions x and velocities v (n × 3; fixed vertices untouched) by one substep h. Returns the
    /// solver iterations it took (0 for a direct method).
    virtual int substep(Positions& x, Positions& v, double h) = 0;
    /// Whether the last substep's iterations met their tolerance (a direct or explicit method always does).
    virtual bool converged() const { return true; }
    /// After a step is taken (no refinement to follow), with the tets it leaves inverted (rows of the model's volume
    /// terms): a last change of positions only (velocities stay). Nothing by default.
    virtual void finish_step(Positions& /*x*/, const std::vector<std::int32_t>& /*inverted*/) {}
    /// The step is taken again because it gained energy: iterate to a tighter tolerance this time. False when the
    /// integrator cannot (a direct or explicit method, or already at its tightest); `relax` when the step is taken.
    virtual bool tighten() { return false; }
    virtual void relax() {}
    /// Whether the last substep can be continued (resume) rather than taken again from its start: false by default.
    virtual bool resumable() const { return false; }
    /// After `tighten`, instead of substep(x, v, h) again from the same start (x, v: the last substep's start, given
    /// back as for substep): the last substep's iterations continue from where they stopped, with its inertial
    /// target, contacts and convergence reference, to the tighter tolerance. Returns the iterations it took. Only
    /// when `resumable`.
    virtual int resume(Positions& /*x*/, Positions& /*v*/, double /*h*/) { return 0; }
    /// The thread count of the next substeps (≥ 1); the result does not depend on it. Ignored by default.
    virtual void set_threads(int /*threads*/) {}
};

std::unique_ptr<StepIntegrator> make_symplectic_euler(const StepContext& ctx);
std::unique_ptr<StepIntegrator> make_implicit_euler(const StepContext& ctx);
std::unique_ptr<StepIntegrator> make_block_descent(const StepContext& ctx);

inline std::unique_ptr<StepIntegrator> make_integrator(const StepContext& ctx)
{
    switch (ctx.scene.integrator) {
    case Integrator::symplectic_euler:
        return make_symplectic_euler(ctx);
    case Integrator::implicit_euler:
        return make_implicit_euler(ctx);
    case Integrator::vbd:
        break;
    }
    return make_block_descent(ctx);
}

} // namespace tethash::sim
