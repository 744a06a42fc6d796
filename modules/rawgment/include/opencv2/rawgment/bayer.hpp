// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_BAYER_HPP
#define OPENCV_RAWGMENT_BAYER_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/export.hpp>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_bayer
//! @{

/** @brief The colour filter array (CFA) layout of a Bayer mosaic, named by its top-left 2x2 block
 * read row by row, or CFA_MONO for a sensor without a colour filter.
 *
 * A monochrome frame is handled as a "mosaic" whose four sites all see the same light (channel CFA_W):
 * per-site quantities (black levels, contrasts) must then be equal, and resampling steps work on the
 * full pixel grid rather than on half-resolution CFA planes.
 *
 * The underlying type is fixed so that any int cast to it is a valid value that the functions can
 * reject with a clear error.
 */
// OpenCV 4.6's binding parser reads an enum's base only with no space before ':'.
// clang-format off
enum CfaPattern: int
// clang-format on
{
    CFA_RGGB = 0, //!< R G / G B
    CFA_BGGR = 1, //!< B G / G R
    CFA_GRBG = 2, //!< G R / B G
    CFA_GBRG = 3, //!< G B / R G
    CFA_MONO = 4  //!< no colour filter (a monochrome sensor): every pixel is CFA_W
};

/** @brief The four colour channels of a Bayer mosaic.
 *
 * The two greens are told apart by their row: `CFA_G1` shares its row with red, `CFA_G2` with blue
 * (often called Gr and Gb).
 */
// OpenCV 4.6's binding parser reads an enum's base only with no space before ':'.
// clang-format off
enum CfaChannel: int
// clang-format on
{
    CFA_R = 0,  //!< red
    CFA_G1 = 1, //!< green on the red rows (Gr)
    CFA_G2 = 2, //!< green on the blue rows (Gb)
    CFA_B = 3,  //!< blue
    CFA_W = 4   //!< unfiltered (panchromatic): the only channel of a CFA_MONO frame
};

/** @brief The site of a pixel inside its 2x2 CFA block: \f$ s = 2\,(row \bmod 2) + (col \bmod 2) \f$.
 *
 * Sites are the layout-independent way to index per-position quantities (black levels, planes):
 * site 0 is top-left, 1 top-right, 2 bottom-left, 3 bottom-right.
 * @param row pixel row, any integer (negative rows are taken modulo 2 as well)
 * @param col pixel column, any integer
 */
CV_EXPORTS_W int cfaSite(int row, int col);

/** @brief The colour channel at (row, col) of a mosaic with the given pattern.
 * @param pattern CFA layout of the mosaic
 * @param row pixel row, any integer
 * @param col pixel column, any integer
 */
CV_EXPORTS_W CfaChannel cfaChannelAt(CfaPattern pattern, int row, int col);

/** @brief The site (0..3, see cfaSite()) where a channel lies in the 2x2 block of a pattern; 0 for CFA_W in a
 * CFA_MONO frame (every site holds it).
 * @throws cv::Exception (StsBadArg) for a channel the pattern does not have (CFA_R of CFA_MONO, CFA_W of a
 * Bayer pattern). */
CV_EXPORTS_W int cfaSiteOfChannel(CfaPattern pattern, CfaChannel channel);

/** @brief The pattern of a crop of a mosaic whose top-left corner is at (rowOffset, colOffset).
 *
 * An odd offset in a direction swaps the phase in that direction (RGGB cropped at (0, 1) is GRBG).
 * Offsets may be negative (padding).
 */
CV_EXPORTS_W CfaPattern cfaPatternOfCrop(CfaPattern pattern, int rowOffset, int colOffset);

/** @brief The pattern's name ("RGGB", ..., "MONO"). Throws on a value outside the enumeration. */
CV_EXPORTS_W String cfaPatternName(CfaPattern pattern);

/** @brief The pattern with the given name, case-insensitive ("rggb", "BGGR", ..., "mono").
 * @throws cv::Exception (StsBadArg) naming the valid names when the name is unknown.
 */
CV_EXPORTS_W CfaPattern cfaPatternFromName(const String& name);

/** @brief How a Bayer mosaic (or a monochrome frame, CFA_MONO) encodes light: CFA layout, black and white
 * levels, and the analog gain at which it was captured.
 *
 * All values are in DN (digital numbers) of the stored mosaic. The black level is given per 2x2 site
 * (see cfaSite()) because many sensors have a different offset per colour; a pixel's signal is
 * \f$ x = raw - black(site) \f$. The gain is the *linear* analog gain (0 dB = 1, see dbToLinearGain()),
 * relative to the gain at which the noise model was calibrated; augmentation steps update it.
 */
struct CV_EXPORTS_W_SIMPLE RawFormat
{
    //! RGGB, no black level, white 65535, gain 1, exposure time not stated.
    CV_WRAP RawFormat()
        : pattern(CFA_RGGB), blackLevel(Vec4d::all(0)), whiteLevel(65535), gain(1.0),
          sensorOrigin(Point(0, 0)), exposureTime(0)
    {
    }
    CV_PROP_RW CfaPattern pattern; //!< CFA layout of the top-left 2x2 block
    CV_PROP_RW Vec4d blackLevel;   //!< black level per site, in DN (index = cfaSite())
    CV_PROP_RW double whiteLevel;  //!< saturation level in DN, on the stored (black-included) scale
    CV_PROP_RW double gain;        //!< linear analog gain of the capture (> 0)
    /** Where the mosaic's top-left pixel lies on the sensor, (x, y) >= 0: (0, 0) for a whole frame, the
     * crop's offset for a crop (cropped() adds it). Per-pixel maps of the sensor (a NoiseModel's dark
     * shading) are read there, so a crop gets its own pixels' pattern. */
    CV_PROP_RW Point sensorOrigin;
    /** The capture's exposure time in seconds (>= 0; 0: not stated). Noise itself does not depend on it in
     * the model, but dark current does: a dark-frame bank (NoiseOptions::darkBank) draws from its frames of
     * this exposure. readRaw() takes it from the file, readMosaic() from the sidecar. */
    CV_PROP_RW double exposureTime;

    /** @brief Throws cv::Exception (StsBadArg) naming the field when the format is not usable: pattern
     * outside the enumeration, non-finite or negative black level, white level not above every black
     * level, gain not finite and positive, a negative sensorOrigin, an exposure time not finite and >= 0, or
     * a CFA_MONO format whose four black levels differ (a sensor without a colour filter has no 2x2 structure
     * to give them).
     */
    CV_WRAP void validate() const;

    /** @brief True for a sensor without a colour filter (CFA_MONO). */
    CV_WRAP bool isMonochrome() const { return pattern == CFA_MONO; }

    /** @brief Black level of the pixel at (row, col). */
    CV_WRAP double blackAt(int row, int col) const { return blackLevel[cfaSite(row, col)]; }

    /** @brief The format of a crop whose top-left corner is at (rowOffset, colOffset): the pattern and
     * the per-site black levels follow the phase, sensorOrigin moves by the offset; levels, gain and exposure
     * time are unchanged.
     */
    CV_WRAP RawFormat cropped(int rowOffset, int colOffset) const;

    /** @brief Writes the format as a map under `name` (fields pattern, black_level, white_level, gain,
     * sensor_origin [x, y] when it is not (0, 0), and exposure_time when it is stated). */
    void write(FileStorage& fs, const String& name) const;

    /** @brief Reads a format written by write(), validating it.
     * @throws cv::Exception naming the missing or invalid field.
     */
    static RawFormat read(const FileNode& node);
};

/** @brief Splits a Bayer mosaic into its four CFA planes, one per site, each of half the size.
 *
 * `planes[s](i, j) = mosaic(2i + s / 2, 2j + s % 2)`. Use cfaSiteOfChannel() to find a colour's plane.
 * @param mosaic single-channel mosaic of any depth, with an even number of rows and columns (a mosaic
 *        with odd sides has planes of different sizes; crop it first)
 * @param planes output: a vector of four Mats of the mosaic's type, each (rows/2) x (cols/2)
 * @throws cv::Exception when the mosaic is empty, has more than one channel, or an odd side.
 */
CV_EXPORTS_W void splitCfaPlanes(InputArray mosaic, OutputArrayOfArrays planes);

/** @brief Interleaves four CFA planes back into a mosaic: the exact inverse of splitCfaPlanes().
 * @param planes four single-channel Mats of one type and one size
 * @param mosaic output of twice the planes' size and their type
 */
CV_EXPORTS_W void mergeCfaPlanes(InputArrayOfArrays planes, OutputArray mosaic);

/** @brief Subtracts the per-site black level and optionally normalises to [0, 1].
 *
 * \f[ x = raw - black(site) \qquad\text{or, with normalize,}\qquad
 *     x = \frac{raw - black(site)}{white - black(site)} \f]
 * Values below black stay negative: they carry the read noise that calibration and augmentation need.
 * @param src mosaic, CV_16UC1 or CV_32FC1 (any size; the site follows the pixel's position)
 * @param format the mosaic's format (validated)
 * @param dst output, CV_32FC1, same size
 * @param normalize divide by the per-site range white - black
 */
CV_EXPORTS_W void subtractBlackLevel(InputArray src, const RawFormat& format, OutputArray dst,
                                     bool normalize = false);

/** @brief subtractBlackLevel() and splitCfaPlanes() in one pass, in the R, G1, G2, B order whatever the
 * pattern: the input layout of most RAW networks, written straight into the memory it will be used from.
 * A CFA_MONO frame is packed in site order (a 2x2 space-to-depth).
 *
 * Plane k of the output is rows [k h, (k + 1) h) with h = rows / 2: the planes of channel CFA_R, CFA_G1,
 * CFA_G2, CFA_B (cfaSiteOfChannel()), each black-subtracted per site and, with `normalize`, divided by
 * white - black; the same values as splitCfaPlanes() of subtractBlackLevel(). When `planes` is already a
 * CV_32FC1 Mat of that size (for example a tensor's memory wrapped in a Mat), it is written in place.
 * @param mosaic CV_16UC1 or CV_32FC1, even sides
 * @param format its format (validated)
 * @param planes output: CV_32FC1, (2 rows) x (cols / 2), the four planes stacked
 * @param normalize divide by the per-site range
 */
CV_EXPORTS_W void packCfaPlanes(InputArray mosaic, const RawFormat& format, OutputArray planes,
                                bool normalize = true);

/** @brief The inverse of subtractBlackLevel(): adds the black level back (after scaling by the per-site
 * range if `normalized`), rounds and clips to [0, white] for integer output.
 * @param src CV_32FC1 signal
 * @param format the target format (validated)
 * @param dst output of depth `ddepth`
 * @param ddepth CV_16U (rounded to nearest, clipped to [0, white level]) or CV_32F (clipped to
 *        [0, white level], not rounded)
 * @param normalized src is on the [0, 1] scale of subtractBlackLevel(..., true)
 */
CV_EXPORTS_W void addBlackLevel(InputArray src, const RawFormat& format, OutputArray dst, int ddepth = CV_16U,
                                bool normalized = false);

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_BAYER_HPP
