#include "simd.hpp"

#include <cstdlib>
#include <cstring>

namespace tethash::detail {

bool avx2_kernels(bool fma)
{
    const char* env = std::getenv("TETHASH_SIMD");
    return !(env && std::strcmp(env, "scalar") == 0) && cpu_has_avx2(fma);
}

bool cpu_has_avx2(bool fma)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && (!fma || __builtin_cpu_supports("fma"));
#else
    (void)fma;
    return false;
#endif
}

} // namespace tethash::detail
