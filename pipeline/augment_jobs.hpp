// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The pipeline layer: what the apps and the Python module (rawgment.batch, Dask workers) share to read
// inputs and make augmented outputs, so that a job gives the same bytes wherever it runs. Above the
// library, below the apps; errors are std::runtime_error or cv::Exception naming the file.
#ifndef RAWGMENT_PIPELINE_AUGMENT_JOBS_HPP
#define RAWGMENT_PIPELINE_AUGMENT_JOBS_HPP

#include "output_files.hpp"

#include <opencv2/rawgment.hpp>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace rawgment_pipeline {

//! A mosaic from any file the apps read: our mosaics with a sidecar, or camera RAW files.
struct LoadedMosaic
{
    cv::Mat mosaic;
    cv::rawgment::RawFormat format;
    bool hasCamera = false; //!< a camera RAW file, or a mosaic whose sidecar has camera tags
    /** Read by LibRaw (no sidecar), or converted from such a file (MosaicMetadata::gainFromIso):
     * format.gain is 1, whatever the ISO. */
    bool fromCameraFile = false;
    cv::rawgment::CameraTags camera;
};
LoadedMosaic loadMosaicFile(const std::string& path);

/** The name of each input's outputs, unique per input and never changed by the other inputs of a later run:
 * the name of the input's existing output when it has one (`sourceOf(i, name)`: the source recorded by the
 * existing output of input i named `name`, an empty string when it exists but names none, nullopt when there
 * is none), whether plain or hashed; else its stem, unless an earlier input of the run or another input's
 * existing output has it: then the stem and 8 hex digits of a hash of the input's path (a/x.dng stays x when
 * b/x.dng joins a later run, which names b/x.dng x-<hash>). The same file given twice is an error. */
std::vector<std::string> uniqueOutputNames(
    const std::vector<std::string>& inputs,
    const std::function<std::optional<std::string>(size_t input, const std::string& name)>& sourceOf);
//! Whether an output's recorded `source` names `input` (as given, or the same file by another path).
bool sameInput(const std::string& recorded, const std::string& input);
//! The `source` an existing output's sidecar records ("" when it names none or cannot be read), or nullopt
//! when neither the output nor its sidecar exists.
std::optional<std::string> sourceOfOutput(const std::string& out);
/** Throws std::runtime_error naming the input when one lies in `outDir`: a later run over that folder would
 * take the outputs for inputs (rawgment_convert --out=raws raws converted its own outputs again). */
void refuseOutputsAmongInputs(const std::string& outDir, const std::vector<std::string>& inputs);

//! What convertMosaics() did: outputs written, and outputs a previous run of the same inputs had finished.
struct ConvertResult
{
    int written = 0;
    int skipped = 0;
    std::vector<std::string> outputs; //!< every output, in input order
};

/** Converts each input (a camera RAW that LibRaw reads, or a mosaic with a sidecar) into `outDir` (created
 * when missing) as `<name><extension>` with its sidecar: the same mosaic, format and camera tags, with
 * `source` naming the input. A camera RAW's sidecar sets MosaicMetadata::gainFromIso, so the converted
 * file augments exactly as the RAW. An existing output is skipped when its sidecar says it was converted
 * from the same input, and is an error otherwise. `advance` is called once per input. */
ConvertResult convertMosaics(const std::vector<std::string>& inputs, const std::string& outDir,
                             const std::string& extension, const std::function<void()>& advance);

//! An sRGB-like 8-bit preview of a mosaic (tone curve gamma 2.2 with the sRGB toe, white balance 1).
cv::Mat previewOf(const cv::Mat& mosaic, const cv::rawgment::RawFormat& format, double exposure = 1.0);

struct AugmentOptions
{
    std::vector<std::string> inputs;
    std::string model; //!< a NoiseModel file, an Android profile YAML, or a darktable profile file
    /** With a darktable profile file: a camera name, a comma-separated list of names or "good" /
     * "usable" (selectCameraProfiles()); with several cameras each output draws one
     * (drawCameraIndex() of its seed). Must be empty for the other model files. */
    std::string camera;
    std::string scene;  //!< a Scene file (map `scene`), or
    std::string policy; //!< a RandomScenePolicy file
    std::string outDir;
    int variants = 1;
    uint64_t seed = 1;
    std::string extension; //!< output container; empty: .dng for RAW inputs, else the input's
    bool previews = false;
    bool acceptFailedCalibration = false; //!< also a model whose calibration failed (NoiseModel::load())
    /** A dark-frame bank file (DarkFrameBank::save()) as every output's read noise, instead of the scene's or
     * policy's own (NoiseOptions::darkBank); empty: theirs. */
    std::string darkBank;
    bool darkBankTied = false; //!< the inputs are the bank's sensor's (NoiseOptions::darkBankTied)
};

/** One output of an augmentation run. Every front end (the app, Python, Dask workers) makes an output
 * with runAugmentJob(), so the same job gives the same bytes wherever it runs. */
struct AugmentJob
{
    std::string input;   //!< the input file as given
    std::string name;    //!< the input's output name: its stem, plus a hash of its path if stems collide
    int variant = 0;     //!< variant number
    uint64_t seed = 0;   //!< augmentedOutputSeed(options seed, name, variant)
    std::string out;     //!< the output mosaic (its sidecar beside it)
    std::string preview; //!< the preview PNG, empty for none
};

/** The outputs of a run: the jobs still to do, and the outputs that a previous run finished (a finished
 * output is one whose sidecar says it was made from the same input with the same seed; anything else
 * at an output's path is an error). Checks the options and the inputs, and creates the output folder. */
struct AugmentPlan
{
    std::vector<AugmentJob> jobs;
    std::vector<std::string> outputs; //!< every output, finished or not, in input and variant order
    int skipped = 0;                  //!< outputs already finished
};
AugmentPlan planAugmentJobs(const AugmentOptions& options);

//! What every job of a run applies: the model and either one scene or a random policy.
struct AugmentRecipe
{
    cv::rawgment::NoiseModel model; //!< from a NoiseModel file (when cameras and android are empty)
    std::vector<cv::rawgment::CameraNoiseProfile> cameras; //!< real cameras: each output takes one
    std::string android; //!< an Android profile YAML, whose model depends on each input's format
    bool randomScenes = false;
    cv::rawgment::Scene scene;              //!< when !randomScenes
    cv::rawgment::RandomScenePolicy policy; //!< when randomScenes
};
//! Loads the model and the scene or policy files of the options; errors name the file.
AugmentRecipe loadAugmentRecipe(const AugmentOptions& options);
/** The model of one job and, for a real camera, its name: a fixed model, the Android profile at the
 * input's format, or the job's camera (the only one, or drawCameraIndex() of the seed) at that format. */
cv::rawgment::NoiseModel modelOfJob(const AugmentRecipe& recipe, const cv::rawgment::RawFormat& format,
                                    uint64_t seed, std::string& cameraName);
//! Makes one output (and its preview); throws on any error. Atomic: a failed job leaves no output.
void runAugmentJob(const AugmentJob& job, const AugmentRecipe& recipe);
//! The scene of a scene file (a map `scene`, as Scene::write() writes it); errors name the file.
cv::rawgment::Scene readSceneFile(const std::string& path);

} // namespace rawgment_pipeline

#endif // RAWGMENT_PIPELINE_AUGMENT_JOBS_HPP
