// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The pipeline layer's conversion (augment_jobs.hpp): camera RAWs and mosaics of any container rewritten
// once into one that reads fast (.npy), so that a training run decodes nothing.
#include "augment_jobs.hpp"

#include <stdexcept>

namespace rawgment_pipeline {

using namespace cv::rawgment;

ConvertResult convertMosaics(const std::vector<std::string>& inputs, const std::string& outDir,
                             const std::string& extension, const std::function<void()>& advance)
{
    if (inputs.empty())
        throw std::runtime_error("no input to convert");
    refuseOutputsAmongInputs(outDir, inputs);
    prepareOutputDirectory(outDir);
    const std::vector<std::string> names = uniqueOutputNames(inputs, [&](size_t, const std::string& name) {
        return sourceOfOutput(outDir + "/" + name + extension);
    });
    ConvertResult result;
    for (size_t k = 0; k < inputs.size(); ++k) {
        const std::string& input = inputs[k];
        const std::string out = outDir + "/" + names[k] + extension;
        result.outputs.push_back(out);
        if (pathExists(out)) {
            // A finished conversion of this input (a run that is repeated or was interrupted later) is
            // kept; anything else at its path is never overwritten.
            const std::string sidecar = sidecarPathOf(out);
            if (!pathExists(sidecar))
                throw std::runtime_error("'" + out + "' exists without its sidecar; it is never overwritten");
            cv::Mat existing;
            const MosaicMetadata meta = readMosaic(out, existing);
            if (!sameInput(meta.source, input) || meta.hasScene)
                throw std::runtime_error("'" + out + "' exists but holds '" + meta.source + "', not '" +
                                         input + "'; it is never overwritten (choose another --out)");
            ++result.skipped;
            advance();
            continue;
        }
        const LoadedMosaic m = loadMosaicFile(input);
        MosaicMetadata meta;
        meta.format = m.format;
        meta.hasCamera = m.hasCamera;
        meta.camera = m.camera;
        meta.source = input;
        meta.gainFromIso = m.fromCameraFile && m.camera.iso > 0;
        writeMosaic(out, m.mosaic, meta);
        ++result.written;
        advance();
    }
    return result;
}

} // namespace rawgment_pipeline
