// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Noise-accounted scaling (paper Eq. 15 with bilinear weights) and the boxes that follow it.
#include "noise_step.hpp"
#include "resample_rows.hpp"

#include "cpu_dispatch.hpp"

#include <algorithm>
#include <cstring>
#include <emmintrin.h>

namespace cv {
namespace rawgment {

namespace {

using detail::finishPlaneRow;
using detail::loadPlaneRow;
using detail::PlaneGrid;
using detail::ResampleConstants;
using detail::RowScratch;

// Source position on the plane grid of each output plane pixel for a scale about the mosaic centre:
// plane index j of site column px sits at mosaic x = step j + px (PlaneGrid); its source is
// C + (x - C) / scale.
struct BilinearAxis
{
    std::vector<int> i0, i1;
    std::vector<float> f; // weight of i1; 0 when the two clamp onto the same pixel
};

BilinearAxis bilinearAxis(int planeSize, int phase, double scale, int step)
{
    // Whole blocks for bilinearRow(): the extra entries read pixel 0 with weight 0.
    BilinearAxis a;
    a.i0.assign(detail::wholeBlocks(planeSize), 0);
    a.i1.assign(detail::wholeBlocks(planeSize), 0);
    a.f.assign(detail::wholeBlocks(planeSize), 0.0f);
    const double centre = (static_cast<double>(step) * planeSize - 1) / 2;
    for (int j = 0; j < planeSize; ++j) {
        const double x = centre + (static_cast<double>(step) * j + phase - centre) / scale;
        const double planeX = (x - phase) / step;
        const double lo = std::floor(planeX);
        const int i0 = static_cast<int>(std::min(std::max(lo, 0.0), planeSize - 1.0));
        const int i1 = static_cast<int>(std::min(std::max(lo + 1, 0.0), planeSize - 1.0));
        a.i0[static_cast<size_t>(j)] = i0;
        a.i1[static_cast<size_t>(j)] = i1;
        a.f[static_cast<size_t>(j)] = i0 == i1 ? 0.0f : static_cast<float>(planeX - lo);
    }
    return a;
}

// One block of W output pixels: the four neighbours gathered lane by lane, then the weights, the mean,
// Eq. 15's shot sum and the read-noise factor on vectors, in the order of the scalar formula.
template <int W>
RAWGMENT_KERNEL void bilinearBlock(const float* row0, const float* row1, float fy, const int* c0,
                                   const int* c1, const float* fx, float* mean, float* shot,
                                   float* readFactor)
{
    typedef typename detail::Lanes<W>::F F;
    F a, b, c, d, x;
    for (int i = 0; i < W; ++i) {
        a[i] = row0[c0[i]];
        b[i] = row0[c1[i]];
        c[i] = row1[c0[i]];
        d[i] = row1[c1[i]];
    }
    std::memcpy(&x, fx, sizeof(x));
    const F zero = F{};
    const F w00 = (1 - x) * (1 - fy), w01 = x * (1 - fy), w10 = (1 - x) * fy, w11 = x * fy;
    const F m = w00 * a + w01 * b + w10 * c + w11 * d;
    const F sh = w00 * (1 - w00) * detail::maxLanes(a, zero) + w01 * (1 - w01) * detail::maxLanes(b, zero) +
                 w10 * (1 - w10) * detail::maxLanes(c, zero) + w11 * (1 - w11) * detail::maxLanes(d, zero);
    const F rf = 1 - (w00 * w00 + w01 * w01 + w10 * w10 + w11 * w11);
    std::memcpy(mean, &m, sizeof(m));
    std::memcpy(shot, &sh, sizeof(sh));
    std::memcpy(readFactor, &rf, sizeof(rf));
}

// Bilinear taps of one output row: mean, Eq. 15's shot sum and the read-noise factor 1 - sum w^2,
// all per pixel because the weights change along the row. The outputs and the axis hold whole blocks
// (detail::wholeBlocks(); the axis's extra entries point at pixel 0).
template <int W>
RAWGMENT_KERNEL void bilinearRowKernel(const float* row0, const float* row1, float fy, const int* c0,
                                       const int* c1, const float* fx, float* mean, float* shot,
                                       float* readFactor, int n)
{
    for (int j = 0; j < n; j += W)
        bilinearBlock<W>(row0, row1, fy, c0 + j, c1 + j, fx + j, mean + j, shot + j, readFactor + j);
}
RAWGMENT_DISPATCHED_BY_WIDTH(void, bilinearRow,
                             (const float* row0, const float* row1, float fy, const int* c0, const int* c1,
                              const float* fx, float* mean, float* shot, float* readFactor, int n),
                             (row0, row1, fy, c0, c1, fx, mean, shot, readFactor, n))

template <typename T>
void scalePlaneRows(const Mat& src, Mat& dst, const BilinearAxis* cols, const BilinearAxis* rows,
                    const ResampleConstants& k, const Range& range)
{
    const PlaneGrid& grid = k.grid;
    const int pw = src.cols / grid.step;
    // Two loaded plane rows per site, kept from one output row to the next: a scale near 1 reads the row
    // the previous output row read as its second, so most rows are loaded (converted, checked) once.
    struct LoadedRow
    {
        int planeRow = -1;
        std::vector<float> values;
    };
    std::vector<LoadedRow> loaded(static_cast<size_t>(2 * grid.sites));
    for (LoadedRow& l : loaded)
        l.values.resize(static_cast<size_t>(pw));
    const auto rowOf = [&](int site, int planeRow, int keep) -> const float* {
        LoadedRow* pair = &loaded[static_cast<size_t>(2 * site)];
        for (int slot = 0; slot < 2; ++slot)
            if (pair[slot].planeRow == planeRow)
                return pair[slot].values.data();
        LoadedRow& slot = pair[0].planeRow == keep ? pair[1] : pair[0];
        if (!loadPlaneRow<T>(src, grid, site, planeRow, 0, k.black[site], slot.values.data(), k.inputShading,
                             k.nonFiniteInput != nullptr))
            *k.nonFiniteInput = true;
        slot.planeRow = planeRow;
        return slot.values.data();
    };
    std::vector<float> means[2] = {std::vector<float>(detail::wholeBlocks(pw)),
                                   std::vector<float>(detail::wholeBlocks(pw))};
    std::vector<float> shot(detail::wholeBlocks(pw)), readFactor(detail::wholeBlocks(pw));
    RowScratch scratch(pw);
    // Whole plane rows i, the four sites in turn, so that a task writes mosaic rows 2 i and 2 i + 1
    // whole (storePlaneRow()).
    for (int i = range.start; i < range.end; ++i)
        for (int site = 0; site < grid.sites; ++site) {
            std::vector<float>& mean = means[site % 2];
            const BilinearAxis& ax = cols[site % 2];
            const BilinearAxis& ay = rows[site / 2];
            const int i0 = ay.i0[static_cast<size_t>(i)], i1 = ay.i1[static_cast<size_t>(i)];
            const float* row0 = rowOf(site, i0, i1);
            const float* row1 = rowOf(site, i1, i0);
            bilinearRow(row0, row1, ay.f[static_cast<size_t>(i)], ax.i0.data(), ax.i1.data(), ax.f.data(),
                        mean.data(), shot.data(), readFactor.data(), pw);
            const float fy = ay.f[static_cast<size_t>(i)];
            finishPlaneRow(mean, shot.data(), readFactor.data(), scratch, k, pw, site, i,
                           (1 - fy) * (1 - fy) + fy * fy);
            detail::storePlaneRow<T>(grid, means, site, i, pw, dst);
        }
}

/* A scale as a noise step (noise_step.hpp): prepare() validates the factor, begin() makes the bilinear axes,
 * the constants of Eq. 15 with their weights and the read part (a bank's or the dark components). */
class ScaleStep : public detail::ResampleStep
{
public:
    explicit ScaleStep(double scale) : scale_(scale) {}

    const char* name() const override { return "scaleMosaic"; }
    const char* reportName() const override { return "scale"; }

    RawFormat prepare(const detail::StepContext& context) override
    {
        prepareResampling(context, "scaleMosaic");
        if (!std::isfinite(scale_) || !(scale_ > 0))
            CV_Error(Error::StsBadArg,
                     cv::format("scaleMosaic: scale must be finite and > 0 (got %g)", scale_));
        return format_;
    }

    bool isIdentity() const override { return scale_ == 1; }

    void begin(const Mat& src, bool checkValues, detail::StepTally& tally) override
    {
        using namespace detail;
        const StepNoise& step = *step_;
        k_ = resampleConstants(depth_, format_, step, seed_, RandomStream::SCALE_GAUSSIAN,
                               RandomStream::SCALE_POISSON);
        k_.nonFiniteShading = &tally.nonFiniteShading;
        k_.nonFiniteInput = checkValues ? &tally.nonFiniteInput : nullptr;
        const PlaneGrid& grid = k_.grid;
        plane_ = grid.plane(src.size());
        const int phases = grid.step; // the site columns (rows) of the grid: 2, or 1 for a monochrome frame
        cols_[0] = bilinearAxis(plane_.width, 0, scale_, grid.step);
        cols_[1] = bilinearAxis(plane_.width, phases - 1, scale_, grid.step);
        rows_[0] = bilinearAxis(plane_.height, 0, scale_, grid.step);
        rows_[1] = bilinearAxis(plane_.height, phases - 1, scale_, grid.step);
        if (!step.hasDarkComponents() && !step.bank)
            return;
        // The typical weights: sum w^2 and sum w^4 of the bilinear taps averaged over the output pixels
        // (a product of the two axes' averages).
        double axis2[2] = {0, 0}, axis4[2] = {0, 0};
        for (int a = 0; a < 2; ++a) {
            const BilinearAxis* axis = a == 0 ? cols_ : rows_;
            const int n = a == 0 ? plane_.width : plane_.height;
            for (int p = 0; p < phases; ++p)
                for (int j = 0; j < n; ++j) {
                    const double f = axis[p].f[static_cast<size_t>(j)];
                    axis2[a] += (f * f + (1 - f) * (1 - f)) / (static_cast<double>(phases) * n);
                    axis4[a] += (std::pow(f, 4) + std::pow(1 - f, 4)) / (static_cast<double>(phases) * n);
                }
        }
        if (step.bank) {
            const ValidatedNoiseModel& model = *model_;
            const double scale = scale_;
            const uint64 seed = seed_;
            bank_ = resampleBankRead(
                step, format_, src.size(), axis2[0] * axis2[1], seed_, RandomStream::SCALE_BANK,
                "scaleMosaic", [&](const Mat& in, const RawFormat& f, Mat& out) {
                    RawFormat unused;
                    runNoiseStep(makeScaleStep(scale), in, f, model, NoiseOptions(NoiseAlignment::NONE), seed,
                                 out, unused, nullptr, true);
                });
            k_.bank = &bank_;
            k_.readBrightening = &tally.readBrightening;
        } else {
            resampleDarkTerms(k_, step, axis2[0] * axis2[1], axis4[0] * axis4[1], seed_,
                              RandomStream::SCALE_ROW, RandomStream::SCALE_TUKEY);
        }
    }

    int rowCount() const override { return plane_.height; }

    void runRows(const Mat& src, Mat& dst, const Range& planeRows) const override
    {
        if (src.depth() == CV_16U)
            scalePlaneRows<ushort>(src, dst, cols_, rows_, k_, planeRows);
        else
            scalePlaneRows<float>(src, dst, cols_, rows_, k_, planeRows);
    }

    // A magnification reads no row near the top and bottom edges: those are checked here.
    void finish(const Mat& src, bool checkValues, detail::StepTally& tally) const override
    {
        if (src.depth() != CV_32F || !checkValues)
            return;
        const PlaneGrid& grid = k_.grid;
        std::vector<uchar> loaded(static_cast<size_t>(src.rows), 0);
        for (int p = 0; p < grid.step; ++p)
            for (int i = 0; i < plane_.height; ++i)
                for (const int planeRow :
                     {rows_[p].i0[static_cast<size_t>(i)], rows_[p].i1[static_cast<size_t>(i)]})
                    loaded[static_cast<size_t>(grid.step * planeRow + p)] = 1;
        for (int r = 0; r < src.rows; ++r)
            if (!loaded[static_cast<size_t>(r)] && !detail::rowIsFinite(src.ptr<float>(r), src.cols))
                tally.nonFiniteInput = true;
    }

    void moveBoxes(std::vector<Rect>& boxes, Size size) const override
    {
        for (Rect& b : boxes)
            b = scaleBox(b, size, scale_);
    }

private:
    double scale_;
    ResampleConstants k_;
    Size plane_;
    BilinearAxis cols_[2], rows_[2];
    detail::BankRead bank_;
};

} // namespace

namespace detail {

std::unique_ptr<NoiseStep> makeScaleStep(double scale)
{
    return std::unique_ptr<NoiseStep>(new ScaleStep(scale));
}

} // namespace detail

void scaleMosaic(InputArray _src, const RawFormat& format, const NoiseModel& model, double scale,
                 const NoiseOptions& noise, uint64 seed, OutputArray dst, AugmentReport* report)
{
    RawFormat dstFormat;
    detail::runPublicStep(detail::makeScaleStep(scale), _src, format, model, noise, seed, dst, dstFormat,
                          report);
}

Rect scaleBox(const Rect& box, Size size, double scale)
{
    if (!(std::isfinite(scale) && scale > 0))
        CV_Error(Error::StsBadArg, format("scaleBox: scale must be finite and > 0 (got %g)", scale));
    if (size.width <= 0 || size.height <= 0)
        CV_Error(Error::StsBadArg,
                 format("scaleBox: the frame size must be positive (got %dx%d)", size.width, size.height));
    if (box.width < 0 || box.height < 0)
        CV_Error(Error::StsBadArg, format("scaleBox: the box (%d, %d, %d x %d) has a negative size", box.x,
                                          box.y, box.width, box.height));
    if (box.area() == 0)
        return Rect();
    // Edges in continuous coordinates (pixel k covers [k, k + 1)); the box grows to whole pixels. An edge
    // beyond the frame is clipped before it becomes an int, which it might not fit.
    const double cx = size.width / 2.0, cy = size.height / 2.0;
    const auto edge = [](double v, int limit, bool up) {
        return static_cast<int>(
            std::min<double>(std::max<double>(up ? std::ceil(v) : std::floor(v), -1), limit + 1.0));
    };
    const int x0 = edge(cx + (box.x - cx) * scale, size.width, false);
    const int y0 = edge(cy + (box.y - cy) * scale, size.height, false);
    const int x1 = edge(cx + (double(box.x) + box.width - cx) * scale, size.width, true);
    const int y1 = edge(cy + (double(box.y) + box.height - cy) * scale, size.height, true);
    return Rect(Point(x0, y0), Point(x1, y1)) & Rect(Point(0, 0), size);
}

} // namespace rawgment
} // namespace cv
