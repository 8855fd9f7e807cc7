#pragma once
/// \file predicates.hpp
/// Exact orientation and closed point-in-tetrahedron tests on double coordinates.
///
/// Convention: orient3d(a, b, c, d) = det[b − a, c − a, d − a] = 6 × the signed volume of the tet
/// (a, b, c, d), positive for the positive orientation used by mesh.hpp's signed_volume().
/// The sign returned is the sign of the exact real value of that determinant for the given doubles
/// (no rounding): a floating-point evaluation with Shewchuk's forward error bound decides almost
/// always; when it cannot, the determinant is evaluated exactly in expansion arithmetic.
/// Assumes no overflow or underflow in the products (coordinates between about 1e-90 and 1e90 in
/// magnitude, or zero).

#include <cstdint>

namespace tethash::predicates {

/// Unit roundoff of double (2^-53).
inline constexpr double epsilon = 1.1102230246251565e-16;
/// Relative error bound of the floating-point orient3d evaluation (Shewchuk's (7 + 56ε)ε, rounded up
/// to 8ε to also cover fused multiply-add contractions).
inline constexpr double orient3d_error_bound = 8.0 * epsilon;

/// Result of an orientation evaluation: the exact sign and an approximation of the value.
struct Orientation {
    int sign = 0;       ///< −1, 0 or +1: the sign of the exact determinant
    double value = 0;   ///< floating-point approximation (0 exactly when sign == 0)
    bool exact = false; ///< true when the filter could not decide and exact arithmetic was used
};

/// Exact orientation with filter. Points are 3 doubles each.
Orientation orient3d(const double* a, const double* b, const double* c, const double* d);
/// Exact orientation without filter (always expansion arithmetic); for tests and fallbacks.
Orientation orient3d_exact(const double* a, const double* b, const double* c, const double* d);

/// Closed inside test of point p in tet (a, b, c, d): exact.
struct InsideResult {
    bool degenerate = false;       ///< the tet has zero volume (exact): never contains anything
    bool inside = false;           ///< p lies in the closed tet (on faces, edges, corners included)
    int exact_evaluations = 0;     ///< how many of the orientations needed exact arithmetic
    double bary[4] = {0, 0, 0, 0}; ///< barycentric coordinates (valid when inside); exact zeros where p is on a face
};
InsideResult inside_tet(const double* p, const double* a, const double* b, const double* c, const double* d);

/// Orientations of the four sub-tets with p replacing vertex i, in the order i = 0..3:
/// orient3d(p,b,c,d), orient3d(a,p,c,d), orient3d(a,b,p,d), orient3d(a,b,c,p).
/// Their exact sum equals orient3d(a,b,c,d).

} // namespace tethash::predicates
