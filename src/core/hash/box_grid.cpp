#include "box_grid.hpp"

#include "../simd.hpp"

#include <algorithm>
#include <limits>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define TETHASH_X86 1
#endif

namespace tethash::detail {

namespace {

std::int32_t box_filter_scalar(const float* const box[6], std::int32_t begin, std::int32_t end, const float q[6],
                               std::int32_t* hits)
{
    std::int32_t n = 0;
    for (std::int32_t e = begin; e < end; ++e) {
        const size_t u = static_cast<size_t>(e);
        if ((q[3] < box[0][u]) | (q[0] > box[3][u]) | (q[4] < box[1][u]) | (q[1] > box[4][u]) | (q[5] < box[2][u]) |
            (q[2] > box[5][u]))
            continue;
        hits[n++] = e;
    }
    return n;
}

#ifdef TETHASH_X86
/// Eight entries at a time (the columns are padded by eight, so the last group's loads stay inside).
__attribute__((target("avx2"))) std::int32_t box_filter_avx2(const float* const box[6], std::int32_t begin,
                                                             std::int32_t end, const float q[6], std::int32_t* hits)
{
    const __m256 qlo0 = _mm256_set1_ps(q[0]), qlo1 = _mm256_set1_ps(q[1]), qlo2 = _mm256_set1_ps(q[2]);
    const __m256 qhi0 = _mm256_set1_ps(q[3]), qhi1 = _mm256_set1_ps(q[4]), qhi2 = _mm256_set1_ps(q[5]);
    std::int32_t n = 0;
    for (std::int32_t e = begin; e < end; e += 8) {
        const size_t u = static_cast<size_t>(e);
        __m256 miss = _mm256_cmp_ps(qhi0, _mm256_loadu_ps(box[0] + u), _CMP_LT_OQ);
        miss = _mm256_or_ps(miss, _mm256_cmp_ps(qlo0, _mm256_loadu_ps(box[3] + u), _CMP_GT_OQ));
        miss = _mm256_or_ps(miss, _mm256_cmp_ps(qhi1, _mm256_loadu_ps(box[1] + u), _CMP_LT_OQ));
        miss = _mm256_or_ps(miss, _mm256_cmp_ps(qlo1, _mm256_loadu_ps(box[4] + u), _CMP_GT_OQ));
        miss = _mm256_or_ps(miss, _mm256_cmp_ps(qhi2, _mm256_loadu_ps(box[2] + u), _CMP_LT_OQ));
        miss = _mm256_or_ps(miss, _mm256_cmp_ps(qlo2, _mm256_loadu_ps(box[5] + u), _CMP_GT_OQ));
        unsigned meet = ~static_cast<unsigned>(_mm256_movemask_ps(miss)) & 0xffu;
        if (end - e < 8) meet &= (1u << (end - e)) - 1;
        while (meet) {
            hits[n++] = e + __builtin_ctz(meet);
            meet &= meet - 1;
        }
    }
    return n;
}
#endif

BoxFilter choose_box_filter()
{
#ifdef TETHASH_X86
    if (avx2_kernels()) return box_filter_avx2;
#endif
    return box_filter_scalar;
}

} // namespace

extern const BoxFilter chosen_box_filter = choose_box_filter();

std::vector<std::pair<const char*, BoxFilter>> box_filters()
{
    std::vector<std::pair<const char*, BoxFilter>> all{{"scalar", box_filter_scalar}};
#ifdef TETHASH_X86
    if (cpu_has_avx2()) all.emplace_back("avx2", box_filter_avx2);
#endif
    return all;
}

const char* box_filter_name()
{
    return chosen_box_filter == box_filter_scalar ? "scalar" : "avx2";
}

void BoxGrid::lay_out(std::size_t entries)
{
    for (int k = 0; k < 3; ++k) {
        m_column[k].resize(entries + 8);
        m_column[3 + k].resize(entries + 8);
        std::fill(m_column[k].begin() + static_cast<std::ptrdiff_t>(entries), m_column[k].end(),
                  std::numeric_limits<float>::infinity());
        std::fill(m_column[3 + k].begin() + static_cast<std::ptrdiff_t>(entries), m_column[3 + k].end(),
                  -std::numeric_limits<float>::infinity());
    }
    m_item.resize(entries);
}

} // namespace tethash::detail
