// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_CALIBRATION_HPP
#define OPENCV_RAWGMENT_CALIBRATION_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/bayer.hpp>
#include <opencv2/rawgment/export.hpp>
#include <opencv2/rawgment/noise_model.hpp>
#include <opencv2/rawgment/normality.hpp>

#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_calibration
//! @{

/** @brief Streaming per-pixel temporal mean and unbiased variance of a burst.
 *
 * Frames are added one at a time and never all held in memory: the statistics are float64 running
 * sums updated with Chan's pairwise merge of small groups of frames (Welford's update generalised),
 * which stays exact for large means (60000 DN with a variance of 1) and long bursts. A group of
 * frames is buffered (a copy of each) so that the float64 state, eight times the size of a 16-bit
 * frame, is read and written once per group instead of once per frame; for CV_16UC1 input the group's
 * sums are exact integers. Peak memory for a W x H burst: 17 bytes per pixel of state (9 with a float32
 * state) plus `groupFrames` frames (8 x 24 MB for 12 MP by default). The state traffic per frame falls as
 * 1/groupFrames, but beyond 8-16 frames the buffers' own traffic dominates (see perf_calibration).
 *
 * Values are black-subtracted with the RawFormat (per site). A pixel that is at or above the white
 * level, or at or below zero, in any frame is marked clipped: its variance is biased and calibration
 * excludes it.
 */
class CV_EXPORTS_W BurstStatistics
{
public:
    /** @param format the burst's format (validated); its black and white levels are used
     *  @param groupFrames frames buffered between merges, in [1, 256]; results differ between group
     *         sizes only by float64 rounding
     *  @param stateDepth depth of the running mean and M2: CV_64F (default, exact to float64 rounding) or
     *         CV_32F, which halves the state's memory (8 instead of 16 bytes per pixel) and its traffic.
     *         Each group is still merged in float64, so float32 only rounds the stored state: about
     *         1e-7 relative on the mean, whose rounding at each merge then enters M2 through the
     *         merge's delta: at mean 60000 and variance 1 the variance errs by up to ~2e-3 relative
     *         (rawgment_tradeoffs measures it), at ordinary means far less. */
    explicit BurstStatistics(const RawFormat& format, int groupFrames = 8, int stateDepth = CV_64F);
    /** @brief The constructor's object, held by a Ptr: the way bindings make one. OpenCV 4.6's generated
     * cv2 constructor cannot raise cv2.error (a refused argument came out as SystemError), a function can.
     * @throws cv::Exception as the constructor does. */
    CV_WRAP static Ptr<BurstStatistics> create(const RawFormat& format, int groupFrames = 8,
                                               int stateDepth = CV_64F);
    ~BurstStatistics();
    BurstStatistics(const BurstStatistics&) = delete;
    BurstStatistics& operator=(const BurstStatistics&) = delete;

    /** @brief Adds a frame: CV_16UC1 or CV_32FC1 raw mosaic (black level included). The first frame
     * of a burst fixes the size and type; later frames must match. NaN or Inf in a CV_32FC1 frame is
     * rejected. */
    CV_WRAP void add(InputArray frame);
    /** @brief Starts a new burst of `format` (validated) in the same memory: frames() becomes 0, and the
     * state and the group buffers stay allocated, so a calibration over many bursts of one size and type
     * touches each page once instead of once per burst (100 frames of 12 MP took 432 ms with a new object
     * and 362 ms reset on host H3: perf_calibration's `reused` benchmark).
     * A burst of another size or type may follow: the first frame then reallocates. Results are the
     * same bits as a new object's. */
    CV_WRAP void reset(const RawFormat& format);
    CV_WRAP int frames() const;              //!< frames added so far in this burst
    CV_WRAP Size size() const;               //!< size of the frames (empty before the first)
    CV_WRAP const RawFormat& format() const; //!< the format given to the constructor or the last reset()
    /** @brief Temporal mean, black-subtracted, CV_64FC1. Needs at least one frame. */
    CV_WRAP void mean(OutputArray dst) const;
    /** @brief Unbiased temporal variance (divided by frames - 1), CV_64FC1. Needs at least 2 frames. */
    CV_WRAP void variance(OutputArray dst) const;
    /** @brief CV_8UC1 mask, 255 where the pixel was clipped (<= 0 or >= white) in any frame. */
    CV_WRAP void clippedMask(OutputArray dst) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/** @brief One (mean, variance) observation of the noise: a pixel's temporal statistics over a burst,
 * or the spatial statistics of a uniform patch in single-frame mode. */
struct CV_EXPORTS_W_SIMPLE NoiseSample
{
    //! Every field at its default, as initialised here.
    CV_WRAP NoiseSample() : mean(0), variance(0), gain(1), dof(1), channel(-1), pixel(-1) {}
    CV_PROP_RW double mean;     //!< black-subtracted mean (DN)
    CV_PROP_RW double variance; //!< unbiased variance (DN^2)
    CV_PROP_RW double gain;     //!< linear gain of the capture
    CV_PROP_RW int dof;         //!< degrees of freedom of the variance (frames - 1 for a burst)
    CV_PROP_RW int channel;     //!< CfaChannel of the pixel (or patch plane)
    /** The pixel's position on the sensor, row * width + column, or -1 when the sample is not one pixel
     * (single-frame patches). calibrateNoiseModel() leaves a pixel that is an outlier in one burst out
     * of every burst (a noisy or stuck pixel), so samples of one sensor must number pixels alike. */
    CV_PROP int64 pixel;
};

/** @brief Squares of side `side` (even) centred in each patch, with even corners so that each holds
 * whole 2x2 CFA blocks. @throws cv::Exception when a patch is smaller than the square. */
CV_EXPORTS_W std::vector<Rect> cfaAlignedSquares(const std::vector<Rect>& patches, int side = 24);

/** @brief The temporal noise samples of every unclipped pixel of the squares.
 * @param stats statistics of a burst with at least 2 frames
 * @param squares pixel rectangles inside the frame (see cfaAlignedSquares())
 * @param gain linear gain of the burst (stored in the samples)
 */
CV_RAWGMENT_EXPORTS std::vector<NoiseSample>
sampleBurstPatches(const BurstStatistics& stats, const std::vector<Rect>& squares, double gain);

/** @brief The temporal noise samples of a burst of dark frames (a lens cap), each counted at mean 0.
 *
 * Dark frames hold no photo-electrons: their variance is the read noise alone. Their temporal means
 * scatter around 0 by sigma / sqrt(T) (and by any dark shading), and the model's shot term
 * \f$ g\alpha\max(\mu, 0) \f$ at those means would bias the read-noise terms low (2% at 16 frames and
 * 24 dB, measured); so every sample's mean is 0. The one home of that rule: rawgment_calibrate, the
 * trade-off report and the coverage study all take dark samples from here.
 * @param stats statistics of a dark burst with at least 2 frames
 * @param squares pixel rectangles inside the frame (for a dark frame, which has no scene, any region:
 *        the apps take the whole frame less an 8-pixel border)
 * @param gain linear gain of the burst (stored in the samples)
 */
CV_RAWGMENT_EXPORTS std::vector<NoiseSample> sampleDarkBurst(const BurstStatistics& stats,
                                                             const std::vector<Rect>& squares, double gain);

/** @brief The temporal noise samples of a burst of any static scene, without a chart: unclipped pixels
 * away from edges, on a regular grid of whole 2x2 blocks.
 *
 * Temporal statistics need no uniform patch: each pixel is its own patch. What they need is a scene that
 * did not move, and a shaken tripod or a breathing lens moves edges, which turns into variance. So a
 * pixel is kept only when the temporal means of its eight same-colour neighbours (two pixels away) all
 * lie within \f$ 4\sqrt{2 v_{med} / T} + 0.002|\mu_p| \f$ of its own mean, with \f$ v_{med} \f$ the median
 * temporal variance of the eight neighbours (never the pixel's own, so that the selection does not depend on
 * the variance the fit measures: with it, noisier pixels passed more often and alpha came out 0.4% high)
 * and T the frames: a neighbourhood flat within the noise of a difference of means (the median sets it,
 * because shake inflates the variance of the very pixels it smears, at most three along an edge) and a 0.2%
 * allowance for smooth shading, whose own shake adds under 1% of the shot noise. Neither the pixels within 4
 * of the frame's border nor clipped pixels (or pixels next to them) are sampled; dark frames (a lens cap)
 * pass as flat scenes.
 * @param stats statistics of a burst with at least 2 frames
 * @param gain linear gain of the burst (stored in the samples)
 * @param maxSamples at most this many samples (>= 4): the grid's step in blocks grows until the frame's
 *        blocks fit, so a 12-megapixel burst costs no more than a small one
 */
CV_RAWGMENT_EXPORTS std::vector<NoiseSample> sampleStaticScene(const BurstStatistics& stats, double gain,
                                                               int maxSamples = 100000);

/** @name The samplers for a burst held by Ptr
 * The overloads OpenCV's binding generator wraps: its classes live in a Ptr, and a null one is an error. */
//! @{
//! @overload
CV_EXPORTS_W std::vector<NoiseSample> sampleBurstPatches(const Ptr<BurstStatistics>& stats,
                                                         const std::vector<Rect>& squares, double gain);
//! @overload
CV_EXPORTS_W std::vector<NoiseSample> sampleDarkBurst(const Ptr<BurstStatistics>& stats,
                                                      const std::vector<Rect>& squares, double gain);
//! @overload
CV_EXPORTS_W std::vector<NoiseSample> sampleStaticScene(const Ptr<BurstStatistics>& stats, double gain,
                                                        int maxSamples = 100000);
//! @}

/** @brief Single-frame mode: the spatial mean and variance of each CFA plane of each square.
 *
 * A plane a + b x + c y is fitted to each square's CFA plane and removed first, which takes out the
 * patch's low-frequency shading (vignetting, uneven light); the variance of the residual is divided by
 * n - 3. Less exact than a burst: the spatial variance also holds fixed-pattern noise (PRNU grows with
 * the mean squared, DSNU adds a constant), and any texture of the patch. Planes with a clipped pixel
 * are skipped.
 * @param raw CV_16UC1 or CV_32FC1 mosaic
 * @param format its format
 * @param squares CFA-aligned rectangles of uniform patches (each plane needs >= 4 pixels)
 * @param gain linear gain of the capture
 */
CV_EXPORTS_W std::vector<NoiseSample> sampleSingleFramePatches(InputArray raw, const RawFormat& format,
                                                               const std::vector<Rect>& squares, double gain);

/** @brief Settings of the per-gain line fit. */
struct CV_EXPORTS_W_SIMPLE LineFitParams
{
    //! Every field at its default, as initialised here.
    CV_WRAP LineFitParams()
        : robust(true), ransacIterations(500), inlierThreshold(4.0), seed(0), readExcessKurtosis(0)
    {
    }
    CV_PROP_RW bool robust; //!< RANSAC, then least squares on the inliers; false: least squares on all
    CV_PROP_RW int ransacIterations; //!< line hypotheses drawn from random pairs of samples
    /** Inlier band: a sample is kept when its variance lies where a sample variance of `dof` degrees of
     * freedom lies with the probability that a normal variable lies within +-k,
     * \f$ \chi^2_{dof}(\Phi(-k))/dof \le v / line(\mu) \le \chi^2_{dof}(\Phi(k))/dof \f$ (about
     * +-k standard errors for large dof; equal in probability on both sides, because a sample variance is
     * skewed and a band of equal width keeps every zero variance and cuts only the high tail). */
    CV_PROP_RW double inlierThreshold;
    CV_PROP_RW uint64 seed; //!< seed of the RANSAC draws (deterministic)
    /** Excess kurtosis of the read noise (\f$ g n_d + n_r \f$ together; 0: Gaussian, in [-2, 1000]).
     * With the Poisson part it sets how far a sample variance spreads, \f$ Var(s^2) = 2v^2/dof +
     * \kappa_4/(dof + 1) \f$ with fourth cumulant \f$ \kappa_4 = \kappa b^2 + a^3\mu \f$: the inlier
     * band is that of the scaled chi-square with the same spread, and the weights are its inverse, so
     * heavy tails are neither trimmed nor down-weighted as if they were defects.
     * calibrateNoiseModel() sets it from CalibrationParams::readExcessKurtosis or its estimate. */
    CV_PROP_RW double readExcessKurtosis;
};

/** @brief The line \f$ \sigma^2 = a\mu + b \f$ fitted to the samples of one gain.
 *
 * The final fit is iterated weighted least squares with weights \f$ dof / (2 v^2) \f$, the inverse
 * variance of a sample variance, which makes the offset b far more precise than ordinary least squares
 * (paper) does on the same inliers. */
struct CV_EXPORTS_W_SIMPLE NoiseLineFit
{
    //! Every field at its default, as initialised here.
    CV_WRAP NoiseLineFit()
        : gain(1), rSquared(0), inliers(0), samples(0), slopeStdError(0), offsetStdError(0),
          slopeOffsetCorrelation(0)
    {
    }
    CV_PROP_RW double gain;     //!< linear gain
    CV_PROP_RW NoiseLine line;  //!< slope a and offset b (unconstrained: a negative value is reported as is)
    CV_PROP_RW double rSquared; //!< coefficient of determination on the inliers
    CV_PROP_RW int inliers;     //!< samples used by the final least squares
    CV_PROP_RW int samples;     //!< samples offered
    /** Standard errors of a and b and their correlation: the sandwich (Huber-White) covariance of the
     * final weighted least squares, \f$ A^{-1} B A^{-1} \f$ with \f$ A = \sum w_i x_i x_i^T \f$ and
     * \f$ B = \sum w_i^2 e_i^2 x_i x_i^T \f$, \f$ x_i = (\mu_i, 1) \f$: it takes the scatter the data
     * show rather than the \f$ 2v^2/dof \f$ of Gaussian noise, so excess kurtosis (Poisson at low
     * counts, quantisation, noisy pixels inside the inlier band) widens it as it should. Conditional on
     * the inliers chosen. 0 when there are fewer than 3 inliers. */
    CV_PROP_RW double slopeStdError;
    CV_PROP_RW double offsetStdError;         //!< standard error of b (see slopeStdError)
    CV_PROP_RW double slopeOffsetCorrelation; //!< correlation of the errors of a and b (see slopeStdError)
};

/** @brief Fits \f$ \sigma^2 = a\mu + b \f$ to samples of one gain (paper Eq. 6), robustly by default.
 * @throws cv::Exception with fewer than 2 samples, samples of different gains, non-finite values, or
 *         when all samples share one mean (the slope is then undefined).
 */
CV_EXPORTS_W NoiseLineFit fitNoiseLine(const std::vector<NoiseSample>& samples,
                                       const LineFitParams& params = LineFitParams());

/** @brief How the cross-gain parameters are estimated. */
// OpenCV 4.6's binding parser reads an enum's base only with no space before ':'.
// clang-format off
enum NoiseFitMethod: int
// clang-format on
{
    /** One fit of \f$ \sigma^2 = g\alpha\mu + g^2\sigma_d^2 + \sigma_r^2 \f$ over all samples of all gains,
     * each weighted by the inverse squared standard error of a sample variance, \f$ dof / (2\sigma^4) \f$
     * (iterated: the weights use the previous fit), corrected for the error of each sample's own mean
     * (see docs/mathematics.md), on the per-gain RANSAC inliers, with every parameter >= 0 (an exact
     * bounded solve). The default: it uses the dark samples that pin \f$ \sigma_r^2 \f$ directly
     * instead of extrapolating each offset. */
    NOISE_FIT_JOINT = 0,
    /** The paper's method (Eq. 7, 8): per-gain lines, then \f$ a_g = g\alpha \f$ and
     * \f$ b_g = g^2\sigma_d^2 + \sigma_r^2 \f$ by least squares with non-negative bounds. */
    NOISE_FIT_TWO_STAGE = 1
};

/** @brief Settings of calibrateNoiseModel(). */
struct CV_EXPORTS_W_SIMPLE CalibrationParams
{
    //! Every field at its default, as initialised here.
    CV_WRAP CalibrationParams()
        : method(NOISE_FIT_JOINT), reweightIterations(8), lossScale(0.0), minGainRatio(1.12),
          bootstrapReplicates(200), readExcessKurtosis(std::numeric_limits<double>::quiet_NaN())
    {
    }
    CV_PROP_RW NoiseFitMethod method;  //!< cross-gain method
    CV_PROP_RW LineFitParams line;     //!< per-gain line fits (also select the joint fit's inliers)
    CV_PROP_RW int reweightIterations; //!< joint fit: re-weighting rounds from the two-stage fit
    /** Joint fit: Huber loss scale in standard errors, 0 for none (the default). The per-gain band
     * (LineFitParams::inlierThreshold) has already removed what cannot be noise, and a loss on a skewed
     * residual (a sample variance is chi-squared) cuts its long tail only and biases the fit low: Cauchy
     * at 3 by ~0.4%, and even Huber at 4 measurably. */
    CV_PROP_RW double lossScale;
    /** Gains closer than this ratio count as one when deciding whether sigma_d^2 and sigma_r^2 are
     * separable (1.12 is 1 dB). */
    CV_PROP_RW double minGainRatio;
    /** Bootstrap replicates of the final fit (0: none), the check of the covariance and its stand-in
     * where the covariance does not hold (see ModelUncertainty). Each replicate draws the samples of
     * each gain anew with replacement and repeats the final weighted fit; 200 give each standard
     * error to about 5% (\f$ 1/\sqrt{2R} \f$). Keyed by `line.seed`: the same seed gives the same
     * errors on any number of threads. */
    CV_PROP_RW int bootstrapReplicates;
    /** Excess kurtosis of the read noise (see LineFitParams::readExcessKurtosis), or NaN (the default) to
     * estimate it from the spread of the sample variances around their lines (CalibrationReport::
     * readExcessKurtosis). Give it when dark frames have measured it: NoiseModel::readExcessKurtosis() of
     * calibrateDarkNoise()'s model (0 for Gaussian read noise). The estimate needs samples where read
     * noise dominates (dark frames or dark patches); without them the fit takes 0 and says so. */
    CV_PROP_RW double readExcessKurtosis;
};

/** @brief The parameters of a NoiseModel, as indices into the vectors and matrices of
 * ModelUncertainty. */
// OpenCV 4.6's binding parser reads an enum's base only with no space before ':'.
// clang-format off
enum NoiseModelParameter: int
// clang-format on
{
    NOISE_PARAM_ALPHA = 0,    //!< \f$ \alpha \f$
    NOISE_PARAM_SIGMA_D2 = 1, //!< \f$ \sigma_d^2 \f$
    NOISE_PARAM_SIGMA_R2 = 2  //!< \f$ \sigma_r^2 \f$
};

/** @brief Where the standard errors of a calibration come from. */
// OpenCV 4.6's binding parser reads an enum's base only with no space before ':'.
// clang-format off
enum UncertaintySource: int
// clang-format on
{
    UNCERTAINTY_NONE = 0, //!< none were computed (a report of format 1)
    /** The sandwich covariance of the final fit (see NoiseLineFit::slopeStdError), confirmed by the
     * bootstrap where one ran. */
    UNCERTAINTY_COVARIANCE = 1,
    /** The bootstrap: a parameter sits at its bound 0, where a covariance from derivatives does not
     * hold, or the bootstrap found an error over 25% larger than the covariance's (its own spread at
     * 200 replicates is 5%, so this is no chance). */
    UNCERTAINTY_BOOTSTRAP = 2
};

/** @brief How exact a calibrated model is: the standard errors of alpha, sigma_d^2 and sigma_r^2 and
 * their covariance.
 *
 * The errors are those of the final fit given its inliers (the RANSAC choice is not redone); they
 * describe scatter, not bias, and the coverage study (study_calibration_coverage) measures how often
 * the 95% interval holds the simulator's truth. When sigma_d^2 and sigma_r^2 are not separable only
 * alpha has an error. */
struct CV_EXPORTS_W_SIMPLE ModelUncertainty
{
    //! Every field at its default, as initialised here.
    CV_WRAP ModelUncertainty() : source(UNCERTAINTY_NONE), bootstrapReplicates(0) {}
    CV_PROP_RW UncertaintySource source; //!< which of the two estimates below is used
    CV_PROP_RW Vec3d stdError;           //!< standard errors used, indexed by NoiseModelParameter
    CV_PROP_RW Matx33d covariance;       //!< their covariance (DN units squared of each pair)
    CV_PROP_RW Vec3d
        fitStdError; //!< from the sandwich covariance of the fit (0 for a parameter at its bound)
    CV_PROP_RW Vec3d bootstrapStdError; //!< from the bootstrap (0 when none ran)
    CV_PROP_RW int bootstrapReplicates; //!< replicates of the bootstrap that ran

    /** @brief The correlation of the errors of two parameters (0 when either has no error). The one
     * of sigma_d^2 and sigma_r^2 is usually strongly negative: both make up each gain's offset. */
    CV_WRAP double correlation(NoiseModelParameter first, NoiseModelParameter second) const;
};

/** @brief Everything a calibration found, readable and writable as YAML or JSON. */
struct CV_EXPORTS_W_SIMPLE CalibrationReport
{
    //! Every field at its default, as initialised here.
    CV_WRAP CalibrationReport()
        : method(NOISE_FIT_JOINT), separable(false), rSquaredSlope(0), rSquaredOffset(0), samples(0),
          samplesUsed(0), readExcessKurtosis(0), readExcessKurtosisEstimated(false)
    {
    }
    /** Newest version of the file format. Version 2 adds the uncertainty and the per-gain standard
     * errors, version 3 the read noise's excess kurtosis; a report without an uncertainty (source
     * UNCERTAINTY_NONE) is written as version 1, and files of versions 1 and 2 still load (kurtosis 0). */
    static constexpr int FORMAT_VERSION = 3;

    CV_PROP_RW NoiseFitMethod method; //!< the method that ran
    /** The fitted model. Valid only when `separable`; with a single gain (or gains closer than
     * CalibrationParams::minGainRatio) only alpha is known, and sigma_d^2, sigma_r^2 are left at 0. */
    CV_PROP_RW NoiseModel model;
    CV_PROP_RW bool separable;                    //!< sigma_d^2 and sigma_r^2 could be told apart
    CV_PROP_RW std::vector<NoiseLineFit> perGain; //!< the per-gain lines, by increasing gain
    CV_PROP_RW double rSquaredSlope;              //!< R^2 of a_g = g alpha over the gains (paper: 1.0000)
    CV_PROP_RW double rSquaredOffset;             //!< R^2 of b_g = g^2 sigma_d^2 + sigma_r^2 (paper: 0.9984)
    CV_PROP_RW int samples;                       //!< samples offered
    CV_PROP_RW int samplesUsed;                   //!< samples in the final fit
    CV_PROP_RW std::vector<std::string> notes; //!< what the user should know (bounds hit, not separable, ...)
    CV_PROP_RW ModelUncertainty uncertainty;   //!< standard errors of the model's parameters
    /** The read noise's excess kurtosis the bands, weights and errors used: the given one, or the
     * estimate (see CalibrationParams::readExcessKurtosis). */
    CV_PROP_RW double readExcessKurtosis;
    CV_PROP_RW bool
        readExcessKurtosisEstimated; //!< whether readExcessKurtosis was estimated from the samples

    /** @brief The two-sided confidence interval of a parameter, value \f$ \pm z_{(1+level)/2} \f$
     * standard errors (normal: each estimate is a weighted sum over thousands of samples). Not cut at
     * 0, so that an interval that spans 0 shows the data cannot tell the parameter from 0.
     * @throws cv::Exception when level is not in (0, 1) or the report has no uncertainty. */
    CV_WRAP Vec2d interval(NoiseModelParameter parameter, double level = 0.95) const;

    /** @brief Writes the report as a map under `name`; its model without the dark-shading maps, which
     * NoiseModel::save() writes beside the model file. */
    void write(FileStorage& fs, const String& name) const;
    /** @brief Reads a report written by write(). @throws cv::Exception naming a missing field. */
    static CalibrationReport read(const FileNode& node);
    /** @brief Saves to .yml/.yaml/.json atomically (top-level map `calibration_report`). */
    void save(const String& path) const;
    /** @brief Loads a report saved by save(). */
    CV_WRAP static CalibrationReport load(const String& path);
};

/** @brief A change to the data of a calibration, for projectedStdError(): what a user could shoot more of. */
struct CV_RAWGMENT_EXPORTS CalibrationPlan
{
    double frameFactor = 1; //!< frames per burst times this (> 0): each sample's dof + 1 scales
    double pixelFactor = 1; //!< pixels per burst times this (> 0): more or larger patches
    bool addDarkFrames =
        false; //!< one burst of dark frames (mean 0) per gain, as many pixels as its light samples
    /** > 0: one more gain (linear), shot like the highest gain: the same means, pixels and frames. */
    double addGain = 0;
};

/** @brief The standard errors a calibration would have if its data changed by `plan`.
 *
 * From the Fisher information of the samples under the fitted model, \f$ I = \sum_i x_i x_i^T\, dof_i /
 * (2 m_i^2) \f$ with \f$ x_i = (g\mu_i, g^2, 1) \f$ and \f$ m_i \f$ the model's variance, the errors of the
 * changed data are the report's errors times \f$ \sqrt{[I'^{-1}]_{kk} / [I^{-1}]_{kk}} \f$: the ratio
 * carries over whatever the report measured beyond Gaussian scatter (shot noise's kurtosis, quantisation).
 * More of the same data has the formula \f$ \sigma' = \sigma / \sqrt{p} \f$ for p times the pixels and about
 * \f$ \sigma\sqrt{(T - 1)/(fT - 1)} \f$ for f times T frames; new gains and dark frames change the design,
 * and only the information says what they buy. Where the report has no error for a parameter (not
 * separable), the information's own error is returned.
 * @param samples the samples the report was calibrated from
 * @param report its report (with an uncertainty)
 * @param plan the change
 * @return standard errors of alpha, sigma_d^2 and sigma_r^2 (0 where the changed data still cannot
 *         determine a parameter)
 * @throws cv::Exception on an invalid plan, no samples, or a report without an uncertainty
 */
CV_RAWGMENT_EXPORTS Vec3d projectedStdError(const std::vector<NoiseSample>& samples,
                                            const CalibrationReport& report, const CalibrationPlan& plan);

/** @brief Calibrates the noise model from samples of one or more gains (paper Sec. 3.2).
 * @param samples noise samples of all gains (their `gain` field groups them)
 * @param params method and settings
 * @throws cv::Exception when there are no samples, a value is not finite, or a gain has fewer than
 *         2 distinct means.
 */
CV_EXPORTS_W CalibrationReport calibrateNoiseModel(const std::vector<NoiseSample>& samples,
                                                   const CalibrationParams& params = CalibrationParams());

/** @brief What the verdict of a calibration needs to know about one burst besides its samples. */
struct CV_RAWGMENT_EXPORTS CalibrationBurstFacts
{
    String name;                //!< how the report names the burst (its first file)
    double gainDb = 0;          //!< its gain as the calibration took it (dB)
    int frames = 0;             //!< its frames
    double clippedFraction = 0; //!< of the pixels it could sample (squares, or the frame without a chart)
    bool dark = false;          //!< dark frames (no light)
};

/** @brief One check of a calibration's verdict: a measured figure against a stated threshold. */
struct CV_RAWGMENT_EXPORTS VerdictCheck
{
    String name;      //!< what is checked
    bool pass = true; //!< whether the figure meets the threshold
    String figure;    //!< the measured figure, the threshold and, on a failure, what to do
};

/** @brief PASS when every check passes; the checks and their thresholds are in
 * docs/calibrate_your_camera.md. */
struct CV_RAWGMENT_EXPORTS CalibrationVerdict
{
    bool pass = true;                 //!< every check passed
    std::vector<VerdictCheck> checks; //!< in the order of the report
};

/** @brief The variance a calibration predicts at `mean` and linear `gain`: the model when sigma_d^2 and
 * sigma_r^2 were separable; otherwise the line fitted at the nearest calibrated gain, since the model then
 * holds alpha alone and would leave out the read noise. */
CV_EXPORTS_W double fittedVariance(const CalibrationReport& report, double mean, double gain);

/** @brief Judges a calibration from its samples, its report and its bursts, each check a measured figure
 * against a stated threshold (docs/calibrate_your_camera.md says where each comes from): frames per burst,
 * clipped fraction, separability of sigma_d^2 and sigma_r^2 (gain ratio and both 95% intervals above 0),
 * each gain's slope against its tagged gain (naming the burst that disagrees and the gain it implies),
 * residuals of the variance against the model per gain and mean bin, distinct means per gain, and the
 * curvature of variance against mean (a non-linear raw file).
 * @param samples the samples the report was fitted to
 * @param report what calibrateNoiseModel() (or calibrateWithDarkFrames()) gave
 * @param bursts one entry per burst, light and dark
 * @param signalRange white level minus black level of the frames
 */
CV_RAWGMENT_EXPORTS CalibrationVerdict judgeCalibration(const std::vector<NoiseSample>& samples,
                                                        const CalibrationReport& report,
                                                        const std::vector<CalibrationBurstFacts>& bursts,
                                                        double signalRange);

/** @brief Options of calibrateDarkNoise(): which dark-frame components to fit. */
struct CV_RAWGMENT_EXPORTS DarkCalibrationParams
{
    bool rowNoise = true;    //!< fit NoiseModel::rowSigmaD2 and rowSigmaR2 (two or more distinct gains)
    bool darkShading = true; //!< fit the dark-shading maps (two or more distinct gains)
    bool tukeyShape = true;  //!< fit NoiseModel::tukeyLambda (and set tukeyRead)
    double lambdaMin = -0.2; //!< the search range of lambda (>= -0.2)
    double lambdaMax = 0.5;  //!< (<= 1; 0.14 is Gaussian, so the range covers light tails too)
    /** Residuals per gain that enter the probability plot (a fixed spread-out subsample; all when fewer).
     * 100,000 put the PPCC's own noise near 1e-5, below the differences between lambdas 0.01 apart. */
    int ppccSamples = 100000;

    void validate() const; //!< throws cv::Exception naming the invalid field
};

/** @brief What one gain's dark burst shows (calibrateDarkNoise()). */
struct CV_RAWGMENT_EXPORTS DarkGainStatistics
{
    double gain = 0;        //!< linear gain
    int frames = 0;         //!< frames of the burst
    double rowMeanVar = 0;  //!< variance of a row's mean after the fixed pattern is removed
    double rowVariance = 0; //!< the row noise: rowMeanVar less the pixel noise's share, pixelVariance / width
    double rowVarianceSE = 0;  //!< its standard error (Gaussian row means)
    double pixelVariance = 0;  //!< per-pixel temporal variance without the rows
    double excessKurtosis = 0; //!< of the pixel residuals after the rows are removed
    ShapiroWilkResult before;  //!< Shapiro-Wilk of 5000 residuals with the row offsets still in
    ShapiroWilkResult after;   //!< ... and of the same residuals without them
};

/** @brief The statistics of one burst of a flat scene (dark frames, or any burst whose scene is
 * constant over its frames), as calibrateDarkNoise() computes them per gain: with e the residual of
 * each black-subtracted value from its pixel's temporal mean, R its row's mean and f = e - R over T
 * frames of H x W, the row-mean variance sum R^2 / ((T - 1) H), the per-pixel variance without the rows,
 * the excess kurtosis of f, and Shapiro-Wilk of the residuals with and without the rows. The one home of
 * these measures: the trade-off report uses it too.
 * @param frames 3 or more frames of one size, CV_16UC1 or CV_32FC1
 * @param format black levels of the frames (per CFA site)
 * @param gain linear gain of the burst (stored)
 * @param pixelMean optional output: the black-subtracted temporal mean of each pixel, CV_64FC1 (the
 *        fixed pattern plus the scene)
 * @throws cv::Exception for fewer than 3 frames, frames of other sizes or types, NaN or Inf, or frames
 *         that do not vary at all. */
CV_RAWGMENT_EXPORTS DarkGainStatistics darkBurstStatistics(const std::vector<Mat>& frames,
                                                           const RawFormat& format, double gain,
                                                           OutputArray pixelMean = noArray());

/** @brief Everything calibrateDarkNoise() found. */
struct CV_RAWGMENT_EXPORTS DarkCalibrationReport
{
    NoiseModel model;                      //!< the base model with the fitted components
    std::vector<DarkGainStatistics> gains; //!< by increasing gain
    std::vector<Vec2d> ppcc;               //!< (lambda, probability-plot correlation) over the search grid
    /** The lambda whose probability plot fits the residuals best, before the correction for what the
     * temporal mean and rounding mix into them (model.tukeyLambda is after it). */
    double lambdaOfResiduals = 0;
    double ppccBest = 0;            //!< the correlation at lambdaOfResiduals
    double ppccGaussian = 0;        //!< the correlation of a normal probability plot, for comparison
    std::vector<std::string> notes; //!< what the user should know (a component at a bound, few frames, ...)

    /** @brief Writes the report (without the maps, which the model's save() writes) under `name`. */
    void write(FileStorage& fs, const String& name) const;
};

/** @brief Calibrates the dark-frame components of a noise model from bursts of dark frames (lens cap)
 * at several gains (docs/mathematics.md, "Dark-frame noise").
 *
 * Per gain g with T frames of H x W: the residual of a frame is its pixels less their temporal mean,
 * which removes the fixed pattern. Its row means R have variance \f$ (1 - 1/T)(\sigma_{row}^2 +
 * \sigma_{pix}^2 / W) \f$, and the rest of the residual \f$ (1 - 1/T)(1 - 1/W)\sigma_{pix}^2 \f$, which
 * gives each gain's row variance corrected for the pixel noise's part of a row mean.
 * - row noise: \f$ \sigma_{row}^2(g) = g^2\sigma_{row,d}^2 + \sigma_{row,r}^2 \f$ by weighted least squares
 *   over the gains (each weighted by its standard error), both parts >= 0;
 * - dark shading: each pixel's temporal means over the gains fitted by the line \f$ g B_d + B_r \f$
 *   (weights: frames over variance per gain);
 * - Tukey lambda: the lambda that maximises the probability-plot correlation (Filliben's medians) of the
 *   pooled, standardised residuals without the rows, over the gains whose pixel noise is at least 2 DN
 *   (quantisation flattens the tails below; the highest gain when none is). Removing the temporal mean
 *   mixes 1/T of the other frames into each residual, and rounding a uniform part, both of which pull
 *   the shape towards the Gaussian; their effect on the excess kurtosis is known (c(T) and the share
 *   1/12 over the variance), so the lambda of the residuals is carried back to the read noise's through
 *   its kurtosis. The accuracy reached per number of frames is in docs/calibrate_your_camera.md.
 *
 * @param bursts bursts[k] are the dark frames at gains[k]: CV_16UC1 or CV_32FC1 mosaics of one size,
 *        at least 3 frames each
 * @param gains the linear gains, finite and > 0
 * @param format the CFA format (its black level is subtracted; its gain is not used)
 * @param base the model to extend, as calibrateNoiseModel() gives it: alpha and the base ISO are kept;
 *        its sigma_d^2 and sigma_r^2, measured from per-pixel temporal variances, hold the row noise too,
 *        so the fitted row parts are moved out of them (at least 0, with a note when they do not fit)
 * @param params what to fit
 * @throws cv::Exception naming the problem: no bursts, sizes or types that differ, fewer than 3 frames,
 *         fewer than 2 distinct gains for row noise or dark shading, non-finite values.
 */
CV_RAWGMENT_EXPORTS DarkCalibrationReport calibrateDarkNoise(
    const std::vector<std::vector<Mat>>& bursts, const std::vector<double>& gains, const RawFormat& format,
    const NoiseModel& base, const DarkCalibrationParams& params = DarkCalibrationParams());

/** @brief What calibrateWithDarkFrames() found: the final fit and the dark-frame components. */
struct CV_RAWGMENT_EXPORTS DarkFrameCalibration
{
    /** The final fit of the light and dark samples; its model carries the dark-frame components, with the
     * row parts moved out of sigma_d^2 and sigma_r^2 (the pixel's own read noise, as the simulator's). */
    CalibrationReport report;
    DarkCalibrationReport dark;     //!< the components' report (its model is report.model)
    std::vector<std::string> notes; //!< what was done to the light samples and the fit, for the user
    /** The samples of the final fit: the light samples (their means without the dark shading when it was
     * fitted), then the dark samples, in the order given. */
    std::vector<NoiseSample> samples;
};

/** @brief The whole model of a sensor from its light samples and its dark bursts, in one call: what
 * calibrateNoiseModel() alone cannot know about dark frames.
 *
 * 1. calibrateNoiseModel() of the light and dark samples gives the base model;
 * 2. calibrateDarkNoise() of the dark bursts gives row noise, dark shading and the read noise's shape;
 * 3. with dark shading, each light sample's mean loses its pixel's \f$ g B_d + B_r \f$: the shading is
 *    no signal, and left in the means it takes \f$ g\alpha s \f$ from each line's offset (with 4 DN of
 *    shading sigma_r^2 came out 59% low, and a plain calibrateNoiseModel() of a shaded sensor's light and
 *    dark samples gives sigma_d^2 about 2% low); with a heavy-tailed read noise, its excess kurtosis
 *    (NoiseModel::readExcessKurtosis() of the dark fit) replaces the light samples' estimate unless
 *    params gives one; the model is then fitted again;
 * 4. the row noise, which every pixel's temporal variance holds, moves out of the read terms.
 *
 * @param lightSamples samples of bursts with light (sampleBurstPatches(), sampleStaticScene())
 * @param darkSamples samples of the dark bursts (sampleDarkBurst(): means 0), or empty
 * @param darkBursts darkBursts[k]: the dark frames at darkGains[k] (see calibrateDarkNoise())
 * @param darkGains their linear gains
 * @param format the CFA format of the frames (black levels)
 * @param params the fit of the noise model
 * @param darkParams what to fit of the dark-frame components (row noise and dark shading need 2 or more
 *        distinct gains: with one, only the read noise's shape is fitted, with a note)
 * @param lightFrames per light sample, the size of the frame whose pixel NoiseSample::pixel numbers;
 *        empty: every light sample numbers a pixel of the dark frames. A sample of a frame of another size
 *        (or of no single pixel) loses the maps' mean shading instead.
 * @throws cv::Exception as calibrateNoiseModel() and calibrateDarkNoise() do, and when lightFrames is
 *         neither empty nor one size per light sample.
 */
CV_RAWGMENT_EXPORTS DarkFrameCalibration calibrateWithDarkFrames(
    const std::vector<NoiseSample>& lightSamples, const std::vector<NoiseSample>& darkSamples,
    const std::vector<std::vector<Mat>>& darkBursts, const std::vector<double>& darkGains,
    const RawFormat& format, const CalibrationParams& params = CalibrationParams(),
    const DarkCalibrationParams& darkParams = DarkCalibrationParams(),
    const std::vector<Size>& lightFrames = std::vector<Size>());

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_CALIBRATION_HPP
