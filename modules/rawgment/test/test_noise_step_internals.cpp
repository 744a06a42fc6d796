// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The loop that runs noise steps (src/noise_step.hpp), on steps made for the test: the contract every step of
// the library relies on (all validated before any runs, the identity free, the buffers, the end of a step).
// The steps' own results are in test_color_jitter.cpp, test_resample.cpp and test_scene.cpp.
#include "test_common.hpp"

#include "../src/augment_steps.hpp"

#include <atomic>
#include <memory>
#include <string>

namespace cv {
namespace rawgment {
namespace {

// What the test's steps did, in order.
struct Journal
{
    std::vector<std::string> calls;
    std::vector<double> gainsSeen; // the input gain each prepare() saw
    std::vector<const uchar*> outputs;
};

// Adds `value` to every pixel of a CV_32FC1 mosaic, row by row, doubling the gain; an `identity` step does
// nothing. It can refuse in prepare(), find non-finite shading in its rows, and count brightening pixels.
class AddStep : public detail::NoiseStep
{
public:
    AddStep(std::string label, float value, Journal& journal)
        : label_(std::move(label)), value_(value), j_(journal)
    {
    }
    bool identity = false, refuse = false, badShading = false;
    std::atomic<int>* unitsRun = nullptr;

    const char* name() const override { return label_.c_str(); }
    const char* reportName() const override { return "add"; }
    RawFormat prepare(const detail::StepContext& context) override
    {
        j_.calls.push_back("prepare " + label_);
        j_.gainsSeen.push_back(context.format.gain);
        if (refuse)
            CV_Error(Error::StsBadArg, label_ + ": refused");
        RawFormat out = context.format;
        out.gain *= 2;
        return out;
    }
    bool isIdentity() const override { return identity; }
    void begin(const Mat& src, bool checkValues, detail::StepTally& tally) override
    {
        j_.calls.push_back("begin " + label_ + (checkValues ? " checking" : ""));
        rows_ = src.rows;
        tally_ = &tally;
        checkValues_ = checkValues;
    }
    int rowCount() const override { return rows_; }
    void runRows(const Mat& src, Mat& dst, const Range& rows) const override
    {
        for (int r = rows.start; r < rows.end; ++r) {
            if (checkValues_ && !detail::rowIsFinite(src.ptr<float>(r), src.cols))
                tally_->nonFiniteInput = true;
            for (int c = 0; c < src.cols; ++c)
                dst.at<float>(r, c) = src.at<float>(r, c) + value_;
            tally_->brightening += 1;
            if (unitsRun)
                unitsRun[r] += 1;
        }
        if (badShading)
            tally_->nonFiniteShading = true;
    }
    void finish(const Mat& src, bool, detail::StepTally&) const override
    {
        j_.calls.push_back("finish " + label_);
        j_.outputs.push_back(src.data);
    }
    void describeInput(const Mat&, AugmentReport*) const override
    {
        j_.calls.push_back("describe " + label_);
    }

private:
    std::string label_;
    float value_;
    Journal& j_;
    int rows_ = 0;
    detail::StepTally* tally_ = nullptr;
    bool checkValues_ = false;
};

struct Sequence
{
    Journal journal;
    detail::NoiseSteps steps;
    AddStep& add(const std::string& label, float value)
    {
        steps.emplace_back(new AddStep(label, value, journal));
        return static_cast<AddStep&>(*steps.back());
    }
};

const NoiseModel kModel(0.5, 1, 1);

void run(Sequence& s, const Mat& src, OutputArray dst, RawFormat& dstFormat, AugmentReport* report = nullptr,
         bool valuesChecked = false)
{
    const detail::ValidatedNoiseModel valid(kModel);
    RawFormat fmt;
    fmt.gain = 1;
    detail::runNoiseSteps(s.steps, src, fmt, valid, NoiseOptions(), 1, dst, dstFormat, report, nullptr, "seq",
                          valuesChecked);
}

// Every step is prepared, in order and with the format its predecessor leaves, before any reads a pixel: a
// bad parameter of the last step fails before the first has run.
TEST(NoiseStep, everyStepIsPreparedWithItsInputFormatBeforeAnyRuns)
{
    Mat src(4, 6, CV_32FC1, Scalar(1)), dst;
    RawFormat out;
    Sequence s;
    s.add("a", 1);
    s.add("b", 2).identity = true;
    s.add("c", 3);
    run(s, src, dst, out);
    const std::vector<std::string> expected = {"prepare a", "prepare b",  "prepare c",  "begin a checking",
                                               "finish a",  "describe a", "describe b", "begin c",
                                               "finish c",  "describe c"};
    EXPECT_EQ(s.journal.calls, expected);
    EXPECT_EQ(s.journal.gainsSeen, std::vector<double>({1, 2, 4}));
    EXPECT_EQ(out.gain, 8); // every step's format, the identity's too
    EXPECT_EQ(countNonZero(dst != 5), 0);

    Sequence refused;
    refused.add("a", 1);
    refused.add("z", 1).refuse = true;
    EXPECT_CV_ERROR_CONTAINS(run(refused, src, dst, out), "z: refused");
    EXPECT_EQ(refused.journal.calls, std::vector<std::string>({"prepare a", "prepare z"}));
}

// A sequence of identities reads no row and copies nothing: dst is src; the values are still checked.
TEST(NoiseStep, identityStepsReadNothingAndCopyNothing)
{
    Mat src(4, 6, CV_32FC1, Scalar(7)), dst;
    RawFormat out;
    Sequence s;
    s.add("a", 1).identity = true;
    s.add("b", 1).identity = true;
    run(s, src, dst, out);
    EXPECT_EQ(dst.data, src.data);
    EXPECT_EQ(s.journal.calls,
              std::vector<std::string>({"prepare a", "prepare b", "describe a", "describe b"}));

    src.at<float>(3, 5) = std::numeric_limits<float>::quiet_NaN();
    Sequence t;
    t.add("a", 1).identity = true;
    EXPECT_CV_ERROR_CONTAINS(run(t, src, dst, out), "seq: src contains NaN or Inf");
    // Known finite (a step's own output): not read at all.
    Sequence u;
    u.add("a", 1).identity = true;
    EXPECT_NO_THROW(run(u, src, dst, out, nullptr, true));
}

// Steps write two buffers in turn, the last the caller's dst when it can: src is never written, not even by
// a call in place; every unit of every step runs exactly once.
TEST(NoiseStep, theLastStepWritesTheCallersDstAndNoStepWritesSrc)
{
    const Mat original(64, 40, CV_32FC1, Scalar(1));
    for (int steps = 1; steps <= 4; ++steps) {
        Mat src = original.clone(), dst(src.size(), src.type(), Scalar(-1));
        const uchar* given = dst.data;
        std::vector<std::atomic<int>> units(static_cast<size_t>(steps * src.rows));
        Sequence s;
        for (int i = 0; i < steps; ++i)
            s.add(std::to_string(i), 1).unitsRun = &units[static_cast<size_t>(i * src.rows)];
        RawFormat out;
        run(s, src, dst, out);
        EXPECT_EQ(dst.data, given) << steps;
        EXPECT_EQ(countNonZero(dst != 1 + steps), 0) << steps;
        EXPECT_EQ(countNonZero(src != original), 0) << steps;
        for (const std::atomic<int>& u : units)
            EXPECT_EQ(u.load(), 1);
        // No step read its input from the buffer it wrote.
        for (size_t i = 1; i < s.journal.outputs.size(); ++i)
            EXPECT_NE(s.journal.outputs[i], s.journal.outputs[i - 1]);

        Sequence inPlace;
        for (int i = 0; i < steps; ++i)
            inPlace.add(std::to_string(i), 1);
        Mat same = original.clone();
        const Mat alias = same;
        run(inPlace, same, same, out);
        EXPECT_EQ(countNonZero(alias != original), 0) << steps; // the caller's src buffer is untouched
        EXPECT_EQ(countNonZero(same != 1 + steps), 0) << steps;
    }
}

// What rows found ends the step in one place: errors name the step, counts and the step's name go to the
// report; only the first step checks the input's values.
TEST(NoiseStep, theLoopEndsEveryStepTheSameWay)
{
    Mat src(8, 6, CV_32FC1, Scalar(1)), dst;
    RawFormat out;
    AugmentReport report;
    Sequence s;
    s.add("a", 1);
    s.add("b", 1);
    run(s, src, dst, out, &report);
    EXPECT_EQ(report.steps, std::vector<String>({"add", "add"}));
    EXPECT_EQ(report.stepSeconds.size(), 2u);
    EXPECT_EQ(report.brighteningPixels, 16);
    EXPECT_EQ(s.journal.calls[2], "begin a checking");
    EXPECT_EQ(s.journal.calls[5], "begin b");

    Sequence shading;
    shading.add("a", 1);
    shading.add("b", 1).badShading = true;
    EXPECT_CV_ERROR_CONTAINS(run(shading, src, dst, out), "b: the model's dark shading contains NaN or Inf");

    src.at<float>(5, 2) = std::numeric_limits<float>::infinity();
    Sequence input;
    input.add("a", 1);
    EXPECT_CV_ERROR_CONTAINS(run(input, src, dst, out), "a: src contains NaN or Inf");
}

} // namespace
} // namespace rawgment
} // namespace cv
