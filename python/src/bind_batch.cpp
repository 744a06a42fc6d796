// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The units of rawgment_augment for Python front ends (rawgment.batch on Dask runs the app's own plan
// and jobs, so its files are the app's, byte for byte), and the timing hook of the Python benchmark.
#include "binding_tools.hpp"

#include "augment_command_line.hpp"
#include "augment_jobs.hpp"

#include <chrono>

namespace rawgment_python {

using namespace cv::rawgment;

namespace {

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
    // The augment command line once (augment_command_line.hpp): rawgment.batch builds its argparse parser
    // from augmentFlags() and its options with setAugmentOption(), as rawgment_augment does.
    py::class_<rawgment_pipeline::AugmentOptions>(
        apps, "AugmentOptions",
        "The options of an augmentation run, as rawgment_augment's flags "
        "set them (AugmentOptions of pipeline/augment_jobs.hpp).")
        .def(py::init<>())
        .def_readwrite("inputs", &rawgment_pipeline::AugmentOptions::inputs)
        .def_readwrite("model", &rawgment_pipeline::AugmentOptions::model)
        .def_readwrite("camera", &rawgment_pipeline::AugmentOptions::camera)
        .def_readwrite("scene", &rawgment_pipeline::AugmentOptions::scene)
        .def_readwrite("policy", &rawgment_pipeline::AugmentOptions::policy)
        .def_readwrite("outDir", &rawgment_pipeline::AugmentOptions::outDir)
        .def_readwrite("variants", &rawgment_pipeline::AugmentOptions::variants)
        .def_readwrite("seed", &rawgment_pipeline::AugmentOptions::seed)
        .def_readwrite("extension", &rawgment_pipeline::AugmentOptions::extension)
        .def_readwrite("previews", &rawgment_pipeline::AugmentOptions::previews)
        .def_readwrite("acceptFailedCalibration", &rawgment_pipeline::AugmentOptions::acceptFailedCalibration)
        .def_readwrite("darkBank", &rawgment_pipeline::AugmentOptions::darkBank)
        .def_readwrite("darkBankTied", &rawgment_pipeline::AugmentOptions::darkBankTied)
        .def(py::pickle(
            [](const rawgment_pipeline::AugmentOptions& o) {
                return py::make_tuple(o.inputs, o.model, o.camera, o.scene, o.policy, o.outDir, o.variants,
                                      o.seed, o.extension, o.previews, o.acceptFailedCalibration, o.darkBank,
                                      o.darkBankTied);
            },
            [](const py::tuple& t) {
                if (t.size() != 13)
                    throw std::invalid_argument("AugmentOptions: a pickled state of 13 fields was expected");
                rawgment_pipeline::AugmentOptions o;
                o.inputs = t[0].cast<std::vector<std::string>>();
                o.model = t[1].cast<std::string>();
                o.camera = t[2].cast<std::string>();
                o.scene = t[3].cast<std::string>();
                o.policy = t[4].cast<std::string>();
                o.outDir = t[5].cast<std::string>();
                o.variants = t[6].cast<int>();
                o.seed = t[7].cast<uint64>();
                o.extension = t[8].cast<std::string>();
                o.previews = t[9].cast<bool>();
                o.acceptFailedCalibration = t[10].cast<bool>();
                o.darkBank = t[11].cast<std::string>();
                o.darkBankTied = t[12].cast<bool>();
                return o;
            }));
    apps.def(
        "augmentFlags",
        [] {
            py::list flags;
            for (const rawgment_pipeline::AugmentFlag& f : rawgment_pipeline::augmentFlags()) {
                py::dict d;
                d["name"] = f.name;
                d["shortName"] = f.shortName;
                d["defaultValue"] = f.defaultValue;
                d["isSwitch"] = f.isSwitch;
                d["required"] = f.required;
                d["oneOf"] = f.oneOf;
                d["help"] = f.help;
                flags.append(d);
            }
            return flags;
        },
        "The flags of the augment command line, as rawgment_augment lists them: dicts of name, shortName, "
        "defaultValue, isSwitch, required, oneOf (a group of which a run gives exactly one) and help.");
    apps.def(
        "setAugmentOption", &rawgment_pipeline::setAugmentOption, py::arg("options"), py::arg("flag"),
        py::arg("value"),
        "Gives a flag's text to the options by the flag's rules; ValueError naming the flag for a value it "
        "does not take.");
    apps.def(
        "planAugmentJobs",
        [](const rawgment_pipeline::AugmentOptions& options) {
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
        py::arg("options"),
        "The jobs of an augmentation run, as rawgment_augment plans them: a dict with 'jobs' (each a dict: "
        "input, name, variant, seed, out, preview), 'outputs' and 'skipped' (outputs a previous run "
        "finished).");
    apps.def(
        "runAugmentJob",
        [](const py::dict& job, const rawgment_pipeline::AugmentOptions& options) {
            const rawgment_pipeline::AugmentJob j = jobFromDict(job);
            rawgment_pipeline::AugmentOptions one = options;
            one.inputs = {j.input};
            withoutGil("runAugmentJob", [&] {
                const rawgment_pipeline::AugmentRecipe recipe = rawgment_pipeline::loadAugmentRecipe(one);
                rawgment_pipeline::runAugmentJob(j, recipe);
            });
        },
        py::arg("job"), py::arg("options"),
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
