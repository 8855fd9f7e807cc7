#include "simulation.hpp"

#include <Eigen/SparseCholesky>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace fem {

namespace {
double ms_since(std::chrono::steady_clock::time_point t0)
{
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
} // namespace

Simulation::Simulation(const Mesh& mesh, const Material& material, const ContactSettings& contact,
                       const SimulationSettings& settings)
    : m_mesh(mesh), m_elastic(mesh, material), m_contact(mesh, contact), m_settings(settings), m_x(mesh.rest),
      m_v(Vec::Zero(mesh.rest.size())), m_load(Vec::Zero(mesh.rest.size())),
      m_gravity_force(Vec::Zero(mesh.rest.size())), m_fixed(static_cast<size_t>(mesh.nodes()), 0)
{
    for (int i = 0; i < mesh.nodes(); ++i)
        m_gravity_force.segment<3>(3 * i) = m_elastic.mass().segment<3>(3 * i).cwiseProduct(settings.gravity);
}

int Simulation::step()
{
    const auto n3 = m_x.size();
    const double h = m_settings.dt, alpha = m_settings.damping;
    const Vec& M = m_elastic.mass();
    const Vec x_prev = m_x, v_prev = m_v;
    const Vec x_pred = x_prev + h * v_prev;
    // Free degrees of freedom, numbered.
    std::vector<int> free(static_cast<size_t>(n3), -1);
    int nf = 0;
    for (Eigen::Index d = 0; d < n3; ++d)
        if (!m_fixed[static_cast<size_t>(d / 3)]) free[static_cast<size_t>(d)] = nf++;
    // Predictor: xₙ + h vₙ on the free dofs.
    for (Eigen::Index d = 0; d < n3; ++d)
        if (free[static_cast<size_t>(d)] >= 0) m_x[d] = x_pred[d];
    const Vec f_ext = m_load + m_gravity_force;
    m_contact.begin_step();
    const double f_scale = std::max(1.0, f_ext.lpNorm<Eigen::Infinity>());

    // The incremental potential Φ(x) = ½|x − x̃|²_M/h² + α/(2h)|x − xₙ|²_M + E_elastic + E_penalty − f_ext·x, whose
    // gradient is the residual g: evaluated at x with the stiffness (tethash runs here, once per evaluation).
    Vec f(n3), g(n3), rhs(nf);
    Triplets K, reduced;
    double ms_tethash = 0;
    int evaluations = 0;
    auto evaluate = [&](const Vec& x) {
        ++evaluations;
        f = f_ext;
        K.clear();
        m_elastic_energy = m_elastic.add(x, f, &K);
        m_contact.add(x, f, &K, m_report);
        ms_tethash += m_report.ms_tethash;
        g = M.cwiseProduct(x - x_pred) / (h * h) + alpha * M.cwiseProduct(x - x_prev) / h - f;
        const Vec a = x - x_pred, b = x - x_prev;
        return 0.5 * a.dot(M.cwiseProduct(a)) / (h * h) + 0.5 * alpha * b.dot(M.cwiseProduct(b)) / h +
               m_elastic_energy + m_report.energy - f_ext.dot(x);
    };
    auto residual = [&] {
        double g_max = 0;
        for (Eigen::Index d = 0; d < n3; ++d)
            if (free[static_cast<size_t>(d)] >= 0) {
                rhs[free[static_cast<size_t>(d)]] = -g[d];
                g_max = std::max(g_max, std::abs(g[d]));
            }
        return g_max;
    };

    auto free_norm = [&] {
        double sum = 0;
        for (Eigen::Index d = 0; d < n3; ++d)
            if (free[static_cast<size_t>(d)] >= 0) sum += g[d] * g[d];
        return std::sqrt(sum);
    };
    Eigen::SparseMatrix<double> A(nf, nf);
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
    auto t0 = std::chrono::steady_clock::now();
    double phi = evaluate(m_x);
    int it = 0;
    m_converged = false;
    for (; it < m_settings.max_newton; ++it) {
        if (residual() < m_settings.tolerance * f_scale) {
            m_converged = true;
            break;
        }
        reduced.clear();
        for (const auto& t : K) {
            const int r = free[static_cast<size_t>(t.row())], c = free[static_cast<size_t>(t.col())];
            if (r >= 0 && c >= 0) reduced.emplace_back(r, c, t.value());
        }
        for (Eigen::Index d = 0; d < n3; ++d)
            if (free[static_cast<size_t>(d)] >= 0)
                reduced.emplace_back(free[static_cast<size_t>(d)], free[static_cast<size_t>(d)],
                                     M[d] / (h * h) + alpha * M[d] / h);
        A.setFromTriplets(reduced.begin(), reduced.end());
        solver.compute(A);
        if (solver.info() != Eigen::Success) throw std::runtime_error("Newton: factorization failed");
        const Vec dx = solver.solve(rhs);
        Vec step = Vec::Zero(n3);
        for (Eigen::Index d = 0; d < n3; ++d)
            if (free[static_cast<size_t>(d)] >= 0) step[d] = dx[free[static_cast<size_t>(d)]];
        // Backtracking (Armijo) on Φ: contact switching on and off makes full steps overshoot.
        // A step is also taken when it lowers the residual: the penalty's depth is an estimate, its force not
        // exactly the gradient of ½ k d², so near the solution Φ alone can stall.
        const double slope = g.dot(step); // < 0: A is positive definite
        const double g_norm = free_norm();
        const Vec x0 = m_x;
        double t = 1;
        for (int ls = 0; ls < 12; ++ls, t *= 0.5) {
            m_x = x0 + t * step;
            const double phi_new = evaluate(m_x);
            if (phi_new <= phi + 1e-4 * t * slope || free_norm() < (1 - 1e-4 * t) * g_norm || ls == 11) {
                phi = phi_new;
                break;
            }
        }
        m_timings.push_back({ms_since(t0), ms_tethash, m_report.reused, evaluations});
        t0 = std::chrono::steady_clock::now();
        ms_tethash = 0;
        evaluations = 0;
        // Stop when the step no longer moves anything (round-off), or when the line search had to cut it below
        // 1/64 (m_residual reports what was left).
        if (t * step.lpNorm<Eigen::Infinity>() < 1e-12 * m_elastic.smallest_edge() || t < 1.0 / 64) {
            m_converged = residual() < m_settings.tolerance * f_scale;
            ++it;
            break;
        }
    }
    m_residual = residual() / f_scale;
    m_v = (m_x - x_prev) / h;
    return it;
}

double Simulation::energy() const
{
    const double kinetic = 0.5 * m_v.dot(m_elastic.mass().cwiseProduct(m_v));
    const double potential = -(m_load + m_gravity_force).dot(m_x - m_mesh.rest);
    return kinetic + m_elastic_energy + m_report.energy + potential;
}

} // namespace fem
