// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// A scene's shift as a noise step: the content moves by whole CFA periods, the sensor's dark shading stays.
#include "augment_steps.hpp"
#include "huge_pages.hpp"
#include "noise_step.hpp"
#include "resample_rows.hpp"

#include <cstring>
#include <limits>
#include <type_traits>

namespace cv {
namespace rawgment {

namespace {

/* Where each output pixel of a shift reads: each CFA plane (of step 2; a monochrome frame is one plane of
 * step 1, PlaneGrid) moved by shift / step, vacated pixels replicating the plane's edge. Output pixel
 * (r, c) is source pixel (step clamp(r/step - shift.y/step) + r%step, step clamp(c/step - shift.x/step) +
 * c%step), the clamps to the plane's rows and columns; output columns [first, last) read source column
 * c - shift.x, those left of them the first step of source columns, those right of them the last. */
struct ShiftSource
{
    int step, planeRows, planeCols, planeShiftY, shiftX, first, last;

    ShiftSource(Size size, Point shift, int gridStep)
        : step(gridStep), planeRows(size.height / gridStep), planeCols(size.width / gridStep),
          planeShiftY(shift.y / gridStep), shiftX(shift.x), first(std::min(std::max(shift.x, 0), size.width)),
          last(std::max(std::min(size.width + shift.x, size.width), 0))
    {
    }
    int row(int r) const
    {
        return step * std::min(std::max(r / step - planeShiftY, 0), planeRows - 1) + r % step;
    }
    int column(int c) const
    {
        return c < first ? c % step : c < last ? c - shiftX : step * (planeCols - 1) + c % step;
    }
};

/* The shift in one pass (ShiftSource): the same values as splitting the planes, moving each with warpAffine
 * (INTER_NEAREST, BORDER_REPLICATE) and merging them (Augment.shiftMatchesThePlaneWiseComposition), at the
 * cost of a copy: the inner columns of a row are one memcpy.
 *
 * The sensor's dark shading S stays where the sensor has it: the shifted content carries the input's S of its
 * source pixel, which is swapped for the S of the pixel it lands on, dst(x) = src(x - d) - S(x - d) + S(x)
 * (float arithmetic, the same on every path; integer mosaics rounded to nearest, ties to even, and kept in
 * range). Clipped pixels stay clipped. A shift adds no noise: the step prepares only the shading. */
class ShiftStep : public detail::NoiseStep
{
public:
    explicit ShiftStep(Point requested) : requested_(requested) {}

    const char* name() const override { return "applyScene"; }
    const char* reportName() const override { return "shift"; }

    RawFormat prepare(const detail::StepContext& context) override
    {
        format_ = context.format;
        // A Bayer mosaic moves by whole 2x2 blocks so that its CFA phase stays; a monochrome frame has none.
        gridStep_ = detail::PlaneGrid(format_).step;
        shift_ = gridStep_ == 1 ? requested_
                                : Point(2 * cvRound(requested_.x / 2.0), 2 * cvRound(requested_.y / 2.0));
        if (shift_ == Point(0, 0))
            return format_;
        // A tied bank takes the input's fixed pattern out where the sensor has it; a shift moves the pattern
        // with the content, and the bank's pattern is not moved back as the dark shading is.
        const NoiseOptions& noise = context.noise;
        if (noise.darkBankTied && !noise.darkBank.empty() && noise.alignment != NoiseAlignment::NONE)
            CV_Error(Error::StsBadArg,
                     "applyScene: a tied dark-frame bank (NoiseOptions::darkBankTied) cannot follow "
                     "a shifted scene, which moves the input's fixed pattern; untie the bank or "
                     "drop the shift");
        // The dark shading belongs to the sensor, not to the content: it must not move with the shift.
        shading_ = detail::StepNoise(context.model, format_, noise, 1, context.size, "applyScene").shading;
        return format_;
    }

    bool isIdentity() const override { return shift_ == Point(0, 0); }

    void begin(const Mat& src, bool checkValues, detail::StepTally& tally) override
    {
        from_.reset(new ShiftSource(src.size(), shift_, gridStep_));
        checkValues_ = checkValues && src.depth() == CV_32F;
        tally_ = &tally;
        rows_ = src.rows;
    }

    int rowCount() const override { return rows_; }

    void runRows(const Mat& src, Mat& dst, const Range& rows) const override
    {
        const size_t esz = src.elemSize();
        for (int r = rows.start; r < rows.end; ++r) {
            const uchar* s = src.ptr(from_->row(r));
            // A step that reads the scene's input checks each source row whole, while it is in cache.
            if (checkValues_ && !detail::rowIsFinite(reinterpret_cast<const float*>(s), src.cols))
                tally_->nonFiniteInput = true;
            uchar* d = dst.ptr(r);
            for (int c = 0; c < from_->first; ++c)
                std::memcpy(d + c * esz, s + from_->column(c) * esz, esz);
            if (from_->last > from_->first)
                std::memcpy(d + from_->first * esz, s + from_->column(from_->first) * esz,
                            (from_->last - from_->first) * esz);
            for (int c = std::max(from_->last, from_->first); c < src.cols; ++c)
                std::memcpy(d + c * esz, s + from_->column(c) * esz, esz);
            if (shading_.empty())
                continue;
            const bool finite = src.depth() == CV_16U ? swapShading(r, dst.ptr<ushort>(r), src.cols)
                                                      : swapShading(r, dst.ptr<float>(r), src.cols);
            if (!finite)
                tally_->nonFiniteShading = true;
        }
    }

    // The rows the shift moved out of the frame, which no output row read.
    void finish(const Mat& src, bool checkValues, detail::StepTally& tally) const override
    {
        if (!checkValues || src.depth() != CV_32F)
            return;
        std::vector<uchar> read(static_cast<size_t>(src.rows), 0);
        for (int r = 0; r < src.rows; ++r)
            read[static_cast<size_t>(from_->row(r))] = 1;
        for (int r = 0; r < src.rows; ++r)
            if (!read[static_cast<size_t>(r)] && !detail::rowIsFinite(src.ptr<float>(r), src.cols))
                tally.nonFiniteInput = true;
    }

    void moveBoxes(std::vector<Rect>& boxes, Size size) const override
    {
        for (Rect& b : boxes)
            b = (b + shift_) & Rect(Point(0, 0), size);
    }

private:
    // Row r of dst, as copied from source row from_->row(r): each unclipped value's source shading swapped
    // for its own. False when a shading value is not finite.
    template <typename T> bool swapShading(int r, T* d, int cols) const
    {
        const float white = static_cast<float>(format_.whiteLevel);
        const bool integer = std::is_same<T, ushort>::value;
        const float highest = integer ? 65535.f : std::numeric_limits<float>::max();
        const float lowest = integer ? 0.f : -std::numeric_limits<float>::max();
        const int sr = from_->row(r);
        const float *bdSrc = shading_.perGainRow(sr), *brSrc = shading_.offsetRow(sr);
        const float *bdDst = shading_.perGainRow(r), *brDst = shading_.offsetRow(r);
        for (int c = 0; c < cols; ++c) {
            const int sc = from_->column(c);
            const float value = static_cast<float>(d[c]);
            const float swapped = value - shading_.at(bdSrc, brSrc, sc) + shading_.at(bdDst, brDst, c);
            if (!std::isfinite(swapped))
                return false;
            if (value >= white)
                continue;
            const float kept = std::min(std::max(swapped, lowest), highest);
            d[c] = static_cast<T>(integer ? std::nearbyint(kept) : kept);
        }
        return true;
    }

    Point requested_, shift_;
    int gridStep_ = 2;
    RawFormat format_;
    detail::DarkShading shading_;
    std::unique_ptr<ShiftSource> from_;
    bool checkValues_ = false;
    detail::StepTally* tally_ = nullptr;
    int rows_ = 0;
};

} // namespace

namespace detail {

std::unique_ptr<NoiseStep> makeShiftStep(Point shift)
{
    return std::unique_ptr<NoiseStep>(new ShiftStep(shift));
}

} // namespace detail
} // namespace rawgment
} // namespace cv
