// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_ISP_HPP
#define OPENCV_RAWGMENT_ISP_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/bayer.hpp>
#include <opencv2/rawgment/export.hpp>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_isp
//! @{

/** @brief A gamma tone curve with an optional linear toe: the paper's simple ISPs.
 *
 * With \f$ x \in [0, 1] \f$ the black-normalised linear signal (values outside are clipped first):
 * \f[ y = \begin{cases} s\,x & x < x_0 \\ (1 + a)\,x^{1/\gamma} - a & x \ge x_0 \end{cases}
 *     \qquad a = \frac{s\,x_0 - x_0^{1/\gamma}}{x_0^{1/\gamma} - 1} \f]
 * The three parameters are the exponent \f$ \gamma \f$ (`gamma`), the break point \f$ x_0 \f$
 * (`breakPoint`) and the slope \f$ s \f$ of the toe (`toeSlope`); the offset \f$ a \f$ is derived so that
 * the two pieces meet at \f$ x_0 \f$, and \f$ y(1) = 1 \f$ always holds.
 *
 * - \f$ x_0 = 0 \f$ gives the paper's simplest ISP, \f$ y = x^{1/\gamma} \f$ with \f$ \gamma = 5 \f$
 *   (simpleGamma()).
 * - The paper's second ISP is "a gamma tone mapping parameterized with three parameters"
 *   @cite mosleh2020hardware, whose exact formula is not published; this is the three-parameter
 *   family of the sRGB and ITU-R BT.709 transfer functions, which contains both: srgb() is
 *   \f$ (\gamma, x_0, s) = (2.4, 0.0031308, 12.92) \f$, giving \f$ a = 0.055 \f$ as in the standard.
 *
 * validate() rejects parameters for which the curve is not increasing on [0, 1].
 */
struct CV_RAWGMENT_EXPORTS ToneCurve
{
    double gamma = 5.0;      //!< exponent \f$ \gamma \f$ (> 0); the curve applies \f$ x^{1/\gamma} \f$
    double breakPoint = 0.0; //!< \f$ x_0 \in [0, 1) \f$; 0 means a pure power curve
    double toeSlope = 0.0;   //!< \f$ s \ge 0 \f$, slope of the linear part below \f$ x_0 \f$

    //! The paper's simplest ISP, \f$ y = x^{1/\gamma} \f$.
    static ToneCurve simpleGamma(double gamma = 5.0);
    //! The three-parameter curve; see the class description.
    static ToneCurve parametric(double gamma, double breakPoint, double toeSlope);
    //! The sRGB transfer function (IEC 61966-2-1).
    static ToneCurve srgb();

    //! The derived offset \f$ a \f$ (0 when breakPoint is 0).
    double offset() const;
    //! The curve at x, after clipping x to [0, 1].
    double operator()(double x) const;
    /** @brief Throws cv::Exception (StsBadArg) naming the parameter when gamma is not finite and
     * positive, breakPoint is outside [0, 1), toeSlope is negative or not finite, or the two pieces do
     * not make an increasing curve (1 + a <= 0 or a jump downwards at the break point). */
    void validate() const;

    //! Writes the curve as a map under `name` (fields gamma, break_point, toe_slope).
    void write(FileStorage& fs, const String& name) const;
    //! Reads a curve written by write(), validating it.
    static ToneCurve read(const FileNode& node);
};

/** @brief Applies a tone curve element-wise.
 * @param linear CV_32F or CV_64F array with any number of channels, values on the [0, 1] scale (others
 *        are clipped)
 * @param dst output of the same size and channel count
 * @param curve the curve (validated)
 * @param ddepth CV_8U (rounded, 255 = 1.0), CV_32F, or -1 for the depth of `linear`
 */
CV_RAWGMENT_EXPORTS void applyToneCurve(InputArray linear, OutputArray dst, const ToneCurve& curve,
                                        int ddepth = -1);

/** @brief How renderSimpleIsp() turns the mosaic into three colours per pixel. */
// OpenCV 4.6's binding parser reads an enum's base only with no space before ':'.
// clang-format off
enum DemosaicMethod: int
// clang-format on
{
    DEMOSAIC_BILINEAR = 0,   //!< OpenCV's bilinear Bayer demosaicing (cv::COLOR_BayerBG2BGR family)
    DEMOSAIC_EDGE_AWARE = 1, //!< OpenCV's edge-aware demosaicing (cv::COLOR_BayerBG2BGR_EA family)
    /** One output pixel per 2x2 block (R, mean of the greens, B): half the size, no interpolation,
     * the fastest preview. */
    DEMOSAIC_HALF_SIZE = 2
};

/** @brief Settings of the simple ISP. The defaults are the paper's simplest ISP (gamma 5, no white
 * balance, bilinear demosaicing, 8-bit output). */
struct CV_RAWGMENT_EXPORTS IspParams
{
    ToneCurve tone;                              //!< tone curve applied last
    Vec3d whiteBalance = Vec3d(1, 1, 1);         //!< gains for R, G, B (> 0), applied before demosaicing
    Matx33d colorMatrix = Matx33d::eye();        //!< camera RGB to output RGB, applied after demosaicing
    double exposure = 1.0;                       //!< digital gain (> 0) applied with the white balance
    DemosaicMethod demosaic = DEMOSAIC_BILINEAR; //!< demosaicing method
    int outputDepth = CV_8U;                     //!< CV_8U or CV_32F (values in [0, 1])

    //! Throws cv::Exception (StsBadArg) naming the first invalid field.
    void validate() const;
};

/** @brief The paper's simple ISP: black-level normalisation, white balance, demosaicing, colour
 * matrix, tone curve. Output channels are in OpenCV's BGR order.
 *
 * Each value becomes \f$ x = \mathrm{clip}\big(e\,w_c\,(raw - black) / (white - black), 0, 1\big) \f$
 * with \f$ e \f$ the exposure and \f$ w_c \f$ the white-balance gain of the pixel's colour. The clipped
 * linear signal is quantised to 16 bits for OpenCV's demosaicing (a step of 1/65535 of the range, finer
 * than any sensor's ADC), then the colour matrix and the tone curve are applied through a 65536-entry
 * table. Runs in parallel over rows. A CFA_MONO frame has no colours to balance, interpolate or mix: white
 * balance and colour matrix are not applied, and the grey value fills the three channels (averaged over
 * each 2x2 block with DEMOSAIC_HALF_SIZE).
 * @param mosaic Bayer mosaic or monochrome frame, CV_16UC1 or CV_32FC1 (black included, as stored), even
 * sides
 * @param format its format (pattern, black and white levels; the gain is not used)
 * @param bgr output: CV_8UC3 or CV_32FC3, the mosaic's size (half of it with DEMOSAIC_HALF_SIZE)
 * @param params the ISP settings (validated)
 */
CV_RAWGMENT_EXPORTS void renderSimpleIsp(InputArray mosaic, const RawFormat& format, OutputArray bgr,
                                         const IspParams& params = IspParams());

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_ISP_HPP
