// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The pipeline layer's augmentation jobs (augment_jobs.hpp): a run planned as jobs, each made by
// runAugmentJob() from the run's recipe, by the app, rawgment.batch or a Dask worker alike.
#include "augment_jobs.hpp"

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>

namespace rawgment_pipeline {

using namespace cv::rawgment;

bool sameInput(const std::string& recorded, const std::string& input)
{
    return recorded == input || (!recorded.empty() && canonicalPath(recorded) == canonicalPath(input));
}

std::vector<std::string> uniqueOutputNames(
    const std::vector<std::string>& inputs,
    const std::function<std::optional<std::string>(size_t input, const std::string& name)>& sourceOf)
{
    std::map<std::string, std::string> seen; // canonical path -> the name it was given as first
    for (const std::string& in : inputs) {
        const auto given = seen.emplace(canonicalPath(in), in);
        if (!given.second)
            throw std::runtime_error(
                "input '" + in + "' is given twice" +
                (given.first->second == in ? std::string() : " (also as '" + given.first->second + "')"));
    }
    // An input keeps the name its existing output has (plain or hashed, from this version or an earlier one),
    // so that inputs added to a later run never rename it; otherwise the plain stem when no earlier input of
    // the run and no other input's output has it, else the stem and a hash of the input's path.
    std::set<std::string> claimed;
    std::vector<std::string> names;
    for (size_t i = 0; i < inputs.size(); ++i) {
        const std::string& in = inputs[i];
        const std::string plain = stemOf(in);
        const std::string hashed =
            plain +
            cv::format("-%08llx", static_cast<unsigned long long>(augmentedOutputSeed(0, in, 0) >> 32));
        const std::optional<std::string> plainSource = sourceOf(i, plain);
        std::string name;
        if (plainSource && sameInput(*plainSource, in))
            name = plain;
        else if (const std::optional<std::string> hashedSource = sourceOf(i, hashed);
                 hashedSource && sameInput(*hashedSource, in))
            name = hashed;
        else
            name = !plainSource && !claimed.count(plain) ? plain : hashed;
        if (!claimed.insert(name).second)
            throw std::runtime_error("input '" + in + "' would share the output name '" + name +
                                     "' with another input; rename one of them");
        names.push_back(name);
    }
    return names;
}

std::optional<std::string> sourceOfOutput(const std::string& out)
{
    const std::string sidecar = sidecarPathOf(out);
    if (!pathExists(out) && !pathExists(sidecar))
        return std::nullopt;
    try {
        cv::FileStorage fs = openFileStorageForReading(sidecar, "sidecar");
        return std::string(MosaicMetadata::read(fs["mosaic_metadata"]).source);
    } catch (const cv::Exception&) {
        return std::string(); // there, but of no input this run can tell: another's
    }
}

void refuseOutputsAmongInputs(const std::string& outDir, const std::vector<std::string>& inputs)
{
    const std::string out = canonicalPath(outDir);
    for (const std::string& in : inputs)
        if (canonicalPath(directoryOf(in)) == out)
            throw std::runtime_error("input '" + in + "' lies in the output folder '" + outDir +
                                     "': a later run over that folder would take the outputs for inputs; "
                                     "choose another --out");
}

namespace {

//! Throws unless `out`'s sidecar says it was made from `input` with `seed`: only then is it skipped.
void requireFinishedBy(const std::string& out, const std::string& input, uint64_t seed)
{
    const std::string sidecar = sidecarPathOf(out);
    if (!pathExists(sidecar))
        throw std::runtime_error("'" + out +
                                 "' exists without its sidecar; it is never overwritten (choose "
                                 "another --out)");
    cv::FileStorage fs = openFileStorageForReading(sidecar, "sidecar");
    MosaicMetadata meta;
    try {
        meta = MosaicMetadata::read(fs["mosaic_metadata"]);
    } catch (const cv::Exception& e) {
        throw std::runtime_error("'" + sidecar + "': " + e.err);
    }
    if (!sameInput(meta.source, input) || !meta.hasScene || meta.seed != seed)
        throw std::runtime_error("'" + out + "' exists but was made from '" + meta.source + "', not from '" +
                                 input +
                                 "' with this seed; it is never overwritten (choose "
                                 "another --out)");
}

} // namespace

Scene readSceneFile(const std::string& path)
{
    cv::FileStorage fs = openFileStorageForReading(path, "scene");
    Scene scene;
    try {
        scene = Scene::read(fs["scene"]);
    } catch (const cv::Exception& e) {
        throw std::runtime_error("'" + path + "': " + e.err);
    }
    // A bank named by the file lies relative to the file (RandomScenePolicy::load() does the same).
    if (!scene.noise.darkBank.empty() && scene.noise.darkBank[0] != '/') {
        const size_t slash = path.find_last_of('/');
        if (slash != std::string::npos)
            scene.noise.darkBank = path.substr(0, slash + 1) + scene.noise.darkBank;
    }
    return scene;
}

AugmentRecipe loadAugmentRecipe(const AugmentOptions& o)
{
    if (o.scene.empty() == o.policy.empty())
        throw std::runtime_error("give exactly one of a scene file and a policy file");
    AugmentRecipe recipe;
    const int kind = noiseModelFileKind(o.model);
    if (kind == DARKTABLE_PROFILE_FILE) {
        if (o.camera.empty())
            throw std::runtime_error("'" + o.model +
                                     "' is a darktable noise-profile file of many cameras: choose with "
                                     "--camera (a name, a comma-separated list, good or usable; "
                                     "rawgment_cameras lists them)");
        recipe.cameras = selectCameraProfiles(readCameraProfiles(o.model), o.camera);
    } else if (!o.camera.empty()) {
        throw std::runtime_error(
            "--camera chooses among the cameras of a darktable noise-profile file, and '" + o.model +
            "' is not one");
    } else if (kind == ANDROID_PROFILE_FILE) {
        recipe.android = o.model;
        // Checked now, at a format of full range, so that a malformed file fails before any job.
        noiseModelFromAndroidFile(o.model, RawFormat());
    } else {
        recipe.model = NoiseModel::load(o.model, o.acceptFailedCalibration);
    }
    recipe.randomScenes = o.scene.empty();
    if (recipe.randomScenes)
        recipe.policy = RandomScenePolicy::load(o.policy);
    else
        recipe.scene = readSceneFile(o.scene);
    if (!o.darkBank.empty()) {
        // Loaded once here, so that a bad bank stops the run before its first output.
        DarkFrameBank::load(o.darkBank);
        NoiseOptions& noise = recipe.randomScenes ? recipe.policy.noise : recipe.scene.noise;
        noise.darkBank = o.darkBank;
        noise.darkBankTied = o.darkBankTied;
    } else if (o.darkBankTied) {
        throw std::runtime_error("a tied dark-frame bank needs the bank (--dark_bank)");
    }
    return recipe;
}

namespace {

//! One field of a job record: `identity` fields decide whether two runs are one job, the others (file
//! names) are there for a reader: a model moved with its content kept is the same model.
struct JobField
{
    std::string key, value;
    bool identity;
};

/* What decides an output's bytes besides its input: the version, the content of the model, the scene or
 * policy and the bank (the options' or the one the scene or policy names; its file holds its frames'
 * fingerprints and its maps' checksums), and the options. Previews are outputs of their own, not a
 * recipe. */
std::vector<JobField> recipeFields(const AugmentOptions& o)
{
    const bool random = o.scene.empty();
    const std::string recipeFile = random ? o.policy : o.scene;
    std::string bank = o.darkBank;
    if (bank.empty())
        bank = random ? std::string(RandomScenePolicy::load(o.policy).noise.darkBank)
                      : std::string(readSceneFile(o.scene).noise.darkBank);
    return {{"version", RAWGMENT_PROJECT_VERSION, true},
            {"model", o.model, false},
            {"model_fnv1a64", fileFingerprint(o.model), true},
            {"camera", o.camera, true},
            {"recipe_kind", random ? "policy" : "scene", true},
            {"recipe", recipeFile, false},
            {"recipe_fnv1a64", fileFingerprint(recipeFile), true},
            {"dark_bank", bank, false},
            {"dark_bank_fnv1a64", bank.empty() ? std::string() : fileFingerprint(bank), true},
            {"dark_bank_tied", o.darkBankTied ? "true" : "false", true},
            {"seed", cv::format("%llu", static_cast<unsigned long long>(o.seed)), true},
            {"extension", o.extension, true}};
}

/* The job record of an output folder (`augment_job.yml`): a rerun into the folder resumes only the same job
 * (the same recipe; each input it shares with the record of the same content), and adds its new inputs.
 * Under a lock of the folder, so that runs at the same time take turns; identical runs agree. */
void claimAugmentJob(const AugmentOptions& o)
{
    const std::vector<JobField> recipe = recipeFields(o);
    std::vector<std::pair<std::string, std::string>> inputs; // canonical path, fingerprint
    for (const std::string& in : o.inputs)
        inputs.emplace_back(canonicalPath(in), fileFingerprint(in));
    const std::string path = o.outDir + "/augment_job.yml";
    const FolderLock lock(o.outDir);
    std::vector<std::pair<std::string, std::string>> recorded;
    if (pathExists(path)) {
        cv::FileStorage fs = openFileStorageForReading(path, "augment job record");
        const cv::FileNode job = fs["augment_job"];
        try {
            std::vector<cv::String> keys = {"inputs"};
            for (const JobField& f : recipe)
                keys.push_back(f.key);
            if (!job.isMap())
                throw std::runtime_error("no map 'augment_job'");
            rejectUnknownKeys(job, keys);
            for (const JobField& f : recipe) {
                const cv::FileNode n = job[f.key];
                // OpenCV reads an empty string back as no value: an option not given.
                if (!n.isString() && !n.isNone())
                    throw std::runtime_error("field '" + f.key + "' is not a string");
                const std::string value = n.isString() ? n.string() : std::string();
                if (f.identity && value != f.value)
                    throw std::runtime_error(
                        "it records another augmentation job: its " + f.key + " is '" + value +
                        "', this run's '" + f.value +
                        "' (other model, scene or policy, bank, seed, options or version); its outputs are "
                        "not this job's");
            }
            for (const cv::FileNode& n : job["inputs"]) {
                if (!n.isMap() || !n["path"].isString() || !n["fnv1a64"].isString())
                    throw std::runtime_error("each of 'inputs' must be a map of path and fnv1a64");
                recorded.emplace_back(n["path"].string(), n["fnv1a64"].string());
            }
        } catch (const std::runtime_error& e) {
            throw std::runtime_error("'" + path + "': " + e.what() + "; choose another --out");
        } catch (const cv::Exception& e) {
            throw std::runtime_error("'" + path + "': " + e.err + "; choose another --out");
        }
    }
    bool changed = !pathExists(path);
    std::map<std::string, std::string> known(recorded.begin(), recorded.end()); // a run may have 10^6 inputs
    for (size_t i = 0; i < inputs.size(); ++i) {
        const auto entry = known.emplace(inputs[i]);
        if (entry.second) {
            recorded.push_back(inputs[i]);
            changed = true;
        } else if (entry.first->second != inputs[i].second) {
            throw std::runtime_error("input '" + o.inputs[i] + "' is not the file it was when '" + path +
                                     "' recorded it (its content changed): its outputs there are of the "
                                     "old file; choose another --out");
        }
    }
    if (!changed)
        return;
    writeTextAtomically(path, fileStorageText(path, [&](cv::FileStorage& fs) {
                            fs << "augment_job"
                               << "{";
                            for (const JobField& f : recipe)
                                writeString(fs, f.key, f.value);
                            fs << "inputs"
                               << "[";
                            for (const auto& in : recorded) {
                                fs << "{";
                                writeString(fs, "path", in.first);
                                writeString(fs, "fnv1a64", in.second);
                                fs << "}";
                            }
                            fs << "]"
                               << "}";
                        }));
}

} // namespace

//! The most variants of one input, and outputs of one run (each job is a few hundred bytes in the plan).
const int kMaxVariants = 100000;
const size_t kMaxJobs = 1000000;

AugmentPlan planAugmentJobs(const AugmentOptions& o)
{
    if (o.inputs.empty())
        throw std::runtime_error("no input files");
    if (o.variants < 1 || o.variants > kMaxVariants)
        throw std::runtime_error(
            cv::format("variants must lie in [1, %d] (got %d)", kMaxVariants, o.variants));
    // Every job is planned before the first runs: a bound keeps the plan in memory.
    if (o.inputs.size() * static_cast<size_t>(o.variants) > kMaxJobs)
        throw std::runtime_error(
            cv::format("%zu inputs x %d variants is more than the %zu outputs one run makes; "
                       "split the inputs over several runs",
                       o.inputs.size(), o.variants, kMaxJobs));
    for (const std::string& in : o.inputs) {
        if (!pathExists(in))
            throw std::runtime_error("input '" + in + "': no such file");
        if (!isRegularFile(in))
            throw std::runtime_error("input '" + in + "' is not a file (a directory?)");
    }
    refuseOutputsAmongInputs(o.outDir, o.inputs);
    prepareOutputDirectory(o.outDir);
    claimAugmentJob(o);

    AugmentPlan plan;
    std::vector<std::string> extensions;
    for (const std::string& in : o.inputs) {
        const size_t dot = in.find_last_of('.');
        const std::string inExt = dot == std::string::npos ? std::string() : in.substr(dot);
        const bool ours = pathExists(sidecarPathOf(in));
        extensions.push_back(!o.extension.empty() ? o.extension : (ours ? inExt : std::string(".dng")));
    }
    // An input's outputs are known by its first variant.
    const std::vector<std::string> names =
        uniqueOutputNames(o.inputs, [&](size_t i, const std::string& name) {
            return sourceOfOutput(o.outDir + "/" + name + "_v00" + extensions[i]);
        });
    for (size_t i = 0; i < o.inputs.size(); ++i) {
        const std::string& ext = extensions[i];
        for (int v = 0; v < o.variants; ++v) {
            const std::string stem = o.outDir + "/" + names[i] + cv::format("_v%02d", v);
            AugmentJob job;
            job.input = o.inputs[i];
            job.name = names[i];
            job.variant = v;
            // The seed depends on the file name and the variant, not on the order of the inputs.
            job.seed = augmentedOutputSeed(o.seed, names[i], v);
            job.out = stem + ext;
            job.preview = o.previews ? stem + "_preview.png" : std::string();
            for (const std::string& in : o.inputs)
                if (in == job.out)
                    throw std::runtime_error("output '" + job.out +
                                             "' would replace an input; choose another --out");
            plan.outputs.push_back(job.out);
            if (pathExists(job.out)) {
                // Resumable: a finished output of this very job stays; anything else there is refused.
                requireFinishedBy(job.out, job.input, job.seed);
                ++plan.skipped;
                continue;
            }
            plan.jobs.push_back(job);
        }
    }
    return plan;
}

NoiseModel modelOfJob(const AugmentRecipe& recipe, const RawFormat& format, uint64_t seed,
                      std::string& cameraName)
{
    cameraName.clear();
    if (!recipe.android.empty())
        return noiseModelFromAndroidFile(recipe.android, format);
    if (recipe.cameras.empty())
        return recipe.model;
    const CameraNoiseProfile& camera =
        recipe.cameras[size_t(drawCameraIndex(int(recipe.cameras.size()), seed))];
    cameraName = camera.name();
    return camera.modelFor(format);
}

void runAugmentJob(const AugmentJob& job, const AugmentRecipe& recipe)
{
    LoadedMosaic m = loadMosaicFile(job.input);
    std::string cameraName;
    const NoiseModel model = modelOfJob(recipe, m.format, job.seed, cameraName);
    // A camera file (or its conversion) is at the gain its ISO says for the model (formatAtIso()); one that
    // states no ISO is taken at the gain its format says.
    if (m.fromCameraFile)
        m.format = formatAtIso(m.format, m.camera.iso, model);
    const Scene scene = recipe.randomScenes ? recipe.policy.draw(m.mosaic, m.format, job.seed) : recipe.scene;
    cv::Mat out;
    RawFormat outFormat;
    AugmentReport report;
    applyScene(m.mosaic, m.format, model, scene, job.seed, out, outFormat, &report);
    MosaicMetadata meta;
    meta.format = outFormat;
    meta.hasScene = true;
    meta.scene = scene;
    meta.seed = job.seed;
    meta.source = job.input;
    meta.noiseCamera = cameraName;
    // The output is the camera's capture of the darker or brighter scene: the input's camera tags, with
    // the ISO scaled by the gain ratio, the target's exposure time (the scene's, by default the input's:
    // the darkening is the light's, and a bank's dark frames were drawn at that exposure) and the noise
    // profile of the model at the output's gain.
    const double signalRatio =
        scene.jitter.contrast[m.format.isMonochrome() ? 0 : cfaSiteOfChannel(m.format.pattern, CFA_G1)];
    meta.hasCamera = true;
    meta.camera = m.camera;
    meta.camera.iso = m.camera.iso * outFormat.gain / m.format.gain;
    meta.camera.exposureTime = outFormat.exposureTime;
    meta.camera.noiseProfile = model.alpha > 0 ? dngNoiseProfile(model, outFormat) : std::vector<cv::Vec2d>();
    // A preview brightened back to the input's level shows the noise the scene added, not a dark frame.
    if (!job.preview.empty())
        writeNewImage(job.preview, previewOf(out, outFormat, 1.0 / signalRatio));
    writeMosaic(job.out, out, meta);
}

} // namespace rawgment_pipeline
