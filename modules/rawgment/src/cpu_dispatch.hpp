// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Run-time dispatch of the hot loops to the instruction sets of opencv2/rawgment/cpu.hpp.
//
// A hot loop is written once, as an always-inline kernel on the vector types of lanes.hpp (GCC's vector
// extensions, or arrays of lanes on the portable path) or plain loops, and
// RAWGMENT_DISPATCHED compiles that one source four times, for x86-64, x86-64-v2, -v3 and -v4, and
// defines the entry point that calls the version of the active CpuPath. The vectors are written at one
// width in every version (the compiler splits them into registers), or, for kernels that compare and
// select, at the native width of each path (RAWGMENT_DISPATCHED_BY_WIDTH); either way every version runs
// full-width vector code and performs the same operations lane by lane.
// With -ffp-contract=off (the module's CMakeLists.txt) no version fuses a multiply and an add, so all
// give the same bits.
#ifndef OPENCV_RAWGMENT_SRC_CPU_DISPATCH_HPP
#define OPENCV_RAWGMENT_SRC_CPU_DISPATCH_HPP

#include "lanes.hpp"

#include <opencv2/rawgment/cpu.hpp>

#include <cmath>
#include <cstdint>

namespace cv {
namespace rawgment {
namespace detail {

//! The path the dispatchers call: activeCpuPath() (an invalid RAWGMENT_CPU_PATH throws from the first
//! hot loop).
CpuPath dispatchPath();

//! The vectors of a kernel of width W (RAWGMENT_DISPATCHED_BY_WIDTH): W floats, int32, uint32, uint16.
template <int W> struct Lanes
{
    typedef RAWGMENT_VECTOR(float, 4 * W) F;
    typedef RAWGMENT_VECTOR(int32_t, 4 * W) I;
    typedef RAWGMENT_VECTOR(uint32_t, 4 * W) U;
    typedef RAWGMENT_VECTOR(uint16_t, 2 * W) U16;
};

//! The widest kernel width, AVX-512's 16 floats. A row buffer of the module sized by wholeBlocks() lets
//! a kernel of any width run its last block over the row's end (on values it does not store) instead
//! of handling a partial block.
constexpr int kWidestLanes = 16;
inline size_t wholeBlocks(int n)
{
    return static_cast<size_t>((n + kWidestLanes - 1) / kWidestLanes * kWidestLanes);
}

//! Lane-wise std::max and std::min (the same operand chosen when one is NaN).
template <typename V> RAWGMENT_ALWAYS_INLINE V maxLanes(V a, V b)
{
    return selectLanes(a < b, b, a);
}
template <typename V> RAWGMENT_ALWAYS_INLINE V minLanes(V a, V b)
{
    return selectLanes(b < a, b, a);
}

//! IEEE square roots lane by lane, of float or double lanes: exact to the rounding on every path,
//! compiled to (v)sqrtps or (v)sqrtpd.
template <typename V> RAWGMENT_ALWAYS_INLINE V sqrtLanes(V v)
{
    V r;
    for (int i = 0; i < static_cast<int>(sizeof(V) / sizeof(v[0])); ++i)
        r[i] = std::sqrt(v[i]);
    return r;
}

} // namespace detail
} // namespace rawgment
} // namespace cv

/* A kernel's helpers are inlined into each path's entry point and so compiled for its target. Not so a
 * lambda's body: it is a function of its own, compiled for the baseline, which on AVX2 then passes 256-bit
 * vectors to the AVX helpers by another ABI (GCC's -Wpsabi, which the build silences). Such a lambda once
 * gave wrong Poisson counts on the AVX2 path only; a kernel's helper is a RAWGMENT_KERNEL function. */
#define RAWGMENT_KERNEL static RAWGMENT_ALWAYS_INLINE

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(RAWGMENT_NO_MULTIVERSIONING)
#define RAWGMENT_HAVE_CPU_PATHS 1
/* The four versions of `name##Kernel` (instantiated as `name##Kernel w512`, `w256`, `w128`: empty, or
 * a template width) and the entry point `ret name params` that calls the active path's. */
#define RAWGMENT_DISPATCHED_AS(ret, name, params, args, w512, w256, w128)                                    \
    __attribute__((target("arch=x86-64-v4"))) static ret name##Avx512 params                                 \
    {                                                                                                        \
        return name##Kernel w512 args;                                                                       \
    }                                                                                                        \
    __attribute__((target("arch=x86-64-v3"))) static ret name##Avx2 params                                   \
    {                                                                                                        \
        return name##Kernel w256 args;                                                                       \
    }                                                                                                        \
    __attribute__((target("arch=x86-64-v2"))) static ret name##Sse42 params                                  \
    {                                                                                                        \
        return name##Kernel w128 args;                                                                       \
    }                                                                                                        \
    static ret name##Baseline params                                                                         \
    {                                                                                                        \
        return name##Kernel w128 args;                                                                       \
    }                                                                                                        \
    ret name params                                                                                          \
    {                                                                                                        \
        switch (::cv::rawgment::detail::dispatchPath()) {                                                    \
        case ::cv::rawgment::CpuPath::AVX512:                                                                \
            return name##Avx512 args;                                                                        \
        case ::cv::rawgment::CpuPath::AVX2:                                                                  \
            return name##Avx2 args;                                                                          \
        case ::cv::rawgment::CpuPath::SSE42:                                                                 \
            return name##Sse42 args;                                                                         \
        default:                                                                                             \
            return name##Baseline args;                                                                      \
        }                                                                                                    \
    }
#else
#define RAWGMENT_HAVE_CPU_PATHS 0
#define RAWGMENT_DISPATCHED_AS(ret, name, params, args, w512, w256, w128)                                    \
    ret name params                                                                                          \
    {                                                                                                        \
        return name##Kernel w128 args;                                                                       \
    }
#endif

/** Defines `ret name params` running `name##Kernel args` compiled for the active CpuPath. */
#define RAWGMENT_DISPATCHED(ret, name, params, args) RAWGMENT_DISPATCHED_AS(ret, name, params, args, , , )

/** As RAWGMENT_DISPATCHED, for a kernel template on its vector width in floats: `name##Kernel<W> args`
 * with W = 8 (AVX-512 and AVX2) or 4 (SSE). GCC lowers vectors wider than the registers piecewise, and
 * their comparisons and selections lane by lane in scalar code: a kernel with those runs at the native
 * width of each path.
 *
 * The AVX-512 path runs the 256-bit kernels compiled for AVX-512 (EVEX encodings, 32 vector registers,
 * masked operations), not 512-bit ones: on host H1 (Intel Xeon) 512-bit multiplies and float arithmetic
 * lower the core's clock, and 12 M standard normals took 12.9 ms at 16 lanes, 9.4 ms with 512-bit
 * Philox and 256-bit floats and 7.8 ms at 8 lanes (the AVX2 path: 8.8 ms), the jitter 14.7 ms at 16
 * lanes and 10.5 ms at 8 (docs/performance.md). On AMD's Zen 4 a 512-bit operation is two 256-bit ones,
 * so 16 lanes buy nothing there either. The kernels take any W, so a CPU where 512 bits pay needs only
 * <16> here. */
#define RAWGMENT_DISPATCHED_BY_WIDTH(ret, name, params, args)                                                \
    RAWGMENT_DISPATCHED_AS(ret, name, params, args, <8>, <8>, <4>)

#if RAWGMENT_HAVE_CPU_PATHS
#include <immintrin.h>
#endif

namespace cv {
namespace rawgment {
namespace detail {

#if RAWGMENT_HAVE_CPU_PATHS
// The sign bits of a 256-bit mask of float or double lanes in one instruction. Target v3, so that the
// kernels of the AVX2 and AVX-512 paths, the only ones with 256-bit masks, inline them.
__attribute__((target("arch=x86-64-v3"))) inline int signBits8x32(__m256 m)
{
    return _mm256_movemask_ps(m);
}
__attribute__((target("arch=x86-64-v3"))) inline int signBits4x64(__m256d m)
{
    return _mm256_movemask_pd(m);
}
// The 8-lane bodies of storeScaledAsDoubles() and differenceAsFloats() below, target v3 for the same reason.
__attribute__((target("arch=x86-64-v3"))) inline void storeScaledAsDoubles8(__m256 v, double scale,
                                                                            double* out)
{
    const __m256d s = _mm256_set1_pd(scale);
    _mm256_storeu_pd(out, _mm256_mul_pd(_mm256_cvtps_pd(_mm256_castps256_ps128(v)), s));
    _mm256_storeu_pd(out + 4, _mm256_mul_pd(_mm256_cvtps_pd(_mm256_extractf128_ps(v, 1)), s));
}
__attribute__((target("arch=x86-64-v3"))) inline __m256 differenceAsFloats8(const double* a, const double* b)
{
    const __m128 lo = _mm256_cvtpd_ps(_mm256_sub_pd(_mm256_loadu_pd(a), _mm256_loadu_pd(b)));
    const __m128 hi = _mm256_cvtpd_ps(_mm256_sub_pd(_mm256_loadu_pd(a + 4), _mm256_loadu_pd(b + 4)));
    return _mm256_insertf128_ps(_mm256_castps128_ps256(lo), hi, 1);
}
#endif

/** out[i] = double(v[i]) * scale for the W float lanes of v: the exact conversion, then the product rounded
 * to double, as __builtin_convertvector and a multiply give. GCC 12 lowers that conversion of a whole
 * kernel vector (8 doubles, two AVX registers) through the stack and general registers: the POISSON
 * jitter's split and noise passes took 3.5 ms more of its 77 on host H2's AVX2 path. So the x86 paths
 * convert half registers with cvtps2pd. */
template <typename F> RAWGMENT_ALWAYS_INLINE void storeScaledAsDoubles(F v, double scale, double* out)
{
    constexpr int lanes = static_cast<int>(sizeof(F) / sizeof(v[0]));
#if RAWGMENT_HAVE_CPU_PATHS
    if constexpr (lanes == 8) {
        storeScaledAsDoubles8((__m256)v, scale, out);
        return;
    }
    if constexpr (lanes == 4) {
        const __m128d s = _mm_set1_pd(scale);
        _mm_storeu_pd(out, _mm_mul_pd(_mm_cvtps_pd((__m128)v), s));
        _mm_storeu_pd(out + 2, _mm_mul_pd(_mm_cvtps_pd(_mm_movehl_ps((__m128)v, (__m128)v)), s));
        return;
    }
#endif
    for (int i = 0; i < lanes; ++i)
        out[i] = static_cast<double>(v[i]) * scale;
}

/** The W floats float(a[i] - b[i]): the difference rounded to double, then to float (to nearest), as
 * __builtin_convertvector of a double vector gives; with cvtpd2ps on half registers on x86, for the reason
 * storeScaledAsDoubles() gives. */
template <typename F> RAWGMENT_ALWAYS_INLINE F differenceAsFloats(const double* a, const double* b)
{
    constexpr int lanes = static_cast<int>(sizeof(F) / sizeof(float));
#if RAWGMENT_HAVE_CPU_PATHS
    if constexpr (lanes == 8)
        return (F)differenceAsFloats8(a, b);
    if constexpr (lanes == 4) {
        const __m128 lo = _mm_cvtpd_ps(_mm_sub_pd(_mm_loadu_pd(a), _mm_loadu_pd(b)));
        const __m128 hi = _mm_cvtpd_ps(_mm_sub_pd(_mm_loadu_pd(a + 2), _mm_loadu_pd(b + 2)));
        return (F)_mm_movelh_ps(lo, hi);
    }
#endif
    F r;
    for (int i = 0; i < lanes; ++i)
        r[i] = static_cast<float>(a[i] - b[i]);
    return r;
}

/** Bit i set where lane i of a comparison mask (lanes of 0 or -1, 4 or 8 bytes each) is set: a kernel
 * tests "any lane" or walks the set lanes with this. One movemask on x86 (reading a mask lane by lane
 * costs two instructions per lane, which showed in the samplers' profiles); a loop elsewhere. */
template <typename M> RAWGMENT_ALWAYS_INLINE int maskBits(M mask)
{
    constexpr int lanes = static_cast<int>(sizeof(M) / sizeof(mask[0]));
#if RAWGMENT_HAVE_CPU_PATHS
    if constexpr (sizeof(M) == 32 && sizeof(mask[0]) == 4)
        return signBits8x32((__m256)mask);
    if constexpr (sizeof(M) == 32 && sizeof(mask[0]) == 8)
        return signBits4x64((__m256d)mask);
    if constexpr (sizeof(M) == 16 && sizeof(mask[0]) == 4)
        return _mm_movemask_ps((__m128)mask);
    if constexpr (sizeof(M) == 16 && sizeof(mask[0]) == 8)
        return _mm_movemask_pd((__m128d)mask);
#endif
    int bits = 0;
    for (int i = 0; i < lanes; ++i)
        bits |= static_cast<int>(mask[i] != 0) << i;
    return bits;
}

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_CPU_DISPATCH_HPP
