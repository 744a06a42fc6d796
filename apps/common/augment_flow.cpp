// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// rawgment_augment: N variants of each input under a scene or a random policy.
#include "pipeline.hpp"

#include "app_tools.hpp"
#include "flow_common.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <stdexcept>

namespace rawgment_apps {

using namespace cv::rawgment;

AugmentResult augmentFiles(const AugmentOptions& o)
{
    if (o.inputs.empty())
        throw std::runtime_error("no input files");
    if (o.scene.empty() == o.policy.empty())
        throw std::runtime_error("give exactly one of a scene file and a policy file");
    if (o.variants < 1)
        throw std::runtime_error("variants must be >= 1");
    const NoiseModel model = NoiseModel::load(o.model);
    Scene fixedScene;
    RandomScenePolicy policy;
    if (!o.scene.empty()) {
        cv::FileStorage fs = openYaml(o.scene, "scene");
        try {
            fixedScene = Scene::read(fs["scene"]);
        } catch (const cv::Exception& e) {
            throw std::runtime_error("'" + o.scene + "': " + e.err);
        }
    } else {
        policy = RandomScenePolicy::load(o.policy);
    }
    for (const std::string& in : o.inputs)
        if (!pathExists(in))
            throw std::runtime_error("input '" + in + "': no such file");
    makeDirectories(o.outDir);

    struct Job
    {
        size_t input;
        int variant;
        std::string out, preview;
    };
    std::vector<Job> jobs;
    AugmentResult result;
    for (size_t i = 0; i < o.inputs.size(); ++i) {
        const std::string inExt = o.inputs[i].substr(o.inputs[i].find_last_of('.'));
        const bool ours = pathExists(sidecarPathOf(o.inputs[i]));
        const std::string ext = !o.extension.empty() ? o.extension : (ours ? inExt : std::string(".dng"));
        for (int v = 0; v < o.variants; ++v) {
            const std::string stem = o.outDir + "/" + stemOf(o.inputs[i]) + cv::format("_v%02d", v);
            Job job{i, v, stem + ext, o.previews ? stem + "_preview.png" : std::string()};
            for (const std::string& in : o.inputs)
                if (in == job.out)
                    throw std::runtime_error("output '" + job.out +
                                             "' would replace an input; choose another --out");
            result.outputs.push_back(job.out);
            if (pathExists(job.out)) {
                ++result.skipped; // resumable: a finished output stays
                continue;
            }
            jobs.push_back(job);
        }
    }
    ProgressBar progress("augment", jobs.size());
    std::mutex errorMutex;
    std::string firstError;
    std::atomic<int> written{0};
    cv::parallel_for_(cv::Range(0, int(jobs.size())), [&](const cv::Range& range) {
        for (int j = range.start; j < range.end; ++j) {
            const Job& job = jobs[size_t(j)];
            try {
                const LoadedMosaic m = loadMosaicFile(o.inputs[job.input]);
                // The seed depends on the file name and the variant, not on the order of the inputs.
                const uint64_t seed = augmentedOutputSeed(o.seed, stemOf(o.inputs[job.input]), job.variant);
                const Scene scene = o.scene.empty() ? policy.draw(m.mosaic, m.format, seed) : fixedScene;
                cv::Mat out;
                RawFormat outFormat;
                AugmentReport report;
                applyScene(m.mosaic, m.format, model, scene, seed, out, outFormat, &report);
                MosaicMetadata meta;
                meta.format = outFormat;
                meta.hasScene = true;
                meta.scene = scene;
                meta.seed = seed;
                meta.source = o.inputs[job.input];
                if (!job.preview.empty())
                    writeImageAtomically(job.preview, previewOf(out, outFormat));
                writeMosaic(job.out, out, meta);
                ++written;
            } catch (const std::exception& e) {
                std::lock_guard<std::mutex> lock(errorMutex);
                if (firstError.empty())
                    firstError = "'" + o.inputs[job.input] + "' variant " + std::to_string(job.variant) +
                                 ": " + e.what();
            }
            progress.advance();
        }
    });
    progress.finish();
    result.written = written;
    if (!firstError.empty())
        throw std::runtime_error(firstError);
    return result;
}

} // namespace rawgment_apps
