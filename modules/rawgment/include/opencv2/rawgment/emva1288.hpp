// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_EMVA1288_HPP
#define OPENCV_RAWGMENT_EMVA1288_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/export.hpp>

#include <functional>
#include <vector>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_emva1288
//! @{

/** @brief The images of one exposure in an EMVA 1288 descriptor: a `b` (bright) or `d` (dark) line and
 * the `i` lines that follow it. */
struct CV_EXPORTS_W_SIMPLE Emva1288Images
{
    //! Every field at its default, as initialised here.
    CV_WRAP Emva1288Images() : exposureNs(0), photons(0), dark(false), line(0) {}
    CV_PROP_RW double exposureNs; //!< exposure time as the descriptor states it (ns in releases 3 and 4)
    CV_PROP_RW double photons;    //!< mean photons per pixel during the exposure (0 for a dark line)
    CV_PROP_RW bool dark;         //!< a `d` line: the same exposure without light
    CV_PROP_RW std::vector<String> images; //!< the image paths, resolved against the descriptor's folder
    CV_PROP_RW int line;                   //!< the descriptor line of the `b` or `d` command (1-based)
};

/** @brief A measurement series in the EMVA 1288 standard's own form, as readEmva1288() reads it.
 *
 * As the standard's reference implementation classifies them, an exposure with exactly two images is a
 * temporal step and one with more is the spatial set (DSNU and PRNU). Every temporal exposure time has
 * one dark pair and one or more bright pairs; the spatial set, when present, is one exposure time with
 * one bright and one dark stack. Only paths are held: images are read one step at a time.
 */
struct CV_EXPORTS_W_SIMPLE Emva1288Series
{
    //! Every field at its default, as initialised here.
    CV_WRAP Emva1288Series() : bits(0), width(0), height(0) {}
    CV_PROP_RW String path;    //!< the descriptor file
    CV_PROP_RW String version; //!< its `v` line ("3.0", "4.0"), "" when it has none
    CV_PROP_RW int bits;   //!< bits per pixel value (`n bits width height`): values lie in [0, 2^bits - 1]
    CV_PROP_RW int width;  //!< image width in pixels
    CV_PROP_RW int height; //!< image height in pixels
    CV_PROP_RW std::vector<Emva1288Images> temporal; //!< the pairs, bright and dark, in the file's order
    CV_PROP_RW std::vector<Emva1288Images> spatial;  //!< the stacks of the spatial set (0 or 2 of them)
};

//! The largest `bits` of a descriptor: 16-bit containers hold the values.
static constexpr int MAX_EMVA1288_BITS = 16;
//! The largest image a descriptor may describe (pixels): 2^28, a 16384x16384 sensor.
static constexpr long long MAX_EMVA1288_PIXELS = 1LL << 28;
//! The largest photon count per pixel a `b` line may state: 10^12, a million times a large full well.
static constexpr double MAX_EMVA1288_PHOTONS = 1e12;
//! The longest exposure a line may state: 10^15 (ns: eleven days).
static constexpr double MAX_EMVA1288_EXPOSURE = 1e15;
//! The most images a descriptor may list (the standard asks for about 100 steps and 2 x 100 spatial frames).
static constexpr int MAX_EMVA1288_IMAGES = 100000;

/** @brief Reads an EMVA 1288 descriptor (`EMVA1288_Data.txt`, releases 3.x and 4.x).
 *
 * Lines: `v <release>`, `n <bits> <width> <height>` (once, before any exposure), `b <exposure> <photons>`
 * or `d <exposure>`, each followed by its `i <image>` lines; `#` starts a comment line. CRLF line ends,
 * Windows path separators and a decimal comma are read as the reference implementation reads them.
 * Image paths are resolved against the descriptor's folder; each must name an existing regular file (its
 * content is checked when it is read, see emva1288Results()).
 *
 * @param path the descriptor
 * @return the series (paths only; nothing is decoded)
 * @throws cv::Exception StsParseError naming the file and line for: a file that is not a descriptor (no
 * `n` line, an unknown command, text that is not a descriptor's), a malformed line, `bits` outside
 * [1, 16], dimensions or image counts beyond MAX_EMVA1288_PIXELS or MAX_EMVA1288_IMAGES, a negative or
 * non-finite exposure or photon count or one beyond MAX_EMVA1288_EXPOSURE or MAX_EMVA1288_PHOTONS, an
 * exposure with fewer than two images, a missing image file, the same (exposure, photons) listed twice, a
 * temporal exposure without its dark pair or without a bright pair, a spatial set that is not one bright and
 * one dark stack at one exposure; StsError for a descriptor that cannot be read (see readFileBounded()).
 */
CV_EXPORTS_W Emva1288Series readEmva1288(const String& path);

/** @brief One image of a series, decoded and checked against its descriptor: a PNG or TIFF, one
 * channel of 8 or 16 bits, `width` x `height` as `n` states, no value above 2^bits - 1. The header is
 * checked before anything is decoded, so a file that claims a huge image allocates nothing.
 * @param series the series the image belongs to
 * @param imagePath one of its image paths
 * @param line the descriptor line that lists it, for the message
 * @return the image, CV_8UC1 or CV_16UC1
 * @throws cv::Exception StsError naming the image and the descriptor line. */
CV_EXPORTS_W Mat readEmva1288Image(const Emva1288Series& series, const String& imagePath, int line);

/** @brief One temporal step measured: the mean and temporal variance of a pair of frames A, B.
 *
 * \f$\mu_y = \tfrac12(\langle A\rangle + \langle B\rangle)\f$ and \f$\sigma_y^2 = \tfrac12\left[\langle
 * (A-B)^2\rangle - \langle A-B\rangle^2\right]\f$ over the P pixels, as the standard defines them: the
 * difference cancels every fixed pattern (DSNU, PRNU, hot pixels' offsets), so no pixel is left out. The
 * standard error of \f$\sigma_y^2\f$ is measured, not assumed: \f$\tfrac12\sqrt{(m_4 - m_2^2)/P}\f$ with
 * \f$m_k\f$ the central moments of A - B, so that Poisson, quantisation and heavy tails widen it as they
 * should; or, when larger (noise shared along rows), the standard error of the mean of the rows' own
 * estimates. */
struct CV_EXPORTS_W_SIMPLE Emva1288Pair
{
    //! Every field at its default, as initialised here.
    CV_WRAP Emva1288Pair() : exposureNs(0), photons(0), dark(false), mean(0), variance(0), varianceStdError(0)
    {
    }
    CV_PROP_RW double exposureNs;       //!< exposure time
    CV_PROP_RW double photons;          //!< photons per pixel (0 for a dark pair)
    CV_PROP_RW bool dark;               //!< a dark pair
    CV_PROP_RW double mean;             //!< mu_y (DN)
    CV_PROP_RW double variance;         //!< sigma_y^2 (DN^2)
    CV_PROP_RW double varianceStdError; //!< standard error of sigma_y^2 (DN^2)
};

/** @brief Measures one temporal step from its two frames (see Emva1288Pair).
 * @param a first frame, CV_8UC1 or CV_16UC1 as the standard's images, or CV_32FC1 (augmented frames)
 * @param b second frame, of the same size and type
 * @param exposureNs the step's exposure time (>= 0)
 * @param photons its photons per pixel (>= 0, 0 for a dark pair)
 * @param dark whether it is a dark pair
 * @throws cv::Exception for frames of other types, different sizes, non-finite values or fewer than 2 pixels.
 */
CV_EXPORTS_W Emva1288Pair measureEmva1288Pair(InputArray a, InputArray b, double exposureNs, double photons,
                                              bool dark);

/** @brief The spatial set's stack, measured: the mean and the spatial variance of its mean image with the
 * temporal part removed, \f$s_y^2 = s^2_{measured} - \sigma^2_{stack}/L\f$ (the standard's Eq. for L frames).
 */
struct CV_EXPORTS_W_SIMPLE Emva1288Stack
{
    //! Every field at its default, as initialised here.
    CV_WRAP Emva1288Stack() : exposureNs(0), photons(0), dark(false), frames(0), mean(0), variance(0) {}
    CV_PROP_RW double exposureNs; //!< exposure time
    CV_PROP_RW double photons;    //!< photons per pixel (0 for the dark stack)
    CV_PROP_RW bool dark;         //!< the dark stack
    CV_PROP_RW int frames;        //!< L
    CV_PROP_RW double mean;       //!< mu_y of the stack (DN)
    CV_PROP_RW double
        variance; //!< s_y^2 (DN^2), which may be < 0 when the pattern is below what L frames resolve
};

/** @brief Measures a stack of L >= 2 frames (CV_8UC1, CV_16UC1 or CV_32FC1, one size and type) of the spatial
 * set.
 * @throws cv::Exception for fewer than two frames or frames of other types or sizes. */
CV_EXPORTS_W Emva1288Stack measureEmva1288Stack(InputArrayOfArrays frames, double exposureNs, double photons,
                                                bool dark);

/** @brief The EMVA 1288 figures of a series, defined as the standard (release 3.1/4.0) and its reference
 * implementation define them.
 *
 * Per temporal step (two frames A and B): \f$\mu_y\f$ is the mean of both, \f$\sigma_y^2 =
 * \tfrac12\left[\langle (A-B)^2\rangle - \langle A-B\rangle^2\right]\f$; dark pairs give
 * \f$\mu_{y.dark}, \sigma^2_{y.dark}\f$ at each exposure time. Saturation is the step of the largest
 * temporal variance, found scanning from the brightest step down as the reference does; K is the slope
 * through the origin of \f$\sigma_y^2 - \sigma^2_{y.dark}\f$ against \f$\mu_y - \mu_{y.dark}\f$ over the
 * steps from the first up to 70% of the saturation signal, and the responsivity R the same fit of
 * \f$\mu_y - \mu_{y.dark}\f$ against photons (\f$\eta = R/K\f$). \f$\sigma_{y.dark}\f$ is the intercept
 * of the dark variance against exposure time (the first dark variance when there are at most two
 * exposure times), at least \f$\sqrt{0.24}\f$ DN (the quantisation floor).
 * See docs/emva1288.md for every formula.
 */
struct CV_EXPORTS_W_SIMPLE Emva1288Results
{
    //! Every figure NaN and every list empty until emva1288Results() fills them.
    CV_WRAP Emva1288Results();
    CV_PROP_RW double K;              //!< overall system gain (DN/e-)
    CV_PROP_RW double sigmaYDark;     //!< temporal dark noise (DN)
    CV_PROP_RW double sigmaD;         //!< temporal dark noise in electrons, sqrt(sigmaYDark^2 - 1/12)/K
    CV_PROP_RW double responsivity;   //!< R, DN per photon
    CV_PROP_RW double eta;            //!< quantum efficiency (%), NaN when every photon count is 0
    CV_PROP_RW double muPSat;         //!< saturation (photons), NaN without photon counts
    CV_PROP_RW double muESat;         //!< saturation capacity (e-): eta mu_p.sat, or signal at saturation / K
    CV_PROP_RW double snrMax;         //!< sqrt(muESat)
    CV_PROP_RW double snrMaxDb;       //!< 20 log10 snrMax
    CV_PROP_RW double muPMin;         //!< absolute sensitivity threshold (photons), NaN without photons
    CV_PROP_RW double dynamicRangeDb; //!< 20 log10(muPSat / muPMin), NaN without photons
    CV_PROP_RW double
        dsnu1288; //!< dark signal non-uniformity (e-); NaN without a spatial set or when its estimate is < 0
    CV_PROP_RW double prnu1288; //!< photo-response non-uniformity (%); NaN as dsnu1288
    //! (%) smallest relative deviation from the linearity fit; NaN when fewer than two steps lie between
    //! 5% and 95% of the saturation signal
    CV_PROP_RW double linearityErrorMin;
    CV_PROP_RW double linearityErrorMax; //!< (%) largest relative deviation from the linearity fit, or NaN
    CV_PROP_RW bool photonsGiven;        //!< some bright step states a photon count above 0

    /* The temporal points, one per bright step in ascending exposure (then photons). */
    CV_PROP_RW std::vector<double> exposureNs;   //!< exposure time of each point
    CV_PROP_RW std::vector<double> photons;      //!< photons per pixel of each point
    CV_PROP_RW std::vector<double> mean;         //!< mu_y (DN)
    CV_PROP_RW std::vector<double> variance;     //!< sigma_y^2 (DN^2)
    CV_PROP_RW std::vector<double> darkMean;     //!< mu_y.dark at the point's exposure time (DN)
    CV_PROP_RW std::vector<double> darkVariance; //!< sigma_y.dark^2 at the point's exposure time (DN^2)
    CV_PROP_RW int saturationIndex;              //!< the point of saturation
    CV_PROP_RW int sensitivityMaxIndex;   //!< the last point of the K and R fits (70% of saturation signal)
    CV_PROP_RW int linearityMinIndex;     //!< first point of the linearity fit (5% of saturation signal)
    CV_PROP_RW int linearityMaxIndex;     //!< last point of the linearity fit (95% of saturation signal)
    CV_PROP_RW double linearityFitSlope;  //!< a of the linearity fit mu_y - mu_y.dark = a mu_p + b
    CV_PROP_RW double linearityFitOffset; //!< b of that fit (DN)
    CV_PROP_RW std::vector<double> linearityDeviation;   //!< (%) each point's relative deviation from it
    CV_PROP_RW std::vector<double> varianceStdError;     //!< standard error of each point's variance
    CV_PROP_RW std::vector<double> darkVarianceStdError; //!< and of its dark variance
    CV_PROP_RW std::vector<Emva1288Pair> pairs;          //!< every pair measured, bright and dark, as given
    CV_PROP_RW std::vector<Emva1288Stack> stacks; //!< the spatial set's stacks (none or bright and dark)
};

/** @brief The standard's figures of measured pairs and stacks (see Emva1288Results for the definitions).
 * @param pairs the temporal steps: bright pairs, and one dark pair per exposure time of a bright pair
 * @param stacks the spatial set: none, or one bright and one dark stack
 * @return the figures and the temporal points they come from
 * @throws cv::Exception StsBadArg for fewer than three bright pairs, a bright pair without a dark pair at
 * its exposure time, stacks that are not one bright and one dark, a signal that does not rise over two
 * steps below 70% of saturation, a variance that does not rise with it (K not > 0) or a signal that does
 * not rise with the photon counts given. */
CV_EXPORTS_W Emva1288Results
emva1288Results(const std::vector<Emva1288Pair>& pairs,
                const std::vector<Emva1288Stack>& stacks = std::vector<Emva1288Stack>());

/** @brief The standard's figures of a series read with readEmva1288().
 *
 * Images are read one exposure at a time (the spatial stacks one frame at a time, accumulated), never
 * the whole series at once.
 * @throws cv::Exception StsError naming the image and descriptor line of an image that cannot be read
 * or does not match the descriptor (see readEmva1288Image()); what emva1288Results() of pairs throws,
 * with the descriptor named. */
CV_EXPORTS_W Emva1288Results emva1288Results(const Emva1288Series& series);

/** @brief As emva1288Results(), calling `progress(done, total)` after each exposure is read (an app's
 * progress bar); `progress` may be empty. */
CV_RAWGMENT_EXPORTS Emva1288Results emva1288Results(const Emva1288Series& series,
                                                    const std::function<void(int, int)>& progress);

/** @brief Settings of calibrateEmva1288(). */
struct CV_EXPORTS_W_SIMPLE Emva1288CalibrationParams
{
    //! Every field at its default, as initialised here.
    CV_WRAP Emva1288CalibrationParams() : maxSignalFraction(0.3), minGainRatio(1.12) {}
    /** The bright steps fitted: those whose signal (mean above dark) is at most this fraction of the
     * signal at saturation, in (0, 1]. 0.3 by default, not the standard's 0.7: the model is for dark scenes,
     * and a real photon transfer curve bends down at high signal (set 001: K 0.2873 up to 30%, 0.2801 up
     * to 70%; docs/emva1288.md shows which one predicts the sensor's darker steps). */
    CV_PROP_RW double maxSignalFraction;
    //! Gains closer than this ratio count as one when separating sigma_d^2 and sigma_r^2 (1.12 is 1 dB).
    CV_PROP_RW double minGainRatio;
};

/** @brief The project's noise model from EMVA 1288 measurements of one or more gains.
 *
 * Per gain, the line \f$\sigma_y^2 = a\,(\mu_y - \mu_{y.dark}) + b\f$ is fitted by weighted least squares
 * to the bright pairs up to `maxSignalFraction` of saturation and the dark pairs of their exposure times
 * (at signal 0), each point weighted by its measured inverse squared standard error
 * (Emva1288Pair::varianceStdError). Every pixel of every pair counts; nothing is selected by its own
 * variance (at two frames per step such a selection biased fitNoiseLine() before its fix: see
 * docs/emva1288.md). The line's covariance is the fit's, scaled by its reduced chi-square when that
 * exceeds 1 (a curve that bends, correlated pixels), so the stated errors cover what the points show.
 * Across gains, Eq. 5: \f$a_g = g\alpha\f$ and \f$b_g = g^2\sigma_d^2 + \sigma_r^2\f$, by weighted least
 * squares with both variances kept >= 0; with one gain (or gains closer than minGainRatio) the model
 * holds the read noise as sigma_r^2 at that gain, sigma_d^2 0, and `separable` is false.
 * @param measurements emva1288Results() of each gain's series
 * @param gains the linear gain of each (> 0; 1 for the camera's base gain)
 * @param params the fit range and the separability ratio
 * @return the report: model, per-gain lines (their range in CalibrationReport::notes), standard errors
 * @throws cv::Exception StsBadArg for no measurements, a gain count that differs, a gain that is not
 * finite and > 0, params out of range, or a gain with fewer than two bright steps in range. */
CV_EXPORTS_W CalibrationReport
calibrateEmva1288(const std::vector<Emva1288Results>& measurements, const std::vector<double>& gains,
                  const Emva1288CalibrationParams& params = Emva1288CalibrationParams());

/** @brief The line of a calibrateEmva1288() report at one of its gains (its per-gain lines are sorted by
 * gain, not in the order of the measurements).
 * @throws cv::Exception when the report has no line at exactly that gain. */
CV_EXPORTS_W const NoiseLineFit& emva1288LineAtGain(const CalibrationReport& report, double gain);

/** @brief The verdict of a calibration from EMVA 1288 series: what many two-frame steps can show, each a
 * measured figure against a stated threshold (docs/calibrate_your_camera.md, "EMVA 1288 data"), per gain:
 * bright steps in the fit (at least 3), effective degrees of freedom (each fitted step's variance to 2%),
 * residuals (every fitted step within 3% of the line) and the standard's linearity error (within +-3%).
 * @param results the measurements given to calibrateEmva1288()
 * @param gains their gains, as given to it
 * @param report its report
 * @param params its settings
 * @throws cv::Exception when the three lists differ in length or a gain has no line in the report. */
CV_RAWGMENT_EXPORTS CalibrationVerdict judgeEmva1288(
    const std::vector<Emva1288Results>& results, const std::vector<double>& gains,
    const CalibrationReport& report, const Emva1288CalibrationParams& params = Emva1288CalibrationParams());

/** @brief The paper's validation on a real sensor's steps: a brighter step of the series taken to a darker
 * one with colorJitter(), against the darker step's real frames.
 *
 * Steps of one series are the same sensor at the same gain with more and less light: exactly the paper's
 * "bright burst converted to a darker exposure against a real darker burst". Each frame of the bright pair
 * is darkened by the photon ratio of the descriptor (its own seed), as float32 so that no second rounding
 * adds its 1/12 DN^2, and the augmented pair's temporal variance is compared with the real pair's. */
struct CV_EXPORTS_W_SIMPLE Emva1288Darkening
{
    //! Every field at its default, as initialised here.
    CV_WRAP Emva1288Darkening()
        : brightPoint(-1), darkPoint(-1), photonRatio(0), alignment(NoiseAlignment::ACCOUNT_PRIOR),
          augmentedVariance(0), augmentedStdError(0), realVariance(0), realStdError(0), ratio(0),
          ratioStdError(0), pairScatter(1)
    {
    }
    CV_PROP_RW int brightPoint;          //!< the bright step: an index into Emva1288Results' temporal points
    CV_PROP_RW int darkPoint;            //!< the darker step it is taken to
    CV_PROP_RW double photonRatio;       //!< photons of the darker step over the bright one's
    CV_PROP_RW NoiseAlignment alignment; //!< how the augmentation treated the bright frames' noise
    CV_PROP_RW double augmentedVariance; //!< sigma_y^2 of the augmented pair (DN^2)
    CV_PROP_RW double augmentedStdError; //!< its standard error (see Emva1288Pair)
    CV_PROP_RW double realVariance;      //!< sigma_y^2 of the real darker pair (DN^2)
    CV_PROP_RW double realStdError;      //!< its standard error
    CV_PROP_RW double ratio;             //!< augmentedVariance / realVariance
    /** The ratio's standard error: both pairs' errors, each times sqrt(pairScatter). A pair's variance
     * varies from pair to pair by more than its pixels imply on real sensors (frame-level noise, drift); the
     * series shows by how much in its dark pairs, and the comparison takes it. */
    CV_PROP_RW double ratioStdError;
    /** The reduced chi-square of the series' dark-pair variances about their weighted mean, at least 1
     * (set 001: 8.8; a simulated sensor: about 1). A dark current that grows with exposure counts too,
     * which only widens the error. */
    CV_PROP_RW double pairScatter;
    //! Edges of the histograms below: 61 bins of (A - B) / sqrt(2) over about +-6 real standard deviations,
    //! each a whole number of the integer difference's steps wide and centred on them
    CV_PROP_RW std::vector<double> histogramEdges;
    CV_PROP_RW std::vector<double> augmentedHistogram; //!< fraction of the augmented pair's pixels per bin
    CV_PROP_RW std::vector<double> realHistogram;      //!< and of the real pair's
};

/** @brief Step pairs for emva1288Darkening(): up to `count` bright points inside the model's range (10% to
 * 30% of the saturation signal), each taken to the point whose signal is nearest (in ratio) a quarter of its
 * own and at most half of it (darker scenes are what augmentation makes). Returned as (bright, dark) point
 * indices.
 * @throws cv::Exception when no such pair exists (too few steps below 30% of saturation). */
CV_EXPORTS_W std::vector<Point> emva1288DarkeningSteps(const Emva1288Results& results, int count = 5);

/** @brief Takes bright steps of a series to darker ones with NONE, IGNORE_PRIOR and ACCOUNT_PRIOR (three
 * entries per step pair, in that order) and compares each with the real darker pair.
 * @param series the series (its images are read again, one step at a time)
 * @param results its emva1288Results()
 * @param model the noise model at the series' gain (calibrateEmva1288()'s, at gain 1)
 * @param steps (bright, dark) point indices, as emva1288DarkeningSteps() gives them
 * @param seed the noise seed: frame f of step pair k uses deriveSeed(seed, SEED_VALIDATION_CONVERSION, 2k +
 * f)
 * @throws cv::Exception for an index outside the points, a dark point not darker than its bright one, or a
 * point whose images the series does not list. */
CV_EXPORTS_W std::vector<Emva1288Darkening> emva1288Darkening(const Emva1288Series& series,
                                                              const Emva1288Results& results,
                                                              const NoiseModel& model,
                                                              const std::vector<Point>& steps, uint64 seed);

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_EMVA1288_HPP
