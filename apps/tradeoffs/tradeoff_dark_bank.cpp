// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The dark-frame bank's knob in the trade-off study (rawgment_tradeoffs): the dark frames shot per gain
// against how close the bank's fixed pattern comes to the sensor's, and the time to make a gain's group.
#include "tradeoff_study.hpp"

#include <opencv2/rawgment/dark_frames.hpp>
#include <opencv2/rawgment/mosaic_files.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <unistd.h>

namespace rawgment_apps {
namespace tradeoff_study {

using namespace cv;
using namespace cv::rawgment;

namespace {

/* A sensor whose dark frames hold a fixed pattern (DSNU 1 DN) under 30 DN^2 of temporal noise at gain 4 (row
 * noise, Tukey lambda -0.1 tails, 1% noisy pixels): a mean of 4 frames is 88% frozen temporal noise, of 50
 * frames 38%, so the frames per gain decide how much of the sensor's own pattern a bank holds. */
SensorParams bankSensor(uint64_t seed)
{
    SensorParams p;
    p.noise.rowSigmaD2 = 0.3;
    p.noise.rowSigmaR2 = 0.5;
    p.noise.tukeyRead = true;
    p.noise.tukeyLambda = -0.1;
    p.dsnu = 1.0;
    p.noisyPixelFraction = 0.01;
    p.noisyPixelVariance = 100;
    p.fixedPatternSeed = seed;
    return p;
}

//! Mean of `m` over the pixels of CFA site `site`.
double siteMean(const Mat& m, int site)
{
    double s = 0, n = 0;
    for (int r = site / 2; r < m.rows; r += 2)
        for (int c = site % 2; c < m.cols; c += 2) {
            s += m.at<float>(r, c);
            n += 1;
        }
    return s / n;
}

//! A folder of its own under the system's temporary folder, removed with the object.
struct ScratchFolder
{
    std::string path;
    ScratchFolder()
        : path((std::filesystem::temp_directory_path() /
                ("rawgment_tradeoffs_bank_" + std::to_string(static_cast<long long>(getpid()))))
                   .string())
    {
        std::filesystem::remove_all(path);
        std::filesystem::create_directories(path);
    }
    ~ScratchFolder()
    {
        std::error_code ignored;
        std::filesystem::remove_all(path, ignored);
    }
};

} // namespace

void measureDarkBankFrames(const TradeoffSettings& set, std::vector<TradeoffRow>& rows)
{
    if (set.bankFrames.empty())
        return;
    const ScratchFolder scratch;
    const Size size(128, 96);
    const double gain = 4;
    const int most = *std::max_element(set.bankFrames.begin(), set.bankFrames.end());
    std::vector<std::vector<double>> errors(set.bankFrames.size());
    for (int campaign = 0; campaign < set.seeds; ++campaign) {
        const uint64_t seed = studySeed(set, DRAW_BANK_CAMPAIGN, static_cast<uint64_t>(campaign));
        const SensorSimulator sensor(bankSensor(seed), size);
        MosaicMetadata meta;
        meta.format = sensor.rawFormat(gain);
        const std::string folder = scratch.path + cv::format("/campaign_%03d", campaign);
        std::filesystem::create_directories(folder);
        std::vector<String> files;
        for (int t = 0; t < most; ++t) {
            Mat raw;
            sensor.capture(Mat::zeros(size, CV_32FC1), gain, 1.0, seed, t, raw);
            files.push_back(folder + cv::format("/dark_%03d.png", t));
            writeMosaic(files.back(), raw, meta);
        }
        // The truth: the pixels' offsets above black (the sensor has no dark shading: its DSNU), each about
        // its site's level (the pattern, not the black level, is compared).
        Mat prnu, truth, defects;
        sensor.fixedPattern(prnu, truth, defects);
        double truthLevel[4];
        for (int site = 0; site < 4; ++site)
            truthLevel[site] = siteMean(truth, site);
        for (size_t k = 0; k < set.bankFrames.size(); ++k) {
            const DarkFrameBank bank = DarkFrameBank::create(
                std::vector<String>(files.begin(), files.begin() + set.bankFrames[k]), NoiseModel());
            const DarkFrameStatistics& s = bank.groups.front().statistics;
            double squares = 0;
            for (int r = 0; r < size.height; ++r)
                for (int c = 0; c < size.width; ++c) {
                    const int site = cfaSite(r, c);
                    const double d = (s.pattern.at<float>(r, c) - s.level[site]) -
                                     (truth.at<float>(r, c) - truthLevel[site]);
                    squares += d * d;
                }
            errors[k].push_back(std::sqrt(squares / static_cast<double>(size.area())));
        }
        std::filesystem::remove_all(folder);
    }
    // The time to make one gain's group of a timing-size camera from its frames (.npy in the page cache): on
    // frames of that size, since a sixteenth of the pixels, scaled, came out about half as long (12 MP frames
    // no longer sit in the caches).
    const Size timed = set.timingSize;
    const SensorSimulator timingSensor(bankSensor(set.seed), timed);
    MosaicMetadata meta;
    meta.format = timingSensor.rawFormat(gain);
    std::vector<String> files;
    for (int t = 0; t < most; ++t) {
        Mat raw;
        timingSensor.capture(Mat::zeros(timed, CV_32FC1), gain, 1.0, set.seed, t, raw);
        files.push_back(scratch.path + cv::format("/timed_%03d.npy", t));
        writeMosaic(files.back(), raw, meta);
    }
    for (size_t k = 0; k < set.bankFrames.size(); ++k) {
        const int frames = set.bankFrames[k];
        const double ms = fastestMs(set.repeats, [&] {
            DarkFrameBank::create(std::vector<String>(files.begin(), files.begin() + frames), NoiseModel());
        });
        TradeoffRow row{"Dark-frame bank frames per gain",
                        cv::format("%d frames", frames),
                        "RMS error of the bank's fixed pattern against the sensor's (DN)",
                        rmsOf(errors[k]),
                        ms / (frames * megapixels(timed)),
                        frames < 16
                            ? "the bank's pattern has the sensor's variance but little of its "
                              "shape (the shrinkage keeps what the mean's frozen noise lets through); "
                              "draws repeat a frame with probability 1/M"
                            : "more of the sensor's own pattern; one frame read per draw whatever M",
                        {}};
        row.campaignErrors = errors[k];
        row.errorStdError = rmsStandardError(errors[k]);
        row.framesToShoot = frames;
        row.secondsPerCalibration = ms / 1000;
        rows.push_back(row);
    }
}

} // namespace tradeoff_study
} // namespace rawgment_apps
