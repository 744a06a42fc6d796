// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The calibration's samples: burst statistics of a burst, and the (mean, variance) samples of its patches,
// dark frames or static scene (src/burst_statistics.cpp, src/calibration_sampling.cpp).
#ifndef OPENCV_RAWGMENT_CALIBRATION_SAMPLES_HPP
#define OPENCV_RAWGMENT_CALIBRATION_SAMPLES_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/bayer.hpp>
#include <opencv2/rawgment/export.hpp>

#include <memory>
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
     *         merge's delta: at mean 60000 and variance 1 the variance errs by 0.00247 relative
     *         (rawgment_tradeoffs measures it, docs/performance.md), at ordinary means far less. */
    explicit BurstStatistics(const RawFormat& format, int groupFrames = 8, int stateDepth = CV_64F);
    /** @brief A burst with no format yet (8 frames per group, float64 state): reset(format) gives it one,
     * and add() before that is refused, naming create(). It never throws, so it is the constructor cv2
     * wraps: OpenCV 4.6's generated type of a class with no wrapped constructor makes an object holding
     * no C++ object, whose first method call crashed the interpreter. format() is a default RawFormat
     * until reset(). */
    CV_WRAP BurstStatistics();
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

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_CALIBRATION_SAMPLES_HPP
