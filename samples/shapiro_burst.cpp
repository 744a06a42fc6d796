// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Sample: is the noise of a burst Gaussian (the paper's Sec. 4.3)? Every pixel's values over the frames
// are tested with Shapiro-Wilk; the summary shows the rate of Gaussian-looking pixels against the mean,
// and the ties (few distinct values) that make the test reject in the dark.
#include <opencv2/rawgment.hpp>

#include <cstdio>

int main()
{
    using namespace cv::rawgment;
    const SensorSimulator sensor(SensorParams(), cv::Size(64, 48));
    cv::Mat mean(sensor.size(), CV_32FC1);
    for (int c = 0; c < mean.cols; ++c)
        mean.col(c).setTo(0.2 + 0.5 * c * c); // from a fraction of a DN to 2000 DN, below white
    std::vector<cv::Mat> burst;
    sensor.captureBurst(mean, 1.0, 1.0, 64, 11, burst);

    const BurstNormality tested = shapiroWilkBurst(burst);
    const std::vector<NormalityBin> bins = summarizeNormality(tested, 6, 0.05);
    std::printf("%zu pixels, 64 frames each\n%12s %8s %10s %10s\n", tested.results.size(), "raw mean (DN)",
                "pixels", "Gaussian", "distinct");
    for (const NormalityBin& b : bins)
        std::printf("%5.0f-%6.0f %8d %9.0f%% %10.1f\n", b.meanLow, b.meanHigh, b.count,
                    100 * b.fractionAboveAlpha, b.meanDistinctValues);
    return 0;
}
