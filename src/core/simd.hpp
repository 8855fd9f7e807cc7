// Which kernels run: the wide ones (AVX2, compiled with target attributes, so one build runs everywhere) where the
// processor has them, unless TETHASH_SIMD=scalar asks for the scalar ones (what a machine without AVX2 runs; CI
// runs the kernels' tests that way too). Private to the libraries (core and sim include it as "core/simd.hpp").
#pragma once

namespace tethash::detail {

/// The processor has AVX2 (and FMA, when `fma`): the AVX2 kernels can run (tests compare them with the scalar ones).
bool cpu_has_avx2(bool fma = false);
/// True when the AVX2 kernels may run: cpu_has_avx2(fma) and TETHASH_SIMD is not "scalar". Read by each kernel
/// family once, when it chooses its kernel.
bool avx2_kernels(bool fma = false);

} // namespace tethash::detail
