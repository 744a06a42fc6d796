// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_NOISE_MODEL_HPP
#define OPENCV_RAWGMENT_NOISE_MODEL_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/export.hpp>

#include <vector>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_noise_model
//! @{

// Adding a noise component (row noise, a fixed pattern, ...) touches one declared place per topic:
//  1. noise_model: a field of NoiseModel (absent by default), validate(), write()/read() with a new
//     FORMAT_VERSION (older files keep loading), and its term in detail::NoiseTerms
//     (src/noise_terms.hpp), the one home of the model's terms and of variance().
//  2. simulate: SensorSimulator::capture() draws it where it arises (src/simulate.cpp), the ground
//     truth of every test.
//  3. calibration: its estimator in src/calibration.cpp (the joint residual uses NoiseTerms, so a term
//     that depends on the mean enters the fit there).
//  4. augment: what a target lacks of it, in detail::AddedVariance (src/augment_steps.hpp) as
//     computed by jitterVariance() (src/color_jitter.cpp) and finishResampledRow()
//     (src/resample.cpp); nothing is computed when the model lacks it.
//  5. tests: test_noise_model.cpp (file round trip, old version), test_simulate.cpp (its statistics),
//     test_calibration_fit.cpp (recovery), test_color_jitter.cpp, test_motion_blur.cpp, test_scale_mosaic.cpp
//     and test_resample.cpp (against a capture simulated at the target), and a row of
//     apps/rawgment_tradeoffs. docs/mathematics.md gets its equation.

/** @brief Linear analog gain of a gain in decibels: \f$ g = 10^{dB/20} \f$ (0 dB = 1).
 * @throws cv::Exception when dB is not finite.
 */
CV_EXPORTS_W double dbToLinearGain(double db);

/** @brief Gain in decibels of a linear gain: \f$ dB = 20 \log_{10} g \f$.
 * @throws cv::Exception when g is not finite and positive.
 */
CV_EXPORTS_W double linearGainToDb(double gain);

/** @brief The noise of one gain as a line in the mean: \f$ \sigma^2 = a\,\mu + b \f$
 * @cite yoshimura2023rawgment. */
struct CV_EXPORTS_W_SIMPLE NoiseLine
{
    //! a = b = 0.
    CV_WRAP NoiseLine() : a(0), b(0) {}
    CV_PROP_RW double a; //!< slope, \f$ a = g\alpha \f$
    CV_PROP_RW double b; //!< offset, \f$ b = g^2\sigma_d^2 + \sigma_r^2 \f$
};

/** @brief A noise line measured at one gain: darktable's profile of one ISO, one gain's fit of a
 * calibration, or a DNG's own NoiseProfile. Raw DN of the mosaic, black subtracted.
 *
 * NoiseModel::measuredLines holds them; the augmentation then follows the measurements at every gain
 * (NoiseModel::lineAtGain()) instead of Eq. 5's three parameters. */
struct CV_EXPORTS_W_SIMPLE MeasuredNoiseLine
{
    //! Every field 0: not yet a valid line.
    CV_WRAP MeasuredNoiseLine() : gain(0), slopeStdError(0), offsetStdError(0), iso(0) {}
    CV_PROP_RW double gain;           //!< linear gain it was measured at, finite and > 0
    CV_PROP_RW NoiseLine line;        //!< slope a and offset b, finite and >= 0
    CV_PROP_RW double slopeStdError;  //!< standard error of a (0: not stated)
    CV_PROP_RW double offsetStdError; //!< standard error of b (0: not stated)
    CV_PROP_RW double iso;            //!< the ISO it was measured at (0: not stated); informative only
};

/** @brief Heteroscedastic Gaussian sensor noise model (paper Eq. 5) @cite yoshimura2023rawgment.
 *
 * A pixel with expected black-subtracted value \f$ \mu \f$ (DN) captured at linear analog gain g is
 * \f[ x \sim \mathcal{N}\left(\mu,\; \sigma^2 = g\,\alpha\,\max(\mu, 0) + g^2\sigma_d^2 + \sigma_r^2\right)
 * \f] where \f$ \alpha \f$ is the DN per photo-electron at gain 1 (shot noise), \f$ \sigma_d^2 \f$ the read
 * noise before the gain and \f$ \sigma_r^2 \f$ the noise after it (including quantisation, 1/12 DN^2).
 *
 * A negative mean (a pixel whose expectation lies below black, which a real sensor does not produce but
 * an estimate such as a single noisy value can) has no photon shot noise: the shot term uses
 * \f$ \max(\mu, 0) \f$, so the variance is never below the read-noise floor and never negative.
 */
struct CV_EXPORTS_W_SIMPLE NoiseModel
{
    //! Newest version of the file format; read() rejects newer versions (see write()).
    static constexpr int FORMAT_VERSION = 5;
    /** The range of a known baseIso, with room on both sides of every camera's (ISO 25 to 3,280,000):
     * beyond it a gain ISO / baseIso under- or overflows the noise terms (a base ISO of 1e300 wrote a
     * model of zeros, 1e-300 stopped the solver). */
    static constexpr double MIN_BASE_ISO = 1;
    static constexpr double MAX_BASE_ISO = 1e7; //!< see MIN_BASE_ISO

    CV_PROP_RW double alpha;   //!< shot-noise slope at gain 1, DN per electron (>= 0)
    CV_PROP_RW double sigmaD2; //!< read-noise variance before the analog gain, DN^2 at gain 1 (>= 0)
    CV_PROP_RW double sigmaR2; //!< noise variance after the analog gain, DN^2 (>= 0)
    /** ISO of gain 1, when the model was calibrated from files that say their ISO (0: unknown; else in
     * [MIN_BASE_ISO, MAX_BASE_ISO]). It
     * lets a camera file give its own gain, \f$ g = \mathrm{ISO} / \mathrm{baseIso} \f$; the noise
     * terms do not depend on it. */
    CV_PROP_RW double baseIso;

    /** Why the calibration that made this model failed its verdict (the failed checks), or empty when it
     * is not known to have failed. A model that carries it is written with it (format version 4), and
     * load() refuses it unless the caller accepts it explicitly, so that a failed calibration never
     * leaves a file that silently works. */
    CV_PROP_RW String failedCalibration;

    /** @name Dark-frame components beyond the paper (each absent by default)
     * An absent component changes no output and costs nothing; see docs/mathematics.md, "Dark-frame
     * noise". Calibrated from dark frames by calibrateDarkNoise(). */
    //! @{
    /** Row noise (banding) before the analog gain, DN^2 at gain 1: every pixel of a row shares one
     * offset of variance \f$ g^2\sigma_{row,d}^2 + \sigma_{row,r}^2 \f$ per frame. */
    CV_PROP_RW double rowSigmaD2;
    CV_PROP_RW double rowSigmaR2; //!< row noise after the analog gain, DN^2 (see rowSigmaD2)
    /** Dark shading per unit gain, \f$ B_d \f$: CV_32FC1 of the sensor's size, DN. A dark frame at gain
     * g has the fixed per-pixel offset \f$ g B_d + B_r \f$ above the black level. Empty: no dark
     * shading (then darkShadingOffset must be empty too). */
    CV_PROP_RW Mat darkShadingPerGain;
    CV_PROP_RW Mat
        darkShadingOffset; //!< dark shading independent of the gain, \f$ B_r \f$ (see darkShadingPerGain)
    /** Whether the read noise (\f$ g^2\sigma_d^2 + \sigma_r^2 \f$ together, variance unchanged) has the
     * heavy-tailed Tukey-lambda shape of tukeyLambda instead of a Gaussian one. An explicit flag:
     * lambda = 0 is the logistic shape, not "absent". */
    CV_PROP_RW bool tukeyRead;
    /** Shape of the read noise when tukeyRead: -0.2 <= lambda <= 1 (validate()); about 0.14 is Gaussian,
     * smaller values have heavier tails (0: logistic, excess kurtosis 1.2). */
    CV_PROP_RW double tukeyLambda;

    CV_WRAP bool hasRowNoise() const
    {
        return rowSigmaD2 > 0 || rowSigmaR2 > 0;
    } //!< whether row noise is present
    CV_WRAP bool hasDarkShading() const
    {
        return !darkShadingPerGain.empty();
    } //!< whether dark shading is present
    //! Whether any dark-frame component is present.
    CV_WRAP bool hasDarkComponents() const { return hasRowNoise() || hasDarkShading() || tukeyRead; }
    /** @brief Excess kurtosis of the read noise: 0 unless tukeyRead, else that of the Tukey-lambda shape
     * (19 at lambda -0.2, 1.2 at 0, about 0 at 0.14, -1.2 at 1). What CalibrationParams::
     * readExcessKurtosis takes from a model that calibrateDarkNoise() fitted to dark frames. */
    CV_WRAP double readExcessKurtosis() const;
    /** @brief Variance of the row offset at linear gain g: \f$ g^2\sigma_{row,d}^2 + \sigma_{row,r}^2 \f$. */
    CV_WRAP double rowVariance(double gain) const;
    /** @brief The dark shading at linear gain g, \f$ g B_d + B_r \f$ (CV_32FC1), or an empty Mat without
     * dark shading. */
    CV_WRAP Mat darkShadingAt(double gain) const;
    //! @}

    /** @brief Noise lines measured at some gains, by increasing gain (empty: Eq. 5 alone, the paper's
     * model).
     *
     * When present, lineAtGain() and every noise-accounted step follow them: the measured line at a
     * measured gain; between two, each term in the shape Eq. 5 gives it, through both neighbours: the
     * slope linear in g, the offset linear in \f$ g^2 \f$ (exact whenever two neighbouring lines follow
     * Eq. 5 with parameters of their own, and never outside the two; interpolating in log-log instead is
     * off by up to 6% a stop apart where the offset turns from \f$ \sigma_r^2 \f$ to \f$ g^2\sigma_d^2 \f$);
     * beyond the measured range, the nearest line carried on by Eq. 5's trend (a in proportion to g, b in
     * proportion to Eq. 5's offset), so the line never jumps at the range's edge. alpha, sigmaD2 and
     * sigmaR2 then hold Eq. 5 fitted to the lines: a summary, and the trend beyond them. The split of a
     * measured offset into the parts before and after the gain (which a contrast change scales
     * differently, Eq. 13) is Eq. 5's at that gain. validate() requires increasing gains and finite,
     * non-negative values. */
    CV_PROP_RW std::vector<MeasuredNoiseLine> measuredLines;
    CV_WRAP bool hasMeasuredLines() const
    {
        return !measuredLines.empty();
    } //!< whether measuredLines is present

    //! Every parameter 0.
    CV_WRAP NoiseModel()
        : alpha(0), sigmaD2(0), sigmaR2(0), baseIso(0), rowSigmaD2(0), rowSigmaR2(0), tukeyRead(false),
          tukeyLambda(0)
    {
    }
    /** @brief A validated model. @throws cv::Exception when a parameter is negative or not finite.
     * Not in cv2.rawgment: OpenCV 4.6's generated constructors turn a C++ exception into a SystemError,
     * so there a model is made empty, filled and validate()d. */
    NoiseModel(double alpha, double sigmaD2, double sigmaR2);

    /** @brief Throws cv::Exception (StsBadArg) naming the parameter that is negative or not finite, a
     * tukeyLambda outside [-0.2, 1], or dark-shading maps that are not two CV_32FC1 Mats of one size.
     * Cheap, so every step calls it; a map that holds NaN or Inf is refused where a model is read,
     * written or simulated, and by the steps in the rows they read. */
    CV_WRAP void validate() const;

    /** @brief The per-gain line: \f$ a = g\alpha,\; b = g^2\sigma_d^2 + \sigma_r^2 \f$, or the
     * measured lines' (measuredLines) when the model has them.
     * @param gain linear gain, finite and > 0
     */
    CV_WRAP NoiseLine lineAtGain(double gain) const;

    /** @brief Variance of a pixel with mean `mean` at linear gain `gain`:
     * \f$ g\alpha\max(\mu,0) + g^2\sigma_d^2 + \sigma_r^2 \f$ (with measuredLines, \f$ a\max(\mu,0) + b
     * \f$ of lineAtGain()).
     * @param mean black-subtracted expected value in DN (any finite value)
     * @param gain linear gain, finite and > 0
     */
    CV_WRAP double variance(double mean, double gain) const;

    /** @brief variance() of every element of a mean image.
     * @param mean CV_32FC1 or CV_64FC1 Mat of black-subtracted means (finite values)
     * @param gain linear gain, finite and > 0
     * @param dst variance, same size and type as `mean`
     */
    CV_WRAP void variance(InputArray mean, double gain, OutputArray dst) const;

    /** @brief Writes the model as a map under `name`: format_version, alpha, sigma_d2, sigma_r2,
     * base_iso when it is known, the dark-frame components that are present (row_sigma_d2,
     * row_sigma_r2, tukey_lambda, and dark_shading: the names, size and FNV-1a checksums of two
     * CV_32FC1 TIFF images), failed_calibration when it is set, and measured_lines (a list of maps gain,
     * a, b, a_std_error, b_std_error, iso) when present. The version is the lowest that holds
     * what the model has (1 without a base ISO, 2 with one, 3 with a dark-frame component, 4 with
     * failedCalibration, 5 with measured lines), so a model without them stays readable by older builds, and
     * an older build refuses a failed calibration's model instead of using it.
     * @param fs the storage
     * @param name the map's name
     * @param shadingImages the file names of the dark-shading images (per gain, offset) as the file
     *        refers to them (relative to the model file's folder); required when the model has dark
     *        shading, which save() writes as those files. write() itself writes no image.
     */
    void write(FileStorage& fs, const String& name, const std::vector<String>& shadingImages = {}) const;

    /** @brief Reads a model written by write().
     * @param node the map
     * @param folder where the dark-shading images named in the file are (the model file's folder)
     * @throws cv::Exception naming the field when a field is missing, not a number, negative or not
     *         finite, or unknown; when format_version is newer than FORMAT_VERSION; when a dark-shading
     *         image is not a plain file name in `folder`, is missing, not a regular file, unreadable, of
     *         another size or type, or does not match its checksum.
     */
    static NoiseModel read(const FileNode& node, const String& folder = String());

    /** @brief Saves the model to a YAML (.yml, .yaml) or JSON (.json) file, atomically: the file is
     * written under a temporary name next to `path` and renamed, so a reader never sees half a file.
     * The save is all or nothing: a model that validate() refuses or a map with NaN or Inf writes
     * nothing. Dark shading goes first into new files `<file name of path>.dark_shading_per_gain.<fnv>.tiff`
     * and `.dark_shading_offset.<fnv>.tiff` (fnv: the map's FNV-1a 64 checksum, so `cam.yml` and
     * `cam.json` never share a map and a new map never replaces one the current model file names); the
     * model file, which names them with their checksums, is switched last; only then are the maps of the
     * model file's earlier saves removed. When any write fails (a full disk), the maps this call made
     * are removed and the model file and its maps are as they were.
     */
    CV_WRAP void save(const String& path) const;

    /** @brief Loads a model saved by save() (the top-level map is `noise_model`), with its dark-shading
     * images.
     * @param path the model file
     * @param acceptFailedCalibration also load a model whose failedCalibration is set (the calibration
     *        that made it failed its verdict); without it such a model is refused with an error that
     *        names the file and the failed checks
     */
    CV_WRAP static NoiseModel load(const String& path, bool acceptFailedCalibration = false);
};

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_NOISE_MODEL_HPP
