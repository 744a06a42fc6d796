// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
//
// The overloads that OpenCV's binding generator wraps (cv2.rawgment): a report it can return instead of
// an optional pointer, boxes it can move in place, and a burst made and held by Ptr. Each starts from an
// empty report and forwards to the one implementation, so both doors give the same bits.
#include "precomp.hpp"

#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/calibration.hpp>

namespace cv {
namespace rawgment {

namespace {

const BurstStatistics& heldBurst(const Ptr<BurstStatistics>& stats, const char* function)
{
    if (!stats)
        CV_Error_(Error::StsNullPtr, ("%s: the BurstStatistics is null", function));
    return *stats;
}

} // namespace

Ptr<BurstStatistics> BurstStatistics::create(const RawFormat& format, int groupFrames, int stateDepth)
{
    return makePtr<BurstStatistics>(format, groupFrames, stateDepth);
}

void colorJitter(InputArray src, const RawFormat& format, const NoiseModel& model, const ColorJitter& jitter,
                 const NoiseOptions& noise, uint64 seed, OutputArray dst, RawFormat& dstFormat,
                 AugmentReport& report, OutputArray saturatedMask)
{
    report = AugmentReport();
    colorJitter(src, format, model, jitter, noise, seed, dst, dstFormat, &report, saturatedMask);
}

void motionBlur(InputArray src, const RawFormat& format, const NoiseModel& model, InputArray kernel,
                const NoiseOptions& noise, uint64 seed, OutputArray dst, AugmentReport& report)
{
    report = AugmentReport();
    motionBlur(src, format, model, kernel, noise, seed, dst, &report);
}

void scaleMosaic(InputArray src, const RawFormat& format, const NoiseModel& model, double scale,
                 const NoiseOptions& noise, uint64 seed, OutputArray dst, AugmentReport& report)
{
    report = AugmentReport();
    scaleMosaic(src, format, model, scale, noise, seed, dst, &report);
}

void applyScene(InputArray src, const RawFormat& format, const NoiseModel& model, const Scene& scene,
                uint64 seed, OutputArray dst, RawFormat& dstFormat, AugmentReport& report,
                std::vector<Rect>& boxes)
{
    report = AugmentReport();
    applyScene(src, format, model, scene, seed, dst, dstFormat, &report, &boxes);
}

std::vector<NoiseSample> sampleBurstPatches(const Ptr<BurstStatistics>& stats,
                                            const std::vector<Rect>& squares, double gain)
{
    return sampleBurstPatches(heldBurst(stats, "sampleBurstPatches"), squares, gain);
}

std::vector<NoiseSample> sampleDarkBurst(const Ptr<BurstStatistics>& stats, const std::vector<Rect>& squares,
                                         double gain)
{
    return sampleDarkBurst(heldBurst(stats, "sampleDarkBurst"), squares, gain);
}

std::vector<NoiseSample> sampleStaticScene(const Ptr<BurstStatistics>& stats, double gain, int maxSamples)
{
    return sampleStaticScene(heldBurst(stats, "sampleStaticScene"), gain, maxSamples);
}

} // namespace rawgment
} // namespace cv
