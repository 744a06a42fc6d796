// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_RAW_IO_HPP
#define OPENCV_RAWGMENT_RAW_IO_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/bayer.hpp>
#include <opencv2/rawgment/export.hpp>
#include <opencv2/rawgment/files.hpp>
#include <opencv2/rawgment/noise_model.hpp>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_raw_io
//! @{

/** @brief A colour tag of a DNG as a file stores it, kept verbatim when a DNG is written again.
 *
 * The colour tags (ColorMatrix1/2 50721/50722, CameraCalibration1/2 50723/50724, ReductionMatrix1/2
 * 50725/50726, AnalogBalance 50727, AsShotNeutral 50728, AsShotWhiteXY 50729, CalibrationIlluminant1/2
 * 50778/50779, ForwardMatrix1/2 50964/50965) together define the camera's colour and white point for a
 * reader that follows the DNG specification; rebuilding any of them from a normalised matrix moves the
 * white point. Values hold the TIFF values as numbers: a RATIONAL or SRATIONAL as its numerator and
 * denominator, so `values` has 2 x count entries and nothing is rounded.
 */
struct CV_EXPORTS_W_SIMPLE DngTag
{
    //! Every field at its default, as initialised here.
    CV_WRAP DngTag() : tag(0), type(0), count(0) {}
    CV_PROP_RW int tag;   //!< TIFF tag number (one of the colour tags above)
    CV_PROP_RW int type;  //!< TIFF type: 3 SHORT, 4 LONG, 5 RATIONAL, 10 SRATIONAL, 11 FLOAT or 12 DOUBLE
    CV_PROP_RW int count; //!< number of values as TIFF counts them (1 to 64)
    CV_PROP_RW std::vector<double> values; //!< the values (numerator, denominator pairs for rationals)
    //! Throws cv::Exception (prefixed by `what`) unless the tag is one of the colour tags, of a type
    //! above, and its values fit the type (integers in range, non-zero denominators).
    void validate(const char* what) const;
};

/** @brief A Bayer mosaic read from a camera RAW file, with what the file says about its capture. */
struct CV_EXPORTS_W_SIMPLE RawImage
{
    //! Every field at its default, as initialised here.
    CV_WRAP RawImage() : iso(0), exposureTime(0), whiteBalance(Vec3d(1, 1, 1)), cameraToSrgb(Matx33d::eye())
    {
    }
    CV_PROP_RW Mat mosaic;          //!< the visible area as stored (black included), CV_16UC1
    CV_PROP_RW RawFormat format;    //!< CFA pattern of the visible area, per-site black, white level; gain 1
    CV_PROP_RW double iso;          //!< ISO speed, 0 when the file does not say
    CV_PROP_RW double exposureTime; //!< seconds, 0 when the file does not say
    CV_PROP_RW String make;         //!< camera maker, empty when unknown
    CV_PROP_RW String model;        //!< camera model, empty when unknown
    /** As-shot white-balance multipliers for R, G, B, normalised to green = 1; (1, 1, 1) when the file
     * has none. Pass them to IspParams::whiteBalance for a neutral preview. */
    CV_PROP_RW Vec3d whiteBalance;
    /** Camera RGB to linear sRGB, rows summing to 1 (from the file's colour matrix as LibRaw derives
     * it); the identity when the file has none. Pass it to IspParams::colorMatrix. */
    CV_PROP_RW Matx33d cameraToSrgb;
    /** The DNG NoiseProfile (tag 51041): for the signal x of a colour plane normalised to [0, 1] by
     * (white - black), the noise variance is S x + O, with one (S, O) pair per colour plane (red, green,
     * blue) or one pair for all. Empty when the file has none. readRaw() reads it from a DNG's IFDs
     * (LibRaw does not expose it), writeDng() writes it; dngNoiseProfile() makes it from a NoiseModel. */
    CV_PROP_RW std::vector<Vec2d> noiseProfile;
    /** The DNG colour tags, sorted by tag. From a DNG: its IFD0's tags, verbatim. From another RAW file:
     * ColorMatrix1, the XYZ (D65) to camera matrix LibRaw knows for the camera (the Adobe coefficients,
     * given for D65 as the DNG specification defines it), with CalibrationIlluminant1 = D65; empty when
     * LibRaw knows none. writeDng() writes them as they are, adding only what a DNG needs and they lack
     * (ColorMatrix1, from cameraToSrgb, and AsShotNeutral, from whiteBalance). */
    CV_PROP_RW std::vector<DngTag> colorTags;

    /** @brief The format to augment this file with `model`: formatAtIso(format, iso, model), the file's
     * gain ISO / model.baseIso (`format` itself says gain 1: LibRaw knows no gain). Pass it, not `format`,
     * to applyScene() and the other steps. @throws cv::Exception as formatAtIso(). */
    CV_WRAP RawFormat formatFor(const NoiseModel& model) const;
};

/** @brief The format of a capture taken at `iso`, for a noise model: `format` with gain iso / model.baseIso,
 * the gain at which the model gives that capture's noise. The library's one place that turns ISO into gain:
 * RawImage::formatFor(), MosaicMetadata::formatFor(), rawgment_augment and the Python dataset use it.
 * @param format the capture's format (its gain is replaced)
 * @param iso the capture's ISO; 0 (unknown) leaves `format` as it is, the capture taken to be at the gain it
 *        states
 * @param model the model the capture is augmented with
 * @throws cv::Exception when `iso` is negative or not finite, or when the file states an ISO and the model
 * has no base ISO: its gain 1 is then no ISO, and reading the file at gain 1 would take its noise at the base
 * gain whatever the ISO (set NoiseModel::baseIso, or the format's gain yourself).
 */
CV_EXPORTS_W RawFormat formatAtIso(const RawFormat& format, double iso, const NoiseModel& model);

/** @brief The DNG NoiseProfile of a noise model at the format's gain (for RawImage::noiseProfile).
 *
 * For each colour plane (red, green, blue), with g = format.gain and r the white level minus the mean
 * black level of the plane's CFA sites: \f$ S = g\alpha / r \f$, \f$ O = (g^2\sigma_d^2 + \sigma_r^2) / r^2
 * \f$, so that \f$ S x + O \f$ is the model's variance of x = (value - black) / r. Like the model, the
 * profile gives no shot noise below black (the DNG form is linear there).
 * @throws cv::Exception when the format is invalid or the model gives S <= 0 (alpha = 0): a DNG reader
 *         requires a positive S.
 */
CV_EXPORTS_W std::vector<Vec2d> dngNoiseProfile(const NoiseModel& model, const RawFormat& format);

/** @brief The noise line of one CFA site at its capture's gain, from a DNG NoiseProfile: a = S r and
 * b = O r^2 in DN, with r the white level minus the mean black level of the site's colour plane (the
 * exact inverse of dngNoiseProfile()).
 * @param profile one (S, O) pair for all colours, or three (red, green, blue)
 * @param format the format of the mosaic the profile describes
 * @param channel the CFA site
 * @throws cv::Exception when the profile has another count or a pair with S <= 0, O < 0 or a
 *         non-finite value.
 */
CV_RAWGMENT_EXPORTS NoiseLine noiseLineFromDngProfile(const std::vector<Vec2d>& profile,
                                                      const RawFormat& format, CfaChannel channel);

/** @brief A model that also follows a file's own DNG NoiseProfile: the profile's green line (
 * noiseLineFromDngProfile() at CFA_G1) as a measured line (NoiseModel::measuredLines) at the file's gain,
 * ISO / model.baseIso, replacing a line the model had at that gain. The augmentation of that file, at its own
 * gain (`image.formatFor(model)`, RawImage::formatFor()), then takes its prior noise from what the file
 * states (a camera maker's or a converter's measurement).
 * @param model the model, with a base ISO
 * @param image a file read by readRaw() with a NoiseProfile and an ISO
 * @throws cv::Exception when the file has no NoiseProfile or no ISO, the model no base ISO, or the
 *         profile is invalid for the file's format.
 */
CV_EXPORTS_W NoiseModel withDngNoiseProfileLine(const NoiseModel& model, const RawImage& image);

/** @brief darktable's noise variance over the per-pixel raw variance (green channel), as its profiling
 * tool measures: the Haar-MAD variance of a PPG-demosaiced export (docs/real_cameras.md). */
constexpr double DARKTABLE_HAAR_VARIANCE_RATIO = 0.0794;

/** @brief The same ratio for a profile made with darktable's RCD demosaic (its default for Bayer sensors
 * from 3.6), green channel on grey (`python/tools/darktable_haar_ratio.py --demosaics 4`). Set
 * DarktableImportParams::haarVarianceRatio to it for profiles known to be made with RCD. */
constexpr double DARKTABLE_RCD_HAAR_VARIANCE_RATIO = 0.0474;

/** @brief A noise model as darktable's noise profiles (the `noiseprofiles.json` that its "denoise
 * (profiled)" module reads): one profile per ISO, each with per-colour `a` and `b` (red, green, blue)
 * in darktable's units: the variance darktable's profiling tool would measure on a signal x normalised
 * to [0, 1] by (white - black) is a x + b.
 *
 * A profile at ISO s is c times the DNG NoiseProfile of the model at gain g = s / baseIso
 * (dngNoiseProfile()): \f$ a = c g\alpha / r \f$, \f$ b = c (g^2\sigma_d^2 + \sigma_r^2) / r^2 \f$,
 * r = white - mean black of the colour's sites, c = `haarVarianceRatio` (darktable measures the Haar
 * coefficients of a demosaiced image, whose variance is c times the pixels'; see
 * DarktableImportParams). darktable measures its own profiles on raw data before white balance, which
 * is what this assumes.
 * @param model the calibrated model
 * @param format black and white levels of the camera's raw files (its gain is not used)
 * @param baseIso the ISO at which the model's gain is 1 (finite, > 0)
 * @param isos the ISOs to write a profile for (each finite and > 0, no repeats; at least one)
 * @param maker camera maker as darktable names it (e.g. "Canon"); not empty
 * @param cameraModel camera model as darktable names it (e.g. "EOS 5D Mark II"); not empty
 * @param haarVarianceRatio c, in (0, 1]
 * @return the JSON text of a complete noise-profile file with one maker and one model entry; numbers are
 *         written with 17 significant digits, so noiseModelFromDarktableExport() (with the same c) gives the
 *         model back, and readCameraProfiles() finds it GOOD.
 * @throws cv::Exception on an invalid argument or a model without shot noise (alpha = 0).
 */
CV_RAWGMENT_EXPORTS String darktableNoiseProfiles(const NoiseModel& model, const RawFormat& format,
                                                  double baseIso, const std::vector<double>& isos,
                                                  const String& maker, const String& cameraModel,
                                                  double haarVarianceRatio = DARKTABLE_HAAR_VARIANCE_RATIO);

/** @brief The noise model of a darktable profile file that darktableNoiseProfiles() wrote: the strict
 * inverse of the project's own export, for round trips and checks of it.
 *
 * A real camera's profiles, as darktable measured them, are read by readCameraProfiles() and
 * CameraNoiseProfile::modelFor() (what loadAnyNoiseModel() and the apps use); this function refuses them.
 * Reads the profiles of one maker and model (profiles with `"skip": true` are ignored) and inverts
 * darktableNoiseProfiles(): \f$ \alpha = a r / (c g) \f$ from every colour and ISO, and \f$ \sigma_d^2 \f$,
 * \f$ \sigma_r^2 \f$ from the line \f$ b r^2 / c = g^2\sigma_d^2 + \sigma_r^2 \f$ across ISOs (least
 * squares).
 * The model has one alpha for all colours and no other terms, so the file's values must agree with one
 * model to 1e-9 relative; a profile measured by darktable's own tool generally does not, and is refused
 * with the spread it has rather than averaged silently.
 * @param path a darktable noise-profile JSON file (read with openFileStorageForReading(); every key is
 *        checked)
 * @param format black and white levels of the camera's raw files
 * @param baseIso the ISO at which the returned model's gain is 1 (its NoiseModel::baseIso)
 * @param maker, cameraModel the entry to read, compared exactly
 * @param haarVarianceRatio c, in (0, 1], as the file was written with
 * @throws cv::Exception naming the file when it is unreadable or malformed, has no such entry, has
 *         fewer than two distinct ISOs (sigma_d^2 and sigma_r^2 cannot be told apart), or is not of the
 *         model's form.
 */
CV_RAWGMENT_EXPORTS NoiseModel noiseModelFromDarktableExport(
    const String& path, const RawFormat& format, double baseIso, const String& maker,
    const String& cameraModel, double haarVarianceRatio = DARKTABLE_HAAR_VARIANCE_RATIO);

/** @brief The noise model in the form of Android's camera tests (the CTS/ITS `dng_noise_model` output
 * behind `android.sensor.noiseProfile`): for sensitivity s (ISO), the DNG NoiseProfile of each CFA
 * channel is \f$ S = A s + B \f$ and \f$ O = C s^2 + D \f$.
 *
 * The values are per CFA site in the order of the mosaic's 2x2 block read row by row (the order of
 * Android's `android.sensor.blackLevelPattern`), each normalised by its own range r = white - black of
 * the site. The form covers analog gain only: Android's tests scale D by the square of any digital
 * gain above the maximum analog sensitivity, which the model does not describe.
 */
struct CV_RAWGMENT_EXPORTS AndroidNoiseProfile
{
    Vec4d A; //!< slope of S in sensitivity, per CFA site
    Vec4d B; //!< S at sensitivity 0, per CFA site (0 for this model)
    Vec4d C; //!< coefficient of sensitivity squared in O, per CFA site
    Vec4d D; //!< O at sensitivity 0, per CFA site
};

/** @brief The Android form of a noise model:
 * \f$ A = \alpha / (r s_0) \f$, B = 0, \f$ C = \sigma_d^2 / (r s_0)^2 \f$, \f$ D = \sigma_r^2 / r^2 \f$, with
 * \f$ s_0 \f$ the base ISO (gain g = s / \f$ s_0 \f$) and r = white - black of each CFA site. The form is
 * Eq. 5's: a model's measured lines (NoiseModel::measuredLines) have no place in it, so the profile is the
 * model's Eq. 5 summary (darktableNoiseProfiles() states each ISO's line instead).
 * @throws cv::Exception on an invalid model, format or base ISO.
 */
CV_RAWGMENT_EXPORTS AndroidNoiseProfile androidNoiseProfile(const NoiseModel& model, const RawFormat& format,
                                                            double baseIso);

/** @brief The noise model of an Android-form profile, where the mapping is exact: B must be 0 (the
 * model's shot noise is proportional to the gain) and the four sites must give the same
 * alpha, sigma_d^2 and sigma_r^2 to 1e-9 relative (the model has one set for all colours). The
 * model's NoiseModel::baseIso is `baseIso`.
 * @throws cv::Exception naming the site and the value when the profile is not of the model's form.
 */
CV_RAWGMENT_EXPORTS NoiseModel noiseModelFromAndroid(const AndroidNoiseProfile& profile,
                                                     const RawFormat& format, double baseIso);

/** @brief Reads the Bayer mosaic of a camera RAW file (any format LibRaw reads: DNG, NEF, CR2, CRW, ...).
 *
 * The mosaic is the visible area LibRaw reports (masked borders removed). The CFA pattern is the one
 * of the visible area's top-left pixel as LibRaw reports it, never assumed. The black level of each
 * site is LibRaw's `black + cblack[colour] + cblack[6 + pattern position]`; the white level is LibRaw's
 * `maximum`. Every LibRaw return code is checked. The DNG NoiseProfile, which LibRaw does not expose,
 * is read from the file's IFDs (IFD0, the IFDs chained after it and their SubIFDs).
 * @param path the file
 * @throws cv::Exception naming the file and the reason when the file is missing or unreadable, is not a
 *         RAW file, is truncated or corrupt (LibRaw's data-error callback fired), or is not a 2x2 Bayer
 *         mosaic (X-Trans, Foveon, four-colour, or a linear/demosaiced DNG), or has a malformed
 *         NoiseProfile tag.
 */
CV_EXPORTS_W RawImage readRaw(const String& path);

/** @brief Writes a mosaic as an uncompressed DNG 1.4 file that LibRaw and RAW viewers open.
 *
 * The file holds the CFA pattern, the per-site black level (BlackLevelRepeatDim 2x2), the white level,
 * make and model, ISO, exposure time, the as-shot neutral from the white balance and, when
 * RawImage::noiseProfile is not empty, the NoiseProfile tag (51041). The ISO is rounded to an integer (the
 * EXIF tags hold integers); from 65535 on it goes to EXIF 2.3's 32-bit ISOSpeed, which readRaw() reads back.
 * It is written atomically (a temporary file, then a hard link that fails if `path` exists): an existing
 * file of exactly these bytes is this call's output (an identical run that got there first), any other is
 * never overwritten.
 * @param path destination, which must not exist or hold exactly the bytes this call writes
 * @param image `mosaic` must be CV_16UC1 with even sides of at least 22 pixels (LibRaw, and so readRaw(),
 *        reads no smaller RAW file); `iso` 0 (unknown) up to 4294967295; the other fields are written as
 *        they are (`format.gain` is not a DNG field; writeMosaic() keeps it in the sidecar)
 * @throws cv::Exception when `path` exists with other bytes, the mosaic is unsupported, the noise profile
 *         is invalid (see noiseLineFromDngProfile()), or any write fails.
 */
CV_EXPORTS_W void writeDng(const String& path, const RawImage& image);

/** @brief What a RAW file says about its camera and capture beside the mosaic. Augmentation keeps it
 * (MosaicMetadata::camera), so that an augmented DNG is still the camera's for a raw converter: the same
 * maker, model, colour matrix and white balance, with the ISO, exposure time and noise profile of the
 * capture it simulates. */
struct CV_RAWGMENT_EXPORTS CameraTags
{
    String make;                           //!< camera maker, empty when unknown
    String model;                          //!< camera model, empty when unknown
    double iso = 0;                        //!< ISO speed, 0 when unknown
    double exposureTime = 0;               //!< seconds, 0 when unknown
    Vec3d whiteBalance = Vec3d(1, 1, 1);   //!< as RawImage::whiteBalance
    Matx33d cameraToSrgb = Matx33d::eye(); //!< as RawImage::cameraToSrgb
    std::vector<Vec2d> noiseProfile;       //!< as RawImage::noiseProfile; empty for none
    std::vector<DngTag> colorTags;         //!< as RawImage::colorTags; empty for none

    //! The tags of a RAW image (every field but its mosaic and format).
    static CameraTags of(const RawImage& image);
    //! Sets these tags on a RAW image (for writeDng()).
    void applyTo(RawImage& image) const;
    //! Writes the tags as a map under `name`.
    void write(FileStorage& fs, const String& name) const;
    //! Reads tags written by write(). @throws cv::Exception naming an invalid or unknown field.
    static CameraTags read(const FileNode& node);
};

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_RAW_IO_HPP
