// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The loop that runs a sequence of noise steps (noise_step.hpp).
#include "noise_step.hpp"

#include "augment_steps.hpp"
#include "step_noise.hpp"

#include <chrono>

namespace cv {
namespace rawgment {
namespace detail {

void runNoiseSteps(NoiseSteps& steps, const Mat& src, const RawFormat& format,
                   const ValidatedNoiseModel& model, const NoiseOptions& noise, uint64 seed, OutputArray dst,
                   RawFormat& dstFormat, AugmentReport* report, std::vector<Rect>* boxes, const char* who,
                   bool valuesChecked)
{
    // The format and the options once for the sequence: each step's format follows from a valid one by the
    // step's own checked parameters (a jitter's gain ratio and exposure).
    format.validate();
    noise.validate();
    // Every step validates and decides before any pixel is read: a bad parameter of the last step fails
    // before the first has run.
    std::vector<bool> runs(steps.size());
    int stepsLeft = 0;
    RawFormat fmt = format;
    for (size_t i = 0; i < steps.size(); ++i) {
        fmt = steps[i]->prepare({model, noise, seed, src.size(), src.depth(), fmt});
        runs[i] = !steps[i]->isIdentity();
        stepsLeft += runs[i];
    }
    if (stepsLeft == 0 && !valuesChecked)
        checkMosaicInput(src, who);

    Mat buffers[2];
    if (dst.kind() == _InputArray::MAT) {
        const Mat given = dst.getMat();
        // Never the caller's src (an in-place call, dst = src): a later step would write into it.
        const bool overlaps = given.datastart < src.dataend && src.datastart < given.dataend;
        if (!overlaps && given.size() == src.size() && given.type() == src.type())
            buffers[0] = given;
    }
    Mat current = src;
    for (size_t i = 0; i < steps.size(); ++i) {
        NoiseStep& step = *steps[i];
        if (!runs[i]) {
            step.describeInput(current, report);
            steps[i].reset();
            continue;
        }
        const auto start = std::chrono::steady_clock::now();
        Mat& out = buffers[--stepsLeft % 2];
        out = stepOutput(current, out);
        StepTally tally;
        const bool checkValues = !valuesChecked;
        step.begin(current, checkValues, tally);
        parallel_for_(Range(0, step.rowCount()),
                      [&](const Range& units) { step.runRows(current, out, units); });
        step.finish(current, checkValues, tally);
        if (tally.nonFiniteInput)
            throwNonFiniteInput(step.name());
        if (tally.nonFiniteShading)
            throwNonFiniteShading(step.name());
        step.describeInput(current, report);
        if (boxes)
            step.moveBoxes(*boxes, current.size());
        if (report) {
            report->brighteningPixels += tally.brightening.load();
            report->readBrighteningPixels += tally.readBrightening.load();
            recordStep(report, step.reportName(), start);
        }
        // The output of a step is finite: the steps after it need not check it.
        valuesChecked = true;
        current = out;
        steps[i].reset();
    }
    dst.assign(current);
    dstFormat = fmt;
}

void runNoiseStep(std::unique_ptr<NoiseStep> step, const Mat& src, const RawFormat& format,
                  const ValidatedNoiseModel& model, const NoiseOptions& noise, uint64 seed, OutputArray dst,
                  RawFormat& dstFormat, AugmentReport* report, bool valuesChecked)
{
    const char* who = step->name();
    NoiseSteps steps;
    steps.push_back(std::move(step));
    runNoiseSteps(steps, src, format, model, noise, seed, dst, dstFormat, report, nullptr, who,
                  valuesChecked);
}

void runPublicStep(std::unique_ptr<NoiseStep> step, InputArray _src, const RawFormat& format,
                   const NoiseModel& model, const NoiseOptions& noise, uint64 seed, OutputArray dst,
                   RawFormat& dstFormat, AugmentReport* report)
{
    const char* who = step->name();
    const Mat src = twoDimensional(_src, cv::format("%s: src", who).c_str());
    const ValidatedNoiseModel valid(model);
    checkMosaicType(src, who);
    runNoiseStep(std::move(step), src, format, valid, noise, seed, dst, dstFormat, report);
}

} // namespace detail
} // namespace rawgment
} // namespace cv
