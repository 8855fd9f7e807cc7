#pragma once
// A small finite-element code: linear tetrahedra, co-rotational linear elasticity, lumped mass, implicit Euler
// with Newton iterations on Eigen's sparse LDLT, Dirichlet boundary conditions. Contact is a separate module
// (contact.hpp) called inside every Newton iteration.

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <cstdint>
#include <functional>
#include <vector>

namespace fem {

using Vec = Eigen::VectorXd;
using Triplets = std::vector<Eigen::Triplet<double>>;

/// Node coordinates x0 y0 z0 x1 ... (3n), tets as 4 node ids each (4m), one object id per node and per tet.
struct Mesh {
    Vec rest;
    std::vector<std::int32_t> tets;
    std::vector<std::int32_t> node_object, tet_object;
    int nodes() const { return static_cast<int>(rest.size() / 3); }
    int elements() const { return static_cast<int>(tets.size() / 4); }
};

/// Cubes (i, j, k), 0 ≤ i < nx ..., of edge h from `origin` where keep(i, j, k), each split into 6 tets (Kuhn, so
/// neighbours share faces), as object `object`. Lattice points of no kept cube are left out.
Mesh lattice(int nx, int ny, int nz, double h, const Eigen::Vector3d& origin,
             const std::function<bool(int, int, int)>& keep, int object);
/// Appends b's nodes and tets to a (ids shifted, object ids kept).
void append(Mesh& a, const Mesh& b);

struct Material {
    double young = 1e5;   ///< Young's modulus E [Pa]
    double poisson = 0.3; ///< Poisson ratio ν
    double density = 1e3; ///< [kg/m³]
};

/// Co-rotational linear elasticity (Müller and Gross 2004, "warped stiffness"): per element the rotation R of the
/// deformation gradient (polar decomposition), the linear element stiffness K0 in the rotated frame.
class Elasticity {
  public:
    Elasticity(const Mesh& mesh, const Material& material);
    /// Lumped mass per degree of freedom (3n): a quarter of each tet's mass to each of its nodes.
    const Vec& mass() const { return m_mass; }
    /// At positions x (3n): adds the elastic forces to f, the stiffness R K0 Rᵀ to K (if given); returns the
    /// elastic energy ½ uᵀ K0 u, u = Rᵀx − X per element.
    double add(const Vec& x, Vec& f, Triplets* K) const;
    double smallest_edge() const { return m_min_edge; }

  private:
    struct Element {
        int node[4];
        Eigen::Matrix3d inv_rest;         ///< Dm⁻¹, Dm = [X1−X0, X2−X0, X3−X0]
        Eigen::Matrix<double, 12, 12> K0; ///< V Bᵀ D B
    };
    std::vector<Element> m_elements;
    Vec m_rest, m_mass;
    double m_min_edge = 0;
};

} // namespace fem
