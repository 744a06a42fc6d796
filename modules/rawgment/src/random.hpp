// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Counter-based random numbers: private to the module (docs/conventions.md, "Randomness").
//
// Every random value is a pure function of (seed, stream, position in the stream). A parallel loop
// gives each row, tile or pixel its own stream, so the output does not depend on how the work is split
// among threads. The generator is Philox4x32-10 (Salmon et al., "Parallel random numbers: as easy as
// 1, 2, 3", SC 2011), which passes BigCrush and is the standard counter-based generator.
#ifndef OPENCV_RAWGMENT_SRC_RANDOM_HPP
#define OPENCV_RAWGMENT_SRC_RANDOM_HPP

#include "cpu_dispatch.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#if RAWGMENT_HAVE_CPU_PATHS
#include <immintrin.h>
#endif

namespace cv {
namespace rawgment {
namespace detail {

//! Philox4x32-10's multipliers and key increments (Salmon et al. 2011).
constexpr uint32_t kPhiloxM0 = 0xD2511F53u, kPhiloxM1 = 0xCD9E8D57u;
constexpr uint32_t kPhiloxW0 = 0x9E3779B9u, kPhiloxW1 = 0xBB67AE85u;
constexpr int kPhiloxRounds = 10;

//! One Philox4x32-10 block: 4 random 32-bit words for a 128-bit counter and a 64-bit key.
inline std::array<uint32_t, 4> philox4x32(std::array<uint32_t, 4> c, std::array<uint32_t, 2> k)
{
    for (int round = 0; round < kPhiloxRounds; ++round) {
        const uint64_t p0 = static_cast<uint64_t>(kPhiloxM0) * c[0];
        const uint64_t p1 = static_cast<uint64_t>(kPhiloxM1) * c[2];
        c = {static_cast<uint32_t>(p1 >> 32) ^ c[1] ^ k[0], static_cast<uint32_t>(p1),
             static_cast<uint32_t>(p0 >> 32) ^ c[3] ^ k[1], static_cast<uint32_t>(p0)};
        k[0] += kPhiloxW0;
        k[1] += kPhiloxW1;
    }
    return c;
}

// Eight Philox4x32-10 blocks side by side, one per 64-bit lane, each 32-bit word of the state in the
// low half of a lane, on GCC vector extensions: the portable version, used where there are no CPU paths
// (cpu_dispatch.hpp); x86 uses the intrinsic versions below, which compute the same words.
typedef RAWGMENT_VECTOR(uint64_t, 64) U64x8;

//! Ten rounds on eight blocks whose counters are in c0..c3 (one block per lane, words in the low
//! halves), then word j of block b to words[8 j + b].
RAWGMENT_ALWAYS_INLINE void philox8Rounds(U64x8 c0, U64x8 c1, U64x8 c2, U64x8 c3,
                                          const std::array<uint32_t, 2>& key, uint32_t* words)
{
    const U64x8 low = {0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu,
                       0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu};
    uint64_t k0 = key[0], k1 = key[1];
    for (int round = 0; round < kPhiloxRounds; ++round) {
        const U64x8 p0 = (c0 & low) * kPhiloxM0;
        const U64x8 p1 = (c2 & low) * kPhiloxM1;
        c0 = (p1 >> 32) ^ c1 ^ k0;
        c2 = (p0 >> 32) ^ c3 ^ k1;
        c1 = p1 & low;
        c3 = p0 & low;
        k0 = (k0 + kPhiloxW0) & 0xffffffffu;
        k1 = (k1 + kPhiloxW1) & 0xffffffffu;
    }
    // Narrowed as whole vectors (one vpmovqd, or shuffles), not lane by lane.
    typedef RAWGMENT_VECTOR(uint32_t, 32) U32x8;
    const U32x8 w0 = convertLanes<U32x8>(c0), w1 = convertLanes<U32x8>(c1), w2 = convertLanes<U32x8>(c2),
                w3 = convertLanes<U32x8>(c3);
    std::memcpy(words, &w0, sizeof(w0));
    std::memcpy(words + 8, &w1, sizeof(w1));
    std::memcpy(words + 16, &w2, sizeof(w2));
    std::memcpy(words + 24, &w3, sizeof(w3));
}

/** The blocks (firstBlock + b, 0, stream) for b in 0..7, as philox4x32() computes them one by one:
 * word j of block b goes to words[8 j + b]. */
RAWGMENT_ALWAYS_INLINE void philox8Blocks(uint32_t firstBlock, uint64_t stream,
                                          const std::array<uint32_t, 2>& key, uint32_t* words)
{
    const U64x8 zero = {}, lanes = {0, 1, 2, 3, 4, 5, 6, 7};
    philox8Rounds((lanes + firstBlock) & 0xffffffffu, zero, zero + static_cast<uint32_t>(stream),
                  zero + static_cast<uint32_t>(stream >> 32), key, words);
}

/** The blocks (block, 0, streams[b]) for b in 0..7: block `block` of eight streams, one from each, in the
 * layout of philox8Blocks(). */
RAWGMENT_ALWAYS_INLINE void philox8Streams(uint32_t block, const uint64_t* streams,
                                           const std::array<uint32_t, 2>& key, uint32_t* words)
{
    U64x8 s;
    std::memcpy(&s, streams, sizeof(s));
    const U64x8 zero = {};
    philox8Rounds(zero + block, zero, s & 0xffffffffu, s >> 32, key, words);
}

#if RAWGMENT_HAVE_CPU_PATHS
/* philox8Blocks() with x86 intrinsics: GCC multiplies generic 64-bit lanes with three 32-bit
 * multiplies and shifts below AVX-512, and with the slow vpmullq on it, although both factors fit 32
 * bits, which one (v)pmuludq multiplies exactly. The same integers as philox8Blocks(), so the
 * same bits (Simulate.everyPhiloxVersionGivesTheBlocksOfTheScalarOne). Called, not inlined, from the
 * kernels of every path, so that each keeps its own target.
 * A state word is the low half of its 64-bit lane, and the high half is never cleared: (v)pmuludq
 * reads only low halves, the xors keep them apart from the high ones, and the output takes the low
 * halves. So a product moves its high word down with one shuffle that swaps the halves, and the two
 * masks per product of philox8Blocks() are not needed (about 7% of the normals' time on AVX2, Zen 3). */
constexpr int kSwapHalves = _MM_SHUFFLE(2, 3, 0, 1);
constexpr _MM_PERM_ENUM kSwapHalves512 = _MM_PERM_CDAB;
//! One Philox round on two blocks in four registers (state words in the low halves of 64-bit lanes).
RAWGMENT_ALWAYS_INLINE void philoxRoundSse2(__m128i& c0, __m128i& c1, __m128i& c2, __m128i& c3, __m128i m0,
                                            __m128i m1, __m128i kv0, __m128i kv1)
{
    const __m128i p0 = _mm_mul_epu32(c0, m0), p1 = _mm_mul_epu32(c2, m1);
    c0 = _mm_xor_si128(_mm_shuffle_epi32(p1, kSwapHalves), _mm_xor_si128(c1, kv0));
    c2 = _mm_xor_si128(_mm_shuffle_epi32(p0, kSwapHalves), _mm_xor_si128(c3, kv1));
    c1 = p1;
    c3 = p0;
}

//! The low halves of the two lanes of `pair` (two blocks of one state word), side by side at `to`.
RAWGMENT_ALWAYS_INLINE void storeWordPairSse2(__m128i pair, uint32_t* to)
{
    _mm_storel_epi64(reinterpret_cast<__m128i*>(to), _mm_shuffle_epi32(pair, _MM_SHUFFLE(3, 1, 2, 0)));
}

/* Ten rounds on eight blocks, two per register (blocks 2p and 2p + 1 in the registers p*), then word j of
 * block b to words[8 j + b]. Named registers, not arrays, as philox8RoundsAvx2(). */
RAWGMENT_ALWAYS_INLINE void philox8RoundsSse2(__m128i a0, __m128i a1, __m128i a2, __m128i a3, __m128i b0,
                                              __m128i b1, __m128i b2, __m128i b3, __m128i c0, __m128i c1,
                                              __m128i c2, __m128i c3, __m128i d0, __m128i d1, __m128i d2,
                                              __m128i d3, const std::array<uint32_t, 2>& key, uint32_t* words)
{
    const __m128i m0 = _mm_set1_epi64x(kPhiloxM0), m1 = _mm_set1_epi64x(kPhiloxM1);
    uint32_t k0 = key[0], k1 = key[1];
    for (int round = 0; round < kPhiloxRounds; ++round) {
        const __m128i kv0 = _mm_set1_epi64x(k0), kv1 = _mm_set1_epi64x(k1);
        philoxRoundSse2(a0, a1, a2, a3, m0, m1, kv0, kv1);
        philoxRoundSse2(b0, b1, b2, b3, m0, m1, kv0, kv1);
        philoxRoundSse2(c0, c1, c2, c3, m0, m1, kv0, kv1);
        philoxRoundSse2(d0, d1, d2, d3, m0, m1, kv0, kv1);
        k0 += kPhiloxW0;
        k1 += kPhiloxW1;
    }
    const __m128i state[4][4] = {{a0, b0, c0, d0}, {a1, b1, c1, d1}, {a2, b2, c2, d2}, {a3, b3, c3, d3}};
    for (int j = 0; j < 4; ++j)
        for (int p = 0; p < 4; ++p)
            storeWordPairSse2(state[j][p], words + 8 * j + 2 * p);
}

inline void philox8BlocksSse2(uint32_t firstBlock, uint64_t stream, const std::array<uint32_t, 2>& key,
                              uint32_t* words)
{
    const __m128i zero = _mm_setzero_si128(), s0 = _mm_set1_epi64x(static_cast<uint32_t>(stream)),
                  s1 = _mm_set1_epi64x(static_cast<uint32_t>(stream >> 32));
    const auto pair = [firstBlock](uint32_t b) {
        return _mm_set_epi64x(static_cast<uint32_t>(firstBlock + b + 1),
                              static_cast<uint32_t>(firstBlock + b));
    };
    philox8RoundsSse2(pair(0), zero, s0, s1, pair(2), zero, s0, s1, pair(4), zero, s0, s1, pair(6), zero, s0,
                      s1, key, words);
}

//! philox8Streams() with SSE2.
inline void philox8StreamsSse2(uint32_t block, const uint64_t* streams, const std::array<uint32_t, 2>& key,
                               uint32_t* words)
{
    const __m128i zero = _mm_setzero_si128(), b = _mm_set1_epi64x(block);
    // The streams' high halves sit in the lanes' high halves, which (v)pmuludq never reads.
    const auto load = [streams](int p) {
        return _mm_loadu_si128(reinterpret_cast<const __m128i*>(streams + 2 * p));
    };
    const __m128i s0 = load(0), s1 = load(1), s2 = load(2), s3 = load(3);
    philox8RoundsSse2(b, zero, s0, _mm_srli_epi64(s0, 32), b, zero, s1, _mm_srli_epi64(s1, 32), b, zero, s2,
                      _mm_srli_epi64(s2, 32), b, zero, s3, _mm_srli_epi64(s3, 32), key, words);
}

//! One Philox round on four blocks in four registers (state words in the low halves of 64-bit lanes).
__attribute__((target("arch=x86-64-v3"))) inline __attribute__((always_inline)) void
philoxRoundAvx2(__m256i& c0, __m256i& c1, __m256i& c2, __m256i& c3, __m256i m0, __m256i m1, __m256i kv0,
                __m256i kv1)
{
    const __m256i p0 = _mm256_mul_epu32(c0, m0), p1 = _mm256_mul_epu32(c2, m1);
    c0 = _mm256_xor_si256(_mm256_shuffle_epi32(p1, kSwapHalves), _mm256_xor_si256(c1, kv0));
    c2 = _mm256_xor_si256(_mm256_shuffle_epi32(p0, kSwapHalves), _mm256_xor_si256(c3, kv1));
    c1 = p1;
    c3 = p0;
}

//! The low halves of the eight lanes of one state word (blocks 0-3 in `first`, 4-7 in `second`), in order.
__attribute__((target("arch=x86-64-v3"))) inline __attribute__((always_inline)) void
storeWordAvx2(__m256i first, __m256i second, uint32_t* to)
{
    const __m256i gather = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(to),
                     _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(first, gather)));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(to + 4),
                     _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(second, gather)));
}

/* Ten rounds on eight blocks in two sets of four registers (blocks 0-3 in a*, 4-7 in b*), then word j of
 * block b to words[8 j + b]. The state is in named registers, not arrays: with arrays GCC kept it on the
 * stack and every round waited for its stores to be read back, which cost half the time. */
__attribute__((target("arch=x86-64-v3"))) inline __attribute__((always_inline)) void
philox8RoundsAvx2(__m256i a0, __m256i a1, __m256i a2, __m256i a3, __m256i b0, __m256i b1, __m256i b2,
                  __m256i b3, const std::array<uint32_t, 2>& key, uint32_t* words)
{
    const __m256i m0 = _mm256_set1_epi64x(kPhiloxM0), m1 = _mm256_set1_epi64x(kPhiloxM1);
    uint32_t k0 = key[0], k1 = key[1];
    for (int round = 0; round < kPhiloxRounds; ++round) {
        const __m256i kv0 = _mm256_set1_epi64x(k0), kv1 = _mm256_set1_epi64x(k1);
        philoxRoundAvx2(a0, a1, a2, a3, m0, m1, kv0, kv1);
        philoxRoundAvx2(b0, b1, b2, b3, m0, m1, kv0, kv1);
        k0 += kPhiloxW0;
        k1 += kPhiloxW1;
    }
    storeWordAvx2(a0, b0, words);
    storeWordAvx2(a1, b1, words + 8);
    storeWordAvx2(a2, b2, words + 16);
    storeWordAvx2(a3, b3, words + 24);
}

__attribute__((target("arch=x86-64-v3"))) inline void
philox8BlocksAvx2(uint32_t firstBlock, uint64_t stream, const std::array<uint32_t, 2>& key, uint32_t* words)
{
    const __m256i zero = _mm256_setzero_si256();
    const __m256i s0 = _mm256_set1_epi64x(static_cast<uint32_t>(stream)),
                  s1 = _mm256_set1_epi64x(static_cast<uint32_t>(stream >> 32));
    const __m256i first =
        _mm256_set_epi64x(static_cast<uint32_t>(firstBlock + 3), static_cast<uint32_t>(firstBlock + 2),
                          static_cast<uint32_t>(firstBlock + 1), static_cast<uint32_t>(firstBlock));
    const __m256i second =
        _mm256_set_epi64x(static_cast<uint32_t>(firstBlock + 7), static_cast<uint32_t>(firstBlock + 6),
                          static_cast<uint32_t>(firstBlock + 5), static_cast<uint32_t>(firstBlock + 4));
    philox8RoundsAvx2(first, zero, s0, s1, second, zero, s0, s1, key, words);
}

//! philox8Streams() with AVX2.
__attribute__((target("arch=x86-64-v3"))) inline void philox8StreamsAvx2(uint32_t block,
                                                                         const uint64_t* streams,
                                                                         const std::array<uint32_t, 2>& key,
                                                                         uint32_t* words)
{
    const __m256i zero = _mm256_setzero_si256(), b = _mm256_set1_epi64x(block);
    // The streams' high halves sit in the lanes' high halves, which (v)pmuludq never reads.
    const __m256i first = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(streams)),
                  second = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(streams + 4));
    philox8RoundsAvx2(b, zero, first, _mm256_srli_epi64(first, 32), b, zero, second,
                      _mm256_srli_epi64(second, 32), key, words);
}

// GCC 12's avx512fintrin.h warns that _mm512_mul_epu32's masked builtin reads an uninitialised
// pass-through operand, which the full mask never uses.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
//! Ten rounds on eight blocks in one register of eight 64-bit lanes; vpmuludq, not AVX-512's slower vpmullq.
__attribute__((target("arch=x86-64-v4"))) inline __attribute__((always_inline)) void
philox8RoundsAvx512(__m512i c0, __m512i c1, __m512i c2, __m512i c3, const std::array<uint32_t, 2>& key,
                    uint32_t* words)
{
    const __m512i m0 = _mm512_set1_epi64(kPhiloxM0), m1 = _mm512_set1_epi64(kPhiloxM1);
    uint32_t k0 = key[0], k1 = key[1];
    for (int round = 0; round < kPhiloxRounds; ++round) {
        const __m512i p0 = _mm512_mul_epu32(c0, m0), p1 = _mm512_mul_epu32(c2, m1);
        c0 = _mm512_xor_si512(_mm512_xor_si512(_mm512_shuffle_epi32(p1, kSwapHalves512), c1),
                              _mm512_set1_epi64(k0));
        c2 = _mm512_xor_si512(_mm512_xor_si512(_mm512_shuffle_epi32(p0, kSwapHalves512), c3),
                              _mm512_set1_epi64(k1));
        c1 = p1;
        c3 = p0;
        k0 += kPhiloxW0;
        k1 += kPhiloxW1;
    }
    const __m512i state[4] = {c0, c1, c2, c3};
    for (int j = 0; j < 4; ++j)
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(words + 8 * j), _mm512_cvtepi64_epi32(state[j]));
}

__attribute__((target("arch=x86-64-v4"))) inline void
philox8BlocksAvx512(uint32_t firstBlock, uint64_t stream, const std::array<uint32_t, 2>& key, uint32_t* words)
{
    const __m512i low = _mm512_set1_epi64(0xffffffffLL);
    philox8RoundsAvx512(
        _mm512_and_si512(
            _mm512_add_epi64(_mm512_set1_epi64(firstBlock), _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7)), low),
        _mm512_setzero_si512(), _mm512_set1_epi64(static_cast<uint32_t>(stream)),
        _mm512_set1_epi64(static_cast<uint32_t>(stream >> 32)), key, words);
}

//! philox8Streams() with AVX-512.
__attribute__((target("arch=x86-64-v4"))) inline void philox8StreamsAvx512(uint32_t block,
                                                                           const uint64_t* streams,
                                                                           const std::array<uint32_t, 2>& key,
                                                                           uint32_t* words)
{
    const __m512i s = _mm512_loadu_si512(streams); // high halves unread
    philox8RoundsAvx512(_mm512_set1_epi64(block), _mm512_setzero_si512(), s, _mm512_srli_epi64(s, 32), key,
                        words);
}
#pragma GCC diagnostic pop
#endif

//! Eight Philox blocks by the fastest exact means of a path of width W.
template <int W>
RAWGMENT_KERNEL void philox8BlocksFor(uint32_t firstBlock, uint64_t stream,
                                      const std::array<uint32_t, 2>& key, uint32_t* words)
{
#if RAWGMENT_HAVE_CPU_PATHS
    if (W == 4)
        return philox8BlocksSse2(firstBlock, stream, key, words);
    if (W == 8)
        return philox8BlocksAvx2(firstBlock, stream, key, words);
    if (W == 16)
        return philox8BlocksAvx512(firstBlock, stream, key, words);
#endif
    philox8Blocks(firstBlock, stream, key, words);
}

//! Block `block` of eight streams (philox8Streams()) by the fastest exact means of a path of width W.
template <int W>
RAWGMENT_KERNEL void philox8StreamsFor(uint32_t block, const uint64_t* streams,
                                       const std::array<uint32_t, 2>& key, uint32_t* words)
{
#if RAWGMENT_HAVE_CPU_PATHS
    if (W == 4)
        return philox8StreamsSse2(block, streams, key, words);
    if (W == 8)
        return philox8StreamsAvx2(block, streams, key, words);
    if (W == 16)
        return philox8StreamsAvx512(block, streams, key, words);
#endif
    philox8Streams(block, streams, key, words);
}

// clang-format off
/** @name The registry of random streams
 *
 * Every random number of the library is drawn from a CounterRng or fillGaussian() keyed by
 * (key, stream). This is the one list of how keys and streams are derived; a new use of random
 * numbers gets an entry here, never a literal id or an ad-hoc constant at the call site.
 *
 * - augmentation steps (RandomStream below): key stepKey(user seed, family); stream: the row (jitter),
 *   planeRowStream(site, plane row) (blur, scale), 0 (policy draw). A Poisson draw that fillPoisson()
 *   finishes in scalar code (PD's steps Q and E, or a mean beyond 2^40): key poissonRetryKey(family key,
 *   row stream) = stepKey(family key, row stream); stream: the value's index in its row. A Tukey-lambda value that fillTukeyUnit() refines: key tukeyRefineKey(family
 *   key, row stream), the same derivation under the Tukey family's key; stream: the value's index.
 * - simulator captures: key the capture's seed; stream captureStream(frame, row).
 * - simulator fixed pattern (PRNU, DSNU, defects): key SensorParams::fixedPatternSeed; stream
 *   fixedPatternStream(row).
 * - RANSAC of fitNoiseLine(): key LineFitParams::seed; stream ransacStream(iteration).
 * - bootstrap of calibrateNoiseModel(): key LineFitParams::seed; stream bootstrapStream(replicate).
 * - apps and programs on the library: the public SeedPurpose (ids 16 and up, never a RandomStream id):
 *   deriveSeed(user seed, purpose, index) = stepKey(stepKey(seed, purpose), index), given to the
 *   library call it drives; augmented outputs: augmentedOutputSeed(user seed, input stem, variant).
 *
 * Capture streams keep the top bit clear and fixed-pattern streams set it, so a user who gives one
 * seed to both never sees the two share numbers. */
// clang-format on
//! @{

//! The augmentation families: each step's Gaussian and Poisson draws, and the policy's scene draws.
enum class RandomStream : uint64_t
{
    JITTER_GAUSSIAN = 1,
    BLUR_GAUSSIAN = 2,
    POLICY_DRAW = 3,
    SCALE_GAUSSIAN = 4,
    JITTER_POISSON = 5,
    BLUR_POISSON = 6,
    SCALE_POISSON = 8,
    // The dark-frame components (NoiseModel): a row offset per mosaic row (stream: the row) and the
    // uniforms of Tukey-lambda read noise (stream: as the step's Gaussian stream).
    JITTER_ROW = 9,
    JITTER_TUKEY = 10,
    BLUR_ROW = 11,
    BLUR_TUKEY = 12,
    SCALE_ROW = 13,
    SCALE_TUKEY = 14,
    // Which real camera's noise a sample takes (drawCameraIndex(), one draw per seed).
    CAMERA_DRAW = 15,
    // Which dark frames of a bank a step takes (bank_noise.hpp): one stream, its first draws.
    JITTER_BANK = 16,
    BLUR_BANK = 17,
    SCALE_BANK = 18,
    // The simulator's column offsets (SensorParams::columnNoiseVariance): key stepKey(capture seed, this),
    // stream: the frame.
    SIMULATOR_COLUMNS = 19,
};

/** The key of one family under a user's seed: the SplitMix64 finaliser of seed + golden * (id + 1),
 * distinct and well mixed for nearby (seed, id), so that the steps of one call never share numbers. */
inline uint64_t stepKey(uint64_t seed, uint64_t id)
{
    uint64_t z = seed + 0x9E3779B97F4A7C15ull * (id + 1);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

inline uint64_t stepKey(uint64_t seed, RandomStream family)
{
    return stepKey(seed, static_cast<uint64_t>(family));
}

//! Stream of one row of one simulated frame.
inline uint64_t captureStream(int frame, int row)
{
    return (static_cast<uint64_t>(frame) << 32) | static_cast<uint64_t>(row);
}

//! Stream of one row of the simulator's fixed pattern: the top bit set, never a capture stream.
inline uint64_t fixedPatternStream(int row)
{
    return (uint64_t(1) << 63) | static_cast<uint64_t>(row);
}

//! Stream of one RANSAC iteration (the pair of samples it draws).
inline uint64_t ransacStream(int iteration)
{
    return static_cast<uint64_t>(iteration);
}

//! Stream of one bootstrap replicate of a calibration: bit 62 set, never a RANSAC iteration's stream.
inline uint64_t bootstrapStream(int replicate)
{
    return (uint64_t(1) << 62) | static_cast<uint64_t>(replicate);
}

//! Stream of one row of one CFA plane in the resampling steps.
inline uint64_t planeRowStream(int site, int planeRow)
{
    return (static_cast<uint64_t>(site) << 32) | static_cast<uint64_t>(planeRow);
}

//! @}

//! The largest mean poisson() takes: 2^52, where doubles stop holding every integer.
constexpr double kMaxPoissonMean = 4503599627370496.0;

/** A stream of random numbers identified by (seed, stream). Cheap to construct: make one per row or
 * per pixel. */
class CounterRng
{
public:
    CounterRng(uint64_t seed, uint64_t stream)
        : key_{static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32)},
          counter_{0u, 0u, static_cast<uint32_t>(stream), static_cast<uint32_t>(stream >> 32)}
    {
    }

    uint32_t nextU32()
    {
        if (used_ == 4) {
            block_ = philox4x32(counter_, key_);
            if (++counter_[0] == 0)
                ++counter_[1];
            used_ = 0;
        }
        return block_[used_++];
    }

    //! Uniform in (0, 1): 53 random bits, never 0 (safe for log) and never 1.
    double uniform()
    {
        const uint64_t bits = (static_cast<uint64_t>(nextU32()) << 21) ^ (nextU32() >> 11);
        return (static_cast<double>(bits) + 0.5) * (1.0 / 9007199254740992.0);
    }

    //! Standard normal by Box-Muller; the second value of each pair is kept for the next call.
    double gaussian()
    {
        if (hasSpare_) {
            hasSpare_ = false;
            return spare_;
        }
        const double r = std::sqrt(-2.0 * std::log(uniform()));
        const double theta = 2.0 * CV_PI * uniform();
        spare_ = r * std::sin(theta);
        hasSpare_ = true;
        return r * std::cos(theta);
    }

    /** Exact Poisson variate of mean lambda >= 0: inversion below 10, Hormann's transformed rejection
     * (PTRS, 1993) above. Both are exact up to floating-point rounding, unlike a Gaussian
     * approximation, which matters at the few-electron counts of dark pixels. lambda must not exceed
     * kMaxPoissonMean (callers check before their loops: above it, a count no longer fits the integers
     * that a double holds exactly, and a Gaussian is exact to double precision anyway). */
    int64_t poisson(double lambda);

private:
    std::array<uint32_t, 2> key_;
    std::array<uint32_t, 4> counter_;
    std::array<uint32_t, 4> block_{};
    int used_ = 4;
    bool hasSpare_ = false;
    double spare_ = 0;
};

//! log(k!) to about 1e-13 relative: a table below 32, Stirling's series with three terms above.
double logFactorial(int64_t k);

/** Fills out[0..n) with standard normal float32 values from the stream (seed, stream).
 *
 * The hot path of every noise step: Philox blocks eight at a time in vector lanes, then Box-Muller
 * with polynomial log, sin and cos (no library calls, so the loop vectorises too). Within a chunk of
 * 64 values, the radius comes from words 0-31 and the angle from words 32-63 (word j of block b sits
 * at 32 (b / 8) + 8 j + b % 8). Value i depends only on (seed, stream, i): rows filled by different
 * threads never interact.
 * Accuracy: every value is within 1.5 float ulps of its radius of Box-Muller computed in double on the
 * same words (Simulate.fillGaussianIsBoxMullerOfItsPhiloxWordsOnEveryPath), far below any noise they
 * model; the uniforms have 24 bits, so |z| <= 5.8 (probability of a larger |z| for a true normal: 7e-9). */
void fillGaussian(uint64_t seed, uint64_t stream, float* out, int n);

/** The Tukey-lambda quantiles fillTukeyUnit() draws with, for the two CFA sites of a row (even columns:
 * shape lambda[0] scaled by invSd[0], 1 / the shape's standard deviation; odd columns: lambda[1], invSd[1]).
 * For u in [2^-8, 1/2), where all but a share 2^-7 of the uniforms lie, invSd Q(u) is a cubic in each of 32
 * cells per octave of u: the interpolant at the cell's four Chebyshev nodes, in double from the exact
 * quantile, rounded to float coefficients of x = the position in the cell - 1/2 (in [-1/2, 1/2), so the
 * terms do not cancel). Its truncation error is below 2e-9 of the quantile's scale (the fourth derivative
 * of ln u over a cell of 1/32 of its octave), so the float rounding of the coefficients and of the four
 * multiply-adds decide: 2e-7 relative at most, measured at lambda -0.2 to 1. Built once per step (two
 * exponentials at each of 896 nodes and site, about 70 microseconds); a lookup and the cubic cost a
 * fraction of the logarithms and exponentials the quantile needs otherwise. */
class TukeyQuantileTable
{
public:
    static constexpr int kCellsPerOctave = 32;
    static constexpr int kOctaves = 7;          //!< u in [2^-8, 2^-1)
    static constexpr int kLowestExponent = 119; //!< float's biased exponent of 2^-8
    //! The cells of one site: kOctaves * kCellsPerOctave, and one for u = 1/2 (whose quantile is 0).
    static constexpr int kCells = kOctaves * kCellsPerOctave + 1;

    TukeyQuantileTable() = default; //!< unusable: for arrays that are assigned later
    //! Throws StsBadArg unless each lambda is in [kTukeyLambdaMin, 1] and each invSd finite and positive.
    TukeyQuantileTable(float lambda0, float invSd0, float lambda1, float invSd1);
    //! Both sites of the same shape (a plane row of a resampled mosaic is one site).
    TukeyQuantileTable(float lambda_, float invSd_) : TukeyQuantileTable(lambda_, invSd_, lambda_, invSd_) {}

    float lambda[2] = {0, 0}, invSd[2] = {1, 1};
    //! Cell c of site s: the coefficients of x^0..x^3 at 4 (s kCells + c).
    const float* coefficients() const { return coefficients_.data(); }
    bool empty() const { return coefficients_.empty(); }

private:
    std::vector<float> coefficients_;
};

/** Fills out[0..n) with unit-variance Tukey-lambda float32 values from the stream (seed, stream): even
 * indices of the table's first shape, odd ones of its second (the two CFA sites of a mosaic row). Vector
 * lanes on every path, the same bits on each. Value i uses word i % 32 of its chunk (32 values per 8 Philox
 * blocks): its top bit the sign, the other 31 bits m the uniform u = m 2^-32 in (0, 1/2), all float keeps of
 * it from u = 2^-8 up, where the table's cubics give the quantile. Below (m < 2^24, a share 2^-7), 24 bits
 * of the first word of the value's own stream (tukeyRefineKey(seed, stream), i) extend u, so the uniforms
 * reach 2^-57 and the tails are drawn as far as a double uniform's would be; those values are computed
 * from the logarithms and exponentials as polynomials (no library calls). Accuracy: within 2e-6 relative
 * (or 1e-6 absolute near 0) of the double quantile of the same uniform
 * (Simulate.fillTukeyUnitIsTheQuantileOfItsWordsOnEveryPath). */
void fillTukeyUnit(uint64_t seed, uint64_t stream, const TukeyQuantileTable& table, float* out, int n);

/** Fills counts[0..n) with exact Poisson variates of means[0..n) from the stream (seed, stream), the
 * vector sampler that ShotNoiseSampling::POISSON draws with. Every mean must lie in [0, kMaxPoissonMean]
 * (0 gives 0).
 *
 * Value h of a chunk of 16 (8 Philox blocks) owns word 16 + h; Box-Muller pair h % 8 takes its radius from
 * word h % 8 and its angle from word 8 + h % 8, its cosine going to value h % 8 and its sine to value
 * 8 + h % 8. A value depends only on (seed, stream, i, means[i]), on every path, whatever its neighbours'
 * means. Below a mean of 25, inversion by sequential search with u = (own word + 1/2) 2^-32 (in place for a
 * chunk of small means only, gathered into whole chunks from mixed ones). From 25 up to 2^40, Ahrens and
 * Dieter's PD (ACM TOMS 8, 1982): steps N, I and S in double lanes, g = mu + sqrt(mu) T with T the normal of
 * its pair (Box-Muller in double with polynomial logarithm, sine and cosine), taken when floor(g) >=
 * floor(mu - 1.1484) or when the squeeze 6 mu^2 u >= (mu - floor(g))^3 holds for its own uniform u; the rest
 * (3% at a mean of 25, 0.4% at 1000) take steps Q and E, gathered eight at a time into double lanes, with
 * exact Poisson probabilities (Stirling's formula with its remainder, not PD's own 7-digit approximations;
 * logPoissonProbabilities()), step E's try j drawing from block j of the value's stream
 * (poissonRetryKey(seed, stream), i) as CounterRng::uniform() would, until the hat accepts. A mean beyond
 * 2^40 calls CounterRng::poisson() on that stream. CounterRng::poisson(), the simulator's sampler, is
 * inversion below 10 and PTRS above. Exactness: up to double rounding and the 32-bit words: the uniforms and
 * the normal's radius and angle are on grids of 2^-32 (|T| <= 6.7), so each count's probability is exact to
 * about 2^-31 absolute. Same bits on every path (Simulate.fillPoissonIsExactAndTheSameOnEveryPath, which also
 * checks each value against a reference written with the C library). counts must not overlap means. */
void fillPoisson(uint64_t seed, uint64_t stream, const double* means, double* counts, int n);

/** out[i] = ln P(K = ks[i]) for K ~ Poisson(mus[i]), as fillPoisson()'s steps Q and E compute it in lanes
 * (k (ln(1 + v) - v) - ln(2 pi k) / 2 - Stirling's remainder, v = (mu - k) / k; -mu at k = 0), for ks[i] >= 0
 * and mus[i] >= 1: exposed for the test of its accuracy (Simulate.poissonProbabilitiesOfTheLanesAreExact). */
void logPoissonProbabilities(const double* ks, const double* mus, double* out, int n);

//! The key of fillPoisson()'s scalar steps for the stream (seed, stream); such a value i draws from (key, i).
inline uint64_t poissonRetryKey(uint64_t seed, uint64_t stream)
{
    return stepKey(seed, stream);
}

//! The key of fillTukeyUnit()'s refinements for the stream (seed, stream); a refined value i draws from (key,
//! i).
inline uint64_t tukeyRefineKey(uint64_t seed, uint64_t stream)
{
    return stepKey(seed, stream);
}

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_RANDOM_HPP
