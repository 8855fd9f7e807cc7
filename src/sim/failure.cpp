#include "failure.hpp"

#include "block_sum.hpp"

#include <Eigen/Geometry>

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
    // What the scene has to spend, as precisely as the start says: its internal energy plus every free mass falling
    // over the free vertices' span along gravity and from their lowest point to the ground (the blow-up reference
    // above takes the box's diagonal instead: a flat mat 1 m across would count 1.4 m of fall for 8 mm).
    const double gn = model.gravity.norm();
    double fall = 0;
    if (gn > 0) {
        const Eigen::Vector3d down = model.gravity / gn;
        double low = INFINITY, high = -INFINITY;
        Eigen::Index lowest = -1;
        for (size_t i = 0; i < model.mass.size(); ++i) {
            if (model.fixed[i]) continue;
            const double along = down.dot(x.row(static_cast<Eigen::Index>(i)).transpose());
            if (along > high) {
                high = along;
                lowest = static_cast<Eigen::Index>(i); // the lowest point: furthest along gravity
            }
            low = std::min(low, along);
        }
        if (lowest >= 0) {
            fall = high - low;
            const double facing = -model.ground.normal.dot(down); // 1: the ground faces straight up
            if (model.ground.enabled && facing > 0.1)
                fall +=
                    std::max(0.0, model.ground.normal.dot(x.row(lowest).transpose()) - model.ground.height) / facing;
        }
    }
    m_energy_available = std::max(e0.internal() + m_msum * gn * fall + contact_energy, 1e-12 * std::max(1.0, m_msum));
    // Fastest any vertex can move if all the energy the blow-up test allows went into it.
    m_speed_bound = std::sqrt(2 * 1e3 * m_energy_ref / min_mass);
    // Each object's height along gravity (for ρ g h / E, the strain its own weight causes).
    m_object_height.clear();
    std::vector<double> lo_h, hi_h;
    for (size_t i = 0; i < model.mass.size(); ++i) {
        const size_t o = static_cast<size_t>(model.vertex_object[i]);
        if (o >= lo_h.size()) {
            lo_h.resize(o + 1, std::numeric_limits<double>::infinity());
            hi_h.resize(o + 1, -std::numeric_limits<double>::infinity());
        }
        if (model.fixed[i] || !(gn > 0)) continue;
        const double z = -model.gravity.dot(x.row(static_cast<Index>(i)).transpose()) / gn;
        lo_h[o] = std::min(lo_h[o], z);
        hi_h[o] = std::max(hi_h[o], z);
    }
    for (size_t o = 0; o < lo_h.size(); ++o)
        m_object_height.push_back(hi_h[o] > lo_h[o] ? hi_h[o] - lo_h[o] : 0.0);
}

std::int64_t find_inverted_tets(const Model& model, const Positions& x, std::vector<std::int32_t>& out, double* volume,
                                int threads)
{
    // Per block of tets its list and its sum, joined in block order.
    struct Found {
        std::vector<std::int32_t> tets;
        double six_volume = 0;
        Found& operator+=(const Found& o)
        {
            tets.insert(tets.end(), o.tets.begin(), o.tets.end());
            six_volume += o.six_volume;
            return *this;
        }
    };
    const Index nt = static_cast<Index>(model.volumes.tets.rows());
    Found found = detail::block_sum<Found>(nt, threads, [&](Index begin, Index end) {
        Found part;
        for (Index t = begin; t < end; ++t) {
            const auto tet = model.volumes.tets.row(t);
            const Eigen::Vector3d a = x.row(tet(0)).transpose();
            const double w = (x.row(tet(1)).transpose() - a)
                                 .dot((x.row(tet(2)).transpose() - a).cross(x.row(tet(3)).transpose() - a));
            part.six_volume += w;
            if (!(w > 0)) part.tets.push_back(static_cast<std::int32_t>(t));
        }
        return part;
    });
    out.swap(found.tets);
    if (volume) *volume = found.six_volume / 6;
    return static_cast<std::int64_t>(out.size());
}

std::string FailureCheck::check_inverted(const Model& model, const Scene& scene, std::int64_t inverted, double h,
                                         double t, double dt_limit)
{
    const std::int64_t nt = static_cast<std::int64_t>(model.volumes.tets.rows());
    if (inverted * 100 <= nt) {
        m_inverted_since = -1;
        return {};
    }
    if (m_inverted_since < 0) m_inverted_since = t - h;
    const double lasting = t - m_inverted_since;
    if (inverted * 10 <= nt && lasting < 0.1 - 1e-9) return {};
    std::string what = short_number(static_cast<double>(inverted)) + " of " + std::to_string(nt) + " tets (" +
                       short_number(100.0 * static_cast<double>(inverted) / static_cast<double>(nt)) +
                       " %) are inverted" +
                       (inverted * 10 > nt ? std::string() : ", more than 1 % for " + short_number(lasting) + " s") +
                       ": the body crumpled";
    // Likely cause, most specific first.
    const double g = model.gravity.norm();
    double worst = 0, densest = 0, lightest = std::numeric_limits<double>::infinity();
    size_t worst_o = 0, dense_o = 0, light_o = 0;
    for (size_t o = 0; o < scene.objects.size() && o < m_object_height.size(); ++o) {
        const ObjectSpec& spec = scene.objects[o];
        if (spec.is_static || m_object_height[o] <= 0) continue;
        const Material& m = spec.material;
        const double strain = m.density * g * m_object_height[o] / m.young;
        if (strain > worst) {
            worst = strain;
            worst_o = o;
        }
        if (m.density > densest) {
            densest = m.density;
            dense_o = o;
        }
        if (m.density < lightest) {
            lightest = m.density;
            light_o = o;
        }
    }
    auto name = [&](size_t o) {
        return scene.objects[o].name.empty() ? "object " + std::to_string(o) : "'" + scene.objects[o].name + "'";
    };
    std::string cause;
    if (scene.integrator == Integrator::symplectic_euler && h > dt_limit)
        cause = "the time step " + short_number(h) + " s exceeds the explicit stability limit ≈ " +
                short_number(dt_limit) +
                " s (stiffness/mass too high for symplectic_euler): use substeps, a smaller "
                "dt or vbd";
    else if (worst > 0.3)
        cause = name(worst_o) + " cannot carry its own weight: density × g × height / young = " + short_number(worst) +
                " (a strain; above ~0.3 the body flattens): raise its young or lower its density";
    else if (densest > 100 * lightest)
        cause = name(dense_o) + " is " + short_number(densest / lightest) + " times denser than " + name(light_o) +
                ", which it crushes: raise the lighter body's young or lower the density ratio";
    else
        cause = "the time step " + short_number(h) +
                " s is too large for this material and its contacts: lower dt, "
                "raise substeps or (vbd) iterations";
    return what + "; likely cause: " + cause;
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
        return "vertex " + std::to_string(far_vertex) + " is " + short_number(far) +
               " from the scene centre, beyond the " + short_number(reach) +
               " it could reach on the energy available at start";
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

std::string FailureCheck::likely_cause(const Scene& scene, double h, double dt_limit,
                                       const ContactResponse& contacts) const
{
    if (scene.integrator == Integrator::symplectic_euler && h > dt_limit)
        return "the time step " + short_number(h) + " s exceeds the explicit stability limit ≈ " +
               short_number(dt_limit) +
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
    return "stiffness too high for the time step " + short_number(h) + " s (explicit limit ≈ " +
           short_number(dt_limit) + " s): lower dt or raise substeps" +
           (scene.integrator == Integrator::vbd ? std::string(" or iterations") : std::string(", or use vbd"));
}

} // namespace tethash::sim
