#pragma once
// The block-descent sweep's elastic stencils, four vertices at a time (private to tethash::sim).
//
// A sweep solves one 3 × 3 Newton step per vertex; most of its time is gathering the vertex's springs and
// volume terms into a force and a Hessian. Vertices of one colour share no spring and no tet, so any four of
// them can be gathered together: the free vertices of each colour are sorted by their number of tets and
// springs and grouped by four (lanes), and each group's entries are stored lane-interleaved (entry e of the
// group holds that entry for the four lanes; a lane with fewer entries is padded with zero-stiffness ones).
// The gather then runs as four-wide arithmetic (AVX2 with fused multiply-adds where the processor has them,
// chosen at run time; TETHASH_SIMD=scalar forces the one-lane version, which computes the same terms).

#include <cstdint>

namespace tethash::sim::detail {

/// A spring seen from its end in each of four lanes (k = 0 pads). The sweeps stream these entries from memory, so
/// the stiffness (a scale) and the stretch at the start of the substep (a small difference, exactly 0 at rest) are
/// kept in single precision; the rest length, which the stretch is measured from, in double. 64 bytes: one cache
/// line.
struct alignas(32) SpringLanes {
    double rest[4];
    float k[4];
    float stretch_t[4];    ///< length − rest at the start of the substep (relative damping)
    std::int32_t other[4]; ///< the other end's vertex id
};

/// A volume term seen from one corner i in each of four lanes, in terms of W = 6V = (x_a − x_i) · N,
/// N = (x_b − x_a) × (x_c − x_a): energy ½ k36 (W − W0)², ∇_i W = −N (W is linear in x_i). k36 = 0 pads.
/// Single precision for the stiffness and the start-of-substep excess, as for springs. 128 bytes.
struct alignas(32) TetLanes {
    double w0[4];      ///< 6 V0
    float k36[4];      ///< k / (36 V0): the volume term's ½ (k/V0) (V − V0)² in W
    float excess_t[4]; ///< W − W0 at the start of the substep (relative damping)
    std::int32_t a[4], b[4], c[4];
    float guard[4]; ///< the inversion guard's floor τ on W (guard_fraction · W0); 0: not guarded (padding)
};

/// Four vertices of one colour and their entries.
struct alignas(32) LaneGroup {
    double damping[4];      ///< each lane's object damping time (s)
    std::int32_t vertex[4]; ///< vertex ids; a padding lane repeats lane 0 and is not written
    std::int32_t lanes;     ///< real lanes (1 … 4)
    std::int32_t spring_begin, spring_end, tet_begin, tet_end;
};

/// The inversion guard: a vertex's step keeps each of its guarded tets (all but slivers) that has W above the floor
/// τ = guard_fraction · W0 above it, and does not lower one below it (W is linear in the vertex's position, so this
/// is exact): a tet that enters the sweeps with W > 0 leaves them so. The block-descent header says the rest.
inline constexpr double guard_fraction = 0.1;

/// The elastic part of four vertices' local problems: force f = −∇E and Hessian H (xx, yy, zz, xy, xz, yz),
/// lane by lane, with relative damping over the substep (inv_h = 1 / h); and reach2, the squared length of a step
/// in any direction that lowers none of the lane's guarded tets with W > 0 by more than (W − τ)⁺: min over them of
/// ((W − τ)⁺ / |N|)² (infinite without such a tet). A step shorter than 0.9 × reach needs no further guard.
struct LaneTerms {
    alignas(32) double f[3][4];
    alignas(32) double H[6][4];
    alignas(32) double reach2[4];
};

/// Positions are given with a stride of 4 doubles (x, y, z, unused), 32-byte aligned.
using GatherFn = void (*)(const LaneGroup& g, const SpringLanes* springs, const TetLanes* tets, const double* x,
                          double inv_h, LaneTerms& out);

/// Sets stretch_t and excess_t of a group's entries (every lane, padding included) from positions x: how far the
/// lengths and volumes are from their rest values at the start of the substep, for the relative damping.
using StartFn = void (*)(const LaneGroup& g, SpringLanes* springs, TetLanes* tets, const double* x);

/// The fraction (0 … 1] of lane l's step d that the inversion guard allows: min(1, 0.9 t) with t the largest factor
/// that lowers none of its guarded tets with W > 0 by more than (W − τ)⁺, given x before the step.
double guarded_fraction(const LaneGroup& g, const TetLanes* tets, int l, const double* x, const double d[3]);

/// The start-of-substep pass matching choose_gather().
StartFn choose_start(GatherFn gather);

/// Solves the four lanes' H d = f by Cholesky (H as in LaneTerms). Returns a bit mask of the lanes whose H is
/// positive definite (their d is set; the others' is not).
using SolveFn = int (*)(const LaneTerms& t, double d[3][4]);

/// The solve matching choose_gather().
SolveFn choose_solve(GatherFn gather);

/// The gather for this processor (AVX2 + FMA or one lane at a time; TETHASH_SIMD=scalar forces the latter).
/// Without `inversion_guard` it leaves LaneTerms::reach2 infinite and spends nothing on it (the default path).
GatherFn choose_gather(bool inversion_guard = false);

/// "avx2" or "scalar": what choose_gather() returns.
const char* gather_kernel_name(GatherFn fn);

} // namespace tethash::sim::detail
