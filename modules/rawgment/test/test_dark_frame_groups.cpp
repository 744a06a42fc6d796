// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Which of a dark-frame bank's groups a step draws (opencv2/rawgment/dark_frames.hpp): by gain on a log scale
// within the bank's range, then by the exposure of each side of the step; the refusals where the bank has no
// frames of a capture. The groups' statistics and the draws' variances are test_dark_frames.cpp's.
#include "test_common.hpp"

#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/dark_frames.hpp>
#include <opencv2/rawgment/mosaic_files.hpp>

#include <cmath>

namespace cv {
namespace rawgment {
namespace {

/* The nearest group: by gain on a log scale, then the exposure's within a third of a stop; a gain beyond the
 * bank's range is refused, one within 0.1% of its ends is its end (an ISO's rounding); an exposure the gain
 * has no frames of is refused naming those it has (#79 item 10), and so is none where it has several. */
TEST(DarkFrameBank, theNearestGroupLiesWithinTheBanksGains)
{
    DarkFrameBank bank;
    bank.size = Size(4, 4);
    for (const auto& ge : {std::make_pair(1.0, 0.01), std::make_pair(4.0, 0.01), std::make_pair(4.0, 1.0),
                           std::make_pair(16.0, 0.0)}) {
        DarkFrameGroup g;
        g.gain = ge.first;
        g.exposureTime = ge.second;
        bank.groups.push_back(g);
    }
    EXPECT_EQ(bank.nearestGroup(1.0), 0);
    EXPECT_EQ(bank.nearestGroup(1.999), 0);
    EXPECT_EQ(bank.nearestGroup(2.001, 0.01), 1) << "log scale: 2 is as near 1 as 4";
    EXPECT_EQ(bank.nearestGroup(1.0, 0.0125), 0)
        << "a nominal 1/80 s against 0.01 s: within a third of a stop";
    EXPECT_CV_ERROR_CONTAINS(
        bank.nearestGroup(1.0, 0.0127),
        "no frames within a third of a stop of exposure 0.0127 s at gain 1; it has 0.01 s");
    EXPECT_CV_ERROR_CONTAINS(bank.nearestGroup(4.0),
                             "states no exposure time (RawFormat::exposureTime), and the dark-frame bank has "
                             "frames of 2 exposures at gain 4 (0.01 s, 1 s)");
    EXPECT_EQ(bank.nearestGroup(4.0, 1.0), 2);
    EXPECT_EQ(bank.nearestGroup(4.0, 0.9), 2);
    EXPECT_EQ(bank.nearestGroup(4.0, 0.011), 1);
    EXPECT_CV_ERROR_CONTAINS(bank.nearestGroup(4.0, 0.1), "at gain 4; it has 0.01 s, 1 s there");
    EXPECT_EQ(bank.nearestGroup(2.001, 1.0), 2) << "the exposure is matched at the nearest gain";
    EXPECT_EQ(bank.nearestGroup(16.0 * 1.0009), 3);
    EXPECT_EQ(bank.nearestGroup(16.0, 30.0), 3) << "frames that state no exposure take any";
    EXPECT_CV_ERROR_CONTAINS(bank.nearestGroup(16.0 * 1.002), "outside the bank's gains [1, 16]");
    EXPECT_CV_ERROR_CONTAINS(bank.nearestGroup(0.99), "outside the bank's gains");
    EXPECT_CV_ERROR_CONTAINS(bank.nearestGroup(std::nan("")), "must be finite");
    EXPECT_CV_ERROR_CONTAINS(DarkFrameBank().nearestGroup(1), "an empty bank");
    EXPECT_CV_ERROR_CONTAINS(bank.readFrame(4, 0), "group 4 of a bank of 4");
    EXPECT_CV_ERROR_CONTAINS(bank.readFrame(0, 0), "frame 0 of a group of 0");
}

/* A bank of dark frames at 1 ms and 1 s at one gain (#79 item 10): the step draws the target's frames from
 * the group of the target's exposure (the input's unless the jitter states one) and takes the input's read
 * noise from the group of the input's. The 1 s frames vary nine times as much as the 1 ms ones, so the bounds
 * only need to tell the two apart: 0.75 to 1.35 of a group's variance holds the draw of one frame's 6144
 * pixels (2% standard error) and, for ACCOUNT_PRIOR, what the 8-frame groups' estimates of each other miss.
 */
TEST(DarkFrameBank, eachSideOfAStepDrawsTheGroupOfItsOwnExposure)
{
    const std::string dir = test::makeTempDir("dark_bank_exposures");
    const Size size(96, 64);
    const double black = 256, sigmaShort = 2, sigmaLong = 6;
    RawFormat format;
    format.blackLevel = Vec4d::all(black);
    format.whiteLevel = 4095;
    const auto frameOf = [&](double sigma, int seed) {
        Mat noise(size, CV_32FC1), frame;
        RNG rng(static_cast<uint64>(seed));
        rng.fill(noise, RNG::NORMAL, black, sigma);
        noise.convertTo(frame, CV_16U);
        return frame;
    };
    std::vector<String> files;
    for (const auto& exposure : {std::make_pair(0.001, sigmaShort), std::make_pair(1.0, sigmaLong)})
        for (int i = 0; i < 8; ++i) {
            MosaicMetadata meta;
            meta.format = format;
            meta.format.exposureTime = exposure.first;
            const String path = dir + cv::format("/dark_%g_%d.png", exposure.first, i);
            writeMosaic(path, frameOf(exposure.second, 100 * i + int(exposure.second)), meta);
            files.push_back(path);
        }
    DarkFrameBank bank = DarkFrameBank::create(files, NoiseModel());
    ASSERT_EQ(bank.groups.size(), 2u);
    EXPECT_EQ(bank.groups[0].exposureTime, 0.001);
    EXPECT_EQ(bank.groups[1].exposureTime, 1.0);
    EXPECT_EQ(bank.format.exposureTime, 0)
        << "the bank's format is its sensor's; each group has its exposure";
    const String bankPath = dir + "/bank.yml";
    bank.save(bankPath);

    const NoiseModel model(0, 0, 1);
    const auto varianceOf = [&](const Mat& out) {
        Mat above;
        out.convertTo(above, CV_64F, 1, -black);
        Scalar mean, sd;
        meanStdDev(above, mean, sd);
        return sd[0] * sd[0];
    };
    // A 1 s input at black, darkened: IGNORE_PRIOR adds a whole frame of the 1 s group (before the fix, of
    // the 1 ms group: exposure 0 chose the shortest).
    {
        RawFormat longInput = format;
        longInput.exposureTime = 1.0;
        NoiseOptions options(NoiseAlignment::IGNORE_PRIOR);
        options.darkBank = bankPath;
        ColorJitter darker;
        darker.contrast = Vec4d::all(0.5);
        Mat out;
        RawFormat outFormat;
        colorJitter(Mat(size, CV_16UC1, Scalar(black)), longInput, model, darker, options, 1, out, outFormat);
        const double v = varianceOf(out);
        EXPECT_GT(v, 0.75 * sigmaLong * sigmaLong);
        EXPECT_LT(v, 1.35 * sigmaLong * sigmaLong);
        EXPECT_EQ(outFormat.exposureTime, 1.0);
    }
    // A 1 ms capture taken to a stated 1 s target: ACCOUNT_PRIOR adds what the 1 s group has beyond the 1 ms
    // group's read noise, which the input holds.
    {
        RawFormat shortInput = format;
        shortInput.exposureTime = 0.001;
        NoiseOptions options(NoiseAlignment::ACCOUNT_PRIOR);
        options.darkBank = bankPath;
        ColorJitter longer;
        longer.exposureTime = 1.0;
        EXPECT_FALSE(longer.isIdentity());
        Mat out;
        RawFormat outFormat;
        colorJitter(frameOf(sigmaShort, 9999), shortInput, model, longer, options, 2, out, outFormat);
        const double v = varianceOf(out);
        EXPECT_GT(v, 0.75 * sigmaLong * sigmaLong);
        EXPECT_LT(v, 1.35 * sigmaLong * sigmaLong);
        EXPECT_EQ(outFormat.exposureTime, 1.0);
        // Stating the input's own exposure is the identity: the input's bits, no draw.
        longer.exposureTime = 0.001;
        const Mat input = frameOf(sigmaShort, 9998);
        colorJitter(input, shortInput, model, longer, options, 2, out, outFormat);
        EXPECT_EQ(out.data, input.data);
    }
    // Exposures the bank has no frames of, or none stated where it has two, are refused by name.
    {
        RawFormat input = format;
        ColorJitter darker;
        darker.contrast = Vec4d::all(0.5);
        NoiseOptions options;
        options.darkBank = bankPath;
        Mat out;
        RawFormat outFormat;
        const Mat frame(size, CV_16UC1, Scalar(black));
        EXPECT_CV_ERROR_CONTAINS(colorJitter(frame, input, model, darker, options, 1, out, outFormat),
                                 "colorJitter: the output: the mosaic states no exposure time");
        input.exposureTime = 0.1;
        EXPECT_CV_ERROR_CONTAINS(
            colorJitter(frame, input, model, darker, options, 1, out, outFormat),
            "no frames within a third of a stop of exposure 0.1 s at gain 1; it has 0.001 "
            "s, 1 s there");
        input.exposureTime = 1.0;
        darker.exposureTime = 0.1;
        EXPECT_CV_ERROR_CONTAINS(colorJitter(frame, input, model, darker, options, 1, out, outFormat),
                                 "colorJitter: the output: the dark-frame bank ('" + bankPath +
                                     "') has no frames");
        darker.exposureTime = std::nan("");
        EXPECT_CV_ERROR_CONTAINS(colorJitter(frame, input, model, darker, options, 1, out, outFormat),
                                 "exposureTime must be finite");
    }
}

} // namespace
} // namespace rawgment
} // namespace cv
