#pragma once
// Implicit Euler with Newton iterations: find x such that
//   g(x) = M (x − xₙ − h vₙ)/h² + α M (x − xₙ)/h − f_elastic(x) − f_contact(x) − f_external = 0
// on the free degrees of freedom (Dirichlet nodes stay where they are), solving
//   (M/h² + α M/h + K_elastic + K_contact) Δx = −g
// with Eigen's SimplicialLDLT. α is mass-proportional (Rayleigh) damping.

#include "contact.hpp"
#include "fem.hpp"

#include <vector>

namespace fem {

struct SimulationSettings {
    double dt = 0.01;   ///< time step h [s]
    double damping = 0; ///< α [1/s]
    Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
    int max_newton = 20;
    double tolerance =
        1e-5; ///< on max |g| relative to the largest nodal load, and on max |Δx| relative to the smallest edge
};

/// Time of each Newton iteration and of tethash's part in it (milliseconds).
struct IterationTiming {
    double ms_total = 0, ms_tethash = 0;
    bool reused = false;
    int evaluations = 0; ///< force evaluations (each one detection): 1 + line-search trials
};

class Simulation {
  public:
    Simulation(const Mesh& mesh, const Material& material, const ContactSettings& contact,
               const SimulationSettings& settings);
    /// Nodes whose position is fixed (Dirichlet); external nodal loads (3n, constant in time).
    void fix(int node) { m_fixed[static_cast<size_t>(node)] = 1; }
    void set_load(const Vec& load) { m_load = load; }

    /// One implicit Euler step; returns the Newton iterations made.
    int step();

    const Vec& x() const { return m_x; }
    const Vec& v() const { return m_v; }
    const Mesh& mesh() const { return m_mesh; }
    const Elasticity& elasticity() const { return m_elastic; }
    /// Contacts at the end of the last step.
    const ContactReport& contact() const { return m_report; }
    /// Exact depths of those contacts (distance to the penetrated surface).
    std::vector<double> exact_depths() const { return m_contact.exact_depths(m_x, m_report); }
    /// Kinetic + elastic + penalty energy minus the work potential of gravity and loads (measured from the rest
    /// state): non-increasing up to the integrator's and the contact model's errors.
    double energy() const;
    const std::vector<IterationTiming>& timings() const { return m_timings; }
    bool converged() const { return m_converged; }
    /// max |g| over the free dofs at the end of the last step, relative to the largest nodal load.
    double residual() const { return m_residual; }

  private:
    Mesh m_mesh;
    Elasticity m_elastic;
    ContactModule m_contact;
    SimulationSettings m_settings;
    Vec m_x, m_v, m_load, m_gravity_force;
    std::vector<char> m_fixed;
    ContactReport m_report;
    double m_elastic_energy = 0;
    std::vector<IterationTiming> m_timings;
    bool m_converged = true;
    double m_residual = 0;
};

} // namespace fem
