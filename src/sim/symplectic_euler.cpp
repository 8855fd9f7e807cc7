// Symplectic (semi-implicit) Euler: v += h M⁻¹ f(x, v); x += h v. Explicit: stable below the limit that
// Model::explicit_dt_limit estimates; kept as the reference for studies.
#include "integrator.hpp"

namespace tethash::sim {

namespace {

class SymplecticEuler final : public StepIntegrator {
  public:
    explicit SymplecticEuler(const StepContext& ctx) : m_ctx(ctx) {}

    int substep(Positions& x, Positions& v, double h) override
    {
        const Model& model = m_ctx.model;
        const Index n = x.rows();
        m_force.setZero(n, 3);
        Model::ForceOptions opt;
        opt.h = h;
        model.add_forces(x, v, m_force, opt);
        m_ctx.contacts.add_forces(v, m_force, h, false);
        for (Index i = 0; i < n; ++i) {
            if (model.fixed[static_cast<size_t>(i)]) continue;
            v.row(i) += h / model.mass[static_cast<size_t>(i)] * m_force.row(i);
            x.row(i) += h * v.row(i);
        }
        return 0;
    }

  private:
    StepContext m_ctx;
    Positions m_force; // reused across substeps
};

} // namespace

std::unique_ptr<StepIntegrator> make_symplectic_euler(const StepContext& ctx)
{
    return std::make_unique<SymplecticEuler>(ctx);
}

} // namespace tethash::sim
