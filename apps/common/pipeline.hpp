// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The work of each app as a function, so that the demo runs exactly what the apps run; the augmentation
// jobs they share with the Python module are the pipeline layer's (pipeline/augment_jobs.hpp).
#ifndef RAWGMENT_APPS_PIPELINE_HPP
#define RAWGMENT_APPS_PIPELINE_HPP

#include "augment_jobs.hpp"

#include <opencv2/rawgment.hpp>

#include <string>
#include <vector>

namespace rawgment_apps {

// The pipeline layer's inputs and augmentation jobs (augment_jobs.hpp) are the apps' too.
using namespace rawgment_pipeline;

// ---------------------------------------------------------------------------------------------------
//! The ISO that rawgment_simulate writes for unit gain (frames at gain g say ISO 100 g).
constexpr double kSimulatedBaseIso = 100;

struct SimulateOptions
{
    std::string outDir;
    std::vector<double> gainsDb = {6, 12, 24};
    //! Level of the white patch as a fraction of the range (white - black); one burst per level and gain.
    std::vector<double> levels = {0.3, 0.9};
    int frames = 100;
    int patchSize = 40;
    cv::rawgment::SensorParams sensor;
    uint64_t seed = 1;
    std::string extension = ".dng"; //!< container of the frames (any that writeMosaic() writes)
    bool dark = false;              //!< also a burst of dark frames (no light) per gain
    //! Amplitude (DN) of a dark-shading pattern drawn for the chart's size (addDarkShadingPattern(); 0:
    //! none).
    double darkShading = 0;
    bool validation = true; //!< also a bright and two dark bursts (x0.5, x0.1) at validationGainDb
    double validationGainDb = 12;
    int validationFrames = 100;
};

struct SimulateResult
{
    std::string manifest;           //!< calibration manifest (YAML)
    std::string validationManifest; //!< empty when not written
    std::string truthModel;         //!< the model a calibration should recover
    int files = 0;
};

/** Writes simulated colour-checker bursts, their manifests, the ground-truth patches and model.
 * Refuses (std::runtime_error) when the manifest already exists. */
SimulateResult simulateBursts(const SimulateOptions& options);

// ---------------------------------------------------------------------------------------------------
struct CalibrateOptions
{
    std::string manifest;
    std::string outDir;
    cv::rawgment::NoiseFitMethod method = cv::rawgment::NOISE_FIT_JOINT;
    int side = 24;            //!< square side used when the manifest asks for detection
    int shapiroPixels = 2000; //!< pixels per burst tested by Shapiro-Wilk (spread over the squares)
    bool plots = true;
    uint64_t seed = 0; //!< seed of the RANSAC draws of the per-gain line fits
    //! CalibrationParams::bootstrapReplicates: 0 (the fit's covariance alone) or >= 2
    int bootstrapReplicates = 200;
    //! Also the dark-frame components (row noise, dark shading, Tukey read noise) from the dark bursts.
    bool darkComponents = false;
    //! Also a dark-frame bank of the dark bursts' files, written there (DarkFrameBank::save()); "" for none.
    std::string darkBank;
};

struct CalibrateResult
{
    cv::rawgment::CalibrationReport report;
    std::vector<std::string> pngs;  //!< plots written
    std::vector<std::string> notes; //!< what the user should know (plots skipped, ...)
    double gaussianFraction = 0;    //!< fraction of tested pixels with Shapiro-Wilk p > 0.05
    int shapiroTested = 0;
    double baseIso = 0;              //!< the ISO of gain 1 (0 when every gain came from the manifest)
    cv::rawgment::CameraTags camera; //!< the first frame's camera tags
    cv::rawgment::CalibrationVerdict verdict;
    //! What more data would buy: a plan's name and the standard errors it would give (projectedStdError()).
    std::vector<std::pair<std::string, cv::Vec3d>> projections;
    bool haveDark = false; //!< whether the dark-frame components were calibrated
    //! The bank written (CalibrateOptions::darkBank), and how long making it took (s).
    cv::rawgment::DarkFrameBank bank;
    double bankSeconds = 0;
    cv::rawgment::DarkCalibrationReport dark; //!< their calibration (its model is report.model)
};

//! What a calibration manifest says, checked: every key known, gains finite, no file listed twice.
struct CalibrationManifest
{
    struct Burst
    {
        bool hasGainDb = false; //!< false: the gain comes from the files' ISO relative to the base ISO
        double gainDb = 0;
        bool dark = false;              //!< dark frames (lens cap): every flat pixel, whatever `patches` says
        std::vector<std::string> files; //!< resolved against the manifest's folder
    };
    std::vector<Burst> bursts; //!< at least one, each with at least one file
    //! "detect" (cv::mcc), "none" (any static scene: sampleStaticScene()), or the resolved path of a
    //! chart patches file
    std::string patches;
    bool hasBaseIso = false; //!< false: the lowest ISO of the bursts that take their gain from it
    double baseIso = 0;
};
/** Reads a calibration manifest (YAML or JSON), or makes one from a folder that holds one folder of
 * frames per burst (sorted by name; a folder whose name starts with "dark" holds dark frames; patches
 * "none"; every gain from the ISO). Throws std::runtime_error or cv::Exception naming the file. */
CalibrationManifest readCalibrationManifest(const std::string& path);

CalibrateResult calibrateFromManifest(const CalibrateOptions& options);

// ---------------------------------------------------------------------------------------------------
//! One EMVA 1288 series of rawgment_calibrate --emva: its descriptor and its gain.
struct Emva1288Input
{
    std::string descriptor;
    double gainDb = 0;
};

struct Emva1288Options
{
    std::string input;  //!< an EMVA1288_Data.txt descriptor (gain 0 dB), or a manifest (.yml/.yaml/.json)
    std::string outDir; //!< must not hold the outputs already
    double maxSignalFraction = 0.3; //!< Emva1288CalibrationParams::maxSignalFraction
    uint64_t seed = 0;              //!< seed of the real-frame validation's augmentation
    bool plots = true;
};

struct Emva1288FlowResult
{
    std::vector<Emva1288Input> inputs;
    std::vector<cv::rawgment::Emva1288Results> results; //!< per series, as inputs
    cv::rawgment::CalibrationReport report;
    cv::rawgment::CalibrationVerdict verdict;
    std::vector<cv::rawgment::Emva1288Darkening>
        darkening;                    //!< NONE, IGNORE_PRIOR, ACCOUNT_PRIOR per step pair
    std::vector<int> darkeningSeries; //!< the series of each darkening entry
    std::vector<std::string> pngs, notes;
};

//! An EMVA 1288 series of the simulator, written in the standard's form (the demo's; a test's own series).
struct SimulatedEmva1288
{
    cv::rawgment::SensorParams sensor; //!< its noise at gain 1, levels, DSNU, PRNU and defects
    cv::Size size{320, 240};
    int steps = 24;         //!< bright steps, evenly up to 1.15 x the white level (saturation inside)
    int spatialFrames = 16; //!< frames of each stack of the spatial set (0: none), at half of saturation
    double quantumEfficiency = 0.5; //!< photons per electron is its inverse: it sets the photon counts
    uint64_t seed = 1;
};
/** Writes the PNGs and EMVA1288_Data.txt of `series` into `dir` (never over a file) and returns the
 * descriptor's path. */
std::string writeSimulatedEmva1288(const std::string& dir, const SimulatedEmva1288& series);

/** Reads the series (one descriptor, or a manifest `emva1288_manifest: {base_iso:, series: [{descriptor:,
 * gain_db: | iso:}]}`), computes the standard's figures and the model, validates it on each series' own
 * darker steps, and writes noise_model.yml, calibration_report.yml, emva1288.yml, emva1288_points.csv,
 * emva1288_validation.csv, the plots and report.md into outDir. Throws naming the file on bad input. */
Emva1288FlowResult calibrateFromEmva1288(const Emva1288Options& options);
//! report.md of calibrateFromEmva1288().
std::string emva1288ReportMarkdown(const Emva1288FlowResult& result, const Emva1288Options& options);

struct ValidateOptions
{
    std::string manifest;
    std::string model;  //!< a NoiseModel file, an Android profile YAML, or a darktable file with `camera`
    std::string camera; //!< the camera of a darktable profile file (loadAnyNoiseModel())
    std::string outDir;
    int bins = 10;
    uint64_t seed = 7;
    bool plots = true;
    bool acceptFailedCalibration = false; //!< also a model whose calibration failed (NoiseModel::load())
};

//! Per mean bin and factor: the real dark burst's variance and each conversion's.
struct ValidationRow
{
    double factor = 0;
    double meanLow = 0, meanHigh = 0;
    int pixels = 0;
    double realVariance = 0;
    double noneVariance = 0, ignoreVariance = 0, accountVariance = 0;
};

struct ValidateResult
{
    std::vector<ValidationRow> rows;
    std::vector<std::string> pngs;
    std::vector<std::string> notes;
    std::string table; //!< Markdown
};

//! What a validation manifest says, checked: every key known, numbers where numbers belong.
struct ValidationManifest
{
    struct Target
    {
        double factor;                  //!< exposure of the target relative to the bright burst, in (0, 1]
        std::vector<std::string> files; //!< resolved against the manifest's folder
    };
    std::vector<std::string> bright; //!< the bright burst
    std::vector<Target> targets;     //!< at least one
    bool hasGainDb = false;          //!< whether the manifest gives the bursts' gain
    double gainDb = 0;
    std::string patches; //!< resolved path of a chart patches file; empty: every pixel
};
//! Reads a validation manifest; throws std::runtime_error or cv::Exception naming the file.
ValidationManifest readValidationManifest(const std::string& path);

ValidateResult validateConversion(const ValidateOptions& options);

// ---------------------------------------------------------------------------------------------------
struct AugmentResult
{
    int written = 0, skipped = 0;
    std::vector<std::string> outputs;
};

AugmentResult augmentFiles(const AugmentOptions& options);

// ---------------------------------------------------------------------------------------------------
//! rawgment_cameras: what a darktable noise-profile file holds and what its cameras say about Eq. 5.
struct CamerasOptions
{
    std::string profiles;        //!< the file; empty: darktableProfilesPath()
    std::string verdict = "all"; //!< the catalogue's filter: all, good, rough, usable or refused
    std::string camera;          //!< one camera (or a selection): its fit per ISO instead of the catalogue
    std::string reportDir;       //!< write the report (report.md, CSVs, PNGs) here instead
};

struct CamerasResult
{
    std::string text; //!< the catalogue, the per-ISO tables or the report's Markdown
    std::vector<std::string> pngs, notes;
};

CamerasResult runCameras(const CamerasOptions& options);

} // namespace rawgment_apps

#endif // RAWGMENT_APPS_PIPELINE_HPP
