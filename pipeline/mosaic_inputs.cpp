// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The pipeline layer's inputs (augment_jobs.hpp): a mosaic from any file the apps read, and its preview.
#include "augment_jobs.hpp"

namespace rawgment_pipeline {

using namespace cv::rawgment;

LoadedMosaic loadMosaicFile(const std::string& path)
{
    LoadedMosaic out;
    if (pathExists(sidecarPathOf(path))) {
        const MosaicMetadata meta = readMosaic(path, out.mosaic);
        out.format = meta.format;
        out.hasCamera = meta.hasCamera;
        out.camera = meta.camera;
        out.fromCameraFile = meta.gainFromIso;
    } else {
        RawImage image = readRaw(path);
        out.mosaic = image.mosaic;
        out.format = image.format;
        out.hasCamera = true;
        out.camera = CameraTags::of(image);
        out.fromCameraFile = true;
    }
    return out;
}

cv::Mat previewOf(const cv::Mat& mosaic, const RawFormat& format, double exposure)
{
    IspParams isp;
    isp.tone = ToneCurve::srgb();
    isp.exposure = exposure;
    cv::Mat bgr;
    renderSimpleIsp(mosaic, format, bgr, isp);
    return bgr;
}

} // namespace rawgment_pipeline
