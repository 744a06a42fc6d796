// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The rows both resampling steps share (resample_rows.hpp): scaleMosaic() in scale_mosaic.cpp, motionBlur()
// in motion_blur.cpp.
#include "resample_rows.hpp"

#include "cpu_dispatch.hpp"

#include <algorithm>
#include <cstring>
#include <emmintrin.h>

namespace cv {
namespace rawgment {

namespace {

using detail::AddedVariance;
using detail::ResampleConstants;
using detail::RowScratch;

template <int W>
RAWGMENT_KERNEL void finishResampledBlock(float* mean, const float* shotSum, const float* readFactor,
                                          const float* z, const float* extra, const ResampleConstants& k,
                                          float black)
{
    typedef typename detail::Lanes<W>::F F;
    const F zero = F{}, white = zero + k.white;
    F m;
    std::memcpy(&m, mean, sizeof(m));
    if (k.alignment == NoiseAlignment::NONE) {
        m = detail::minLanes(detail::maxLanes(m + black, zero), white);
    } else {
        F zv, v;
        std::memcpy(&zv, z, sizeof(zv));
        if (k.alignment == NoiseAlignment::ACCOUNT_PRIOR) {
            F sh, rf;
            std::memcpy(&sh, shotSum, sizeof(sh));
            std::memcpy(&rf, readFactor, sizeof(rf));
            v = detail::maxLanes(k.shot * sh + rf * k.floorVar, zero);
        } else {
            v = k.shot * detail::maxLanes(m, zero) + k.floorVar;
        }
        m += detail::sqrtLanes(v) * zv;
        if (extra) { // the dark-frame components, when the model has them
            F e;
            std::memcpy(&e, extra, sizeof(e));
            m += e;
        }
        m = detail::minLanes(detail::maxLanes(m + black, zero), white);
    }
    std::memcpy(mean, &m, sizeof(m));
}

// mean[j] + N(0, v): v from the per-pixel shot sum and read-noise factor (ACCOUNT_PRIOR), from the
// mean (IGNORE_PRIOR), or none; black added back, clipped to [0, white]. The buffers hold whole blocks
// (detail::wholeBlocks()).
template <int W>
RAWGMENT_KERNEL void finishResampledRowKernel(float* mean, const float* shotSum, const float* readFactor,
                                              const float* z, const float* extra, const ResampleConstants& k,
                                              float black, int n)
{
    const bool account = k.alignment == NoiseAlignment::ACCOUNT_PRIOR;
    for (int j = 0; j < n; j += W)
        finishResampledBlock<W>(mean + j, account ? shotSum + j : nullptr, account ? readFactor + j : nullptr,
                                z ? z + j : nullptr, extra ? extra + j : nullptr, k, black);
}
RAWGMENT_DISPATCHED_BY_WIDTH(void, finishResampledRow,
                             (float* mean, const float* shotSum, const float* readFactor, const float* z,
                              const float* extra, const ResampleConstants& k, float black, int n),
                             (mean, shotSum, readFactor, z, extra, k, black, n))

// The scalar rows: ShotNoiseSampling::POISSON for a resampled row (the shot part of Eq. 15, or of the
// model for IGNORE_PRIOR, as an electron count at the input gain, see detail::splitNoise()) and Tukey-lambda
// read noise (`tails`: scratch.t holds the row's unit-variance draws, the read part's shape), with the dark
// terms' `extra`.
void finishResampledRowScalar(float* mean, const float* shotSum, const float* readFactor, const float* extra,
                              bool tails, const ResampleConstants& k, float black, uint64_t stream, int n,
                              RowScratch& scratch)
{
    const float *z = scratch.z.data(), *t = tails ? scratch.t.data() : nullptr;
    const bool poisson = k.sampling == ShotNoiseSampling::POISSON;
    std::vector<detail::NoiseSplit>& splits = scratch.splits;
    std::vector<double>&means = scratch.means, &counts = scratch.counts;
    if (!poisson)
        std::fill(counts.begin(), counts.begin() + n, 0.0);
    const detail::PoissonScale scale(k.shot);
    for (int j = 0; j < n; ++j) {
        const AddedVariance v = k.alignment == NoiseAlignment::ACCOUNT_PRIOR
                                    ? AddedVariance{k.shot * shotSum[j], readFactor[j] * k.floorVar}
                                    : AddedVariance{k.shot * std::max(mean[j], 0.0f), k.floorVar};
        splits[static_cast<size_t>(j)] = detail::splitNoise(v, scale, poisson, t != nullptr);
        if (poisson)
            means[static_cast<size_t>(j)] = splits[static_cast<size_t>(j)].mean;
    }
    // The whole row's counts at once, in vector lanes.
    if (poisson)
        detail::fillPoisson(k.poissonKey, stream, means.data(), counts.data(), n);
    for (int j = 0; j < n; ++j) {
        const float noise = detail::poissonNoise(splits[static_cast<size_t>(j)], k.shot,
                                                 counts[static_cast<size_t>(j)], z[j], t ? t[j] : 0.0f);
        float out = mean[j] + noise;
        if (extra)
            out += extra[j];
        mean[j] = std::min(std::max(out + black, 0.0f), k.white);
    }
}

// The dark-frame terms of one output plane row into extra[0..n): the row offset that the step's
// vertical weights removed (rowKeep = their sum of squares: the share of the input's row variance
// kept), drawn once per mosaic row so both sites of a row share it, plus the dark shading to restore.
bool resampledDarkRow(const ResampleConstants& k, int site, int planeRow, float rowKeep, float* extra, int n)
{
    const int r = k.grid.mosaicRow(site, planeRow);
    float amp = 0;
    if (k.dark.row) {
        const double added =
            k.alignment == NoiseAlignment::ACCOUNT_PRIOR ? k.rowVariance * (1.0 - rowKeep) : k.rowVariance;
        detail::CounterRng rng(k.rowKey, static_cast<uint64_t>(r));
        amp = static_cast<float>(std::sqrt(std::max(added, 0.0)) * rng.gaussian());
    }
    const detail::DarkShading& shading = k.dark.shading;
    if (shading.empty()) {
        std::fill(extra, extra + n, amp);
        return true;
    }
    const float *bd = shading.perGainRow(r) + site % 2, *br = shading.offsetRow(r) + site % 2;
    float check = 0; // as in detail::darkRowExtra(): NaN when a map value is not finite
    const int step = k.grid.step;
    for (int j = 0; j < n; ++j) {
        extra[j] = amp + shading.at(bd, br, step * j);
        check += (bd[step * j] - bd[step * j]) + (br[step * j] - br[step * j]);
    }
    return check == 0;
}

} // namespace

namespace detail {

// The columns of one site (column 0 or 1 of the CFA) of a mosaic row, less black, into out[0..width).
// SSE2, which every x86-64 has, takes four at a time with the scalar tail's own conversion and
// subtraction, so every path gives the same bits.
void siteColumns(const ushort* row, int column, int width, float black, float* out)
{
    const __m128 b = _mm_set1_ps(black);
    const __m128i low = _mm_set1_epi32(0xFFFF);
    int j = 0;
    for (; j + 4 <= width; j += 4) {
        const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + 2 * j));
        const __m128i site = column == 0 ? _mm_and_si128(v, low) : _mm_srli_epi32(v, 16);
        _mm_storeu_ps(out + j, _mm_sub_ps(_mm_cvtepi32_ps(site), b));
    }
    for (; j < width; ++j)
        out[j] = static_cast<float>(row[2 * j + column]) - black;
}

void siteColumns(const float* row, int column, int width, float black, float* out)
{
    const __m128 b = _mm_set1_ps(black);
    int j = 0;
    for (; j + 4 <= width; j += 4) {
        const __m128 a = _mm_loadu_ps(row + 2 * j), c = _mm_loadu_ps(row + 2 * j + 4);
        const __m128 site = column == 0 ? _mm_shuffle_ps(a, c, _MM_SHUFFLE(2, 0, 2, 0))
                                        : _mm_shuffle_ps(a, c, _MM_SHUFFLE(3, 1, 3, 1));
        _mm_storeu_ps(out + j, _mm_sub_ps(site, b));
    }
    for (; j < width; ++j)
        out[j] = row[2 * j + column] - black;
}

// Both sites of a mosaic row (plane rows `even` and `odd`, CFA columns 0 and 1) interleaved into it with
// whole-vector stores. One task writes a whole row, so no two threads write into one cache line: when
// each site was stored on its own, the two threads took every line of the output from each other.
// 16-bit values are rounded half to even like detail::roundHalfToEven(): _mm_cvtps_epi32 rounds in the
// default mode, to nearest even. Values lie in [0, white], white at most 65535 (detail::outputWhite()).
void storeMosaicRow(const float* even, const float* odd, ushort* d, int width)
{
    const __m128i bias = _mm_set1_epi32(32768), flip = _mm_set1_epi16(static_cast<short>(0x8000));
    int j = 0;
    for (; j + 4 <= width; j += 4) {
        const __m128i a = _mm_cvtps_epi32(_mm_loadu_ps(even + j)), b = _mm_cvtps_epi32(_mm_loadu_ps(odd + j));
        // Signed saturation is exact on v - 32768 for v in [0, 65535]; the flip of the top bit adds it back.
        const __m128i lo = _mm_sub_epi32(_mm_unpacklo_epi32(a, b), bias);
        const __m128i hi = _mm_sub_epi32(_mm_unpackhi_epi32(a, b), bias);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(d + 2 * j), _mm_xor_si128(_mm_packs_epi32(lo, hi), flip));
    }
    for (; j < width; ++j) {
        d[2 * j] = static_cast<ushort>(static_cast<int>(detail::roundHalfToEven(even[j])));
        d[2 * j + 1] = static_cast<ushort>(static_cast<int>(detail::roundHalfToEven(odd[j])));
    }
}

void storeMosaicRow(const float* even, const float* odd, float* d, int width)
{
    int j = 0;
    for (; j + 4 <= width; j += 4) {
        const __m128 a = _mm_loadu_ps(even + j), b = _mm_loadu_ps(odd + j);
        _mm_storeu_ps(d + 2 * j, _mm_unpacklo_ps(a, b));
        _mm_storeu_ps(d + 2 * j + 4, _mm_unpackhi_ps(a, b));
    }
    for (; j < width; ++j) {
        d[2 * j] = even[j];
        d[2 * j + 1] = odd[j];
    }
}

void storeFrameRow(const float* values, ushort* d, int width)
{
    for (int j = 0; j < width; ++j)
        d[j] = static_cast<ushort>(static_cast<int>(detail::roundHalfToEven(values[j])));
}

void storeFrameRow(const float* values, float* d, int width)
{
    std::memcpy(d, values, static_cast<size_t>(width) * sizeof(float));
}

void finishPlaneRow(std::vector<float>& mean, const float* shotSum, const float* readFactor,
                    RowScratch& scratch, const ResampleConstants& k, int n, int site, int planeRow,
                    float rowKeep)
{
    const uint64_t stream = detail::planeRowStream(site, planeRow);
    const bool noise = k.alignment != NoiseAlignment::NONE;
    if (noise)
        detail::fillGaussian(k.key, stream, scratch.z.data(), n);
    const bool dark = noise && (k.dark.any() || k.bank), tails = noise && k.dark.tails;
    if (noise && k.bank) {
        // The input keeps sum w^2 = 1 - readFactor of its pixel part, rowKeep of its row part.
        for (int j = 0; j < n; ++j)
            scratch.factor[static_cast<size_t>(j)] = 1 - readFactor[j];
        const float rowFactor[2] = {rowKeep, rowKeep};
        *k.readBrightening +=
            bankRowExtra(*k.bank, k.grid.mosaicRow(site, planeRow), k.grid.step == 2 ? site % 2 : 0,
                         k.grid.step, n, rowFactor, scratch.factor.data(), scratch.extra.data());
    } else if (dark && !resampledDarkRow(k, site, planeRow, rowKeep, scratch.extra.data(), n)) {
        *k.nonFiniteShading = true;
    }
    if (tails)
        detail::fillTukeyUnit(k.tukeyKey, stream, k.dark.tailTable[0], scratch.t.data(), n);
    const float* extraRow = dark ? scratch.extra.data() : nullptr;
    if (noise && (k.sampling == ShotNoiseSampling::POISSON || tails)) {
        finishResampledRowScalar(mean.data(), shotSum, readFactor, extraRow, tails, k, k.black[site], stream,
                                 n, scratch);
    } else {
        finishResampledRow(mean.data(), shotSum, readFactor, scratch.z.data(), extraRow, k, k.black[site], n);
    }
}

ResampleConstants resampleConstants(int depth, const RawFormat& format, const StepNoise& step, uint64 seed,
                                    detail::RandomStream gaussian, detail::RandomStream poisson)
{
    ResampleConstants k;
    k.grid = PlaneGrid(format);
    for (int s = 0; s < 4; ++s)
        k.black[s] = static_cast<float>(format.blackLevel[s]);
    k.white = detail::outputWhite(format, depth); // storeMosaicRow() converts through int32
    k.shot = static_cast<float>(step.in.shot);
    k.floorVar = static_cast<float>(step.in.read());
    k.alignment = step.options.alignment;
    k.sampling = step.options.shotSampling;
    k.key = detail::stepKey(seed, gaussian);
    k.poissonKey = detail::stepKey(seed, poisson);
    return k;
}

void resampleDarkTerms(ResampleConstants& k, const StepNoise& step, double sumW2, double sumW4, uint64 seed,
                       detail::RandomStream rowStream, detail::RandomStream tukeyStream)
{
    if (!step.addsNoise())
        return;
    detail::DarkTerms& d = k.dark;
    d.row = step.rowNoise;
    d.shading = step.shading;
    d.tails = step.tails;
    k.rowVariance = step.rowVariance(step.gainIn);
    k.rowKey = detail::stepKey(seed, rowStream);
    k.tukeyKey = detail::stepKey(seed, tukeyStream);
    const bool account = k.alignment == NoiseAlignment::ACCOUNT_PRIOR;
    if (d.tails) {
        const double b = k.floorVar;
        const double lambda =
            account ? detail::addedReadLambda(step.tukeyLambda, b, sumW4 * b * b, (1 - sumW2) * b)
                    : step.tukeyLambda;
        // One shape for every site, so one table (a plane row is one site).
        d.tailTable[0] = detail::TukeyQuantileTable(
            static_cast<float>(lambda), static_cast<float>(detail::TukeyUnitSampler(lambda).invSd));
    }
    if (account)
        k.inputShading = d.shading;
}

BankRead resampleBankRead(const StepNoise& step, const RawFormat& format, Size size, double sumW2,
                          uint64 seed, RandomStream stream, const char* who,
                          const std::function<void(const Mat&, const RawFormat&, Mat&)>& withoutNoise)
{
    BankPattern pattern;
    pattern.amplitude = Vec4d::all(std::sqrt(sumW2));
    if (step.options.darkBankTied && step.options.alignment == NoiseAlignment::ACCOUNT_PRIOR) {
        // The step clips its output at 0: the pattern is lifted above it by a black level, then lowered.
        const Mat held = bankInputPattern(step, format, size);
        double lowest = 0;
        minMaxLoc(held, &lowest);
        const double lift = 1024 + std::max(0.0, -lowest);
        RawFormat lifted = format;
        lifted.blackLevel = Vec4d::all(lift);
        lifted.whiteLevel = 1e9;
        Mat moved;
        withoutNoise(Mat(held + lift), lifted, moved);
        pattern.held = moved - lift;
    }
    return prepareBankRead(step, format, size, pattern, seed, stream, who);
}

} // namespace detail

} // namespace rawgment
} // namespace cv
