// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The one reader of a model's dark-shading maps (NoiseModel::darkShadingPerGain B_d and
// darkShadingOffset B_r): the noise steps' rows, the shift's swap of the shading, the local-mean prior
// and NoiseModel::darkShadingAt() all index the maps through it, so that a mosaic row, its sensor
// origin and the formula g B_d + B_r have one home. Private to the module.
#ifndef OPENCV_RAWGMENT_SRC_DARK_SHADING_HPP
#define OPENCV_RAWGMENT_SRC_DARK_SHADING_HPP

#include <opencv2/core.hpp>

namespace cv {
namespace rawgment {
namespace detail {

/** The dark shading g B_d + B_r at one gain of a mosaic lying at `origin` on the sensor
 * (RawFormat::sensorOrigin), read row by row: a whole-frame map per call (48 MB at 12 MP) would cost more
 * in first-touch page faults than a step itself. Holds the maps' headers (no copy of their data). */
class DarkShading
{
public:
    DarkShading() = default; //!< no shading
    DarkShading(const Mat& perGain, const Mat& offset, double gain, Point origin)
        : perGain_(perGain), offset_(offset), gain_(static_cast<float>(gain)), origin_(origin)
    {
    }
    bool empty() const { return perGain_.empty(); }
    float gain() const { return gain_; }
    //! B_d of mosaic row r, from its column 0.
    const float* perGainRow(int r) const { return perGain_.ptr<float>(r + origin_.y) + origin_.x; }
    //! B_r of mosaic row r, from its column 0.
    const float* offsetRow(int r) const { return offset_.ptr<float>(r + origin_.y) + origin_.x; }
    //! g B_d + B_r at column c of the rows bd, br (float: the same on every CPU path).
    float at(const float* bd, const float* br, int c) const { return gain_ * bd[c] + br[c]; }
    //! The same shading at another gain: the maps and origin are the sensor's, the gain the step's.
    DarkShading atGain(double gain) const { return DarkShading(perGain_, offset_, gain, origin_); }
    /** Whether a mosaic of `size` at this origin lies inside the maps; the error, naming `who`, says how
     * to give a crop its offset. */
    void checkCovers(Size size, const char* who) const;
    //! Row r of g B_d + B_r into out[0..cols).
    void row(int r, int cols, float* out) const
    {
        const float *bd = perGainRow(r), *br = offsetRow(r);
        for (int c = 0; c < cols; ++c)
            out[c] = at(bd, br, c);
    }

private:
    Mat perGain_, offset_;
    float gain_ = 0;
    Point origin_;
};

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_DARK_SHADING_HPP
