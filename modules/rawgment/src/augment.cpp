// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "opencv2/rawgment/augment.hpp"
#include "precomp.hpp"
#include "random.hpp"

#include <opencv2/imgproc.hpp>

#include <atomic>
#include <limits>

namespace cv {
namespace rawgment {

namespace {

// Each step draws from its own family of streams: (step seed, row) with the step's seed derived from
// the user's seed, so that jitter and blur of one call never reuse random numbers.
uint64_t stepSeed(uint64 seed, uint64_t step)
{
    // SplitMix64 finaliser: distinct, well-mixed keys for nearby (seed, step).
    uint64_t z = seed + 0x9E3779B97F4A7C15ull * (step + 1);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

void checkMosaicInput(const Mat& src, const char* who)
{
    if (src.empty())
        CV_Error(Error::StsBadArg, format("%s: src is empty", who));
    if (src.type() != CV_16UC1 && src.type() != CV_32FC1)
        CV_Error(Error::StsBadArg, format("%s: src type %s is not supported; expected CV_16UC1 or CV_32FC1",
                                          who, typeToString(src.type()).c_str()));
    if (src.type() == CV_32FC1 && !checkRange(src, true))
        CV_Error(Error::StsBadArg, format("%s: src contains NaN or Inf", who));
}

// Blur and scale resample each CFA plane: they need whole 2x2 blocks, hence even sides.
void checkResampleInput(const Mat& src, const RawFormat& format, const NoiseModel& model,
                        const NoiseOptions& noise, const char* who)
{
    checkMosaicInput(src, who);
    format.validate();
    model.validate();
    noise.validate();
    if (src.rows % 2 || src.cols % 2)
        CV_Error(Error::StsBadArg,
                 cv::format("%s: both sides must be even (got %dx%d)", who, src.cols, src.rows));
}

struct JitterConstants
{
    float pc[4], black[4];
    float pb, pg, white;
    float shot, read, post; // g alpha, g^2 sigma_d^2, sigma_r^2 at the input gain
    NoiseAlignment alignment;
    ShotNoiseSampling sampling;
};

// The variance to add to a pixel, split into its shot part and the rest (read noise, and for
// ACCOUNT_PRIOR the correction of the scaled prior), before any clipping. xm is the prior-mean estimate
// (black-subtracted), pc the pixel's contrast. Eq. 13 for ACCOUNT_PRIOR; the model at the new mean and
// gain for IGNORE_PRIOR.
struct AddedVariance
{
    float shot, rest;
};

template <NoiseAlignment A> inline AddedVariance jitterVariance(float xm, float pc, const JitterConstants& k)
{
    const float pg = k.pg, pg2 = k.pg * k.pg;
    if (A == NoiseAlignment::ACCOUNT_PRIOR) {
        const float xf = std::max(xm, 1.0f);
        const float pu = std::max((pc * xf + k.pb) / (xf * pg), 0.0f);
        const float mu = std::max(xm, 0.0f);
        return {pu * (1 - pu) * (pg2 * k.shot) * mu,
                (1 - pu * pu) * (pg2 * k.read) + (1 - pu * pu * pg2) * k.post};
    }
    if (A == NoiseAlignment::IGNORE_PRIOR)
        return {pg * k.shot * std::max(pc * xm + k.pb, 0.0f), pg2 * k.read + k.post};
    return {0.0f, 0.0f};
}

template <typename T> inline T storeValue(float out, float white)
{
    out = std::min(std::max(out, 0.0f), white);
    return std::is_same<T, ushort>::value ? static_cast<T>(static_cast<int>(out + 0.5f))
                                          : static_cast<T>(out);
}

// One row of Eq. 11/13, written so that the compiler vectorises it: no branches, per-column constants
// in arrays (the CFA site alternates along the row), float arithmetic in a fixed order. `prior` is the
// local-mean row, or null to use the pixel's own value. Returns the number of brightening pixels.
// Rounding to 16 bits adds 0.5 and truncates (the value is clipped to [0, white] first): the same bits
// in every vector width.
template <typename T, NoiseAlignment A, bool kLocalMean>
inline int jitterRowBody(const T* s, T* d, const float* z, const float* prior, const float* pc,
                         const float* black, const JitterConstants& k, int cols)
{
    int bright = 0;
    for (int c = 0; c < cols; ++c) {
        const float x = static_cast<float>(s[c]) - black[c];
        float out = pc[c] * x + k.pb;
        if (A != NoiseAlignment::NONE) {
            const AddedVariance v = jitterVariance<A>(kLocalMean ? prior[c] : x, pc[c], k);
            const float total = v.shot + v.rest;
            bright += total < 0 ? 1 : 0;
            out += std::sqrt(std::max(total, 0.0f)) * z[c];
        }
        d[c] = storeValue<T>(out + black[c], k.white);
    }
    return bright;
}

template <typename T, bool kLocalMean>
inline int jitterRowAnyAlignment(const T* s, T* d, const float* z, const float* prior, const float* pc,
                                 const float* black, const JitterConstants& k, int cols)
{
    switch (k.alignment) {
    case NoiseAlignment::ACCOUNT_PRIOR:
        return jitterRowBody<T, NoiseAlignment::ACCOUNT_PRIOR, kLocalMean>(s, d, z, prior, pc, black, k,
                                                                           cols);
    case NoiseAlignment::IGNORE_PRIOR:
        return jitterRowBody<T, NoiseAlignment::IGNORE_PRIOR, kLocalMean>(s, d, z, prior, pc, black, k, cols);
    default:
        return jitterRowBody<T, NoiseAlignment::NONE, kLocalMean>(s, d, z, prior, pc, black, k, cols);
    }
}

// One multi-versioned entry point per pixel type: GCC cannot clone a template.
RAWGMENT_HOT_KERNEL
int jitterRow(const ushort* s, ushort* d, const float* z, const float* prior, const float* pc,
              const float* black, const JitterConstants& k, int cols)
{
    return prior ? jitterRowAnyAlignment<ushort, true>(s, d, z, prior, pc, black, k, cols)
                 : jitterRowAnyAlignment<ushort, false>(s, d, z, prior, pc, black, k, cols);
}

RAWGMENT_HOT_KERNEL
int jitterRow(const float* s, float* d, const float* z, const float* prior, const float* pc,
              const float* black, const JitterConstants& k, int cols)
{
    return prior ? jitterRowAnyAlignment<float, true>(s, d, z, prior, pc, black, k, cols)
                 : jitterRowAnyAlignment<float, false>(s, d, z, prior, pc, black, k, cols);
}

// Gaussian noise of variance `rest` plus the shot part as an electron count: q (K - m) with
// K ~ Poisson(m), m = shot / q^2 (ShotNoiseSampling::POISSON). A negative total (brightening) adds
// nothing; a negative rest (the gain grew) is taken from the Poisson part, so the variance added is
// always max(shot + rest, 0), the same as the Gaussian path.
inline float sampledNoise(AddedVariance v, float q, float z, detail::CounterRng& rng)
{
    const float total = std::max(v.shot + v.rest, 0.0f);
    const float shot = q > 0 ? std::min(std::max(v.shot, 0.0f), total) : 0.0f;
    const double m = static_cast<double>(shot) / (static_cast<double>(q) * q);
    const float count = shot > 0 ? static_cast<float>(static_cast<double>(rng.poisson(m)) - m) : 0.0f;
    return q * count + std::sqrt(total - shot) * z;
}

template <typename T, NoiseAlignment A>
int jitterRowPoissonBody(const T* s, T* d, const float* z, const float* prior, const float* pc,
                         const float* black, const JitterConstants& k, detail::CounterRng& rng, int cols)
{
    const float q = k.pg * k.shot; // DN per electron at the output gain: g alpha p_g
    int bright = 0;
    for (int c = 0; c < cols; ++c) {
        const float x = static_cast<float>(s[c]) - black[c];
        const AddedVariance v = jitterVariance<A>(prior ? prior[c] : x, pc[c], k);
        bright += v.shot + v.rest < 0 ? 1 : 0;
        d[c] = storeValue<T>(pc[c] * x + k.pb + sampledNoise(v, q, z[c], rng) + black[c], k.white);
    }
    return bright;
}

template <typename T>
int jitterRowPoisson(const T* s, T* d, const float* z, const float* prior, const float* pc,
                     const float* black, const JitterConstants& k, detail::CounterRng& rng, int cols)
{
    if (k.alignment == NoiseAlignment::ACCOUNT_PRIOR)
        return jitterRowPoissonBody<T, NoiseAlignment::ACCOUNT_PRIOR>(s, d, z, prior, pc, black, k, rng,
                                                                      cols);
    return jitterRowPoissonBody<T, NoiseAlignment::IGNORE_PRIOR>(s, d, z, prior, pc, black, k, rng, cols);
}

template <typename T>
void jitterRows(const Mat& src, const Mat& prior, Mat& dst, const JitterConstants& k, uint64_t seed,
                uint64_t poissonSeed, const Range& rows, std::atomic<int64>& brightening)
{
    const int cols = src.cols;
    std::vector<float> z(static_cast<size_t>(cols));
    // Per-column constants for even rows (sites 0, 1) and odd rows (sites 2, 3).
    std::vector<float> pcByParity(2 * static_cast<size_t>(cols)),
        blackByParity(2 * static_cast<size_t>(cols));
    for (int parity = 0; parity < 2; ++parity)
        for (int c = 0; c < cols; ++c) {
            pcByParity[static_cast<size_t>(parity * cols + c)] = k.pc[2 * parity + (c & 1)];
            blackByParity[static_cast<size_t>(parity * cols + c)] = k.black[2 * parity + (c & 1)];
        }
    const bool poisson = k.sampling == ShotNoiseSampling::POISSON && k.alignment != NoiseAlignment::NONE;
    int64 localBright = 0;
    for (int r = rows.start; r < rows.end; ++r) {
        if (k.alignment != NoiseAlignment::NONE)
            detail::fillGaussian(seed, static_cast<uint64_t>(r), z.data(), cols);
        const float* pc = pcByParity.data() + (r & 1) * cols;
        const float* black = blackByParity.data() + (r & 1) * cols;
        const float* priorRow = prior.empty() ? nullptr : prior.ptr<float>(r);
        if (poisson) {
            detail::CounterRng rng(poissonSeed, static_cast<uint64_t>(r));
            localBright +=
                jitterRowPoisson(src.ptr<T>(r), dst.ptr<T>(r), z.data(), priorRow, pc, black, k, rng, cols);
        } else {
            localBright += jitterRow(src.ptr<T>(r), dst.ptr<T>(r), z.data(), priorRow, pc, black, k, cols);
        }
    }
    brightening += localBright;
}

// PriorMeanEstimate::LOCAL_MEAN: the black-subtracted mean of each pixel's 3x3 neighbourhood on its own
// CFA plane. On the mosaic that is a separable [1 0 1 0 1] / 3 filter; reflecting about the edge pixel
// maps an offset of -2 to +2, so the border also averages pixels of the same site.
Mat localPriorMean(const Mat& src, const RawFormat& format)
{
    Mat x, mean;
    subtractBlackLevel(src, format, x, false);
    const Matx<float, 1, 5> taps(1.0f / 3, 0, 1.0f / 3, 0, 1.0f / 3);
    sepFilter2D(x, mean, CV_32F, taps, taps.t(), Point(-1, -1), 0, BORDER_REFLECT_101);
    return mean;
}

// Saturated pixels are only counted or masked when the caller asks: the hot loop does not pay for them.
void reportSaturation(const Mat& src, const RawFormat& format, AugmentReport* report, OutputArray mask)
{
    if (!report && !mask.needed())
        return;
    Mat saturated;
    compare(src, format.whiteLevel, saturated, CMP_GE);
    if (report)
        report->saturatedPixels += countNonZero(saturated);
    if (mask.needed())
        mask.assign(saturated);
}

} // namespace

void NoiseOptions::validate() const
{
    if (alignment != NoiseAlignment::NONE && alignment != NoiseAlignment::IGNORE_PRIOR &&
        alignment != NoiseAlignment::ACCOUNT_PRIOR)
        CV_Error(Error::StsBadArg, format("NoiseOptions: unknown alignment %d", static_cast<int>(alignment)));
    if (shotSampling != ShotNoiseSampling::GAUSSIAN && shotSampling != ShotNoiseSampling::POISSON)
        CV_Error(Error::StsBadArg,
                 format("NoiseOptions: unknown shotSampling %d", static_cast<int>(shotSampling)));
    if (priorMean != PriorMeanEstimate::PIXEL_VALUE && priorMean != PriorMeanEstimate::LOCAL_MEAN)
        CV_Error(Error::StsBadArg, format("NoiseOptions: unknown priorMean %d", static_cast<int>(priorMean)));
    if (blurNoiseSum != BlurNoiseSum::EXACT && blurNoiseSum != BlurNoiseSum::FROM_BLURRED_MEAN)
        CV_Error(Error::StsBadArg,
                 format("NoiseOptions: unknown blurNoiseSum %d", static_cast<int>(blurNoiseSum)));
}

void NoiseOptions::writeFields(FileStorage& fs) const
{
    fs << "alignment" << static_cast<int>(alignment) << "shot_sampling" << static_cast<int>(shotSampling)
       << "prior_mean" << static_cast<int>(priorMean) << "blur_noise_sum" << static_cast<int>(blurNoiseSum);
}

NoiseOptions NoiseOptions::readFields(const FileNode& map)
{
    NoiseOptions o;
    const auto field = [&](const char* name, int current) {
        const FileNode f = map[name];
        if (f.empty() || f.isNone())
            return current;
        const double value = f.isInt() || f.isReal() ? static_cast<double>(f) : 0.0;
        if ((!f.isInt() && !f.isReal()) || value != std::floor(value))
            CV_Error(Error::StsParseError, format("noise options: field '%s' must be an integer", name));
        return static_cast<int>(value);
    };
    o.alignment = static_cast<NoiseAlignment>(field("alignment", static_cast<int>(o.alignment)));
    o.shotSampling = static_cast<ShotNoiseSampling>(field("shot_sampling", static_cast<int>(o.shotSampling)));
    o.priorMean = static_cast<PriorMeanEstimate>(field("prior_mean", static_cast<int>(o.priorMean)));
    o.blurNoiseSum = static_cast<BlurNoiseSum>(field("blur_noise_sum", static_cast<int>(o.blurNoiseSum)));
    o.validate();
    return o;
}

ColorJitter ColorJitter::exposureChange(double photonRatio, double gainRatio)
{
    detail::checkFinitePositive(photonRatio, "exposureChange: photonRatio");
    detail::checkFinitePositive(gainRatio, "exposureChange: gainRatio");
    ColorJitter j;
    j.contrast = Vec4d::all(photonRatio * gainRatio);
    j.gainRatio = gainRatio;
    return j;
}

bool ColorJitter::isIdentity() const
{
    return contrast == Vec4d::all(1) && brightness == 0 && gainRatio == 1;
}

void colorJitter(InputArray _src, const RawFormat& format, const NoiseModel& model, const ColorJitter& jitter,
                 const NoiseOptions& noise, uint64 seed, OutputArray _dst, RawFormat& dstFormat,
                 AugmentReport* report, OutputArray saturatedMask)
{
    const Mat src = _src.getMat();
    checkMosaicInput(src, "colorJitter");
    format.validate();
    model.validate();
    noise.validate();
    for (int s = 0; s < 4; ++s)
        detail::checkFinitePositive(jitter.contrast[s], "colorJitter: contrast");
    if (!std::isfinite(jitter.brightness))
        CV_Error(Error::StsBadArg, "colorJitter: brightness must be finite");
    detail::checkFinitePositive(jitter.gainRatio, "colorJitter: gainRatio");
    const double newGain = format.gain * jitter.gainRatio;
    detail::checkFinitePositive(newGain, "colorJitter: the new gain");

    if (jitter.isIdentity()) {
        // Skipped entirely: no copy, no random draw.
        reportSaturation(src, format, report, saturatedMask);
        _dst.assign(src);
        dstFormat = format;
        return;
    }
    const NoiseLine line = model.lineAtGain(format.gain);
    JitterConstants k;
    for (int s = 0; s < 4; ++s) {
        k.pc[s] = static_cast<float>(jitter.contrast[s]);
        k.black[s] = static_cast<float>(format.blackLevel[s]);
    }
    k.pb = static_cast<float>(jitter.brightness);
    k.pg = static_cast<float>(jitter.gainRatio);
    k.white = static_cast<float>(format.whiteLevel);
    k.shot = static_cast<float>(line.a);
    k.read = static_cast<float>(format.gain * format.gain * model.sigmaD2);
    k.post = static_cast<float>(model.sigmaR2);
    k.alignment = noise.alignment;
    k.sampling = noise.shotSampling;

    const Mat prior =
        noise.priorMean == PriorMeanEstimate::LOCAL_MEAN && noise.alignment != NoiseAlignment::NONE
            ? localPriorMean(src, format)
            : Mat();
    Mat dst(src.size(), src.type());
    std::atomic<int64> brightening{0};
    const uint64_t key = stepSeed(seed, 1), poissonKey = stepSeed(seed, 5);
    parallel_for_(Range(0, src.rows), [&](const Range& rows) {
        if (src.depth() == CV_16U)
            jitterRows<ushort>(src, prior, dst, k, key, poissonKey, rows, brightening);
        else
            jitterRows<float>(src, prior, dst, k, key, poissonKey, rows, brightening);
    });
    reportSaturation(src, format, report, saturatedMask);
    _dst.assign(dst);
    dstFormat = format;
    dstFormat.gain = newGain;
    if (report) {
        report->brighteningPixels += brightening.load();
        report->steps.push_back("colorJitter");
    }
}

Mat linearMotionKernel(double length, double angleDegrees)
{
    if (!std::isfinite(length) || length < 0)
        CV_Error(Error::StsBadArg,
                 format("linearMotionKernel: length must be finite and >= 0 (got %g)", length));
    if (!std::isfinite(angleDegrees))
        CV_Error(Error::StsBadArg, "linearMotionKernel: angle must be finite");
    const double planeLength = length / 2; // the CFA planes have half the resolution
    if (planeLength <= 1)
        return Mat::ones(1, 1, CV_32FC1);
    const int radius = static_cast<int>(std::ceil(planeLength / 2));
    const int size = 2 * radius + 1;
    Mat k = Mat::zeros(size, size, CV_64FC1);
    const double a = angleDegrees * CV_PI / 180, ca = std::cos(a), sa = -std::sin(a); // image y points down
    // The segment, supersampled and splatted bilinearly.
    const int samples = std::max(64, static_cast<int>(16 * planeLength));
    for (int i = 0; i < samples; ++i) {
        const double t = ((i + 0.5) / samples - 0.5) * planeLength;
        const double x = radius + t * ca, y = radius + t * sa;
        const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
        const double fx = x - x0, fy = y - y0;
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) {
                const int yy = std::min(size - 1, std::max(0, y0 + dy)),
                          xx = std::min(size - 1, std::max(0, x0 + dx));
                k.at<double>(yy, xx) += (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy);
            }
    }
    k /= sum(k)[0];
    Mat out;
    k.convertTo(out, CV_32F);
    return out;
}

namespace {

Mat normalisedKernel(InputArray _kernel, const char* who)
{
    Mat kernel;
    _kernel.getMat().convertTo(kernel, CV_64F);
    if (kernel.empty() || !checkRange(kernel, true))
        CV_Error(Error::StsBadArg, format("%s: kernel must be non-empty and finite", who));
    double lo = 0;
    minMaxLoc(kernel, &lo);
    const double total = sum(kernel)[0];
    if (lo < 0 || !(total > 0))
        CV_Error(Error::StsBadArg, format("%s: kernel must be non-negative with a positive sum", who));
    return kernel / total;
}

bool isIdentityKernel(const Mat& kernel)
{
    return kernel.empty() || kernel.total() == 1;
}

// Constants of a resampling step (blur or scale) on one mosaic: Eq. 15 with the step's weights.
struct ResampleConstants
{
    float black[4];
    float white;
    float shot;     // g alpha
    float floorVar; // g^2 sigma_d^2 + sigma_r^2: the read noise a weighted sum removes, (1 - sum w^2) of it
    NoiseAlignment alignment;
    ShotNoiseSampling sampling;
    uint64_t key, poissonKey; // the step's Gaussian and Poisson streams
};

// Plane row `planeRow` of site `site`, black-subtracted, into out[0..pad + width + pad) with the plane's
// edge replicated `pad` columns on each side.
template <typename T>
void loadPlaneRow(const Mat& src, int site, int planeRow, int pad, float black, float* out)
{
    const T* s = src.ptr<T>(2 * planeRow + site / 2) + site % 2;
    const int width = src.cols / 2;
    for (int j = 0; j < width; ++j)
        out[pad + j] = static_cast<float>(s[2 * j]) - black;
    for (int j = 0; j < pad; ++j) {
        out[j] = out[pad];
        out[pad + width + j] = out[pad + width - 1];
    }
}

// One kernel tap over a row: mean += w x, and for ACCOUNT_PRIOR shot += w (1 - w) max(x, 0) (the prior
// mean is never negative), in one pass over the source row.
RAWGMENT_HOT_KERNEL
void addTapRow(float* mean, float* shot, const float* x, float w, float shotWeight, bool withShot, int n)
{
    if (withShot) {
        for (int j = 0; j < n; ++j) {
            mean[j] += w * x[j];
            shot[j] += shotWeight * std::max(x[j], 0.0f);
        }
    } else {
        for (int j = 0; j < n; ++j)
            mean[j] += w * x[j];
    }
}

// mean[j] + N(0, v): v from the per-pixel shot sum and read-noise factor (ACCOUNT_PRIOR), from the
// mean (IGNORE_PRIOR), or none; black added back, clipped to [0, white].
RAWGMENT_HOT_KERNEL
void finishResampledRow(float* mean, const float* shotSum, const float* readFactor, const float* z,
                        const ResampleConstants& k, float black, int n)
{
    if (k.alignment == NoiseAlignment::ACCOUNT_PRIOR) {
        for (int j = 0; j < n; ++j) {
            const float v = k.shot * shotSum[j] + readFactor[j] * k.floorVar;
            mean[j] =
                std::min(std::max(mean[j] + std::sqrt(std::max(v, 0.0f)) * z[j] + black, 0.0f), k.white);
        }
    } else if (k.alignment == NoiseAlignment::IGNORE_PRIOR) {
        for (int j = 0; j < n; ++j) {
            const float v = k.shot * std::max(mean[j], 0.0f) + k.floorVar;
            mean[j] = std::min(std::max(mean[j] + std::sqrt(v) * z[j] + black, 0.0f), k.white);
        }
    } else {
        for (int j = 0; j < n; ++j)
            mean[j] = std::min(std::max(mean[j] + black, 0.0f), k.white);
    }
}

template <typename T> void storePlaneRow(const float* v, Mat& dst, int site, int planeRow)
{
    T* d = dst.ptr<T>(2 * planeRow + site / 2) + site % 2;
    const int width = dst.cols / 2;
    for (int j = 0; j < width; ++j)
        d[2 * j] = std::is_same<T, ushort>::value ? static_cast<T>(static_cast<int>(v[j] + 0.5f))
                                                  : static_cast<T>(v[j]);
}

// ShotNoiseSampling::POISSON for a resampled row: the shot part of Eq. 15 (or of the model, for
// IGNORE_PRIOR) as an electron count at the input gain (see sampledNoise), the rest Gaussian.
void finishResampledRowPoisson(float* mean, const float* shotSum, const float* readFactor, const float* z,
                               const ResampleConstants& k, float black, detail::CounterRng& rng, int n)
{
    for (int j = 0; j < n; ++j) {
        const AddedVariance v = k.alignment == NoiseAlignment::ACCOUNT_PRIOR
                                    ? AddedVariance{k.shot * shotSum[j], readFactor[j] * k.floorVar}
                                    : AddedVariance{k.shot * std::max(mean[j], 0.0f), k.floorVar};
        mean[j] = std::min(std::max(mean[j] + sampledNoise(v, k.shot, z[j], rng) + black, 0.0f), k.white);
    }
}

// The end of every resampled row: its noise streams (site, row), the noise, the black level, the store.
template <typename T>
void finishPlaneRow(std::vector<float>& mean, const float* shotSum, const float* readFactor,
                    std::vector<float>& z, const ResampleConstants& k, Mat& dst, int site, int planeRow)
{
    const int n = static_cast<int>(mean.size());
    const uint64_t stream = (static_cast<uint64_t>(site) << 32) | static_cast<uint64_t>(planeRow);
    if (k.alignment != NoiseAlignment::NONE)
        detail::fillGaussian(k.key, stream, z.data(), n);
    if (k.alignment != NoiseAlignment::NONE && k.sampling == ShotNoiseSampling::POISSON) {
        detail::CounterRng rng(k.poissonKey, stream);
        finishResampledRowPoisson(mean.data(), shotSum, readFactor, z.data(), k, k.black[site], rng, n);
    } else {
        finishResampledRow(mean.data(), shotSum, readFactor, z.data(), k, k.black[site], n);
    }
    storePlaneRow<T>(mean.data(), dst, site, planeRow);
}

// `step` names the step's random streams (stepSeed); its Poisson streams are step + 4.
ResampleConstants resampleConstants(const RawFormat& format, const NoiseModel& model,
                                    const NoiseOptions& noise, uint64 seed, uint64_t step)
{
    const NoiseLine line = model.lineAtGain(format.gain);
    ResampleConstants k;
    for (int s = 0; s < 4; ++s)
        k.black[s] = static_cast<float>(format.blackLevel[s]);
    k.white = static_cast<float>(format.whiteLevel);
    k.shot = static_cast<float>(line.a);
    k.floorVar = static_cast<float>(line.b);
    k.alignment = noise.alignment;
    k.sampling = noise.shotSampling;
    k.key = stepSeed(seed, step);
    k.poissonKey = stepSeed(seed, step + 4);
    return k;
}

struct KernelTap
{
    int dy, dx;
    float w, shotWeight; // w and w (1 - w)
};

// Within a kernel radius of the frame's edge, several taps replicate one pixel: its prior noise is then
// kept with the square of their summed weight, not the sum of their squares, so Eq. 15 needs the
// weight W of each distinct source pixel. The taps of output pixel (i, j), clamped along the chosen
// axes and merged per source, with offsets that still read i + dy - ry, j + dx - rx; shotWeight is
// W (1 - W) and the return value the read-noise factor 1 - sum W^2.
float mergeClampedTaps(const std::vector<KernelTap>& taps, int i, int j, Size plane, Size radius,
                       bool clampRows, bool clampCols, std::vector<KernelTap>& merged)
{
    merged.clear();
    for (const KernelTap& t : taps) {
        const int dy =
            clampRows ? std::min(std::max(i + t.dy - radius.height, 0), plane.height - 1) - i + radius.height
                      : t.dy;
        const int dx =
            clampCols ? std::min(std::max(j + t.dx - radius.width, 0), plane.width - 1) - j + radius.width
                      : t.dx;
        auto same = std::find_if(merged.begin(), merged.end(),
                                 [&](const KernelTap& m) { return m.dy == dy && m.dx == dx; });
        if (same != merged.end())
            same->w += t.w;
        else
            merged.push_back({dy, dx, t.w, 0.0f});
    }
    float readFactor = 1;
    for (KernelTap& m : merged) {
        m.shotWeight = m.w * (1 - m.w);
        readFactor -= m.w * m.w;
    }
    return readFactor;
}

// Plane rows come from a ring of kernel-height rows: consecutive output rows share all but one source
// row, and the rows a window needs are consecutive after clamping, hence distinct modulo the height.
// Rows near the top or bottom use their taps merged per clamped row (exact for every column whose taps
// do not also clamp sideways, and still vectorised); the columns within a kernel radius of the sides
// use taps merged per clamped column (precomputed), or per pixel where the row clamps too.
template <typename T>
void blurPlaneRows(const Mat& src, Mat& dst, const std::vector<KernelTap>& taps, Size ksize, float readFactor,
                   bool shotFromMean, const ResampleConstants& k, const Range& range)
{
    const int pw = src.cols / 2, ph = src.rows / 2, rx = ksize.width / 2, ry = ksize.height / 2;
    const Size plane(pw, ph), radius(rx, ry);
    const int padded = pw + 2 * rx;
    std::vector<float> ring(static_cast<size_t>(ksize.height) * padded);
    std::vector<int> ringRow(static_cast<size_t>(ksize.height), -1);
    std::vector<float> mean(static_cast<size_t>(pw)), shotSum(static_cast<size_t>(pw)),
        z(static_cast<size_t>(pw)), readFactors(static_cast<size_t>(pw));
    const bool account = k.alignment == NoiseAlignment::ACCOUNT_PRIOR;
    const bool exactShot = account && !shotFromMean;
    struct EdgeColumn
    {
        int j;
        std::vector<KernelTap> taps;
        float readFactor;
    };
    std::vector<EdgeColumn> edgeColumns;
    for (int j = 0; j < pw; ++j)
        if (j < rx || j >= pw - rx) {
            EdgeColumn e{j, {}, 0.0f};
            e.readFactor = mergeClampedTaps(taps, 0, j, plane, radius, false, true, e.taps);
            edgeColumns.push_back(std::move(e));
        }
    std::vector<KernelTap> rowTaps, pixelTaps;
    int ringSite = -1;
    for (int idx = range.start; idx < range.end; ++idx) {
        const int site = idx / ph, i = idx % ph;
        if (site != ringSite) {
            std::fill(ringRow.begin(), ringRow.end(), -1);
            ringSite = site;
        }
        const bool edgeRow = i < ry || i >= ph - ry;
        const float rowReadFactor =
            edgeRow ? mergeClampedTaps(taps, i, 0, plane, radius, true, false, rowTaps) : readFactor;
        std::fill(mean.begin(), mean.end(), 0.0f);
        std::fill(shotSum.begin(), shotSum.end(), 0.0f);
        std::fill(readFactors.begin(), readFactors.end(), rowReadFactor);
        for (const KernelTap& t : edgeRow ? rowTaps : taps) {
            const int si = std::min(std::max(i + t.dy - ry, 0), ph - 1);
            const size_t slot = static_cast<size_t>(si % ksize.height);
            float* row = ring.data() + slot * padded;
            if (ringRow[slot] != si) {
                loadPlaneRow<T>(src, site, si, rx, k.black[site], row);
                ringRow[slot] = si;
            }
            addTapRow(mean.data(), shotSum.data(), row + t.dx, t.w, t.shotWeight, exactShot, pw);
        }
        if (!account) {
            finishPlaneRow<T>(mean, shotSum.data(), readFactors.data(), z, k, dst, site, i);
            continue;
        }
        for (const EdgeColumn& e : edgeColumns) {
            const std::vector<KernelTap>* merged = &e.taps;
            readFactors[static_cast<size_t>(e.j)] = e.readFactor;
            if (edgeRow) {
                readFactors[static_cast<size_t>(e.j)] =
                    mergeClampedTaps(taps, i, e.j, plane, radius, true, true, pixelTaps);
                merged = &pixelTaps;
            }
            float shot = 0;
            for (const KernelTap& t : *merged)
                shot +=
                    t.shotWeight *
                    std::max(ring[static_cast<size_t>((i + t.dy - ry) % ksize.height) * padded + e.j + t.dx],
                             0.0f);
            shotSum[static_cast<size_t>(e.j)] = shot;
        }
        if (shotFromMean) // sum w (1 - w) = 1 - sum w^2, the read-noise factor
            for (int j = 0; j < pw; ++j)
                shotSum[static_cast<size_t>(j)] =
                    readFactors[static_cast<size_t>(j)] * std::max(mean[static_cast<size_t>(j)], 0.0f);
        finishPlaneRow<T>(mean, shotSum.data(), readFactors.data(), z, k, dst, site, i);
    }
}

// Source position on the plane grid of each output plane pixel for a scale about the mosaic centre:
// plane index j of site column px sits at mosaic x = 2 j + px; its source is C + (x - C) / scale.
struct BilinearAxis
{
    std::vector<int> i0, i1;
    std::vector<float> f; // weight of i1; 0 when the two clamp onto the same pixel
};

BilinearAxis bilinearAxis(int planeSize, int phase, double scale)
{
    BilinearAxis a;
    a.i0.resize(static_cast<size_t>(planeSize));
    a.i1.resize(static_cast<size_t>(planeSize));
    a.f.resize(static_cast<size_t>(planeSize));
    const double centre = (2.0 * planeSize - 1) / 2;
    for (int j = 0; j < planeSize; ++j) {
        const double x = centre + (2.0 * j + phase - centre) / scale;
        const double planeX = (x - phase) / 2;
        const double lo = std::floor(planeX);
        const int i0 = static_cast<int>(std::min(std::max(lo, 0.0), planeSize - 1.0));
        const int i1 = static_cast<int>(std::min(std::max(lo + 1, 0.0), planeSize - 1.0));
        a.i0[static_cast<size_t>(j)] = i0;
        a.i1[static_cast<size_t>(j)] = i1;
        a.f[static_cast<size_t>(j)] = i0 == i1 ? 0.0f : static_cast<float>(planeX - lo);
    }
    return a;
}

// Bilinear taps of one output row: mean, Eq. 15's shot sum and the read-noise factor 1 - sum w^2,
// all per pixel because the weights change along the row.
RAWGMENT_HOT_KERNEL
void bilinearRow(const float* row0, const float* row1, float fy, const int* c0, const int* c1,
                 const float* fx, float* mean, float* shot, float* readFactor, int n)
{
    for (int j = 0; j < n; ++j) {
        const float a = row0[c0[j]], b = row0[c1[j]], c = row1[c0[j]], d = row1[c1[j]];
        const float w00 = (1 - fx[j]) * (1 - fy), w01 = fx[j] * (1 - fy), w10 = (1 - fx[j]) * fy,
                    w11 = fx[j] * fy;
        mean[j] = w00 * a + w01 * b + w10 * c + w11 * d;
        shot[j] = w00 * (1 - w00) * std::max(a, 0.0f) + w01 * (1 - w01) * std::max(b, 0.0f) +
                  w10 * (1 - w10) * std::max(c, 0.0f) + w11 * (1 - w11) * std::max(d, 0.0f);
        readFactor[j] = 1 - (w00 * w00 + w01 * w01 + w10 * w10 + w11 * w11);
    }
}

template <typename T>
void scalePlaneRows(const Mat& src, Mat& dst, const BilinearAxis* cols, const BilinearAxis* rows,
                    const ResampleConstants& k, const Range& range)
{
    const int pw = src.cols / 2, ph = src.rows / 2;
    std::vector<float> row0(static_cast<size_t>(pw)), row1(static_cast<size_t>(pw));
    std::vector<float> mean(static_cast<size_t>(pw)), shot(static_cast<size_t>(pw)),
        readFactor(static_cast<size_t>(pw)), z(static_cast<size_t>(pw));
    for (int idx = range.start; idx < range.end; ++idx) {
        const int site = idx / ph, i = idx % ph;
        const BilinearAxis& ax = cols[site % 2];
        const BilinearAxis& ay = rows[site / 2];
        loadPlaneRow<T>(src, site, ay.i0[static_cast<size_t>(i)], 0, k.black[site], row0.data());
        loadPlaneRow<T>(src, site, ay.i1[static_cast<size_t>(i)], 0, k.black[site], row1.data());
        bilinearRow(row0.data(), row1.data(), ay.f[static_cast<size_t>(i)], ax.i0.data(), ax.i1.data(),
                    ax.f.data(), mean.data(), shot.data(), readFactor.data(), pw);
        finishPlaneRow<T>(mean, shot.data(), readFactor.data(), z, k, dst, site, i);
    }
}

} // namespace

void scaleMosaic(InputArray _src, const RawFormat& format, const NoiseModel& model, double scale,
                 const NoiseOptions& noise, uint64 seed, OutputArray _dst, AugmentReport* report)
{
    const Mat src = _src.getMat();
    checkResampleInput(src, format, model, noise, "scaleMosaic");
    if (!std::isfinite(scale) || !(scale > 0))
        CV_Error(Error::StsBadArg, cv::format("scaleMosaic: scale must be finite and > 0 (got %g)", scale));
    if (scale == 1) {
        _dst.assign(src);
        return;
    }
    const BilinearAxis cols[2] = {bilinearAxis(src.cols / 2, 0, scale), bilinearAxis(src.cols / 2, 1, scale)};
    const BilinearAxis rows[2] = {bilinearAxis(src.rows / 2, 0, scale), bilinearAxis(src.rows / 2, 1, scale)};
    const ResampleConstants k = resampleConstants(format, model, noise, seed, 4);
    Mat dst(src.size(), src.type());
    parallel_for_(Range(0, 2 * src.rows), [&](const Range& range) {
        if (src.depth() == CV_16U)
            scalePlaneRows<ushort>(src, dst, cols, rows, k, range);
        else
            scalePlaneRows<float>(src, dst, cols, rows, k, range);
    });
    _dst.assign(dst);
    if (report)
        report->steps.push_back("scale");
}

Rect scaleBox(const Rect& box, Size size, double scale)
{
    // Edges in continuous coordinates (pixel k covers [k, k + 1)); the box grows to whole pixels.
    const double cx = size.width / 2.0, cy = size.height / 2.0;
    const int x0 = static_cast<int>(std::floor(cx + (box.x - cx) * scale));
    const int y0 = static_cast<int>(std::floor(cy + (box.y - cy) * scale));
    const int x1 = static_cast<int>(std::ceil(cx + (box.x + box.width - cx) * scale));
    const int y1 = static_cast<int>(std::ceil(cy + (box.y + box.height - cy) * scale));
    if (box.area() == 0)
        return Rect();
    return Rect(Point(x0, y0), Point(x1, y1)) & Rect(Point(0, 0), size);
}

void motionBlur(InputArray _src, const RawFormat& format, const NoiseModel& model, InputArray _kernel,
                const NoiseOptions& noise, uint64 seed, OutputArray _dst, AugmentReport* report)
{
    const Mat src = _src.getMat();
    checkResampleInput(src, format, model, noise, "motionBlur");
    const Mat w = normalisedKernel(_kernel, "motionBlur");
    if (w.total() == 1) {
        _dst.assign(src);
        return;
    }
    // Sparse: a motion kernel is a line, so most of its box is zero and costs nothing.
    std::vector<KernelTap> taps;
    for (int y = 0; y < w.rows; ++y)
        for (int x = 0; x < w.cols; ++x) {
            const double wk = w.at<double>(y, x);
            if (wk > 0)
                taps.push_back({y, x, static_cast<float>(wk), static_cast<float>(wk * (1 - wk))});
        }
    const ResampleConstants k = resampleConstants(format, model, noise, seed, 2);
    const float readFactor = static_cast<float>(1 - w.dot(w));
    const bool shotFromMean = noise.blurNoiseSum == BlurNoiseSum::FROM_BLURRED_MEAN;
    Mat dst(src.size(), src.type());
    parallel_for_(Range(0, 2 * src.rows), [&](const Range& range) {
        if (src.depth() == CV_16U)
            blurPlaneRows<ushort>(src, dst, taps, w.size(), readFactor, shotFromMean, k, range);
        else
            blurPlaneRows<float>(src, dst, taps, w.size(), readFactor, shotFromMean, k, range);
    });
    _dst.assign(dst);
    if (report)
        report->steps.push_back("motionBlur");
}

// ---------------------------------------------------------------------------------------------------
// Scenes

bool Scene::isIdentity() const
{
    return shift == Point(0, 0) && scale == 1 && jitter.isIdentity() && isIdentityKernel(motionKernel);
}

void Scene::write(FileStorage& fs, const String& name) const
{
    fs << name << "{";
    fs << "shift" << shift << "scale" << scale;
    fs << "contrast"
       << "[" << jitter.contrast[0] << jitter.contrast[1] << jitter.contrast[2] << jitter.contrast[3] << "]";
    fs << "brightness" << jitter.brightness << "gain_ratio" << jitter.gainRatio;
    noise.writeFields(fs);
    fs << "motion_kernel" << (motionKernel.empty() ? Mat::ones(1, 1, CV_32F) : motionKernel);
    fs << "}";
}

Scene Scene::read(const FileNode& node)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError, "scene: expected a map");
    Scene s;
    node["shift"] >> s.shift;
    if (!node["scale"].empty())
        s.scale = detail::readRealField(node, "scale");
    if (!std::isfinite(s.scale) || !(s.scale > 0))
        CV_Error(Error::StsParseError, "scene: field 'scale' must be a finite number > 0");
    const FileNode c = node["contrast"];
    if (!c.isSeq() || c.size() != 4)
        CV_Error(Error::StsParseError, "scene: field 'contrast' must be a list of 4 numbers (one per site)");
    for (int i = 0; i < 4; ++i)
        s.jitter.contrast[i] = static_cast<double>(c[i]);
    s.jitter.brightness = detail::readRealField(node, "brightness");
    s.jitter.gainRatio = detail::readRealField(node, "gain_ratio");
    s.noise = NoiseOptions::readFields(node);
    node["motion_kernel"] >> s.motionKernel;
    return s;
}

void applyScene(InputArray _src, const RawFormat& format, const NoiseModel& model, const Scene& scene,
                uint64 seed, OutputArray _dst, RawFormat& dstFormat, AugmentReport* report,
                std::vector<Rect>* boxes)
{
    Mat current = _src.getMat();
    checkMosaicInput(current, "applyScene");
    format.validate();
    model.validate();
    if (current.rows % 2 || current.cols % 2)
        CV_Error(Error::StsBadArg, "applyScene: the mosaic needs even sides");
    RawFormat fmt = format;
    const Point shift(2 * cvRound(scene.shift.x / 2.0), 2 * cvRound(scene.shift.y / 2.0));
    if (shift != Point(0, 0)) {
        // Shift each CFA plane by half the (even) offset: the phase of the mosaic is kept.
        std::vector<Mat> planes;
        splitCfaPlanes(current, planes);
        const Matx23d m(1, 0, shift.x / 2, 0, 1, shift.y / 2);
        for (Mat& p : planes) {
            Mat moved;
            warpAffine(p, moved, m, p.size(), INTER_NEAREST, BORDER_REPLICATE);
            p = moved;
        }
        // Into a new Mat: `current` still shares the caller's data, which must never be written.
        Mat shifted;
        mergeCfaPlanes(planes, shifted);
        current = shifted;
        if (boxes)
            for (Rect& b : *boxes)
                b = (b + shift) & Rect(0, 0, current.cols, current.rows);
        if (report)
            report->steps.push_back("shift");
    }
    if (scene.scale != 1) {
        scaleMosaic(current, fmt, model, scene.scale, scene.noise, seed, current, report);
        if (boxes)
            for (Rect& b : *boxes)
                b = scaleBox(b, current.size(), scene.scale);
    }
    colorJitter(current, fmt, model, scene.jitter, scene.noise, seed, current, fmt, report);
    if (!isIdentityKernel(scene.motionKernel))
        motionBlur(current, fmt, model, scene.motionKernel, scene.noise, seed, current, report);
    _dst.assign(current);
    dstFormat = fmt;
}

// ---------------------------------------------------------------------------------------------------
// Random policy

namespace {

// min over pixels of (value - black of its site), without a black-subtracted copy of the frame.
template <typename T> double minimumAboveBlackOf(const Mat& src, const RawFormat& format)
{
    double lowest = std::numeric_limits<double>::infinity();
    for (int r = 0; r < src.rows; ++r) {
        const T* p = src.ptr<T>(r);
        T lo[2] = {std::numeric_limits<T>::max(), std::numeric_limits<T>::max()};
        for (int c = 0; c < src.cols; ++c)
            lo[c & 1] = std::min(lo[c & 1], p[c]);
        for (int phase = 0; phase < std::min(2, src.cols); ++phase)
            lowest = std::min(lowest, static_cast<double>(lo[phase]) - format.blackAt(r, phase));
    }
    return lowest;
}

double minimumAboveBlack(const Mat& src, const RawFormat& format)
{
    return src.depth() == CV_16U ? minimumAboveBlackOf<ushort>(src, format)
                                 : minimumAboveBlackOf<float>(src, format);
}

} // namespace

void RandomScenePolicy::validate() const
{
    const auto range = [](double lo, double hi, const char* what) {
        if (!std::isfinite(lo) || !std::isfinite(hi) || lo > hi)
            CV_Error(Error::StsBadArg,
                     format("RandomScenePolicy: %s range [%g, %g] is not a finite interval", what, lo, hi));
    };
    const auto probability = [](double p, const char* what) {
        if (!(p >= 0 && p <= 1))
            CV_Error(Error::StsBadArg, format("RandomScenePolicy: %s must lie in [0, 1] (got %g)", what, p));
    };
    range(contrastMin, contrastMax, "contrast");
    if (!(contrastMin > 0))
        CV_Error(Error::StsBadArg, "RandomScenePolicy: contrastMin must be > 0");
    range(brightnessMin, brightnessMax, "brightness");
    range(hueMin, hueMax, "hue");
    if (!(hueMin > 0))
        CV_Error(Error::StsBadArg, "RandomScenePolicy: hueMin must be > 0");
    range(gainDbMin, gainDbMax, "gain (dB)");
    range(0, blurLengthMax, "blur length");
    range(0, maxShift, "shift");
    if (!(maxScale >= 0 && maxScale < 1))
        CV_Error(Error::StsBadArg,
                 format("RandomScenePolicy: maxScale must lie in [0, 1) (got %g)", maxScale));
    probability(hueProbability, "hueProbability");
    probability(blurProbability, "blurProbability");
    probability(geometryProbability, "geometryProbability");
    noise.validate();
}

Scene RandomScenePolicy::draw(InputArray _src, const RawFormat& format, uint64 seed) const
{
    validate();
    const Mat src = _src.getMat();
    checkMosaicInput(src, "RandomScenePolicy::draw");
    const double minX = minimumAboveBlack(src, format);
    detail::CounterRng rng(stepSeed(seed, 3), 0);
    const auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * rng.uniform(); };
    Scene s;
    s.noise = noise;
    if (rng.uniform() < geometryProbability) {
        s.shift = Point(cvRound(uniform(-maxShift, maxShift) * src.cols),
                        cvRound(uniform(-maxShift, maxShift) * src.rows));
        s.scale = uniform(1 - maxScale, 1 + maxScale);
    }
    const double contrast = std::exp(uniform(std::log(contrastMin), std::log(contrastMax)));
    s.jitter.contrast = Vec4d::all(contrast);
    if (rng.uniform() < hueProbability)
        for (int i = 0; i < 4; ++i)
            s.jitter.contrast[i] *= uniform(hueMin, hueMax);
    s.jitter.brightness = uniform(brightnessMin, brightnessMax) * minX;
    s.jitter.gainRatio = dbToLinearGain(uniform(gainDbMin, gainDbMax));
    if (rng.uniform() < blurProbability)
        s.motionKernel = linearMotionKernel(uniform(0, blurLengthMax), uniform(0, 180));
    return s;
}

void RandomScenePolicy::write(FileStorage& fs, const String& name) const
{
    fs << name << "{";
    fs << "contrast_min" << contrastMin << "contrast_max" << contrastMax;
    fs << "brightness_min" << brightnessMin << "brightness_max" << brightnessMax;
    fs << "hue_probability" << hueProbability << "hue_min" << hueMin << "hue_max" << hueMax;
    fs << "gain_db_min" << gainDbMin << "gain_db_max" << gainDbMax;
    fs << "blur_probability" << blurProbability << "blur_length_max" << blurLengthMax;
    fs << "geometry_probability" << geometryProbability << "max_shift" << maxShift << "max_scale" << maxScale;
    noise.writeFields(fs);
    fs << "}";
}

RandomScenePolicy RandomScenePolicy::read(const FileNode& node)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError, "random scene policy: expected a map");
    RandomScenePolicy p;
    const auto field = [&](const char* name, double& value) {
        const FileNode f = node[name];
        if (f.empty() || f.isNone())
            return;
        if (!f.isReal() && !f.isInt())
            CV_Error(Error::StsParseError, format("random scene policy: field '%s' is not a number", name));
        value = static_cast<double>(f);
    };
    field("contrast_min", p.contrastMin);
    field("contrast_max", p.contrastMax);
    field("brightness_min", p.brightnessMin);
    field("brightness_max", p.brightnessMax);
    field("hue_probability", p.hueProbability);
    field("hue_min", p.hueMin);
    field("hue_max", p.hueMax);
    field("gain_db_min", p.gainDbMin);
    field("gain_db_max", p.gainDbMax);
    field("blur_probability", p.blurProbability);
    field("blur_length_max", p.blurLengthMax);
    field("geometry_probability", p.geometryProbability);
    field("max_shift", p.maxShift);
    field("max_scale", p.maxScale);
    p.noise = NoiseOptions::readFields(node);
    p.validate();
    return p;
}

void RandomScenePolicy::save(const String& path) const
{
    validate();
    detail::writeFileStorageAtomically(path, [&](FileStorage& fs) { write(fs, "random_scene_policy"); });
}

RandomScenePolicy RandomScenePolicy::load(const String& path)
{
    return detail::loadFileStorage(path, "random_scene_policy", "random scene policy",
                                   [](const FileNode& n) { return read(n); });
}

} // namespace rawgment
} // namespace cv
