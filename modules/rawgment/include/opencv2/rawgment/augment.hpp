// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_AUGMENT_HPP
#define OPENCV_RAWGMENT_AUGMENT_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/bayer.hpp>
#include <opencv2/rawgment/export.hpp>
#include <opencv2/rawgment/noise_model.hpp>

#include <string>
#include <vector>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_augment
//! @{

/** @brief How a noise step treats the noise that the input already has (the paper's ablations). */
enum class NoiseAlignment
{
    NONE = 0,         //!< no noise is added: the signal is only scaled or blurred (plain augmentation)
    IGNORE_PRIOR = 1, //!< the input is treated as clean: the full variance of the target is added
    ACCOUNT_PRIOR = 2 //!< the paper's method: only the difference between target and prior noise is added
};

/** @brief How the shot part of the added noise is drawn. */
enum class ShotNoiseSampling
{
    /** The paper's: the whole added variance as one Gaussian. Fast (vectorised); at a few electrons per
     * pixel the true shot noise is skewed and lives on a lattice of one electron, which a Gaussian is not. */
    GAUSSIAN = 0,
    /** The shot part as an electron count: \f$ q(K - m) \f$ with \f$ K \sim \text{Poisson}(m) \f$, q the
     * output's DN per electron (\f$ g\alpha \f$ at the output gain) and \f$ m = v_{shot} / q^2 \f$, so
     * the variance is the same as with GAUSSIAN and only the shape changes; the read-noise part stays
     * Gaussian. Exact for the darkening that matters (p_u << 1, where the scaled prior noise is
     * negligible). The counts are drawn exactly (inversion below 25 electrons, Ahrens and Dieter's PD
     * above) in vector lanes, the same bits on every CPU path: about 6x the time of GAUSSIAN for colour
     * jitter (rawgment_tradeoffs; docs/performance.md). */
    POISSON = 1
};

/** @brief Which estimate of the prior mean \f$ \mu_x \f$ the added variance uses. */
enum class PriorMeanEstimate
{
    /** The paper's: the noisy value itself, \f$ \mu_x = \max(x, 0) \f$. Unbiased except near black,
     * where the clip at 0 biases it up, and as noisy as the pixel. */
    PIXEL_VALUE = 0,
    /** The mean of the 3x3 neighbourhood on the pixel's own CFA plane (same colour, two mosaic pixels
     * apart), clipped at 0 after averaging: nine times less noisy and less biased at black, but it
     * smooths the variance across edges. Costs two float32 frames of temporary memory. Used by colour jitter;
     * blur and scaling already weight many pixels' values in their sums. */
    LOCAL_MEAN = 1
};

/** @brief How motion blur computes its shot-noise term \f$ \sum_k w_k(1-w_k)\max(x_k, 0) \f$. */
enum class BlurNoiseSum
{
    EXACT = 0, //!< Eq. 15 as written: a second weighted sum per pixel
    /** \f$ (1 - \sum_k w_k^2) \max(\bar{x}, 0) \f$ with \f$ \bar{x} \f$ the blurred value: exact on flat
     * areas, wrong across edges (where the taps' means differ); saves the second sum. */
    FROM_BLURRED_MEAN = 1
};

/** @brief Every choice a noise step makes about accuracy and speed. Defaults are the paper's method
 * (with the exact blur sum); the trade-off report (`rawgment_tradeoffs`) measures each option.
 *
 * Implicitly constructible from a NoiseAlignment, so `colorJitter(..., NoiseAlignment::NONE, ...)`
 * keeps the other defaults. */
struct CV_EXPORTS_W_SIMPLE NoiseOptions
{
    CV_PROP_RW NoiseAlignment alignment;       //!< how the prior noise is treated
    CV_PROP_RW ShotNoiseSampling shotSampling; //!< shape of the added shot noise
    CV_PROP_RW PriorMeanEstimate priorMean;    //!< the estimate of mu_x
    CV_PROP_RW BlurNoiseSum blurNoiseSum;      //!< motion blur's shot-noise term
    /** A dark-frame bank's file (DarkFrameBank::save()), or "" for none: its real dark frames then stand in
     * for the model's read terms (read noise, row noise, dark shading, heavy tails), and the model keeps the
     * shot noise. ACCOUNT_PRIOR adds to each pixel's row part and pixel part only what the input's own read
     * noise, scaled by the step, lacks of the target's; IGNORE_PRIOR adds whole dark frames. Given by path so
     * that it reaches other processes as a path: the file is read once per process while it is unchanged.
     * docs/dark_frame_bank.md gives the equations and their tests. */
    CV_PROP_RW String darkBank;
    /** Whether the input comes from the bank's own sensor at the same exposure and temperature, at its
     * RawFormat::sensorOrigin: then ACCOUNT_PRIOR takes the input's fixed pattern, scaled by the step, out
     * and puts the target's in. Otherwise (the default) the input keeps its pattern and only what the
     * target's pattern needs in variance is added. */
    CV_PROP_RW bool darkBankTied;

    //! Every field at its default, as initialised here.
    CV_WRAP NoiseOptions()
        : alignment(NoiseAlignment::ACCOUNT_PRIOR), shotSampling(ShotNoiseSampling::GAUSSIAN),
          priorMean(PriorMeanEstimate::PIXEL_VALUE), blurNoiseSum(BlurNoiseSum::EXACT), darkBankTied(false)
    {
    }
    //! The given alignment with the other defaults; implicit on purpose (see above).
    CV_WRAP NoiseOptions(NoiseAlignment a) : NoiseOptions() { alignment = a; }
    CV_WRAP void validate() const; //!< throws naming an unknown enum value
    //! Writes the options as fields of the current map (`alignment`, `shot_sampling`, ..., `dark_bank` and
    //! `dark_bank_tied` when a bank is set).
    void writeFields(FileStorage& fs) const;
    //! Reads the fields written by writeFields(); missing ones keep their defaults.
    static NoiseOptions readFields(const FileNode& map);
};

/** @brief What augmentation steps did, for logs and for the user's trust. */
struct CV_EXPORTS_W_SIMPLE AugmentReport
{
    //! Nothing counted, no step.
    CV_WRAP AugmentReport() : brighteningPixels(0), saturatedPixels(0), readBrighteningPixels(0) {}
    CV_PROP int64
        brighteningPixels; //!< pixels whose noise variance to add was negative (brightening), clipped to 0
    CV_PROP int64 saturatedPixels; //!< input pixels at or above the white level (their signal is unknown)
    /** Pixels whose read noise the input already held more of than the target has (a dark-frame bank's row or
     * pixel part with k^2 v_s > v_t): they get none of that part, as brightening pixels get no shot noise. */
    CV_PROP int64 readBrighteningPixels;
    CV_PROP std::vector<std::string>
        steps; //!< the steps that ran, in order; skipped identity steps are absent
    /** The wall time of each step of `steps`, in seconds (its checks, noise and output; for a profile of
     * where a sample's time goes, as python/bench/pipeline.py reports it). Never part of a result. */
    CV_PROP std::vector<double> stepSeconds;
};

/** @brief A change of contrast, brightness and hue, simulated as a change of photons and gain (Eq. 13).
 *
 * The new mean of a pixel with black-subtracted value x is \f$ p_c x + p_b \f$, with the contrast
 * \f$ p_c \f$ of the pixel's CFA site (hue: different per site). The product of photon and gain ratios
 * is then \f$ p_u p_g = (p_c x + p_b) / x \f$. The gain ratio \f$ p_g \f$ is given (it is the target
 * capture's gain over the input's); the photon ratio follows as \f$ p_u = (p_c x + p_b) / (x p_g) \f$.
 * Why the gain is drawn and the photons follow: the gain is a property of the whole frame (one analog
 * gain per capture) while the photon ratio may vary per pixel (light, reflectance), so only this split
 * describes a capture a camera could make. Exposure change (Eq. 11) is \f$ p_c = p_u p_g, p_b = 0 \f$:
 * see exposureChange().
 */
struct CV_EXPORTS_W_SIMPLE ColorJitter
{
    //! The identity.
    CV_WRAP ColorJitter() : contrast(Vec4d::all(1)), brightness(0), gainRatio(1), exposureTime(0) {}
    CV_PROP_RW Vec4d contrast;    //!< p_c per CFA site (index = cfaSite()), > 0; one value for CFA_MONO
    CV_PROP_RW double brightness; //!< p_b in DN
    CV_PROP_RW double gainRatio;  //!< p_g: target gain / input gain, > 0
    /** The target capture's exposure time in seconds, >= 0; 0: the input's (RawFormat::exposureTime). The
     * darkening is the scene's light whatever it is (p_c and p_b say how much); the exposure only chooses a
     * dark-frame bank's frames for the target, since dark current grows with it, and is the output's
     * RawFormat::exposureTime. Without a bank the model's noise does not depend on it. */
    CV_PROP_RW double exposureTime;

    //! A pure exposure change: photons x photonRatio, gain x gainRatio (paper Eq. 11).
    CV_WRAP static ColorJitter exposureChange(double photonRatio, double gainRatio);
    //! True when the step changes nothing whatever the input (contrast 1, brightness 0, gain ratio 1, no
    //! exposure time stated); a jitter that states the input's own exposure is skipped as well.
    CV_WRAP bool isIdentity() const;
};

/** @brief Noise-accounted contrast, brightness and hue (paper Eq. 11 and 13).
 *
 * For each pixel with prior value \f$ x \f$ (DN above black, \f$ \mu_x \approx \max(x, 0) \f$), input gain g:
 * \f[ x_{new} = p_c x + p_b + \mathcal{N}(0, v),\quad
 *     v = p_u(1-p_u)p_g^2 g\alpha\mu_x + (1-p_u^2)p_g^2 g^2\sigma_d^2 + (1-p_u^2p_g^2)\sigma_r^2 \f]
 * (ACCOUNT_PRIOR). IGNORE_PRIOR adds the model variance of the new mean at the new gain; NONE adds
 * nothing. A negative v means the target would be *less* noisy than the input (brightening): it cannot
 * be reached by adding noise, so v is clipped to 0 and the pixel is counted in
 * AugmentReport::brighteningPixels. To keep \f$ p_u \f$ finite at \f$ x \to 0 \f$, it is computed with
 * x floored at 1 DN; a negative \f$ p_u \f$ (brightness pushing the pixel below black) is clamped to 0.
 * The output is at gain \f$ p_g g \f$: `dstFormat.gain` says so, and later steps must use it.
 *
 * The output keeps the input's type: CV_16UC1 is rounded and clipped to [0, white]; CV_32FC1 is clipped.
 * Note that rounding adds its 1/12 DN^2 once more on top of the input's.
 * @param src Bayer mosaic with black level, CV_16UC1 or CV_32FC1
 * @param format its format (its gain is g)
 * @param model the calibrated noise model
 * @param jitter the change (a step at identity is skipped: dst shares src's data, no noise is drawn)
 * @param noise how the prior noise is treated (alignment) and how the noise is drawn
 * @param seed the noise seed: the same seed gives the same output on any number of threads
 * @param dst output mosaic; a Mat of src's size and type that shares no memory with src is written in
 * place (no new allocation), anything else is replaced by a new Mat
 * @param dstFormat output format (the new gain)
 * @param report optional: counts of brightening and saturated pixels, steps run
 * @param saturatedMask optional CV_8UC1 output, 255 where the input was at or above white
 */
CV_RAWGMENT_EXPORTS void colorJitter(InputArray src, const RawFormat& format, const NoiseModel& model,
                                     const ColorJitter& jitter, const NoiseOptions& noise, uint64 seed,
                                     OutputArray dst, RawFormat& dstFormat, AugmentReport* report = nullptr,
                                     OutputArray saturatedMask = noArray());

/** @overload
 * For the binding generator: the report is always returned. */
CV_EXPORTS_W void colorJitter(InputArray src, const RawFormat& format, const NoiseModel& model,
                              const ColorJitter& jitter, const NoiseOptions& noise, uint64 seed,
                              OutputArray dst, CV_OUT RawFormat& dstFormat, CV_OUT AugmentReport& report,
                              OutputArray saturatedMask = noArray());

//! The longest motion linearMotionKernel() and RandomScenePolicy take, in mosaic pixels: a kernel of
//! up to 513 x 513 plane pixels (the paper's longest is 13).
constexpr double MAX_MOTION_LENGTH = 1024;

/** @brief A linear motion-blur kernel on the grid motionBlur() works on: the CFA-plane grid (half the
 * mosaic's resolution) of a Bayer pattern, the pixel grid of a CFA_MONO frame.
 * @param length length of the motion in full-resolution mosaic pixels, in [0, MAX_MOTION_LENGTH]; up
 *        to one grid pixel (2 mosaic pixels on the plane grid) the kernel is the identity 1x1
 * @param angleDegrees direction of the motion, counter-clockwise from the x axis
 * @param pattern the pattern of the mosaic it will blur (its grid)
 * @return CV_32FC1 kernel, odd size, sum 1
 */
CV_EXPORTS_W Mat linearMotionKernel(double length, double angleDegrees, CfaPattern pattern = CFA_RGGB);

/** @brief The largest side of a blur kernel, in plane pixels: that of a motion of MAX_MOTION_LENGTH. A blur's
 * cost grows with the kernel's area (a hand-made 2001x2001 kernel took over 30 s on a 64x96 mosaic). */
constexpr int MAX_MOTION_KERNEL_SIDE = static_cast<int>(MAX_MOTION_LENGTH / 2) + 1;

/** @brief Noise-accounted blur (paper Eq. 15) on each CFA plane (on the whole frame for CFA_MONO).
 *
 * \f[ x_{new} = \sum_k w_k x_k + \mathcal{N}\Big(0,\; g\alpha\sum_k (1-w_k)w_k\max(x_k,0)
 *     + \big(1 - \sum_k w_k^2\big)(g^2\sigma_d^2 + \sigma_r^2)\Big) \f]
 * with the exact per-pixel sum (a second filtering with the kernel \f$ w(1-w) \f$), for ACCOUNT_PRIOR.
 * Real motion blur averages photons but not the read noise: a plain blur (NONE) is too clean.
 * IGNORE_PRIOR adds the model variance of the blurred mean. Borders replicate the plane's edge.
 * @param src CV_16UC1 or CV_32FC1 mosaic with black level, even sides
 * @param format its format (the gain stays)
 * @param model the noise model
 * @param kernel non-negative CV_32FC1/CV_64FC1 kernel on the plane grid (the pixel grid for CFA_MONO; see
 *        linearMotionKernel()), normalised here, at most MAX_MOTION_KERNEL_SIDE on a side (2
 *        MAX_MOTION_KERNEL_SIDE - 1 on the pixel grid: the same extent); a 1x1 kernel is the identity and
 *        the step is skipped
 * @param noise how the prior noise is treated (alignment), how the noise is drawn
 * @param seed noise seed
 * @param dst output, same type; reused as colorJitter()'s dst is
 * @param report optional
 */
CV_RAWGMENT_EXPORTS void motionBlur(InputArray src, const RawFormat& format, const NoiseModel& model,
                                    InputArray kernel, const NoiseOptions& noise, uint64 seed,
                                    OutputArray dst, AugmentReport* report = nullptr);

/** @overload
 * For the binding generator: the report is always returned. */
CV_EXPORTS_W void motionBlur(InputArray src, const RawFormat& format, const NoiseModel& model,
                             InputArray kernel, const NoiseOptions& noise, uint64 seed, OutputArray dst,
                             CV_OUT AugmentReport& report);

/** @brief Noise-accounted scaling about the mosaic centre, each CFA plane resampled bilinearly (the whole
 * frame for CFA_MONO).
 *
 * Output pixel of site s at mosaic position X takes its value from \f$ C + (X - C)/\text{scale} \f$ in
 * the same site's plane (C the centre), so the CFA phase is kept and every site is sampled at its own
 * position. Interpolation weights are a kernel that changes from pixel to pixel: like a blur, they
 * average the prior noise away, \f$ \sum_k w_k^2 \f$ of it, which Eq. 15 with those weights puts back:
 * \f[ x_{new} = \sum_k w_k x_k + \mathcal{N}\Big(0,\; g\alpha\sum_k (1-w_k)w_k\max(x_k,0)
 *     + \big(1 - \sum_k w_k^2\big)(g^2\sigma_d^2 + \sigma_r^2)\Big) \f]
 * per pixel (ACCOUNT_PRIOR), so that the output has the model's variance at its new mean everywhere.
 * NONE is plain bilinear resampling (too clean between pixels), IGNORE_PRIOR adds the full model
 * variance. Outside the frame the plane's edge is replicated. The output has the input's size.
 * @param src CV_16UC1 or CV_32FC1 mosaic with black level, even sides
 * @param format its format (the gain stays)
 * @param model the noise model
 * @param scale magnification, > 0 (1.03 enlarges by 3%); exactly 1 is the identity and the step is
 *        skipped (dst shares src's data)
 * @param noise how the prior noise is treated (alignment), how the noise is drawn
 * @param seed noise seed
 * @param dst output, same type and size; reused as colorJitter()'s dst is
 * @param report optional
 */
CV_RAWGMENT_EXPORTS void scaleMosaic(InputArray src, const RawFormat& format, const NoiseModel& model,
                                     double scale, const NoiseOptions& noise, uint64 seed, OutputArray dst,
                                     AugmentReport* report = nullptr);

/** @overload
 * For the binding generator: the report is always returned. */
CV_EXPORTS_W void scaleMosaic(InputArray src, const RawFormat& format, const NoiseModel& model, double scale,
                              const NoiseOptions& noise, uint64 seed, OutputArray dst,
                              CV_OUT AugmentReport& report);

/** @brief A bounding box (mosaic pixels) after scaleMosaic(): its edges scale about the frame centre,
 * it grows to whole pixels and is clipped to the frame; an empty result means it left the frame. */
CV_EXPORTS_W Rect scaleBox(const Rect& box, Size size, double scale);

/** @brief The capture to simulate: what changes from the input, applied by applyScene().
 *
 * Steps run in the order of the paper's training: geometry (shift, then scale), colour jitter, blur. Only the
 * effects a scene asks for are simulated: a step at identity costs nothing, and the identity scene returns
 * the input itself (dst shares its data), bit for bit.
 */
struct CV_EXPORTS_W_SIMPLE Scene
{
    //! The identity scene.
    CV_WRAP Scene() : shift(Point(0, 0)), scale(1) {}
    CV_PROP_RW Point shift;  //!< translation in mosaic pixels; each component rounded to even (CFA phase;
                             //!< a CFA_MONO frame moves by any whole number)
    CV_PROP_RW double scale; //!< magnification about the centre (see scaleMosaic()); 1: none
    CV_PROP_RW ColorJitter jitter; //!< exposure, gain, contrast, brightness, hue
    CV_PROP_RW Mat motionKernel;   //!< blur on the plane grid (empty or 1x1: none)
    CV_PROP_RW NoiseOptions noise; //!< for every noise step

    CV_WRAP bool isIdentity() const; //!< true when no step would change anything
    //! Writes the scene as a map under `name` (the kernel as a matrix).
    void write(FileStorage& fs, const String& name) const;
    //! Reads a scene written by write(). @throws cv::Exception naming an invalid field.
    static Scene read(const FileNode& node);
};

/** @brief Applies a scene: shift (vacated pixels replicate the edge, CFA phase kept), scale
 * (scaleMosaic()), colour jitter, then blur at the gain the jitter produced. Bounding boxes (x, y, w, h
 * in mosaic pixels) move with the shift and the scale (scaleBox()) and are clipped to the frame; a box
 * that leaves the frame becomes empty. A model's dark shading belongs to the sensor and does not move:
 * unless the alignment is NONE, the shift swaps each moved pixel's shading for that of the pixel it lands
 * on (clipped pixels stay clipped), as scaleMosaic() and motionBlur() take it out and put it back.
 */
CV_RAWGMENT_EXPORTS void applyScene(InputArray src, const RawFormat& format, const NoiseModel& model,
                                    const Scene& scene, uint64 seed, OutputArray dst, RawFormat& dstFormat,
                                    AugmentReport* report = nullptr, std::vector<Rect>* boxes = nullptr);

/** @overload
 * For the binding generator: the report is always returned, and `boxes` are moved in place. */
CV_EXPORTS_W void applyScene(InputArray src, const RawFormat& format, const NoiseModel& model,
                             const Scene& scene, uint64 seed, OutputArray dst, CV_OUT RawFormat& dstFormat,
                             CV_OUT AugmentReport& report, CV_IN_OUT std::vector<Rect>& boxes);

/** @brief The seed of one augmented output: a function of (seed, input name, variant) only, so that
 * any order of inputs, any number of processes and the C++ and Python front ends give the same file.
 * The same seed draws the scene (RandomScenePolicy::draw()) and applies it (applyScene()): the two
 * use separate random streams.
 * @param seed the user's seed
 * @param inputName the input's file name without directory and extension (its stem)
 * @param variant the variant number, 0 for the first
 */
CV_EXPORTS_W uint64 augmentedOutputSeed(uint64 seed, const String& inputName, int variant);

/** @brief Draws random scenes with the paper's augmentation ranges (its defaults)
 * @cite yoshimura2023rawgment.
 *
 * A scene's contrast is log-uniform in [contrastMin, contrastMax] (0.01 to 1 spans two decades of
 * darkening, which a uniform draw would nearly never reach below 0.1); with probability hueProbability each
 * CFA site's contrast is further scaled by a uniform factor in [hueMin, hueMax]; the brightness is a
 * uniform fraction in [brightnessMin, brightnessMax] of the input's minimum above black; the target gain
 * is uniform in dB; with probability blurProbability a linear motion kernel of uniform length in
 * [0, blurLengthMax] and uniform angle; with probability geometryProbability a shift of up to maxShift
 * of each side and a scale within 1 +- maxScale. File keys are the snake_case names (contrast_min, ...).
 * A CFA_MONO frame has no hue: its four sites keep one contrast, and its kernel lies on its pixel grid.
 */
struct CV_EXPORTS_W_SIMPLE RandomScenePolicy
{
    //! The paper's ranges.
    CV_WRAP RandomScenePolicy()
        : contrastMin(0.01), contrastMax(1.0), brightnessMin(-0.1), brightnessMax(0.1), hueProbability(0.5),
          hueMin(0.8), hueMax(1.2), gainDbMin(0), gainDbMax(12), blurProbability(0.5), blurLengthMax(13),
          geometryProbability(0.8), maxShift(0.1), maxScale(0.03)
    {
    }
    CV_PROP_RW double contrastMin;         //!< lowest contrast (photon and gain ratio), > 0
    CV_PROP_RW double contrastMax;         //!< highest contrast
    CV_PROP_RW double brightnessMin;       //!< lowest brightness, as a fraction of the input's minimum
    CV_PROP_RW double brightnessMax;       //!< highest brightness, as a fraction of the input's minimum
    CV_PROP_RW double hueProbability;      //!< probability of a per-site contrast factor (a hue shift)
    CV_PROP_RW double hueMin;              //!< lowest per-site factor, > 0
    CV_PROP_RW double hueMax;              //!< highest per-site factor
    CV_PROP_RW double gainDbMin;           //!< lowest gain change in dB
    CV_PROP_RW double gainDbMax;           //!< highest gain change in dB
    CV_PROP_RW double blurProbability;     //!< probability of a motion blur
    CV_PROP_RW double blurLengthMax;       //!< longest motion, in mosaic pixels
    CV_PROP_RW double geometryProbability; //!< probability of a shift and a scale
    CV_PROP_RW double maxShift;            //!< largest shift, as a fraction of each side, in [0, 1)
    CV_PROP_RW double maxScale;            //!< largest relative scale change, in [0, 1)
    CV_PROP_RW NoiseOptions noise;         //!< copied into every scene

    CV_WRAP void validate() const; //!< throws naming the first inconsistent range
    /** @brief A scene for `src` (its minimum sets the brightness scale), from `seed` alone. */
    CV_WRAP Scene draw(InputArray src, const RawFormat& format, uint64 seed) const;
    //! Writes the policy as a map under `name` (snake_case keys, the noise options included).
    void write(FileStorage& fs, const String& name) const;
    static RandomScenePolicy read(const FileNode& node); //!< missing fields keep their defaults
    CV_WRAP void save(const String& path) const;         //!< .yml/.yaml/.json, atomically
    //! Loads a policy saved by save() (top-level map `random_scene_policy`); errors name the file.
    CV_WRAP static RandomScenePolicy load(const String& path);
};

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_AUGMENT_HPP
