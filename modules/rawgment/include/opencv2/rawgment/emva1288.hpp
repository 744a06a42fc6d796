// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_EMVA1288_HPP
#define OPENCV_RAWGMENT_EMVA1288_HPP

#include <opencv2/core.hpp>
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
    CV_PROP_RW double muESat;         //!< saturation capacity (e-): the signal at saturation over K
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
    CV_PROP_RW std::vector<double> linearityDeviation; //!< (%) each point's relative deviation from it
    CV_PROP_RW double spatialMeanBright; //!< mean of the spatial set's bright stack (DN), NaN without one
    CV_PROP_RW double spatialMeanDark;   //!< mean of its dark stack (DN)
    CV_PROP_RW double
        spatialVarianceBright; //!< s_y^2 (DN^2): the spatial variance with its temporal part removed
    CV_PROP_RW double spatialVarianceDark; //!< s_y.dark^2 (DN^2)
};

/** @brief The standard's figures of a series (see Emva1288Results for the definitions).
 *
 * Images are read one exposure at a time (the spatial stacks one frame at a time, accumulated), never
 * the whole series at once.
 * @param series a series from readEmva1288()
 * @return the figures and the temporal points they come from
 * @throws cv::Exception StsError naming the image and descriptor line of an image that cannot be read
 * or does not match the descriptor (see readEmva1288Image()); StsBadArg for a series with fewer than
 * three bright temporal points, one whose signal does not rise over two steps below 70% of saturation, whose
 * variance does not rise with it (K not > 0) or whose signal does not rise with the photon counts given.
 */
CV_EXPORTS_W Emva1288Results emva1288Results(const Emva1288Series& series);

/** @brief As emva1288Results(), calling `progress(done, total)` after each exposure is read (an app's
 * progress bar); `progress` may be empty. */
CV_RAWGMENT_EXPORTS Emva1288Results emva1288Results(const Emva1288Series& series,
                                                    const std::function<void(int, int)>& progress);

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_EMVA1288_HPP
