#pragma once
/// \file ccd.hpp
/// Continuous collision detection (narrow phase) of a vertex against a triangle and of an edge against an edge,
/// for primitives moving linearly from their start positions (t = 0) to their end positions (t = 1).
///
/// Method. A contact is a root of F(t, u, v) over the closed domain t, u, v in [0, 1] (and u + v <= 1 for a
/// triangle):
///   vertex-face: F = p(t) - [a(t) + u (b(t) - a(t)) + v (c(t) - a(t))],
///   edge-edge:   F = [ea0(t) + u (ea1(t) - ea0(t))] - [eb0(t) + v (eb1(t) - eb0(t))],
/// with x(t) = x0 + t (x1 - x0) for every corner. Three filters run in order, each a proof of "no contact":
///  1. the swept boxes (the boxes of each primitive's start and end corners) are apart on an axis;
///  2. the four points are never coplanar: the coplanarity determinant is a cubic in t whose four Bernstein
///     coefficients are sums of 3 × 3 determinants of start and end edge vectors; when all four have one strict
///     sign, certified by a floating-point error bound (Shewchuk's, for determinants of rounded differences),
///     it has no root in [0, 1], and a contact needs coplanarity;
///  3. an inclusion search over boxes of (t, u, v): F is multilinear in (t, u, v), so its range over a box, and
///     the range of any fixed linear combination n · F, is inside the hull of its values at the 8 corners; each
///     corner value is computed in floating point with a proven error bound (64 ε max|coordinate| per axis, plus
///     1e-200 for underflow), and a box is discarded only when that enlarged range excludes 0 along an axis, along
///     the centre of the range, along a row of the adjugate of F's Jacobian over the box (a preconditioned
///     test: nearly the box's offset from the root), or, when that Jacobian is nearly singular (coplanar motion),
///     along in-plane directions normal to its columns. A box that may hold a root is split (along the parameter
///     that changes F most) until its range is at most `tolerance` wide on every axis, and is then accepted as a
///     contact at its earliest t. Boxes are searched depth first from the open box of least t, and cut to times
///     before the earliest accepted box; when no box is left, that earliest t is the time of impact.
///
/// Guarantee. No false negative: a box holding a root is never discarded, so every query with a contact in
/// [0, 1] (degenerate ones included: parallel or coplanar motion, sliding contact, contact at t = 0 or t = 1,
/// no motion, zero-length edges, degenerate triangles) is reported as colliding, and `toi` is no later than the
/// first contact. A reported contact means that at t = toi some point of the accepted (t, u, v) box brings the
/// primitives within `tolerance` + rounding of each other on every axis (u + v may exceed 1 by the box's size),
/// or that the iteration cap was reached (outcome `iteration_cap`, which promises nothing but is conservative).
/// False positives are therefore near misses closer than about `tolerance` (in the coordinates' units: scale it
/// with the scene) and capped searches.
///
/// Assumptions: coordinates finite with magnitude at most 1e50 (else Error). Rounding to nearest; no flush of
/// subnormals to zero; no -ffast-math.
///
/// Cost (tools/bench/ccd_bench.cpp; docs/ccd.md has the figures): a query the filters reject costs tens of
/// nanoseconds, a contact about 110 boxes (8 µs), degenerate contacts more, up to the cap.

#include "tethash/error.hpp"

#include <Eigen/Core>

#include <cstdint>

namespace tethash::ccd {

struct CcdParams {
    /// Width (coordinates' units, per axis) of the range of F over a box below which the box is reported as a
    /// contact. Positive and finite.
    double tolerance = 1e-6;
    /// Boxes examined at most by one search; reaching it reports a contact at the earliest t still open. At least 1.
    std::int64_t max_iterations = 1000000;
};

/// How a query was decided.
enum class CcdOutcome : std::uint8_t {
    boxes_apart,      ///< filter 1: no contact
    never_coplanar,   ///< filter 2: no contact
    excluded,         ///< the search discarded every box: no contact
    within_tolerance, ///< contact: a box's range holds 0 and is within the tolerance
    iteration_cap,    ///< contact assumed: the search reached max_iterations
};

struct CcdResult {
    bool hit = false; ///< the primitives may meet at some t in [0, 1] (never false when they do)
    double toi = 1.0; ///< when hit: a time in [0, 1] no later than the first contact; 1 otherwise
    CcdOutcome outcome = CcdOutcome::boxes_apart;
    std::int64_t iterations = 0; ///< boxes examined by the search (0 when a filter decided)
};

/// Vertex p against triangle (a, b, c): positions at t = 0 (p0, a0, b0, c0) and t = 1 (p1, a1, b1, c1).
/// Throws Error on a non-finite coordinate, a magnitude above 1e50 or bad parameters.
CcdResult vertex_face_ccd(const Eigen::Vector3d& p0, const Eigen::Vector3d& a0, const Eigen::Vector3d& b0,
                          const Eigen::Vector3d& c0, const Eigen::Vector3d& p1, const Eigen::Vector3d& a1,
                          const Eigen::Vector3d& b1, const Eigen::Vector3d& c1, const CcdParams& params = {});

/// Edge (ea0, ea1) against edge (eb0, eb1): positions at t = 0 (…_0) and t = 1 (…_1).
/// Throws Error on a non-finite coordinate, a magnitude above 1e50 or bad parameters.
CcdResult edge_edge_ccd(const Eigen::Vector3d& ea0_0, const Eigen::Vector3d& ea1_0, const Eigen::Vector3d& eb0_0,
                        const Eigen::Vector3d& eb1_0, const Eigen::Vector3d& ea0_1, const Eigen::Vector3d& ea1_1,
                        const Eigen::Vector3d& eb0_1, const Eigen::Vector3d& eb1_1, const CcdParams& params = {});

/// Name of an outcome ("boxes_apart", …).
const char* outcome_name(CcdOutcome outcome);

} // namespace tethash::ccd
