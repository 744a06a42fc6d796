// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_SIMULATE_HPP
#define OPENCV_RAWGMENT_SIMULATE_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/bayer.hpp>
#include <opencv2/rawgment/export.hpp>
#include <opencv2/rawgment/noise_model.hpp>
#include <opencv2/rawgment/seeds.hpp>

#include <vector>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_simulate
//! @{

/** @brief The physical description of a simulated sensor: its noise, its levels and its defects. */
struct CV_RAWGMENT_EXPORTS SensorParams
{
    /** Noise of the analog chain (paper Eq. 1): alpha (DN per electron at gain 1), sigma_d^2 (read
     * noise before the gain, DN^2 at gain 1) and sigma_r^2 (noise after the gain, DN^2), *without*
     * quantisation, which the simulator adds by rounding (see SensorSimulator::effectiveModel()). */
    NoiseModel noise = NoiseModel(0.25, 1.5, 0.8);
    CfaPattern pattern = CFA_RGGB;      //!< CFA layout of the sensor
    Vec4d blackLevel = Vec4d::all(256); //!< black level per site (DN)
    int bitDepth = 12;                  //!< ADC bits; the white level is 2^bitDepth - 1 (1..16)
    bool quantize = true;               //!< round to integer DN (the ADC); off gives CV_32F-exact values
    double prnu = 0;                    //!< photo-response non-uniformity: relative std of the per-pixel gain
    double dsnu = 0;                    //!< dark-signal non-uniformity: std of the per-pixel offset (DN)
    double hotPixelFraction = 0;        //!< fraction of pixels stuck near white (mean high, no variance)
    double deadPixelFraction = 0;       //!< fraction of pixels stuck at black (no signal, no variance)
    double noisyPixelFraction = 0;      //!< fraction of pixels with extra temporal noise (e.g. RTS noise)
    double noisyPixelVariance = 100;    //!< extra variance of those pixels (DN^2)
    /** Variance of an offset shared by each column of each frame (DN^2, at every gain): column banding, which
     * no NoiseModel component describes (a departure for the dark-frame bank's tests); 0: none. */
    double columnNoiseVariance = 0;
    uint64 fixedPatternSeed = 1; //!< seed of the sensor's fixed pattern (PRNU, DSNU, defect map)

    //! Throws cv::Exception naming the first invalid field.
    void validate() const;
};

/** @brief A physical sensor simulator: the project's ground truth.
 *
 * A capture of a scene whose expected signal at gain 1 is \f$ \mu_1 \f$ (DN, black-subtracted) is, per
 * pixel,
 * \f[ raw = \mathrm{clip}\Big(\mathrm{round}\big(g\,(\alpha\,u + n_d) + n_r + dsnu + black\big),\,
 *     0,\, 2^{bits} - 1\Big),\quad u \sim \mathcal{P}\Big(\frac{\mu_1\,e\,prnu}{\alpha}\Big),\;
 *     n_d \sim \mathcal{N}(0, \sigma_d^2),\; n_r \sim \mathcal{N}(0, \sigma_r^2) \f]
 * with the exact Poisson distribution (not its Gaussian approximation), exposure factor e, and the
 * fixed pattern (PRNU, DSNU, hot, dead and noisy pixels) drawn once from `fixedPatternSeed`.
 *
 * The dark-frame components of the model (NoiseModel::hasDarkComponents()) are drawn when present: a
 * Gaussian offset of variance NoiseModel::rowVariance() shared by each row of each frame, the dark
 * shading NoiseModel::darkShadingAt() added to every frame, and with NoiseModel::tukeyRead the read
 * noise \f$ g n_d + n_r \f$ as one Tukey-lambda draw of variance \f$ g^2\sigma_d^2 + \sigma_r^2 \f$.
 *
 * Random numbers come from a counter-based generator keyed by (seed, frame, row): the same seed gives
 * bit-identical frames whatever the number of threads.
 */
class CV_RAWGMENT_EXPORTS SensorSimulator
{
public:
    /** @brief A sensor of the given size (even width and height) and parameters (validated). */
    SensorSimulator(const SensorParams& params, Size size);

    const SensorParams& params() const { return params_; } //!< the validated parameters
    Size size() const { return size_; }                    //!< the size of every capture

    /** @brief The format of this sensor's captures at a linear gain. */
    RawFormat rawFormat(double gain) const;

    /** @brief The noise model a calibration of this sensor should recover: the parameters, with the
     * quantisation noise of rounding (1/12 DN^2) added to sigma_r^2 when `quantize` is on.
     * The 1/12 is exact for a signal spread over many DN; below about 0.5 DN of noise it overstates. */
    NoiseModel effectiveModel() const;

    /** @brief One frame.
     * @param meanAtUnitGain expected signal at gain 1 in DN above black, CV_32FC1 of the sensor's size,
     *        finite and >= 0 (an electron count times alpha)
     * @param gain linear analog gain (> 0)
     * @param exposure factor on the photon count (exposure time x illumination, > 0)
     * @param seed seed of the noise
     * @param frameIndex index of the frame in its burst (frames of one seed differ by it)
     * @param raw output CV_16UC1 mosaic (black level included)
     */
    void capture(InputArray meanAtUnitGain, double gain, double exposure, uint64 seed, int frameIndex,
                 OutputArray raw) const;

    /** @brief `frames` captures of one scene: frame t is capture(..., seed, t). */
    void captureBurst(InputArray meanAtUnitGain, double gain, double exposure, int frames, uint64 seed,
                      std::vector<Mat>& raws) const;

    /** @brief A capture during motion: the kernel blurs the photon image of each CFA plane *before*
     * the noise, as a real exposure does (the ground truth for noise-accounted blur, paper Eq. 14).
     * Beyond the frame, the border rule of every blur of the library applies: the nearest pixel
     * (BORDER_REPLICATE), as in motionBlur().
     * @param meanAtUnitGain as in capture()
     * @param kernel CV_32FC1 or CV_64FC1 kernel on the CFA-plane grid (on the pixel grid for a CFA_MONO
     *        sensor, as in motionBlur()); normalised to sum 1 here
     * @param gain as in capture()
     * @param exposure as in capture()
     * @param seed as in capture()
     * @param frameIndex as in capture()
     * @param raw as in capture()
     */
    void captureBlurred(InputArray meanAtUnitGain, InputArray kernel, double gain, double exposure,
                        uint64 seed, int frameIndex, OutputArray raw) const;

    /** @brief The fixed pattern: per-pixel gain factor (PRNU), offset (DSNU, DN) and defect code
     * (0 normal, 1 hot, 2 dead, 3 noisy), each of the sensor's size. */
    void fixedPattern(OutputArray gainFactor, OutputArray offset, OutputArray defects) const;

private:
    SensorParams params_;
    Size size_;
    Mat prnu_, dsnu_, defects_;
};

/** @brief Options of a simulated ColorChecker chart (classic 24 patches, 6 columns x 4 rows). */
struct CV_RAWGMENT_EXPORTS ColorCheckerOptions
{
    CfaPattern pattern = CFA_RGGB;  //!< CFA layout of the mosaic the scene is rendered for
    int patchSize = 40;             //!< side of a square patch in mosaic pixels (even, >= 2)
    int border = 8;                 //!< width of the black frame around and between patches (even, >= 0)
    double illumination = 2000;     //!< signal of a perfect white reflector at gain 1 (DN above black)
    double vignetting = 0;          //!< relative fall-off at the corners: gain 1 - v r^2, r = 1 at a corner
    double frameReflectance = 0.03; //!< reflectance of the chart's black frame
};

/** @brief A rendered chart: the expected signal at gain 1 of each mosaic pixel, and the patches. */
struct CV_RAWGMENT_EXPORTS ColorCheckerScene
{
    Mat meanAtUnitGain;             //!< CV_32FC1 mosaic, DN above black at gain 1
    std::vector<Rect> patches;      //!< the 24 patch rectangles, row by row (white is patch 18, black 23)
    std::vector<Vec3d> reflectance; //!< linear (R, G, B) reflectance of each patch
};

/** @brief Linear RGB reflectances of the 24 classic ColorChecker patches, row by row, derived from the
 * chart's published sRGB values by the sRGB transfer function (so approximate, but realistic in their
 * spread of colours and of brightness from 3% to 90%). */
CV_RAWGMENT_EXPORTS std::vector<Vec3d> colorCheckerReflectances();

/** @brief Renders the chart as a Bayer mosaic of expected signals (each CFA site sees its channel's
 * reflectance), with optional vignetting. */
CV_RAWGMENT_EXPORTS ColorCheckerScene makeColorCheckerScene(const ColorCheckerOptions& options);

/** @brief Fills a CV_32FC1 matrix with standard normal numbers from the module's own generator: row r is
 * stream r of `seed` (Philox4x32-10, Box-Muller), the numbers the noise steps draw. The same seed gives
 * the same bits on every thread count and CpuPath.
 * @param dst a CV_32FC1 matrix, filled in place (created as `size` when empty)
 * @param size the size when `dst` is empty
 * @param seed the generator's key
 */
CV_RAWGMENT_EXPORTS void fillStandardNormal(InputOutputArray dst, Size size, uint64 seed);

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SIMULATE_HPP
