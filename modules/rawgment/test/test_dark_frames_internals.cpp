// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What dark frames tell apart (src/dark_frames.hpp): the fixed pattern, shrunk for the temporal noise its
// mean holds, and the temporal variance per row and site; against the simulator's truth and EMVA 1288 set
// 001.
#include "test_common.hpp"

#include "../src/dark_frames.hpp"

#include <map>

#include <opencv2/rawgment/emva1288.hpp>
#include <opencv2/rawgment/mosaic_files.hpp>
#include <opencv2/rawgment/raw_io.hpp>
#include <opencv2/rawgment/simulate.hpp>

namespace cv {
namespace rawgment {
namespace {

using detail::estimateDarkFrames;

/* chi2_{1-p}(k) / k from SciPy 1.10 (Debian 12):
 *   /usr/bin/python3 -c "from scipy.stats import chi2; [print(k, p, repr(chi2.isf(p, k) / k))
 *                        for k in (7, 24, 49) for p in (1e-6, 1e-3)]"
 * Wilson and Hilferty's cube overstates it at these p, by at most 3.4% from k = 7 (0.9% at 24): a noisy
 * pixel's threshold errs on the side of not flagging. */
TEST(DarkFrames, theChiSquareThresholdIsWilsonHilfertysAgainstSciPy)
{
    const struct
    {
        int k;
        double p, exact, bound;
    } cases[] = {{7, 1e-6, 5.788833033, 0.034},  {7, 1e-3, 3.474555193, 0.009},
                 {24, 1e-6, 3.009535576, 0.010}, {24, 1e-3, 2.132441574, 0.003},
                 {49, 1e-6, 2.2680797, 0.004},   {49, 1e-3, 1.741848257, 0.001}};
    for (const auto& c : cases) {
        const double q = detail::chiSquareUpperQuantileOverDof(c.k, c.p);
        EXPECT_GE(q, c.exact) << c.k << " " << c.p;
        EXPECT_LE(q, c.exact * (1 + c.bound)) << c.k << " " << c.p;
    }
}

/* A sensor whose dark frames hold what a bank must separate: a fixed pattern (DSNU, the dark shading's
 * per-gain and offset maps with a column gradient), temporal noise with rows and heavy tails, and 1% noisy
 * pixels. Float frames (no rounding), so the truth is exact: pattern DSNU + the shading at the gain; temporal
 * variance g^2 sigma_d^2 + sigma_r^2 + the row variance. */
struct DarkCampaigns
{
    Size size{96, 64};
    double gain = 4;
    int frames = 25;
    SensorParams params;
    DarkCampaigns()
    {
        params = test::darkComponentSensorParams(size, -0.1, 5);
        params.quantize = false;
        params.dsnu = 0.3;
        params.noisyPixelFraction = 0.01;
        params.noisyPixelVariance = 100;
    }
    //! One campaign: its estimate, the plain temporal mean, the true pattern and the defect map.
    DarkFrameStatistics run(uint64 seed, Mat& plainMean, Mat& truthPattern, Mat& defects) const
    {
        const SensorSimulator sensor(params, size);
        BurstStatistics stats(sensor.rawFormat(gain));
        detail::DarkFrameAccumulator rows(sensor.rawFormat(gain));
        for (int t = 0; t < frames; ++t) {
            Mat raw;
            sensor.capture(Mat::zeros(size, CV_32FC1), gain, 1.0, seed, t, raw);
            stats.add(raw);
            rows.add(raw);
        }
        stats.mean(plainMean);
        Mat prnu, dsnu;
        sensor.fixedPattern(prnu, dsnu, defects);
        truthPattern = dsnu + params.noise.darkShadingAt(gain);
        const DarkFrameStatistics e = rows.estimate();
        const DarkFrameStatistics plain = estimateDarkFrames(stats);
        CV_Assert(e.patternVariance == plain.patternVariance &&
                  norm(e.pattern, plain.pattern, NORM_INF) == 0);
        return e;
    }
};

double siteMean(const Mat& m, int site)
{
    double s = 0, n = 0;
    for (int r = 0; r < m.rows; ++r)
        for (int c = 0; c < m.cols; ++c)
            if (cfaSite(r, c) == site) {
                s += m.at<float>(r, c);
                n += 1;
            }
    return s / n;
}

double siteVariance(const Mat& m, int site)
{
    double s = 0, s2 = 0, n = 0;
    for (int r = 0; r < m.rows; ++r)
        for (int c = 0; c < m.cols; ++c)
            if (cfaSite(r, c) == site) {
                const double x = m.at<float>(r, c);
                s += x;
                s2 += x * x;
                n += 1;
            }
    return (s2 - s * s / n) / (n - 1);
}

/* Over 24 campaigns of 25 frames: the pattern variance is unbiased within 3 standard errors of its mean over
 * campaigns, where the plain mean's variance is high by v/M (the bias the issue measured on set 001); the
 * shrunk pattern scatters by the pattern's own variance (what an augmentation adds) and is closer to the
 * truth than the plain mean; the pooled temporal variance and the row noise
 * (from the frames' row means) are the truth within 3 standard errors; nearly every noisy pixel is flagged
 * and almost no other. The accumulator's pattern is estimateDarkFrames()' to the bit. */
TEST(DarkFrames, thePatternIsTheTruthWithoutTheTemporalNoiseItsMeanHolds)
{
    const DarkCampaigns setup;
    const int campaigns = 24;
    const double truthTemporal = setup.gain * setup.gain * setup.params.noise.sigmaD2 +
                                 setup.params.noise.sigmaR2 + setup.params.noise.rowVariance(setup.gain);
    const double truthRow = setup.params.noise.rowVariance(setup.gain);
    std::vector<double> patternBias, plainBias, temporalBias, rowBias, spreadBias;
    double shrunkError = 0, plainError = 0, flaggedNoisy = 0, noisy = 0, flaggedOther = 0, other = 0;
    for (int k = 0; k < campaigns; ++k) {
        Mat plainMean, truth, defects;
        const DarkFrameStatistics e = setup.run(100 + k, plainMean, truth, defects);
        Vec4d truthLevel;
        for (int s = 0; s < 4; ++s) {
            const double tv = siteVariance(truth, s);
            patternBias.push_back(e.patternVariance[s] - tv);
            spreadBias.push_back(siteVariance(e.pattern, s) - tv);
            plainBias.push_back(e.meanVariance[s] - tv);
            temporalBias.push_back(e.temporalVariance[s] - truthTemporal);
            truthLevel[s] = siteMean(truth, s);
        }
        // One value per campaign: the sites of a row share its offset, so they are not independent samples.
        // The simulator's hot and dead pixels (codes 1 and 2) hold fixed values without the offset, so a
        // row's mean carries its offset times the fraction f of its other pixels: the truth is the row
        // variance times the mean of f^2 (1 for this sensor, which has neither). Over 200 campaigns the bias
        // was +0.017 +- 0.014.
        double carried = 0;
        for (int r = 0; r < defects.rows; ++r)
            for (int parity = 0; parity < 2; ++parity) {
                double kept = 0, n = 0;
                for (int c = parity; c < defects.cols; c += 2) {
                    const int code = defects.at<uchar>(r, c);
                    kept += code != 1 && code != 2;
                    n += 1;
                }
                carried += (kept / n) * (kept / n) / (2 * defects.rows);
            }
        rowBias.push_back(
            (e.rowNoiseVariance[0] + e.rowNoiseVariance[1] + e.rowNoiseVariance[2] + e.rowNoiseVariance[3]) /
                4 -
            truthRow * carried);
        for (int r = 0; r < truth.rows; ++r)
            for (int c = 0; c < truth.cols; ++c) {
                const bool isNoisy = defects.at<uchar>(r, c) == 3; // SensorSimulator::fixedPattern()'s code
                const bool flagged =
                    std::find(e.noisyPixels.begin(), e.noisyPixels.end(), Point(c, r)) != e.noisyPixels.end();
                (isNoisy ? noisy : other) += 1;
                (isNoisy ? flaggedNoisy : flaggedOther) += flagged;
                // Each about its own site level: the pattern, not the black level, is compared.
                const int s = cfaSite(r, c);
                const double t = truth.at<float>(r, c) - truthLevel[s];
                shrunkError += std::pow(e.pattern.at<float>(r, c) - e.level[s] - t, 2);
                plainError += std::pow(plainMean.at<double>(r, c) - e.level[s] - t, 2);
            }
    }
    const auto meanAndSe = test::meanAndStandardError;
    double m, se;
    meanAndSe(patternBias, m, se);
    std::cout << "pattern variance bias " << m << " +- " << se << "\n";
    EXPECT_LT(std::abs(m), 3 * se);
    meanAndSe(spreadBias, m, se);
    std::cout << "the shrunk pattern's own variance less the truth's " << m << " +- " << se << "\n";
    EXPECT_LT(std::abs(m), 3 * se);
    meanAndSe(plainBias, m, se);
    std::cout << "plain mean's variance bias " << m << " +- " << se
              << " (v/M = " << truthTemporal / setup.frames << ")\n";
    EXPECT_GT(m, 5 * se);
    meanAndSe(temporalBias, m, se);
    std::cout << "temporal variance bias " << m << " +- " << se << " of " << truthTemporal << "\n";
    EXPECT_LT(std::abs(m), 3 * se);
    meanAndSe(rowBias, m, se);
    std::cout << "row noise variance bias " << m << " +- " << se << " of " << truthRow << "\n";
    EXPECT_LT(std::abs(m), 3 * se);
    std::cout << "flagged: " << flaggedNoisy << " of " << noisy << " noisy pixels, " << flaggedOther << " of "
              << other << " others\n";
    EXPECT_GT(flaggedNoisy, 0.95 * noisy);
    EXPECT_LT(flaggedOther, 1e-3 * other);
    std::cout << "pattern RMS error: shrunk " << std::sqrt(shrunkError / (noisy + other)) << ", plain mean "
              << std::sqrt(plainError / (noisy + other)) << " DN\n";
    EXPECT_LT(shrunkError, plainError);
}

/* Hot pixels (0.2%, thousands of DN above the rest) are pattern beyond doubt: they keep their measured level,
 * and they do not stop the shrinkage of the others (with the sites' plain variance they made every w 1, so
 * the pattern kept the mean's whole v/M). Over the other pixels the shrunk pattern scatters by about v/M less
 * than the plain mean (0.61 DN^2 here); half of it is asked, far beyond one campaign's noise in that
 * difference. */
TEST(DarkFrames, hotPixelsKeepTheirLevelAndLeaveTheShrinkageOfTheOthers)
{
    DarkCampaigns setup;
    setup.params.hotPixelFraction = 0.002;
    Mat plainMean, truth, defects;
    const DarkFrameStatistics e = setup.run(7, plainMean, truth, defects);
    ASSERT_GT(countNonZero(defects == 1), 0);
    double plain = 0, shrunk = 0, frozen = 0;
    for (int s = 0; s < 4; ++s) {
        std::vector<double> p, q;
        for (int r = 0; r < defects.rows; ++r)
            for (int c = 0; c < defects.cols; ++c) {
                if (cfaSite(r, c) != s)
                    continue;
                if (defects.at<uchar>(r, c) == 1) {
                    EXPECT_NEAR(e.pattern.at<float>(r, c), plainMean.at<double>(r, c), 1e-3)
                        << "a hot pixel's level";
                    continue;
                }
                p.push_back(plainMean.at<double>(r, c));
                q.push_back(e.pattern.at<float>(r, c));
            }
        double m, se;
        const auto variance = [&](const std::vector<double>& x) {
            test::meanAndStandardError(x, m, se);
            return se * se * x.size();
        };
        plain += variance(p) / 4;
        shrunk += variance(q) / 4;
        frozen += e.temporalVariance[s] / e.frames / 4;
    }
    std::cout << "spread of the means " << plain << ", of the pattern " << shrunk << ", v/M " << frozen
              << "\n";
    EXPECT_GT(plain - shrunk, 0.5 * frozen);
}

/* EMVA 1288 reference set 001 (a 12-bit CCD): the 50 dark frames of its spatial set. The mean of 50 frames
 * holds v/50 of frozen temporal noise, most of its spatial variance; the pattern variance removes it and
 * agrees with the standard's own figure (measureEmva1288Stack, the whole frame at one level). Each half of
 * 25 frames gives the same pattern variance within its standard error, about sqrt(2 / P) (s_F^2 + v/25)
 * for P pixels, while a plain mean of 25 holds v/25, twice the frozen noise of 50. */
TEST(DarkFrames, set001sDarkFramesHoldAFaintPatternUnderTheirFrozenNoise)
{
    RAWGMENT_DATA_FILE_OR_SKIP(path, "emva1288/EMVA1288_ReferenceSet_001_CCD_12Bit/EMVA1288_Data.txt");
    const Emva1288Series series = readEmva1288(path);
    const Emva1288Images* dark = nullptr;
    for (const Emva1288Images& images : series.spatial)
        if (images.dark)
            dark = &images;
    ASSERT_NE(dark, nullptr);
    ASSERT_EQ(dark->images.size(), 50u);
    RawFormat fmt;
    fmt.pattern = CFA_MONO;
    fmt.blackLevel = Vec4d::all(0);
    fmt.whiteLevel = 4095;
    std::vector<Mat> frames;
    BurstStatistics all(fmt), first(fmt), second(fmt);
    for (size_t k = 0; k < dark->images.size(); ++k) {
        frames.push_back(readEmva1288Image(series, dark->images[k], dark->line));
        all.add(frames.back());
        (k < 25 ? first : second).add(frames.back());
    }
    const DarkFrameStatistics e = estimateDarkFrames(all), a = estimateDarkFrames(first),
                              b = estimateDarkFrames(second);
    const auto siteMean = [](const Vec4d& v) { return (v[0] + v[1] + v[2] + v[3]) / 4; };
    const double v = siteMean(e.temporalVariance), pattern = siteMean(e.patternVariance);
    std::cout << "50 frames: Var(mean) " << siteMean(e.meanVariance) << ", v/M " << v / 50 << ", pattern "
              << pattern << " DN^2 (RMS " << e.fixedPatternRms() << " DN), " << e.noisyPixels.size()
              << " noisy pixels, " << e.degreesOfFreedom << " degrees of freedom\n";
    std::cout << "halves of 25: pattern " << siteMean(a.patternVariance) << " and "
              << siteMean(b.patternVariance) << ", Var(mean) " << siteMean(a.meanVariance) << " and "
              << siteMean(b.meanVariance) << "\n";
    const Emva1288Stack standard = measureEmva1288Stack(frames, dark->exposureNs, 0, true);
    std::cout << "measureEmva1288Stack: s_y^2 " << standard.variance << "\n";
    // The standard's figure removes the mean temporal variance of all pixels, this one that of each site's:
    // the same for a sensor whose sites are one (a monochrome CCD), to the rounding of the sums.
    EXPECT_NEAR(pattern, standard.variance, 1e-3);
    EXPECT_GT(siteMean(e.meanVariance), 5 * pattern) << "the mean of 50 frames is mostly frozen noise";
    const double pixels = static_cast<double>(series.width) * series.height;
    const double halfSe = std::sqrt(2 / pixels) * (pattern + v / 25);
    EXPECT_NEAR(siteMean(a.patternVariance), siteMean(b.patternVariance), 3 * std::sqrt(2.0) * halfSe);
    EXPECT_NEAR(siteMean(a.meanVariance) - pattern, v / 25, 3 * halfSe) << "a plain mean of 25 holds v/25";
}

// Coarse dark frames (0.2 DN of noise, rounded): most pixels never change, so a row's median variance is 0. A
// threshold on 0 would call every pixel that moves noisy (171 of 199 with the row's mean standing in); the
// rounding's 1/12 DN^2 is the least variance a row is taken to have.
TEST(DarkFrames, coarseFramesWhoseMedianVarianceIsZeroFlagAlmostNothing)
{
    SensorParams p;
    p.noise = NoiseModel(0.1, 0.0, 0.04);
    const Size size(64, 32);
    const SensorSimulator sensor(p, size);
    BurstStatistics stats(sensor.rawFormat(1));
    for (int t = 0; t < 8; ++t) {
        Mat raw;
        sensor.capture(Mat::zeros(size, CV_32FC1), 1.0, 1.0, 9, t, raw);
        stats.add(raw);
    }
    Mat variance;
    stats.variance(variance);
    ASSERT_GT(countNonZero(variance), 0);
    ASSERT_LT(countNonZero(variance), static_cast<int>(variance.total() / 2)) << "the median must be 0";
    const DarkFrameStatistics e = estimateDarkFrames(stats);
    std::cout << e.noisyPixels.size() << " of " << countNonZero(variance) << " moving pixels flagged\n";
    EXPECT_LT(e.noisyPixels.size(), variance.total() / 100);
    EXPECT_GT(e.temporalVariance[0], 0);
}

} // namespace
} // namespace rawgment
} // namespace cv
