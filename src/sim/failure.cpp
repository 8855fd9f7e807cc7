#include "failure.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace tethash::sim {

std::string short_number(double v)
{
    std::ostringstream s;
    s.precision(3);
    s << v;
    return s.str();
}

void FailureCheck::setup(const Model& model, const Positions& x, const Positions& v, double contact_energy)
{
    const Energy e0 = model.energy(x, v);
    m_msum = 0;
    double min_mass = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < model.mass.size(); ++i)
        if (!model.fixed[i]) {
            m_msum += model.mass[i];
            min_mass = std::min(min_mass, model.mass[i]);
        }
    if (!std::isfinite(min_mass)) min_mass = 1.0;
    const auto [lo, hi] = bounding_box(x);
    double extent = (hi - lo).norm();
    m_centre0 = 0.5 * (lo + hi);
    m_radius0 = 0.5 * extent;
    if (model.ground.enabled) extent += std::abs(model.ground.normal.dot(lo) - model.ground.height);
    m_energy_ref = e0.internal() + m_msum * model.gravity.norm() * extent + contact_energy;
    m_energy_ref = std::max(m_energy_ref, 1e-12 * std::max(1.0, m_msum));
    // Fastest any vertex can move if all the energy the blow-up test allows went into it.
    m_speed_bound = std::sqrt(2 * 1e3 * m_energy_ref / min_mass);
}

std::string FailureCheck::check_substep(const Model& model, const Positions& x, const Positions& v, double t_end) const
{
    // Catches a blow-up before positions become so large that detection fails.
    const Index n = x.rows();
    const double g = model.gravity.norm();
    const double reach = 10 * (m_radius0 + m_speed_bound * t_end + 0.5 * g * t_end * t_end) + 1.0;
    double kinetic = 0, far = 0;
    Index far_vertex = -1;
    for (Index i = 0; i < n; ++i) {
        if (model.fixed[static_cast<size_t>(i)]) continue;
        const Eigen::Vector3d xi = x.row(i).transpose(), vi = v.row(i).transpose();
        if (!xi.allFinite() || !vi.allFinite())
            return "vertex " + std::to_string(i) + " has a non-finite position or velocity (NaN/Inf)";
        const double d = (xi - m_centre0).norm();
        if (d > far) {
            far = d;
            far_vertex = i;
        }
        kinetic += 0.5 * model.mass[static_cast<size_t>(i)] * vi.squaredNorm();
    }
    if (far > reach)
        return "vertex " + std::to_string(far_vertex) + " is " + short_number(far) + " from the scene centre, beyond the " +
               short_number(reach) + " it could reach on the energy available at start";
    const double kinetic_bound = 1e3 * m_energy_ref + m_msum * g * (reach + m_radius0);
    if (kinetic > kinetic_bound)
        return "the kinetic energy grew to " + short_number(kinetic) + ", " + short_number(kinetic / m_energy_ref) +
               " times all the energy available at start";
    return {};
}

std::string FailureCheck::check_energy(double internal) const
{
    if (!std::isfinite(internal)) return "the energy became NaN/Inf";
    if (internal > 1e3 * m_energy_ref)
        return "the energy grew to " + short_number(internal) + ", " + short_number(internal / m_energy_ref) +
               " times all the energy available at start";
    return {};
}

std::string FailureCheck::likely_cause(const Scene& scene, double h, double dt_limit, const ContactResponse& contacts) const
{
    if (scene.integrator == Integrator::symplectic_euler && h > dt_limit)
        return "the time step " + short_number(h) + " s exceeds the explicit stability limit ≈ " + short_number(dt_limit) +
               " s (stiffness/mass too high for symplectic_euler): use substeps, a smaller dt or vbd";
    double depth = 0, kmax = 0;
    for (size_t q = 0; q < contacts.contacts().size(); ++q)
        if (contacts.contacts()[q].depth > depth) {
            depth = contacts.contacts()[q].depth;
            kmax = std::max(kmax, contacts.stiffness()[q]);
        }
    if (depth > 0)
        return "contact response (max penetration " + short_number(depth) + ", contact stiffness up to " +
               short_number(kmax) + "): lower contact.stiffness or dt, or raise substeps";
    return "stiffness too high for the time step " + short_number(h) + " s (explicit limit ≈ " + short_number(dt_limit) +
           " s): lower dt, raise substeps or use vbd";
}

} // namespace tethash::sim
