// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Colour jitter: noise-accounted exposure, gain, contrast, brightness and hue (paper Eq. 11 and 13).
#include "color_jitter_rows.hpp"

#include "bank_noise.hpp"
#include "noise_step.hpp"

#include <opencv2/imgproc.hpp>

#include <atomic>
#include <cstring>

namespace cv {
namespace rawgment {

namespace {

using detail::AddedVariance;
using detail::JitterColumns;
using detail::JitterConstants;
using detail::jitterRowPoisson;
using detail::jitterVariance;
using detail::PixelLanes;
using detail::PoissonRowBuffers;
using detail::storeValue;

/* Eq. 13 with p_u = p_c / p_g (no brightness) as a line in the black-subtracted mean:
 * slope p_u (1 - p_u) p_g^2 g alpha, offset (1 - p_u^2) p_g^2 g^2 sigma_d^2 + (1 - p_c^2) sigma_r^2,
 * in double and rounded once. The per-pixel form divides by the clamped mean for every pixel and gives
 * the same values to float rounding; this one costs a multiply-add. */
void perSiteLine(double pc, double pg, const detail::NoiseTerms<double>& in, float& slope, float& offset)
{
    const double pu = pc / pg;
    slope = static_cast<float>(pu * (1 - pu) * pg * pg * in.shot);
    offset =
        static_cast<float>((1 - pu * pu) * pg * pg * in.readBeforeGain + (1 - pc * pc) * in.readAfterGain);
}

/* The same line with measured lines, each gain's own: the output gain's line at the output mean p_c mu
 * less the prior scaled by p_c^2, slope p_c a_out - p_c^2 a_in and offset b_out - p_c^2 b_in (perSiteLine()
 * when a_out = p_g a_in and b_out = p_g^2 g^2 sigma_d^2 + sigma_r^2). */
void measuredSiteLine(double pc, const detail::NoiseTerms<double>& in, const detail::NoiseTerms<double>& out,
                      float& slope, float& offset)
{
    slope = static_cast<float>(pc * out.shot - pc * pc * in.shot);
    offset = static_cast<float>(out.read() - pc * pc * in.read());
}

// One row of Eq. 11/13 on explicit vectors of W lanes (cpu_dispatch.hpp). `prior` is the local-mean
// row, or null to use the pixel's own value; per-column constants come in arrays (the CFA site
// alternates along the row). The last partial block runs through the same vector code on padded
// copies, so every pixel goes through the same operations on every path. 16-bit output is clipped to
// [0, white] and rounded half to even (detail::roundHalfToEven). Returns the number of brightening pixels (a
// negative added variance, which adds no noise).
// t: the row's unit-variance heavy-tailed draws (NoiseModel::tukeyRead), or null. With them the read
// part of the variance (the rest, never more than the total) takes t and the shot part z, as
// detail::splitNoise() does; with kLineBySite the read part is the line's offset.
template <int W, typename T, NoiseAlignment A, bool kLocalMean, bool kLineBySite>
RAWGMENT_KERNEL void jitterBlock(const T* s, T* d, const float* z, const float* t, const float* prior,
                                 const float* extra, const JitterColumns& col, int c,
                                 const JitterConstants& k, typename detail::Lanes<W>::I& bright)
{
    typedef typename detail::Lanes<W>::F F;
    typedef PixelLanes<W, T> P;
    F pcv, blackv;
    std::memcpy(&pcv, col.pc + c, sizeof(pcv));
    std::memcpy(&blackv, col.black + c, sizeof(blackv));
    const F x = P::load(s + c) - blackv;
    F out = pcv * x + k.pb;
    if (A != NoiseAlignment::NONE) {
        F xm = x, zv;
        if (kLocalMean)
            std::memcpy(&xm, prior + c, sizeof(xm));
        std::memcpy(&zv, z + c, sizeof(zv));
        if (kLineBySite) {
            F slope, offset;
            std::memcpy(&slope, col.slope + c, sizeof(slope));
            std::memcpy(&offset, col.offset + c, sizeof(offset));
            const F total = slope * detail::maxLanes(xm, F{}) + offset;
            bright -= total < 0; // -1 per brightening lane
            if (t) {
                // The line's offset is the read part of Eq. 13 (perSiteLine()), its slope term the shot part.
                F tv;
                std::memcpy(&tv, t + c, sizeof(tv));
                const F all = detail::maxLanes(total, F{});
                const F read = detail::minLanes(detail::maxLanes(offset, F{}), all);
                out += detail::sqrtLanes(all - read) * zv + detail::sqrtLanes(read) * tv;
            } else {
                out += detail::sqrtLanes(detail::maxLanes(total, F{})) * zv;
            }
        } else {
            const detail::AddedVarianceOf<F> v = jitterVariance<A>(xm, pcv, k);
            const F total = v.shot + v.rest;
            bright -= total < 0;
            if (t) {
                F tv;
                std::memcpy(&tv, t + c, sizeof(tv));
                const F all = detail::maxLanes(total, F{});
                const F read = detail::minLanes(detail::maxLanes(v.rest, F{}), all);
                out += detail::sqrtLanes(all - read) * zv + detail::sqrtLanes(read) * tv;
            } else {
                out += detail::sqrtLanes(detail::maxLanes(total, F{})) * zv;
            }
        }
    }
    if (extra) { // the dark-frame components (row offset, dark shading), when the model has them
        F e;
        std::memcpy(&e, extra + c, sizeof(e));
        out += e;
    }
    P::store(d + c, out + blackv, F{} + k.white);
}

template <int W, typename T, NoiseAlignment A, bool kLocalMean, bool kLineBySite>
RAWGMENT_KERNEL int jitterRowBody(const T* s, T* d, const float* z, const float* t, const float* prior,
                                  const float* extra, const JitterColumns& col, const JitterConstants& k,
                                  int cols)
{
    typename detail::Lanes<W>::I bright = {};
    int c = 0;
    for (; c + W <= cols; c += W)
        jitterBlock<W, T, A, kLocalMean, kLineBySite>(s, d, z, t, prior, extra, col, c, k, bright);
    int total = 0;
    for (int i = 0; i < W; ++i)
        total += bright[i];
    const int rest = cols - c;
    if (rest > 0) {
        // Padded copies: the extra lanes compute on zeros and are neither stored nor counted.
        T sPad[W] = {}, dPad[W];
        float zPad[W] = {}, tPad[W] = {}, priorPad[W] = {}, extraPad[W] = {}, pcPad[W] = {}, blackPad[W] = {},
              slopePad[W] = {}, offsetPad[W] = {};
        for (int i = 0; i < rest; ++i) {
            sPad[i] = s[c + i];
            zPad[i] = z ? z[c + i] : 0.0f;
            tPad[i] = t ? t[c + i] : 0.0f;
            priorPad[i] = kLocalMean ? prior[c + i] : 0.0f;
            extraPad[i] = extra ? extra[c + i] : 0.0f;
            pcPad[i] = col.pc[c + i];
            blackPad[i] = col.black[c + i];
            slopePad[i] = kLineBySite ? col.slope[c + i] : 0.0f;
            offsetPad[i] = kLineBySite ? col.offset[c + i] : 0.0f;
        }
        const JitterColumns padded = {pcPad, blackPad, slopePad, offsetPad};
        typename detail::Lanes<W>::I tail = {};
        jitterBlock<W, T, A, kLocalMean, kLineBySite>(sPad, dPad, zPad, t ? tPad : nullptr, priorPad,
                                                      extra ? extraPad : nullptr, padded, 0, k, tail);
        for (int i = 0; i < rest; ++i) {
            d[c + i] = dPad[i];
            total += tail[i];
        }
    }
    return total;
}

template <int W, typename T, bool kLocalMean>
RAWGMENT_KERNEL int jitterRowAnyAlignment(const T* s, T* d, const float* z, const float* t,
                                          const float* prior, const float* extra, const JitterColumns& col,
                                          const JitterConstants& k, int cols)
{
    switch (k.alignment) {
    case NoiseAlignment::ACCOUNT_PRIOR:
        if (k.lineBySite)
            return jitterRowBody<W, T, NoiseAlignment::ACCOUNT_PRIOR, kLocalMean, true>(s, d, z, t, prior,
                                                                                        extra, col, k, cols);
        return jitterRowBody<W, T, NoiseAlignment::ACCOUNT_PRIOR, kLocalMean, false>(s, d, z, t, prior, extra,
                                                                                     col, k, cols);
    case NoiseAlignment::IGNORE_PRIOR:
        return jitterRowBody<W, T, NoiseAlignment::IGNORE_PRIOR, kLocalMean, false>(s, d, z, t, prior, extra,
                                                                                    col, k, cols);
    default:
        return jitterRowBody<W, T, NoiseAlignment::NONE, kLocalMean, false>(s, d, z, t, prior, extra, col, k,
                                                                            cols);
    }
}

template <int W>
RAWGMENT_KERNEL int jitterRowKernel(const ushort* s, ushort* d, const float* z, const float* t,
                                    const float* prior, const float* extra, const JitterColumns& col,
                                    const JitterConstants& k, int cols)
{
    return prior ? jitterRowAnyAlignment<W, ushort, true>(s, d, z, t, prior, extra, col, k, cols)
                 : jitterRowAnyAlignment<W, ushort, false>(s, d, z, t, prior, extra, col, k, cols);
}

template <int W>
RAWGMENT_KERNEL int jitterRowKernel(const float* s, float* d, const float* z, const float* t,
                                    const float* prior, const float* extra, const JitterColumns& col,
                                    const JitterConstants& k, int cols)
{
    return prior ? jitterRowAnyAlignment<W, float, true>(s, d, z, t, prior, extra, col, k, cols)
                 : jitterRowAnyAlignment<W, float, false>(s, d, z, t, prior, extra, col, k, cols);
}

// One dispatched entry point per pixel type (cpu_dispatch.hpp).
RAWGMENT_DISPATCHED_BY_WIDTH(int, jitterRow,
                             (const ushort* s, ushort* d, const float* z, const float* t, const float* prior,
                              const float* extra, const JitterColumns& col, const JitterConstants& k,
                              int cols),
                             (s, d, z, t, prior, extra, col, k, cols))
RAWGMENT_DISPATCHED_BY_WIDTH(int, jitterRow,
                             (const float* s, float* d, const float* z, const float* t, const float* prior,
                              const float* extra, const JitterColumns& col, const JitterConstants& k,
                              int cols),
                             (s, d, z, t, prior, extra, col, k, cols))

// The column arrays of even rows (sites 0, 1) and odd rows (sites 2, 3), made once per call: a
// parallel_for_ stripe can be a single row, which would otherwise rebuild them for four times its work.
class JitterColumnTables
{
public:
    JitterColumnTables(const JitterConstants& k, int cols) : cols_(cols)
    {
        for (std::vector<float>* t : {&pc_, &black_, &slope_, &offset_})
            t->resize(2 * static_cast<size_t>(cols));
        for (int parity = 0; parity < 2; ++parity)
            for (int c = 0; c < cols; ++c) {
                const size_t i = static_cast<size_t>(parity * cols + c);
                const int site = 2 * parity + (c & 1);
                pc_[i] = k.pc[site];
                black_[i] = k.black[site];
                slope_[i] = k.slope[site];
                offset_[i] = k.offset[site];
            }
    }
    JitterColumns forRow(int r) const
    {
        const size_t start = static_cast<size_t>((r & 1) * cols_);
        return {pc_.data() + start, black_.data() + start, slope_.data() + start, offset_.data() + start};
    }

private:
    int cols_;
    std::vector<float> pc_, black_, slope_, offset_;
};

// The keys of a jitter's random streams (random.hpp): Gaussian, Poisson, row offset, Tukey uniforms.
struct JitterKeys
{
    uint64_t gaussian, poisson, row, tukey;
};

// A bank's factors of the input's read variance per mosaic row parity (p_c^2 of each column's site): what the
// jitter keeps of the input's row part and pixel part.
struct BankFactors
{
    float row[2][2];
    std::vector<float> pixel[2];
    BankFactors(const Vec4d& contrast, int cols)
    {
        for (int parity = 0; parity < 2; ++parity) {
            pixel[parity].resize(static_cast<size_t>(cols));
            for (int c = 0; c < cols; ++c) {
                const double pc = contrast[2 * parity + (c & 1)];
                pixel[parity][static_cast<size_t>(c)] = static_cast<float>(pc * pc);
            }
            for (int p = 0; p < 2; ++p)
                row[parity][p] = static_cast<float>(contrast[2 * parity + p] * contrast[2 * parity + p]);
        }
    }
};

// inputShading (ACCOUNT_PRIOR with dark shading): the input's shading at its gain, which each row takes
// out of its values with the black level, so that Eq. 13's prior mean is signal only (the shot noise of
// a dark input would otherwise count its dark offset as photons); the extra terms then add the target's
// shading less the input's.
template <typename T>
void jitterRows(const Mat& src, const Mat& prior, Mat& dst, const JitterConstants& k,
                const JitterColumnTables& tables, const JitterKeys& keys,
                const detail::DarkShading& inputShading, const detail::BankRead* bank,
                const BankFactors& bankFactors, const Range& rows, std::atomic<int64>& brightening,
                std::atomic<int64>& readBrightening, std::atomic<bool>& nonFinite,
                std::atomic<bool>* nonFiniteInput)
{
    const int cols = src.cols;
    const bool noise = k.alignment != NoiseAlignment::NONE;
    const bool tails = noise && k.dark.tails, dark = noise && (k.dark.any() || bank);
    std::vector<float> z(static_cast<size_t>(cols)), t(tails ? cols : 0), extra(dark ? cols : 0),
        blackAndShading(inputShading.empty() ? 0 : static_cast<size_t>(cols));
    const bool poisson = noise && k.sampling == ShotNoiseSampling::POISSON;
    PoissonRowBuffers poissonRows;
    int64 localBright = 0, localReadBright = 0;
    for (int r = rows.start; r < rows.end; ++r) {
        if (std::is_same<T, float>::value && nonFiniteInput &&
            !detail::rowIsFinite(reinterpret_cast<const float*>(src.ptr<T>(r)), cols)) {
            *nonFiniteInput = true;
            continue;
        }
        if (noise)
            detail::fillGaussian(keys.gaussian, static_cast<uint64_t>(r), z.data(), cols);
        if (tails) {
            detail::fillTukeyUnit(keys.tukey, static_cast<uint64_t>(r), k.dark.tailTable[r & 1], t.data(),
                                  cols);
        }
        if (bank)
            localReadBright += detail::bankRowExtra(*bank, r, 0, 1, cols, bankFactors.row[r & 1],
                                                    bankFactors.pixel[r & 1].data(), extra.data());
        else if (dark && !detail::darkRowExtra(k.dark, keys.row, r, cols, extra.data()))
            nonFinite = true;
        JitterColumns col = tables.forRow(r);
        if (!inputShading.empty()) {
            const float *bd = inputShading.perGainRow(r), *br = inputShading.offsetRow(r);
            for (int c = 0; c < cols; ++c)
                blackAndShading[static_cast<size_t>(c)] = col.black[c] + inputShading.at(bd, br, c);
            col.black = blackAndShading.data();
        }
        const float* priorRow = prior.empty() ? nullptr : prior.ptr<float>(r);
        const float* extraRow = dark ? extra.data() : nullptr;
        if (poisson) {
            localBright +=
                jitterRowPoisson(src.ptr<T>(r), dst.ptr<T>(r), z.data(), tails ? t.data() : nullptr, priorRow,
                                 extraRow, col, k, keys.poisson, static_cast<uint64_t>(r), poissonRows, cols);
        } else {
            localBright += jitterRow(src.ptr<T>(r), dst.ptr<T>(r), z.data(), tails ? t.data() : nullptr,
                                     priorRow, extraRow, col, k, cols);
        }
    }
    brightening += localBright;
    readBrightening += localReadBright;
}

/* The dark-frame components a jitter adds (docs/mathematics.md, "Dark-frame noise"), per CFA site of
 * contrast p_c at gain ratio p_g (p_u = p_c / p_g) from gain g:
 * - row: ACCOUNT_PRIOR adds (1 - p_u^2) p_g^2 g^2 sigma_row_d^2 + (1 - p_c^2) sigma_row_r^2 (Eq. 13's
 *   split applied to the row offset); IGNORE_PRIOR the target's whole row variance;
 * - shading: ACCOUNT_PRIOR takes the input's g B_d + B_r out with the black level (jitterRows()) and
 *   puts the target's g p_g B_d + B_r in its place, so it adds g (p_g - 1) B_d on top of that; IGNORE_PRIOR
 *   adds the target's whole shading to the values as they are;
 * - tails: the added read part's lambda (addedReadLambda(): the prior's read p_c^2 b is kept); IGNORE_PRIOR
 *   the model's lambda. */
detail::DarkTerms jitterDarkTerms(const detail::StepNoise& step, const ColorJitter& jitter)
{
    detail::DarkTerms d;
    if (!step.addsNoise())
        return d;
    d.row = step.rowNoise;
    d.shading = step.shading;
    d.tails = step.tails;
    const double pg = jitter.gainRatio, g = step.gainIn;
    const double readIn = step.in.read(), readOut = step.out.read();
    const bool account = step.options.alignment == NoiseAlignment::ACCOUNT_PRIOR;
    detail::TukeyUnitSampler shapes[4]; // the added read part's heavy-tailed shape per site, when `tails`
    for (int s = 0; s < 4; ++s) {
        const double pc = jitter.contrast[s], pu = pc / pg;
        const double rowAdded =
            account ? (1 - pu * pu) * pg * pg * g * g * step.rowSigmaD2 + (1 - pc * pc) * step.rowSigmaR2
                    : step.rowVariance(g * pg);
        d.rowSigma[s] = static_cast<float>(std::sqrt(std::max(rowAdded, 0.0)));
        d.shadingPerGain[s] = static_cast<float>(account ? g * (pg - 1) : g * pg);
        d.shadingOffset[s] = static_cast<float>(account ? 0.0 : 1.0);
        if (!d.tails)
            continue;
        shapes[s] = detail::TukeyUnitSampler(
            account ? detail::addedReadLambda(step.tukeyLambda, readOut, std::pow(pc, 4) * readIn * readIn,
                                              readOut - pc * pc * readIn)
                    : step.tukeyLambda);
    }
    if (d.tails)
        for (int parity = 0; parity < 2; ++parity) {
            const detail::TukeyUnitSampler &s0 = shapes[2 * parity], &s1 = shapes[2 * parity + 1];
            d.tailTable[parity] =
                detail::TukeyQuantileTable(static_cast<float>(s0.lambda), static_cast<float>(s0.invSd),
                                           static_cast<float>(s1.lambda), static_cast<float>(s1.invSd));
        }
    return d;
}

// PriorMeanEstimate::LOCAL_MEAN: the black-subtracted mean of each pixel's 3x3 neighbourhood on its own
// CFA plane. On the mosaic that is a separable [1 0 1 0 1] / 3 filter; reflecting about the edge pixel
// maps an offset of -2 to +2, so the border also averages pixels of the same site. With ACCOUNT_PRIOR and
// dark shading the input's shading (`inputShading`, not empty) is taken out too, as from the pixel values.
Mat localPriorMean(const Mat& src, const RawFormat& format, const detail::DarkShading& inputShading)
{
    Mat x, mean;
    subtractBlackLevel(src, format, x, false);
    const Matx<float, 1, 5> taps(1.0f / 3, 0, 1.0f / 3, 0, 1.0f / 3);
    sepFilter2D(x, mean, CV_32F, taps, taps.t(), Point(-1, -1), 0, BORDER_REFLECT_101);
    if (!inputShading.empty())
        for (int r = 0; r < mean.rows; ++r) {
            float* m = mean.ptr<float>(r);
            const float *bd = inputShading.perGainRow(r), *br = inputShading.offsetRow(r);
            for (int c = 0; c < mean.cols; ++c)
                m[c] -= inputShading.at(bd, br, c);
        }
    return mean;
}

} // namespace

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
    return contrast == Vec4d::all(1) && brightness == 0 && gainRatio == 1 && exposureTime == 0;
}

namespace {

/* A jitter as a noise step (noise_step.hpp). prepare() validates and computes the constants; begin() makes
 * what the rows read: the local prior mean (from the input's values), the dark terms, a bank's frames. */
class ColorJitterStep : public detail::NoiseStep
{
public:
    ColorJitterStep(const ColorJitter& jitter, const _OutputArray* saturatedMask)
        : jitter_(jitter), saturatedMask_(saturatedMask)
    {
    }

    const char* name() const override { return "colorJitter"; }

    RawFormat prepare(const detail::StepContext& context) override
    {
        using namespace detail;
        const RawFormat& format = context.format;
        format_ = format;
        seed_ = context.seed;
        noise_ = context.noise;
        for (int s = 0; s < 4; ++s)
            checkFinitePositive(jitter_.contrast[s], "colorJitter: contrast");
        // Different contrasts per site would print a 2x2 checkerboard on a frame whose pixels all see the
        // same light: no capture makes that.
        if (format.isMonochrome() && jitter_.contrast != Vec4d::all(jitter_.contrast[0]))
            CV_Error(Error::StsBadArg,
                     cv::format(
                         "colorJitter: a CFA_MONO frame has one contrast for all four sites (got %g, %g, "
                         "%g, %g): a monochrome sensor has no hue",
                         jitter_.contrast[0], jitter_.contrast[1], jitter_.contrast[2], jitter_.contrast[3]));
        if (!std::isfinite(jitter_.brightness))
            CV_Error(Error::StsBadArg, "colorJitter: brightness must be finite");
        checkFinitePositive(jitter_.gainRatio, "colorJitter: gainRatio");
        const double newGain = format.gain * jitter_.gainRatio;
        checkFinitePositive(newGain, "colorJitter: the new gain");
        if (!(std::isfinite(jitter_.exposureTime) && jitter_.exposureTime >= 0))
            CV_Error(Error::StsBadArg,
                     cv::format("colorJitter: exposureTime must be finite and >= 0 seconds (got %g)",
                                jitter_.exposureTime));
        const double newExposure = jitter_.exposureTime > 0 ? jitter_.exposureTime : format.exposureTime;
        // The model's terms at the input gain and at the output gain (its own line there with measured
        // lines).
        step_.reset(new StepNoise(context.model, format, context.noise, jitter_.gainRatio, context.size,
                                  "colorJitter", newExposure));
        checkFloatRange();
        // Another exposure changes the noise only through a bank's frames of it.
        const bool sameCapture = newExposure == format.exposureTime || !step_->bank;
        ColorJitter change = jitter_;
        change.exposureTime = 0;
        identity_ = change.isIdentity() && sameCapture;
        RawFormat out = format;
        out.exposureTime = newExposure;
        if (identity_)
            return out;
        out.gain = newGain;
        prepareConstants(context.depth);
        return out;
    }

    bool isIdentity() const override { return identity_; }

    void begin(const Mat& src, bool checkValues, detail::StepTally& tally) override
    {
        using namespace detail;
        const StepNoise& step = *step_;
        inputShading_ = noise_.alignment == NoiseAlignment::ACCOUNT_PRIOR ? step.shading : DarkShading();
        prior_ = noise_.priorMean == PriorMeanEstimate::LOCAL_MEAN && step.addsNoise()
                     ? localPriorMean(src, format_, inputShading_)
                     : Mat();
        k_.dark = jitterDarkTerms(step, jitter_);
        // With a dark-frame bank its frames are the read part; what the input holds of it is scaled by p_c.
        if (step.bank) {
            BankPattern pattern;
            pattern.amplitude = jitter_.contrast;
            bank_ = prepareBankRead(step, format_, src.size(), pattern, seed_, RandomStream::JITTER_BANK,
                                    "colorJitter");
        }
        bankFactors_.reset(new BankFactors(jitter_.contrast, step.bank ? src.cols : 0));
        keys_ = {stepKey(seed_, RandomStream::JITTER_GAUSSIAN), stepKey(seed_, RandomStream::JITTER_POISSON),
                 stepKey(seed_, RandomStream::JITTER_ROW), stepKey(seed_, RandomStream::JITTER_TUKEY)};
        tables_.reset(new JitterColumnTables(k_, src.cols));
        tally_ = &tally;
        checkValues_ = checkValues;
        rows_ = src.rows;
    }

    int rowCount() const override { return rows_; }

    void runRows(const Mat& src, Mat& dst, const Range& rows) const override
    {
        const detail::BankRead* bank = bank_.empty() ? nullptr : &bank_;
        std::atomic<bool>* nonFiniteInput = checkValues_ ? &tally_->nonFiniteInput : nullptr;
        if (src.depth() == CV_16U)
            jitterRows<ushort>(src, prior_, dst, k_, *tables_, keys_, inputShading_, bank, *bankFactors_,
                               rows, tally_->brightening, tally_->readBrightening, tally_->nonFiniteShading,
                               nullptr);
        else
            jitterRows<float>(src, prior_, dst, k_, *tables_, keys_, inputShading_, bank, *bankFactors_, rows,
                              tally_->brightening, tally_->readBrightening, tally_->nonFiniteShading,
                              nonFiniteInput);
    }

    void describeInput(const Mat& src, AugmentReport* report) const override
    {
        detail::reportSaturation(src, format_, report, saturatedMask_ ? *saturatedMask_ : noArray());
    }

private:
    // The row loops run in float: the largest value and variance they can form must fit one.
    void checkFloatRange() const
    {
        const detail::NoiseTerms<double>&t = step_->in, &outTerms = step_->out;
        double largestContrast = 0;
        for (int s = 0; s < 4; ++s)
            largestContrast = std::max(largestContrast, jitter_.contrast[s]);
        const double g2 = jitter_.gainRatio * jitter_.gainRatio;
        const double largestValue = largestContrast * format_.whiteLevel + std::abs(jitter_.brightness);
        const double largestVariance =
            std::max(g2 * (t.shot * format_.whiteLevel + t.readBeforeGain) + t.readAfterGain,
                     outTerms.shot * largestContrast * format_.whiteLevel + outTerms.read());
        if (!(largestValue < 1e30 && largestVariance < 1e30 && largestContrast * jitter_.gainRatio < 1e30))
            CV_Error(Error::StsBadArg,
                     cv::format("colorJitter: contrast %g, brightness %g and gain ratio %g make values or "
                                "variances beyond float range (%g, %g)",
                                largestContrast, jitter_.brightness, jitter_.gainRatio, largestValue,
                                largestVariance));
    }

    void prepareConstants(int depth)
    {
        const detail::NoiseTerms<double>&terms = step_->in, &outTerms = step_->out;
        JitterConstants& k = k_;
        for (int s = 0; s < 4; ++s) {
            k.pc[s] = static_cast<float>(jitter_.contrast[s]);
            k.black[s] = static_cast<float>(format_.blackLevel[s]);
        }
        k.pb = static_cast<float>(jitter_.brightness);
        k.pg = static_cast<float>(jitter_.gainRatio);
        k.white = detail::outputWhite(format_, depth);
        k.in = {static_cast<float>(terms.shot), static_cast<float>(terms.readBeforeGain),
                static_cast<float>(terms.readAfterGain)};
        k.alignment = noise_.alignment;
        k.sampling = noise_.shotSampling;
        k.lineBySite = noise_.alignment == NoiseAlignment::ACCOUNT_PRIOR && jitter_.brightness == 0;
        // The output gain's line: the model's own there with measured lines, else Eq. 5's scaling of the
        // input's (in float, as jitterVariance() had it).
        k.measured = step_->measured;
        const double pg2 = jitter_.gainRatio * jitter_.gainRatio;
        if (k.measured) {
            k.shotOut = static_cast<float>(outTerms.shot);
            k.readOut = static_cast<float>(outTerms.read());
        } else {
            k.shotOut = k.pg * k.in.shot;
            k.readOut = k.pg * k.pg * k.in.readBeforeGain + k.in.readAfterGain;
        }
        k.pgShotOut = static_cast<float>(jitter_.gainRatio * outTerms.shot);
        k.pg2ShotIn = static_cast<float>(pg2 * terms.shot);
        k.pg2ReadIn = static_cast<float>(pg2 * terms.read());
        for (int s = 0; s < 4; ++s) {
            k.slope[s] = k.offset[s] = 0;
            if (k.lineBySite && k.measured)
                measuredSiteLine(jitter_.contrast[s], terms, outTerms, k.slope[s], k.offset[s]);
            else if (k.lineBySite)
                perSiteLine(jitter_.contrast[s], jitter_.gainRatio, terms, k.slope[s], k.offset[s]);
        }
    }

    ColorJitter jitter_;
    const _OutputArray* saturatedMask_;
    RawFormat format_;
    uint64 seed_ = 0;
    NoiseOptions noise_;
    std::unique_ptr<detail::StepNoise> step_;
    bool identity_ = false;
    JitterConstants k_;
    detail::DarkShading inputShading_;
    Mat prior_;
    detail::BankRead bank_;
    std::unique_ptr<BankFactors> bankFactors_;
    JitterKeys keys_ = {0, 0, 0, 0};
    std::unique_ptr<JitterColumnTables> tables_;
    detail::StepTally* tally_ = nullptr;
    bool checkValues_ = false;
    int rows_ = 0;
};

} // namespace

namespace detail {

std::unique_ptr<NoiseStep> makeColorJitterStep(const ColorJitter& jitter, const _OutputArray* saturatedMask)
{
    return std::unique_ptr<NoiseStep>(new ColorJitterStep(jitter, saturatedMask));
}

} // namespace detail

void colorJitter(InputArray _src, const RawFormat& format, const NoiseModel& model, const ColorJitter& jitter,
                 const NoiseOptions& noise, uint64 seed, OutputArray dst, RawFormat& dstFormat,
                 AugmentReport* report, OutputArray saturatedMask)
{
    detail::runPublicStep(detail::makeColorJitterStep(jitter, &saturatedMask), _src, format, model, noise,
                          seed, dst, dstFormat, report);
}

} // namespace rawgment
} // namespace cv
