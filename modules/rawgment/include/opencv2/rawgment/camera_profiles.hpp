// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_CAMERA_PROFILES_HPP
#define OPENCV_RAWGMENT_CAMERA_PROFILES_HPP

#include <opencv2/rawgment/noise_model.hpp>
#include <opencv2/rawgment/raw_io.hpp>

#include <vector>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment
//! @{

/** @brief What a camera's measured profiles say about the model of Eq. 5, and whether it is imported. */
enum CameraProfileVerdict
{
    /** Every ISO's shot slope and offset follow the model closely (see DarktableImportParams for the
     * bounds): the imported model stands for the camera. */
    CAMERA_PROFILE_GOOD = 0,
    /** Imported, but some ISO's profile departs from the model by more than the GOOD bounds (the reason
     * says which): the model is the best fit, not a description. */
    CAMERA_PROFILE_ROUGH = 1,
    /** Not imported: the profiles cannot give a model (fewer than two usable ISOs, offsets that are all
     * zero or negative, a malformed entry; the reason says which). */
    CAMERA_PROFILE_REFUSED = 2
};

//! "GOOD", "ROUGH" or "REFUSED". @throws cv::Exception for another value.
CV_EXPORTS_W String cameraProfileVerdictName(int verdict);

/** @brief Which demosaic darktable's profiling export used for a camera's profiles, as far as their colours
 * tell (CameraNoiseProfile::demosaic; docs/real_cameras.md has the evidence).
 *
 * For raw shot noise every colour has the same slope per DN; after demosaicing, the red or blue slope over
 * the green one is r = u + v k, where k is green's raw level over that colour's (the scene's colour in the
 * un-white-balanced export, unknown per camera) and (u, v) is the demosaic's: PPG 0.284 + 0.946 k,
 * RCD 0.592 + 0.962 k (`python/tools/darktable_haar_ratio.py --demosaics 4`). A raw of a grey scene has
 * green brightest (k >= 1) under daylight and tungsten alike, so the lowest colour ratio can rule RCD out,
 * never prove it. */
enum ProfileDemosaic
{
    /** Both demosaics fit: each implies a colour balance k >= 1 (CameraNoiseProfile::balancePpg and
     * balanceRcd), or the colours are copies of green and carry no evidence. */
    PROFILE_DEMOSAIC_UNDECIDED = 0,
    /** PPG: with RCD a colour would be brighter than green in the raw (k < 1, by more than the margin). */
    PROFILE_DEMOSAIC_PPG = 1,
    /** Neither: a colour ratio is below what PPG gives on grey, so neither demosaic fits a scene with green
     * brightest (a colour fit that failed, processing in the camera, or a sensor that is not Bayer). */
    PROFILE_DEMOSAIC_NEITHER = 2
};

//! "undecided", "PPG" or "neither". @throws cv::Exception for another value.
CV_EXPORTS_W String profileDemosaicName(int demosaic);

/** @brief How darktable's measured noise profiles are read as per-pixel raw noise, and the bounds of the
 * verdicts.
 *
 * darktable's profiling tool measures the noise of a demosaiced, un-white-balanced export normalised to
 * [0, 1] by (value - black) / (white - black): the robust (MAD) variance of the one-level Haar HH
 * coefficient of each colour, binned by brightness, fitted as a x + b. For independent pixel noise of
 * variance v the HH coefficient's variance is c v, with c = 1/4 without demosaicing; darktable's PPG
 * demosaic (the default when most profiles were made) interpolates half the green sites from their
 * neighbours and lowers it. docs/real_cameras.md has the derivation and the reference. */
struct CV_EXPORTS_W_SIMPLE DarktableImportParams
{
    //! Every field at its default, as initialised here.
    CV_WRAP DarktableImportParams()
        : haarVarianceRatio(DARKTABLE_HAAR_VARIANCE_RATIO), offsetReferenceLevel(1e-3),
          goodMedianSlopeResidual(0.10), goodWorstSlopeResidual(0.35), goodWorstOffsetResidual(1.0),
          goodMinIsos(3)
    {
    }
    /** c: darktable's variance over the per-pixel raw variance, for the green channel. The default,
     * DARKTABLE_HAAR_VARIANCE_RATIO = 0.0794, is darktable's PPG green interpolation followed by its Haar-MAD
     * measurement, simulated on white noise (`python/tools/darktable_haar_ratio.py`); 0.25 would assume no
     * demosaicing. In (0, 1]. */
    CV_PROP_RW double haarVarianceRatio;
    /** The signal level, as a fraction of white, at which offsets are compared: an offset's residual is
     * the error of the fitted offset over |b| + a x_ref, the profile's variance there. Offsets can be
     * zero or negative, so they have no scale of their own. In (0, 1). */
    CV_PROP_RW double offsetReferenceLevel;
    //! GOOD needs the median over ISOs of |slope residual| at most this ...
    CV_PROP_RW double goodMedianSlopeResidual;
    //! ... and the worst at most this ...
    CV_PROP_RW double goodWorstSlopeResidual;
    //! ... the worst |offset residual| at most this ...
    CV_PROP_RW double goodWorstOffsetResidual;
    //! ... and at least this many ISOs.
    CV_PROP_RW int goodMinIsos;

    //! @throws cv::Exception naming a value outside its range.
    CV_WRAP void validate() const;
};

/** @brief One ISO of a camera's profiles, as the fit sees it (green channel, per-pixel units normalised to
 * white - black = 1). */
struct CV_EXPORTS_W_SIMPLE CameraIsoFit
{
    //! Every field at its default, as initialised here.
    CV_WRAP CameraIsoFit()
        : iso(0), gain(0), slope(0), offset(0), slopeResidual(0), offsetResidual(0), colourSpread(1),
          expanded(false), inconsistent(false), rawIso(0)
    {
    }
    CV_PROP_RW double iso;            //!< the profile's ISO
    CV_PROP_RW double gain;           //!< iso / CameraNoiseProfile::baseIso
    CV_PROP_RW double slope;          //!< measured shot slope a / c
    CV_PROP_RW double offset;         //!< measured offset b / c (may be negative)
    CV_PROP_RW double slopeResidual;  //!< (fitted slope - measured) / measured
    CV_PROP_RW double offsetResidual; //!< (fitted offset - measured) / (|measured| + slope x_ref)
    /** Largest over smallest shot slope of the colours with a positive slope (1 when the colours agree,
     * as in profiles that copy green to every colour). */
    CV_PROP_RW double colourSpread;
    /** Red and blue shot slope over green's, as darktable measured them (0 for a colour whose slope is not
     * positive); ProfileDemosaic says what they tell. */
    CV_PROP_RW Vec2d colourSlopeRatios;
    /** An expanded low setting: its green slope falls less than its ISO below the next ISO (its raw is a
     * higher ISO's). Measured and followed by the augmentation, but not the base ISO, not fitted to Eq. 5
     * and not counted in the verdict's figures (readCameraProfiles() says how it is told). */
    CV_PROP_RW bool expanded;
    /** A colour's shot slope is negative (a variance cannot fall as the signal rises): darktable's fit of
     * that profile failed (the Canon EOS 5D Mark III's ISO 160, 320, 640, ... have negative blue slopes).
     * Named, but left out of the fit, the verdict's figures and the measured lines (the ISO's line then comes
     * from its neighbours). */
    CV_PROP_RW bool inconsistent;
    /** A digital setting: the ISO (above the expanded ones) whose raw this one is, 0 for an analog step.
     * darktable normalises each file by its own white level, so a setting that scales an analog ISO's raw
     * together with its white level (Canon's third stops 160, 320, 640, ... from 200, 400, 800), or keeps
     * a lower ISO's raw and marks it for brightening (Fujifilm's high settings), has that ISO's slope a
     * third of a stop or more away. Measured and followed like an expanded setting, not fitted. */
    CV_PROP_RW double rawIso;
    //! Whether the setting is digital (rawIso set).
    CV_WRAP bool digital() const { return rawIso > 0; }
    //! Whether the ISO is fitted to Eq. 5 and counted in the verdict: an analog, consistent setting.
    CV_WRAP bool fitted() const { return !expanded && !inconsistent && !digital(); }
};

/** @brief A real camera's noise, fitted to Eq. 5 from its measured profiles, in units of a raw range of 1.
 *
 * `noise` is the fitted model: the per-pixel variance of a signal x in [0, 1] at gain
 * g = ISO / noise.baseIso is noise.variance(x, g), \f$ g\alpha x + g^2\sigma_d^2 + \sigma_r^2 \f$.
 * modelFor() scales it to a RawFormat's range. */
struct CV_EXPORTS_W_SIMPLE CameraNoiseProfile
{
    //! Every field at its default, as initialised here.
    CV_WRAP CameraNoiseProfile()
        : verdict(CAMERA_PROFILE_REFUSED), skippedProfiles(0), medianSlopeResidual(0), worstSlopeResidual(0),
          worstSlopeIso(0), worstOffsetResidual(0), worstOffsetIso(0), medianColourSpread(1),
          negativeOffsets(0), expandedIsos(0), digitalIsos(0), inconsistentProfiles(0), monotoneSlope(true),
          demosaic(PROFILE_DEMOSAIC_UNDECIDED), haarVarianceRatio(0)
    {
    }
    CV_PROP_RW String maker;  //!< maker as the file names it
    CV_PROP_RW String model;  //!< model as the file names it
    CV_PROP_RW String place;  //!< where the entry is in the file, e.g. "noiseprofiles[5].models[12]"
    CV_PROP_RW int verdict;   //!< a CameraProfileVerdict
    CV_PROP_RW String reason; //!< why the verdict is not GOOD (empty when GOOD)
    /** The fitted model over a raw range of 1: alpha is the shot slope at gain 1 (1 / full well in
     * electrons), sigmaD2 and sigmaR2 the read variances before and after the gain over the range
     * squared, and baseIso the lowest usable ISO that is neither expanded nor digital (gain 1). All zero
     * while the camera is REFUSED before its fit. */
    CV_PROP_RW NoiseModel noise;
    CV_PROP_RW std::vector<CameraIsoFit>
        isos;                       //!< the usable profiles, by ascending ISO (an ISO measured twice twice)
    CV_PROP_RW int skippedProfiles; //!< profiles marked "skip" or without a positive green slope
    CV_PROP_RW double medianSlopeResidual; //!< median over ISOs of |slope residual|
    CV_PROP_RW double worstSlopeResidual;  //!< largest |slope residual|
    CV_PROP_RW double worstSlopeIso;       //!< its ISO
    CV_PROP_RW double worstOffsetResidual; //!< largest |offset residual|
    CV_PROP_RW double worstOffsetIso;      //!< its ISO
    CV_PROP_RW double medianColourSpread;  //!< median over ISOs of CameraIsoFit::colourSpread
    CV_PROP_RW int negativeOffsets;        //!< fitted ISOs whose measured offset is below zero
    CV_PROP_RW int expandedIsos;           //!< expanded low ISOs (CameraIsoFit::expanded), below the base ISO
    CV_PROP_RW int digitalIsos;            //!< digital settings (CameraIsoFit::rawIso), never the base ISO
    CV_PROP_RW int
        inconsistentProfiles; //!< profiles with a negative colour shot slope (CameraIsoFit::inconsistent)
    CV_PROP_RW bool monotoneSlope; //!< whether the measured slope never falls as the ISO rises
    //! Median over fitted ISOs of CameraIsoFit::colourSlopeRatios (red over green, blue over green).
    CV_PROP_RW Vec2d colourSlopeRatios;
    //! Green over red and over blue raw level that colourSlopeRatios imply if the profiles were made with
    //! PPG.
    CV_PROP_RW Vec2d balancePpg;
    //! The same if they were made with RCD.
    CV_PROP_RW Vec2d balanceRcd;
    CV_PROP_RW int demosaic;          //!< a ProfileDemosaic
    CV_PROP_RW String demosaicReason; //!< the evidence for `demosaic`, in a sentence
    /** c, the Haar variance ratio the profiles were divided by (DarktableImportParams::haarVarianceRatio):
     * PPG's green unless set otherwise. With demosaic UNDECIDED it is an assumption: with RCD's c every
     * variance would be 0.0794 / 0.0474 = 1.68 times larger and the full well as much smaller. */
    CV_PROP_RW double haarVarianceRatio;

    //! "maker model", the name cameras are selected by.
    CV_WRAP String name() const;
    //! Whether the camera is imported (GOOD or ROUGH).
    CV_WRAP bool usable() const { return verdict != CAMERA_PROFILE_REFUSED; }
    /** @brief The camera's noise model in DN for mosaics of `format`: `noise` with alpha times r and the
     * variances times r^2, with r = white - the mean black of the green sites (the catalogue takes green's
     * profile, normalised by green's range as darktable and darktableNoiseProfiles() do; its baseIso kept),
     * and every usable ISO's
     * measured line (isos: slope times r, offset times r^2, at its gain) as NoiseModel::measuredLines,
     * which the augmentation follows; an ISO measured twice takes the mean of its lines, a negative
     * measured offset is taken as 0, an inconsistent profile is left out.
     * @throws cv::Exception when the camera is REFUSED (naming the reason) or the format is invalid. */
    CV_WRAP NoiseModel modelFor(const RawFormat& format) const;
};

/** @brief Every camera of a darktable noise-profile file (`noiseprofiles.json`), each fitted to Eq. 5 with
 * its verdict.
 *
 * For each maker and model: the green channel's profiles at every ISO (profiles with `"skip": true` and
 * those without a positive green slope are left out and counted), divided by
 * DarktableImportParams::haarVarianceRatio to per-pixel units; expanded low settings found (from the
 * lowest ISO up, each whose green slope falls less than its ISO towards the next ISO down: slope ratio over
 * ISO ratio above 1.15, where an analog step gives 1 and an expanded setting that reuses the next ISO's raw
 * gives 1.26 to 2) and digital settings found (above those, neighbouring ISOs a third of a stop or more
 * apart whose slopes differ by less than 8%: one raw; the member nearest the camera's trend is the analog
 * one, CameraIsoFit::rawIso), both left out of the fit and the verdict but kept as measured lines; the
 * demosaic judged from the colours (ProfileDemosaic); alpha by least squares on the relative slope residuals
 * through the origin; sigma_d^2 and sigma_r^2 >= 0 by weighted non-negative least squares of the offsets,
 * each weighted by 1 / (|b| + a x_ref)^2. An entry that is malformed (a value that is not a number, a list of
 * another length, an unknown key) is REFUSED with the reason naming its place, and the other cameras are
 * still read. The project's own exports (darktableNoiseProfiles()) come back GOOD with their model.
 * @param path the JSON file (at most the size openFileStorageForReading() allows)
 * @param params how to read the values and the verdicts' bounds
 * @throws cv::Exception naming the file when it cannot be read or its top level is not darktable's form
 *         (a map with a list `noiseprofiles` of maps with `maker` and `models`).
 */
CV_EXPORTS_W std::vector<CameraNoiseProfile>
readCameraProfiles(const String& path, const DarktableImportParams& params = DarktableImportParams());

/** @brief The camera named `name` ("maker model", compared ignoring case and repeated spaces).
 * @throws cv::Exception when no camera has that name, listing the five closest names; or when it is
 *         REFUSED, with the reason.
 */
CV_EXPORTS_W CameraNoiseProfile findCameraProfile(const std::vector<CameraNoiseProfile>& cameras,
                                                  const String& name);

/** @brief The cameras a selection names: a comma-separated list of camera names, or one of the words
 * "good" (every GOOD camera) and "usable" (every GOOD or ROUGH camera).
 * @throws cv::Exception as findCameraProfile() for a name, or when the selection is empty.
 */
CV_EXPORTS_W std::vector<CameraNoiseProfile>
selectCameraProfiles(const std::vector<CameraNoiseProfile>& cameras, const String& selection);

/** @brief The index of the camera a sample with `seed` draws from `count` cameras: uniform, and the same
 * for the same seed on every machine and from Python.
 * @throws cv::Exception when count < 1. */
CV_EXPORTS_W int drawCameraIndex(int count, uint64 seed);

/** @brief The darktable noise-profile file of this machine: the environment variable
 * RAWGMENT_DARKTABLE_PROFILES when set, else the install script's copy
 * (`${RAWGMENT_CACHE_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/rawgment}/darktable/noiseprofiles.json`), else an
 * installed darktable's `/usr/share/darktable/noiseprofiles.json`; empty when none exists. */
CV_EXPORTS_W String darktableProfilesPath();

//! The kinds of file a noise model is taken from (noiseModelFileKind()).
enum NoiseModelFileKind
{
    NOISE_MODEL_FILE = 0,      //!< a NoiseModel (NoiseModel::load())
    ANDROID_PROFILE_FILE = 1,  //!< an Android profile YAML (noiseModelFromAndroidFile())
    DARKTABLE_PROFILE_FILE = 2 //!< darktable's noise profiles, many cameras (readCameraProfiles())
};

/** @brief The NoiseModelFileKind of a model file, from its top-level keys: `noiseprofiles` (in a `.json`
 * file) is darktable's, `android_noise_profile` an Android profile, anything else a NoiseModel (whose
 * reader then names what is wrong with it).
 * @throws cv::Exception when the file cannot be read as YAML or JSON. */
CV_RAWGMENT_EXPORTS int noiseModelFileKind(const String& path);

/** @brief The noise model of an Android profile YAML as the project writes it (`android_noise_profile.yml`
 * of rawgment_calibrate: a map `android_noise_profile` with `base_iso` and the lists A, B, C, D of four
 * values), inverted by noiseModelFromAndroid(). The profile is normalised by each site's range, so the
 * model in DN needs the format of the mosaics it is for.
 * @throws cv::Exception naming the file and the field when it is malformed or has no exact model. */
CV_RAWGMENT_EXPORTS NoiseModel noiseModelFromAndroidFile(const String& path, const RawFormat& format);

/** @brief A noise model from any file the project reads models from (noiseModelFileKind()): a NoiseModel
 * YAML (NoiseModel::load()), an Android profile YAML (noiseModelFromAndroidFile()), or, with `camera`
 * given, a darktable profile file's camera (readCameraProfiles(), then findCameraProfile() and
 * CameraNoiseProfile::modelFor() with `format`).
 * @param path the file
 * @param camera the camera to take from a darktable file; must be empty for the other kinds
 * @param format the range of the mosaics the model is for (used for a darktable camera only)
 * @param acceptFailedCalibration as NoiseModel::load()
 * @throws cv::Exception when the file cannot be read as any of them, a darktable file is given without a
 *         camera, or a camera is given with another kind of file.
 */
CV_EXPORTS_W NoiseModel loadAnyNoiseModel(const String& path, const String& camera, const RawFormat& format,
                                          bool acceptFailedCalibration = false);

//! @}

} // namespace rawgment
} // namespace cv

#endif
