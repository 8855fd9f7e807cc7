#include "fem.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace fem {

Mesh lattice(int nx, int ny, int nz, double h, const Eigen::Vector3d& origin,
             const std::function<bool(int, int, int)>& keep, int object)
{
    auto point = [&](int i, int j, int k) { return (k * (ny + 1) + j) * (nx + 1) + i; };
    std::vector<int> id(static_cast<size_t>((nx + 1) * (ny + 1) * (nz + 1)), -1);
    Mesh m;
    std::vector<double> xyz;
    auto node = [&](int i, int j, int k) {
        int& n = id[static_cast<size_t>(point(i, j, k))];
        if (n < 0) {
            n = static_cast<int>(xyz.size() / 3);
            for (int a = 0; a < 3; ++a)
                xyz.push_back(origin[a] + h * (a == 0 ? i : a == 1 ? j : k));
        }
        return n;
    };
    // Kuhn split: the 6 monotone paths from corner (0,0,0) to (1,1,1) of each cube.
    static const int paths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                if (!keep(i, j, k)) continue;
                for (const auto& p : paths) {
                    int c[3] = {i, j, k};
                    int t[4];
                    t[0] = node(c[0], c[1], c[2]);
                    for (int s = 0; s < 3; ++s) {
                        ++c[p[s]];
                        t[s + 1] = node(c[0], c[1], c[2]);
                    }
                    m.tets.insert(m.tets.end(), t, t + 4);
                }
            }
    m.rest = Eigen::Map<const Vec>(xyz.data(), static_cast<Eigen::Index>(xyz.size()));
    // Positive orientation for every tet.
    for (int e = 0; e < m.elements(); ++e) {
        std::int32_t* t = &m.tets[4 * static_cast<size_t>(e)];
        Eigen::Matrix3d D;
        for (int c = 0; c < 3; ++c)
            D.col(c) = m.rest.segment<3>(3 * t[c + 1]) - m.rest.segment<3>(3 * t[0]);
        if (D.determinant() < 0) std::swap(t[2], t[3]);
    }
    m.node_object.assign(static_cast<size_t>(m.nodes()), object);
    m.tet_object.assign(static_cast<size_t>(m.elements()), object);
    return m;
}

void append(Mesh& a, const Mesh& b)
{
    const int base = a.nodes();
    Vec rest(a.rest.size() + b.rest.size());
    rest << a.rest, b.rest;
    a.rest = rest;
    for (std::int32_t t : b.tets)
        a.tets.push_back(t + base);
    a.node_object.insert(a.node_object.end(), b.node_object.begin(), b.node_object.end());
    a.tet_object.insert(a.tet_object.end(), b.tet_object.begin(), b.tet_object.end());
}

Elasticity::Elasticity(const Mesh& mesh, const Material& mat) : m_rest(mesh.rest), m_mass(Vec::Zero(mesh.rest.size()))
{
    if (!(mat.young > 0) || !(mat.poisson > -1 && mat.poisson < 0.5) || !(mat.density > 0))
        throw std::invalid_argument("material: need E > 0, -1 < nu < 0.5, density > 0");
    const double E = mat.young, nu = mat.poisson;
    const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
    Eigen::Matrix<double, 6, 6> D = Eigen::Matrix<double, 6, 6>::Zero();
    D.topLeftCorner<3, 3>().setConstant(lambda);
    D.topLeftCorner<3, 3>().diagonal().array() += 2 * mu;
    D.bottomRightCorner<3, 3>().diagonal().setConstant(mu);
    m_min_edge = std::numeric_limits<double>::infinity();
    m_elements.reserve(static_cast<size_t>(mesh.elements()));
    for (int e = 0; e < mesh.elements(); ++e) {
        Element el;
        Eigen::Matrix3d Dm;
        for (int a = 0; a < 4; ++a)
            el.node[a] = mesh.tets[4 * static_cast<size_t>(e) + static_cast<size_t>(a)];
        for (int c = 0; c < 3; ++c)
            Dm.col(c) = m_rest.segment<3>(3 * el.node[c + 1]) - m_rest.segment<3>(3 * el.node[0]);
        const double volume = Dm.determinant() / 6;
        if (!(volume > 0)) throw std::invalid_argument("element " + std::to_string(e) + " has volume ≤ 0");
        for (int a = 0; a < 4; ++a)
            for (int b = a + 1; b < 4; ++b)
                m_min_edge = std::min(m_min_edge,
                                      (m_rest.segment<3>(3 * el.node[a]) - m_rest.segment<3>(3 * el.node[b])).norm());
        el.inv_rest = Dm.inverse();
        // Shape function gradients: rows of Dm⁻¹ for nodes 1..3, minus their sum for node 0.
        Eigen::Matrix<double, 4, 3> grad;
        grad.bottomRows<3>() = el.inv_rest;
        grad.row(0) = -el.inv_rest.colwise().sum();
        Eigen::Matrix<double, 6, 12> B = Eigen::Matrix<double, 6, 12>::Zero();
        for (int a = 0; a < 4; ++a) {
            const double bx = grad(a, 0), by = grad(a, 1), bz = grad(a, 2);
            const int c = 3 * a;
            B(0, c) = bx;
            B(1, c + 1) = by;
            B(2, c + 2) = bz;
            B(3, c) = by; // γxy
            B(3, c + 1) = bx;
            B(4, c + 1) = bz; // γyz
            B(4, c + 2) = by;
            B(5, c) = bz; // γzx
            B(5, c + 2) = bx;
        }
        el.K0 = volume * B.transpose() * D * B;
        for (int a = 0; a < 4; ++a)
            m_mass.segment<3>(3 * el.node[a]).array() += mat.density * volume / 4;
        m_elements.push_back(el);
    }
}

double Elasticity::add(const Vec& x, Vec& f, Triplets* K) const
{
    double energy = 0;
    for (const Element& el : m_elements) {
        Eigen::Matrix3d Ds;
        for (int c = 0; c < 3; ++c)
            Ds.col(c) = x.segment<3>(3 * el.node[c + 1]) - x.segment<3>(3 * el.node[0]);
        const Eigen::Matrix3d F = Ds * el.inv_rest;
        const Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
        Eigen::Matrix3d U = svd.matrixU();
        const Eigen::Matrix3d V = svd.matrixV();
        if ((U * V.transpose()).determinant() < 0) U.col(2) *= -1; // a rotation, also for inverted elements
        const Eigen::Matrix3d R = U * V.transpose();
        Eigen::Matrix<double, 12, 1> u;
        for (int a = 0; a < 4; ++a)
            u.segment<3>(3 * a) = R.transpose() * x.segment<3>(3 * el.node[a]) - m_rest.segment<3>(3 * el.node[a]);
        const Eigen::Matrix<double, 12, 1> local = el.K0 * u;
        energy += 0.5 * u.dot(local);
        for (int a = 0; a < 4; ++a)
            f.segment<3>(3 * el.node[a]) -= R * local.segment<3>(3 * a);
        if (!K) continue;
        for (int a = 0; a < 4; ++a)
            for (int b = 0; b < 4; ++b) {
                const Eigen::Matrix3d block = R * el.K0.block<3, 3>(3 * a, 3 * b) * R.transpose();
                for (int r = 0; r < 3; ++r)
                    for (int c = 0; c < 3; ++c)
                        K->emplace_back(3 * el.node[a] + r, 3 * el.node[b] + c, block(r, c));
            }
    }
    return energy;
}

} // namespace fem
