// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The units of rawgment_augment for Python front ends (rawgment.batch on Dask runs the app's own plan
// and jobs, so its files are the app's, byte for byte), and the timing hook of the Python benchmark.
#include "binding_tools.hpp"

#include "augment_jobs.hpp"

#include <chrono>

namespace rawgment_python {

using namespace cv::rawgment;

namespace {

rawgment_pipeline::AugmentOptions
optionsFrom(const std::vector<std::string>& inputs, const std::string& model, const std::string& scene,
            const std::string& policy, const std::string& outDir, int variants, uint64 seed,
            const std::string& extension, bool previews, bool acceptFailedCalibration,
            const std::string& camera, const std::string& darkBank, bool darkBankTied)
{
    rawgment_pipeline::AugmentOptions o;
    o.inputs = inputs;
    o.model = model;
    o.camera = camera;
    o.scene = scene;
    o.policy = policy;
    o.outDir = outDir;
    o.variants = variants;
    o.seed = seed;
    o.extension = extension;
    o.previews = previews;
    o.acceptFailedCalibration = acceptFailedCalibration;
    o.darkBank = darkBank;
    o.darkBankTied = darkBankTied;
    return o;
}

py::dict jobToDict(const rawgment_pipeline::AugmentJob& job)
{
    py::dict d;
    d["input"] = job.input;
    d["name"] = job.name;
    d["variant"] = job.variant;
    d["seed"] = job.seed;
    d["out"] = job.out;
    d["preview"] = job.preview;
    return d;
}

rawgment_pipeline::AugmentJob jobFromDict(const py::dict& d)
{
    rawgment_pipeline::AugmentJob job;
    job.input = d["input"].cast<std::string>();
    job.name = d["name"].cast<std::string>();
    job.variant = d["variant"].cast<int>();
    job.seed = d["seed"].cast<uint64>();
    job.out = d["out"].cast<std::string>();
    job.preview = d["preview"].cast<std::string>();
    return job;
}

} // namespace

void bindBatch(py::module_& m)
{
    py::module_ apps = m.def_submodule("_apps", "The units of rawgment_augment (used by rawgment.batch).");
    apps.def(
        "planAugmentJobs",
        [](const std::vector<std::string>& inputs, const std::string& model, const std::string& scene,
           const std::string& policy, const std::string& outDir, int variants, uint64 seed,
           const std::string& extension, bool previews, bool acceptFailedCalibration,
           const std::string& camera, const std::string& darkBank, bool darkBankTied) {
            const auto options =
                optionsFrom(inputs, model, scene, policy, outDir, variants, seed, extension, previews,
                            acceptFailedCalibration, camera, darkBank, darkBankTied);
            rawgment_pipeline::loadAugmentRecipe(options); // the files are checked before any job is planned
            const rawgment_pipeline::AugmentPlan plan =
                withoutGil("planAugmentJobs", [&] { return rawgment_pipeline::planAugmentJobs(options); });
            py::list jobs;
            for (const auto& job : plan.jobs)
                jobs.append(jobToDict(job));
            py::dict out;
            out["jobs"] = jobs;
            out["outputs"] = plan.outputs;
            out["skipped"] = plan.skipped;
            return out;
        },
        py::arg("inputs"), py::arg("model"), py::arg("scene"), py::arg("policy"), py::arg("outDir"),
        py::arg("variants"), py::arg("seed"), py::arg("extension"), py::arg("previews"),
        py::arg("acceptFailedCalibration") = false, py::arg("camera") = std::string(),
        py::arg("darkBank") = std::string(), py::arg("darkBankTied") = false,
        "The jobs of an augmentation run, as rawgment_augment plans them: a dict with 'jobs' (each a dict: "
        "input, name, variant, seed, out, preview), 'outputs' and 'skipped' (outputs a previous run "
        "finished).");
    apps.def(
        "runAugmentJob",
        [](const py::dict& job, const std::string& model, const std::string& scene, const std::string& policy,
           bool acceptFailedCalibration, const std::string& camera, const std::string& darkBank,
           bool darkBankTied) {
            const rawgment_pipeline::AugmentJob j = jobFromDict(job);
            const auto options = optionsFrom({j.input}, model, scene, policy, "", 1, 0, "", false,
                                             acceptFailedCalibration, camera, darkBank, darkBankTied);
            withoutGil("runAugmentJob", [&] {
                const rawgment_pipeline::AugmentRecipe recipe = rawgment_pipeline::loadAugmentRecipe(options);
                rawgment_pipeline::runAugmentJob(j, recipe);
            });
        },
        py::arg("job"), py::arg("model"), py::arg("scene"), py::arg("policy"),
        py::arg("acceptFailedCalibration") = false, py::arg("camera") = std::string(),
        py::arg("darkBank") = std::string(), py::arg("darkBankTied") = false,
        "Makes one output of a plan, exactly as rawgment_augment does (atomic; never replaces a file).");

    py::module_ bench = m.def_submodule("_benchmark", "Hooks of the Python benchmark (not part of the API).");
    bench.def(
        "colorJitterSeconds",
        [](const py::object& src, const RawFormat& format, const NoiseModel& model, const ColorJitter& jitter,
           const NoiseOptions& noise, uint64 seed, int repeats) {
            const cv::Mat in = matFromArray(src, "src", {CV_16U, CV_32F});
            std::vector<double> seconds;
            withoutGil("colorJitterSeconds", [&] {
                cv::Mat dst;
                RawFormat dstFormat;
                AugmentReport report;
                for (int i = 0; i < repeats; ++i) {
                    dst.release(); // a fresh output per call and a report, as the Python call gets
                    const auto start = std::chrono::steady_clock::now();
                    colorJitter(in, format, model, jitter, noise, seed, dst, dstFormat, &report);
                    seconds.push_back(
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
                }
            });
            return seconds;
        },
        py::arg("src"), py::arg("format"), py::arg("model"), py::arg("jitter"), py::arg("noise"),
        py::arg("seed"), py::arg("repeats"),
        "Seconds of each of `repeats` C++ colorJitter calls, timed in C++.");
}

} // namespace rawgment_python
