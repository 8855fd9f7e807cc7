// Backward Euler linearised once per substep (Baraff & Witkin 1998): with K = −∂f/∂x and C = −∂f/∂v at the
// start of the substep, (M + hC + h²K) v⁺ = M v + h f + h C v, then x⁺ = x + h v⁺. Solved matrix-free by
// Jacobi-preconditioned CG, or assembled and factorised (SimplicialLDLT) for extreme conditioning. Kept as the
// reference for studies; the default integrator is block descent (block_descent.cpp).
#include "integrator.hpp"

#include "tethash/error.hpp"

#include <Eigen/SparseCholesky>

#include <algorithm>

namespace tethash::sim {

namespace {

using SpMat = Eigen::SparseMatrix<double>;

class ImplicitEuler final : public StepIntegrator {
  public:
    explicit ImplicitEuler(const StepContext& ctx) : m_ctx(ctx) {}

    int substep(Positions& x, Positions& v, double h) override
    {
        const Model& model = m_ctx.model;
        const ContactResponse& contacts = m_ctx.contacts;
        const Scene& scene = m_ctx.scene;
        const Index n = x.rows();
        const Index N = 3 * n;
        m_force.setZero(n, 3);
        Model::ForceOptions opt;
        opt.h = h;
        model.add_forces(x, v, m_force, opt);
        contacts.add_forces(v, m_force, h, false);
        const bool cin = scene.contact.in_matrix;
        const Eigen::VectorXd vflat = Eigen::Map<const Eigen::VectorXd>(v.data(), N);
        Eigen::VectorXd cv = Eigen::VectorXd::Zero(N);
        model.apply_matrix(x, 0.0, 1.0, vflat, cv);
        if (cin) contacts.apply(0.0, 1.0, vflat, cv);
        Eigen::VectorXd rhs(N), mdiag(N);
        for (Index i = 0; i < n; ++i) {
            const bool fx = model.fixed[static_cast<size_t>(i)];
            const double m = model.mass[static_cast<size_t>(i)];
            for (int r = 0; r < 3; ++r) {
                mdiag[3 * i + r] = fx ? 1.0 : m;
                rhs[3 * i + r] = fx ? 0.0 : m * vflat[3 * i + r] + h * m_force(i, r) + h * cv[3 * i + r];
            }
        }
        Eigen::VectorXd vnew;
        int iterations = 0;
        if (scene.solver == LinearSolver::ldlt) {
            std::vector<Eigen::Triplet<double>> t;
            model.add_matrix_triplets(x, h * h, h, t);
            if (cin) contacts.add_triplets(h * h, h, t);
            for (Index k = 0; k < N; ++k)
                t.emplace_back(k, k, mdiag[k]);
            SpMat A(N, N);
            A.setFromTriplets(t.begin(), t.end());
            Eigen::SimplicialLDLT<SpMat> solver(A);
            if (solver.info() != Eigen::Success)
                throw RunFailure("the implicit Euler system matrix could not be factorised");
            vnew = solver.solve(rhs);
        } else {
            // Matrix-free preconditioned CG (Jacobi): no assembly, a few sweeps over springs and tets per iteration.
            m_lin.update(model, x, h * h, h);
            auto apply = [&](const Eigen::VectorXd& p, Eigen::VectorXd& out) {
                out = mdiag.cwiseProduct(p);
                m_lin.apply(p, out);
                if (cin) contacts.apply(h * h, h, p, out);
            };
            Eigen::VectorXd diag = mdiag;
            m_lin.add_diagonal(diag);
            if (cin) contacts.add_diagonal(h * h, h, diag);
            const Eigen::VectorXd inv = diag.cwiseInverse();
            vnew = vflat;
            for (Index i = 0; i < n; ++i)
                if (model.fixed[static_cast<size_t>(i)]) vnew.segment<3>(3 * i).setZero();
            Eigen::VectorXd r(N), z(N), p(N), ap(N);
            apply(vnew, ap);
            r = rhs - ap;
            const double bnorm = std::max(rhs.norm(), 1e-300);
            z = inv.cwiseProduct(r);
            p = z;
            double rz = r.dot(z);
            const int max_it = std::max<int>(200, static_cast<int>(N));
            while (iterations < max_it && r.norm() > scene.tolerance * bnorm) {
                apply(p, ap);
                const double pap = p.dot(ap);
                if (!(pap > 0)) break;
                const double alpha = rz / pap;
                vnew += alpha * p;
                r -= alpha * ap;
                z = inv.cwiseProduct(r);
                const double rz_new = r.dot(z);
                p = z + (rz_new / rz) * p;
                rz = rz_new;
                ++iterations;
            }
        }
        for (Index i = 0; i < n; ++i) {
            if (model.fixed[static_cast<size_t>(i)]) continue;
            v.row(i) = vnew.segment<3>(3 * i).transpose();
            x.row(i) += h * v.row(i);
        }
        return iterations;
    }

  private:
    StepContext m_ctx;
    Positions m_force;
    Model::Linearised m_lin; // operator cache; adjacency kept between substeps
};

} // namespace

std::unique_ptr<StepIntegrator> make_implicit_euler(const StepContext& ctx)
{
    return std::make_unique<ImplicitEuler>(ctx);
}

} // namespace tethash::sim
