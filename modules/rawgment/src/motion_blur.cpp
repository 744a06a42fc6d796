// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Noise-accounted motion blur (paper Eq. 15 with the kernel's weights) and its kernel.
#include "noise_step.hpp"
#include "resample_rows.hpp"

#include "cpu_dispatch.hpp"

#include <algorithm>
#include <cstring>

namespace cv {
namespace rawgment {

Mat linearMotionKernel(double length, double angleDegrees, CfaPattern pattern)
{
    if (!(length >= 0 && length <= MAX_MOTION_LENGTH))
        CV_Error(Error::StsBadArg,
                 format("linearMotionKernel: length must lie in [0, %g] mosaic pixels (got %g)",
                        MAX_MOTION_LENGTH, length));
    if (!std::isfinite(angleDegrees))
        CV_Error(Error::StsBadArg, "linearMotionKernel: angle must be finite");
    if (pattern < CFA_RGGB || pattern > CFA_MONO)
        CV_Error(Error::StsBadArg,
                 format("linearMotionKernel: pattern %d is not a CfaPattern", static_cast<int>(pattern)));
    // The CFA planes have half the resolution; a monochrome frame is blurred on its own pixels.
    const double planeLength = pattern == CFA_MONO ? length : length / 2;
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

using detail::finishPlaneRow;
using detail::loadPlaneRow;
using detail::PlaneGrid;
using detail::ResampleConstants;
using detail::RowScratch;

// Every kernel tap of an output row: mean = sum over taps of w x, and for ACCOUNT_PRIOR shot = sum of
// w (1 - w) max(x, 0) (the prior mean is never negative). Taps innermost, so the sums of a block of
// columns stay in registers and each tap costs one load; each pixel adds its taps in their order,
// as a pass per tap would. x[t] is tap t's source row, already offset by the tap's column.
template <int W, bool kShot>
RAWGMENT_KERNEL void addTapsBlocks(float* mean, float* shot, const float* const* x, const float* w,
                                   const float* shotWeight, int taps, int n)
{
    typedef typename detail::Lanes<W>::F F;
    for (int j = 0; j < n; j += W) {
        F m = F{}, sh = F{};
        for (int t = 0; t < taps; ++t) {
            F xv;
            std::memcpy(&xv, x[t] + j, sizeof(xv));
            m += w[t] * xv;
            if (kShot)
                sh += shotWeight[t] * detail::maxLanes(xv, F{});
        }
        std::memcpy(mean + j, &m, sizeof(m));
        if (kShot)
            std::memcpy(shot + j, &sh, sizeof(sh));
    }
}

// The buffers hold whole blocks (detail::wholeBlocks()): the last block runs over the row's end.
template <int W>
RAWGMENT_KERNEL void addTapsRowKernel(float* mean, float* shot, const float* const* x, const float* w,
                                      const float* shotWeight, int taps, bool withShot, int n)
{
    if (withShot)
        addTapsBlocks<W, true>(mean, shot, x, w, shotWeight, taps, n);
    else
        addTapsBlocks<W, false>(mean, shot, x, w, shotWeight, taps, n);
}
RAWGMENT_DISPATCHED_BY_WIDTH(void, addTapsRow,
                             (float* mean, float* shot, const float* const* x, const float* w,
                              const float* shotWeight, int taps, bool withShot, int n),
                             (mean, shot, x, w, shotWeight, taps, withShot, n))

struct KernelTap
{
    int dy, dx;
    float w, shotWeight; // w and w (1 - w)
};

static_assert(detail::kBlurBorder == BORDER_REPLICATE, "the tap merging below implements BORDER_REPLICATE");

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
    const PlaneGrid& grid = k.grid;
    const int pw = src.cols / grid.step, ph = src.rows / grid.step, rx = ksize.width / 2,
              ry = ksize.height / 2;
    const Size plane(pw, ph), radius(rx, ry);
    // A ring row holds the plane row with rx columns of edge on each side, and one widest block more,
    // which addTapRow's last block reads past the row (detail::wholeBlocks()).
    const int stride = pw + 2 * rx + detail::kWidestLanes;
    // A ring per site: a task makes whole plane rows i, the four sites in turn, so that it writes both
    // mosaic rows 2 i and 2 i + 1 whole (storePlaneRow()).
    const size_t ringRows = static_cast<size_t>(ksize.height);
    std::vector<float> ring(static_cast<size_t>(grid.sites) * ringRows * stride);
    std::vector<int> ringRow(static_cast<size_t>(grid.sites) * ringRows, -1);
    std::vector<float> means[2] = {std::vector<float>(detail::wholeBlocks(pw)),
                                   std::vector<float>(detail::wholeBlocks(pw))};
    std::vector<float> shotSum(detail::wholeBlocks(pw)), readFactors(detail::wholeBlocks(pw));
    RowScratch scratch(pw);
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
    std::vector<float> rowWeights; // the kernel's weight per source row (after clamping)
    std::vector<const float*> tapRows;
    std::vector<float> tapWeights, tapShotWeights;
    for (int i = range.start; i < range.end; ++i) {
        const bool edgeRow = i < ry || i >= ph - ry;
        float rowKeep = 1;
        if (k.dark.row) {
            rowWeights.assign(static_cast<size_t>(ksize.height), 0.0f);
            for (const KernelTap& t : taps)
                rowWeights[static_cast<size_t>(std::min(std::max(i + t.dy - ry, 0), ph - 1) - i + ry)] += t.w;
            rowKeep = 0;
            for (float w : rowWeights)
                rowKeep += w * w;
        }
        const float rowReadFactor =
            edgeRow ? mergeClampedTaps(taps, i, 0, plane, radius, true, false, rowTaps) : readFactor;
        for (int site = 0; site < grid.sites; ++site) {
            std::vector<float>& mean = means[site % 2];
            float* const siteRing = ring.data() + static_cast<size_t>(site) * ringRows * stride;
            int* const siteRingRow = ringRow.data() + static_cast<size_t>(site) * ringRows;
            std::fill(readFactors.begin(), readFactors.end(), rowReadFactor);
            // The rows of one output row are distinct ring slots, so every tap's row stays loaded.
            tapRows.clear();
            tapWeights.clear();
            tapShotWeights.clear();
            for (const KernelTap& t : edgeRow ? rowTaps : taps) {
                const int si = std::min(std::max(i + t.dy - ry, 0), ph - 1);
                const size_t slot = static_cast<size_t>(si) % ringRows;
                float* row = siteRing + slot * stride;
                if (siteRingRow[slot] != si) {
                    if (!loadPlaneRow<T>(src, grid, site, si, rx, k.black[site], row, k.inputShading,
                                         k.nonFiniteInput != nullptr))
                        *k.nonFiniteInput = true;
                    siteRingRow[slot] = si;
                }
                tapRows.push_back(row + t.dx);
                tapWeights.push_back(t.w);
                tapShotWeights.push_back(t.shotWeight);
            }
            addTapsRow(mean.data(), shotSum.data(), tapRows.data(), tapWeights.data(), tapShotWeights.data(),
                       static_cast<int>(tapRows.size()), exactShot, pw);
            if (account) {
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
                            std::max(
                                siteRing[static_cast<size_t>(i + t.dy - ry) % ringRows * stride + e.j + t.dx],
                                0.0f);
                    shotSum[static_cast<size_t>(e.j)] = shot;
                }
                if (shotFromMean) // sum w (1 - w) = 1 - sum w^2, the read-noise factor
                    for (int j = 0; j < pw; ++j)
                        shotSum[static_cast<size_t>(j)] = readFactors[static_cast<size_t>(j)] *
                                                          std::max(mean[static_cast<size_t>(j)], 0.0f);
            }
            finishPlaneRow(mean, shotSum.data(), readFactors.data(), scratch, k, pw, site, i, rowKeep);
            detail::storePlaneRow<T>(grid, means, site, i, pw, dst);
        }
    }
}

/* A motion blur as a noise step (noise_step.hpp): prepare() validates the kernel and takes its taps, begin()
 * makes the constants of Eq. 15 and the read part (a bank's or the dark components). */
class MotionBlurStep : public detail::ResampleStep
{
public:
    explicit MotionBlurStep(InputArray kernel) : kernel_(kernel) {}

    const char* name() const override { return "motionBlur"; }

    RawFormat prepare(const detail::StepContext& context) override
    {
        prepareResampling(context, "motionBlur");
        w_ = detail::normalisedKernel(kernel_, "motionBlur", format_.pattern);
        // Sparse: a motion kernel is a line, so most of its box is zero and costs nothing.
        taps_.clear();
        for (int y = 0; y < w_.rows; ++y)
            for (int x = 0; x < w_.cols; ++x) {
                const double wk = w_.at<double>(y, x);
                if (wk > 0)
                    taps_.push_back({y, x, static_cast<float>(wk), static_cast<float>(wk * (1 - wk))});
            }
        return format_;
    }

    bool isIdentity() const override { return w_.total() == 1; }

    void begin(const Mat& src, bool checkValues, detail::StepTally& tally) override
    {
        using namespace detail;
        const StepNoise& step = *step_;
        // Every source row is loaded whole: with any tap offset d, the clamped rows i + d of all output rows
        // i are all the rows.
        k_ = resampleConstants(depth_, format_, step, seed_, RandomStream::BLUR_GAUSSIAN,
                               RandomStream::BLUR_POISSON);
        readFactor_ = static_cast<float>(1 - w_.dot(w_));
        k_.nonFiniteShading = &tally.nonFiniteShading;
        k_.nonFiniteInput = checkValues ? &tally.nonFiniteInput : nullptr;
        if (step.bank) {
            const ValidatedNoiseModel& model = *model_;
            const Mat w = w_;
            const uint64 seed = seed_;
            bank_ = resampleBankRead(step, format_, src.size(), w_.dot(w_), seed_, RandomStream::BLUR_BANK,
                                     "motionBlur", [&](const Mat& in, const RawFormat& f, Mat& out) {
                                         RawFormat unused;
                                         runNoiseStep(makeMotionBlurStep(w), in, f, model,
                                                      NoiseOptions(NoiseAlignment::NONE), seed, out, unused,
                                                      nullptr, true);
                                     });
            k_.bank = &bank_;
            k_.readBrightening = &tally.readBrightening;
        } else if (step.hasDarkComponents()) {
            Mat w2 = w_.mul(w_);
            resampleDarkTerms(k_, step, sum(w2)[0], w2.dot(w2), seed_, RandomStream::BLUR_ROW,
                              RandomStream::BLUR_TUKEY);
        }
        shotFromMean_ = step.options.blurNoiseSum == BlurNoiseSum::FROM_BLURRED_MEAN;
        planeRows_ = src.rows / k_.grid.step;
    }

    int rowCount() const override { return planeRows_; }

    void runRows(const Mat& src, Mat& dst, const Range& planeRows) const override
    {
        if (src.depth() == CV_16U)
            blurPlaneRows<ushort>(src, dst, taps_, w_.size(), readFactor_, shotFromMean_, k_, planeRows);
        else
            blurPlaneRows<float>(src, dst, taps_, w_.size(), readFactor_, shotFromMean_, k_, planeRows);
    }

private:
    _InputArray kernel_;
    Mat w_;
    std::vector<KernelTap> taps_;
    ResampleConstants k_;
    float readFactor_ = 0;
    bool shotFromMean_ = false;
    detail::BankRead bank_;
    int planeRows_ = 0;
};

} // namespace

namespace detail {

std::unique_ptr<NoiseStep> makeMotionBlurStep(InputArray kernel)
{
    return std::unique_ptr<NoiseStep>(new MotionBlurStep(kernel));
}

} // namespace detail

void motionBlur(InputArray _src, const RawFormat& format, const NoiseModel& model, InputArray kernel,
                const NoiseOptions& noise, uint64 seed, OutputArray dst, AugmentReport* report)
{
    RawFormat dstFormat;
    detail::runPublicStep(detail::makeMotionBlurStep(kernel), _src, format, model, noise, seed, dst,
                          dstFormat, report);
}

} // namespace rawgment
} // namespace cv
