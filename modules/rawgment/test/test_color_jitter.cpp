// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Colour jitter (paper Eq. 11 and 13): exposure and gain changes against captures of the target, measured
// lines, Poisson shot draws, local prior means and the dark-frame components a darkening adds.
#include "test_augment_common.hpp"

#include "../src/random.hpp"
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <map>
#include <random>

namespace cv {
namespace rawgment {
namespace {

using namespace augment_test;

//! Average of a per-pixel map over the 8-column block b, leaving out `margin` columns at its sides.
double blockAverage(const Mat& m, int b, int margin = 0)
{
    return cv::mean(m(Rect(8 * b + margin, 0, 8 - 2 * margin, m.rows)))[0];
}

TEST(Augment, exposureChangeMatchesTheModelOnlyWhenThePriorIsAccounted)
{
    const Size size(64, 32);
    const SensorSimulator sensor(test::referenceSensorParams(), size);
    const NoiseModel model = sensor.effectiveModel();
    const RawFormat fmt = sensor.rawFormat(kGain);
    const std::vector<Mat> bright = floatBurst(sensor, levelScene(size), 5);
    // A block averages 256 per-pixel variances of 64 frames: relative standard error
    // sqrt(2 / 63) / sqrt(256) = 1.1%; 5 standard errors = 5.6%.
    const double tolerance = 5 * std::sqrt(2.0 / (kFrames - 1)) / std::sqrt(256.0);
    for (double factor : {0.5, 0.1}) {
        double ratio[3][8];
        for (NoiseAlignment mode : kAllAlignments) {
            RawFormat outFmt;
            Mat mean, var;
            statsAfterStep(
                bright, fmt,
                [&](const Mat& frame, int t, Mat& out) {
                    colorJitter(frame, fmt, model, ColorJitter::exposureChange(factor, 1.0), mode, 1000 + t,
                                out, outFmt);
                },
                mean, var);
            EXPECT_EQ(outFmt.gain, kGain);
            EXPECT_EQ(outFmt.blackLevel, fmt.blackLevel);
            for (int b = 0; b < 8; ++b) {
                const double m = blockAverage(mean, b);
                ratio[static_cast<int>(mode)][b] = blockAverage(var, b) / model.variance(m, kGain);
            }
        }
        for (int b = 0; b < 8; ++b) {
            SCOPED_TRACE(testing::Message() << "x" << factor << ", level block " << b);
            EXPECT_NEAR(ratio[2][b], 1.0, tolerance) << "ACCOUNT_PRIOR";
            EXPECT_LT(ratio[0][b], 1.0 - tolerance) << "NONE keeps only the scaled prior noise";
            // The prior noise matters where f^2 v_in is a sizeable part of the target.
            if (factor == 0.5 || b >= 4) {
                EXPECT_GT(ratio[1][b], 1.0 + tolerance) << "IGNORE_PRIOR adds the target on top of the prior";
            }
        }
        std::cout << "x" << factor << " variance / model, brightest block: NONE " << ratio[0][7]
                  << ", IGNORE_PRIOR " << ratio[1][7] << ", ACCOUNT_PRIOR " << ratio[2][7] << "\n";
    }
}

// A monochrome sensor, flat input: an exposure and gain change gives Eq. 5's variance at the new mean and
// gain, the same on all four sites (one contrast, one black level, one noise line).
TEST(Augment, aMonochromeFlatFrameTakesEq5sVarianceAtTheNewExposureAndGain)
{
    const Size size(64, 32);
    SensorParams params = test::referenceSensorParams();
    params.pattern = CFA_MONO;
    const SensorSimulator sensor(params, size);
    const NoiseModel model = sensor.effectiveModel();
    const RawFormat fmt = sensor.rawFormat(kGain);
    const std::vector<Mat> flat = floatBurst(sensor, Mat(size, CV_32FC1, Scalar(800)), 17);
    for (double photons : {0.5, 0.1}) {
        RawFormat outFmt;
        Mat mean, var;
        statsAfterStep(
            flat, fmt,
            [&](const Mat& frame, int t, Mat& out) {
                colorJitter(frame, fmt, model, ColorJitter::exposureChange(photons, 2.0),
                            NoiseAlignment::ACCOUNT_PRIOR, 40 + t, out, outFmt);
            },
            mean, var);
        EXPECT_TRUE(outFmt.isMonochrome());
        EXPECT_EQ(outFmt.gain, 2 * kGain);
        // Per site, 512 variances of 64 frames: relative standard error sqrt(2 / 63) / sqrt(512) = 0.79%;
        // 5 of them = 3.9%.
        for (int site = 0; site < 4; ++site) {
            double m = 0, v = 0;
            for (int r = site / 2; r < size.height; r += 2)
                for (int c = site % 2; c < size.width; c += 2) {
                    m += mean.at<double>(r, c) / 512;
                    v += var.at<double>(r, c) / 512;
                }
            EXPECT_NEAR(m, 800 * kGain * photons * 2.0, 0.01 * 800 * kGain * photons * 2.0) << site;
            EXPECT_NEAR(v / model.variance(m, 2 * kGain), 1.0, 0.039) << "x" << photons << ", site " << site;
        }
    }
}

/* A sensor whose measured lines leave Eq. 5 (0.4, 0.5, 2.0) by 15-30% at gains 2 and 4 (a digitally
 * scaled setting does that): the simulator draws the lines, and an exposure change to another gain adds
 * what the target gain's own line lacks, not what Eq. 5 would. */
SensorParams measuredLinesSensor()
{
    SensorParams p = test::referenceSensorParams();
    const double lines[4][3] = {{1, 0.4, 2.6}, {2, 0.68, 4.5}, {4, 2.08, 12.0}, {8, 3.2, 34.0}};
    for (const auto& l : lines) {
        MeasuredNoiseLine m;
        m.gain = l[0];
        m.line.a = l[1];
        m.line.b = l[2];
        p.noise.measuredLines.push_back(m);
    }
    return p;
}

TEST(Augment, measuredLinesAreFollowedAtTheSourceAndTargetGains)
{
    const Size size(64, 32);
    const SensorSimulator sensor(measuredLinesSensor(), size);
    const NoiseModel model = sensor.effectiveModel();
    NoiseModel eq5 = model;
    eq5.measuredLines.clear();
    const RawFormat fmt = sensor.rawFormat(kGain);
    const std::vector<Mat> bright = floatBurst(sensor, levelScene(size), 11);
    // As in exposureChangeMatchesTheModelOnlyWhenThePriorIsAccounted: 5 standard errors of a block's
    // mean variance are 5.6%; the lines leave Eq. 5 by 15% or more at gains 2, 3 and 4, so a step that
    // followed Eq. 5 fails.
    const double tolerance = 5 * std::sqrt(2.0 / (kFrames - 1)) / std::sqrt(256.0);
    Mat brightMean, brightVar;
    temporalStats(bright, fmt, brightMean, brightVar);
    for (int b = 1; b < 8; ++b) {
        const double m = blockAverage(brightMean, b);
        EXPECT_NEAR(blockAverage(brightVar, b) / model.variance(m, kGain), 1.0, tolerance)
            << "the simulator draws the measured line, block " << b;
    }
    struct Case
    {
        double gainRatio;
        NoiseAlignment alignment;
        ShotNoiseSampling sampling;
        double brightness; // not 0: Eq. 13 per pixel instead of the line per site
    };
    const Case cases[] = {{2.0, NoiseAlignment::ACCOUNT_PRIOR, ShotNoiseSampling::GAUSSIAN, 0.0},
                          {1.5, NoiseAlignment::ACCOUNT_PRIOR, ShotNoiseSampling::GAUSSIAN, 0.0},
                          {2.0, NoiseAlignment::ACCOUNT_PRIOR, ShotNoiseSampling::GAUSSIAN, 40.0},
                          {2.0, NoiseAlignment::ACCOUNT_PRIOR, ShotNoiseSampling::POISSON, 0.0},
                          {2.0, NoiseAlignment::IGNORE_PRIOR, ShotNoiseSampling::GAUSSIAN, 0.0}};
    for (const Case& c : cases) {
        const double outGain = kGain * c.gainRatio, factor = 0.5;
        NoiseOptions noise;
        noise.alignment = c.alignment;
        noise.shotSampling = c.sampling;
        Mat mean, var;
        statsAfterStep(
            bright, fmt,
            [&](const Mat& frame, int t, Mat& out) {
                RawFormat outFmt;
                ColorJitter jitter = ColorJitter::exposureChange(factor, c.gainRatio);
                jitter.brightness = c.brightness;
                colorJitter(frame, fmt, model, jitter, noise, 2000 + t, out, outFmt);
            },
            mean, var);
        for (int b = 1; b < 8; ++b) {
            SCOPED_TRACE(testing::Message()
                         << "gain ratio " << c.gainRatio << ", alignment " << static_cast<int>(c.alignment)
                         << ", sampling " << static_cast<int>(c.sampling) << ", brightness " << c.brightness
                         << ", block " << b);
            const double m = blockAverage(mean, b), v = blockAverage(var, b);
            const double contrast = factor * c.gainRatio, in = (m - c.brightness) / contrast;
            const double prior = contrast * contrast * model.variance(in, kGain);
            double expected = model.variance(m, outGain);
            // IGNORE_PRIOR adds the target's line on top of the prior scaled by the contrast squared.
            if (c.alignment == NoiseAlignment::IGNORE_PRIOR)
                expected += prior;
            // Eq. 13 takes a brightness as light (the prior scaled by (p_u p_g)^2 = (m / in)^2), but an
            // offset leaves the prior's noise as it is (contrast^2): the difference stays, as with Eq. 5.
            // Blocks from 800 DN: there the noisy value's spread moves E[(p_u p_g)^2] by under 1%.
            if (c.brightness != 0) {
                if (b < 4)
                    continue;
                expected += prior - (m / in) * (m / in) * model.variance(in, kGain);
            }
            EXPECT_NEAR(v / expected, 1.0, tolerance);
            if (b >= 4 && c.alignment == NoiseAlignment::ACCOUNT_PRIOR) {
                EXPECT_GT(std::abs(v / eq5.variance(m, outGain) - 1), tolerance) << "Eq. 5 would pass too";
            }
        }
    }
}

//! colorJitter's exposure change by photonRatio (the gain unchanged) with the shot noise drawn by `sampling`
//! and the other noise options at their defaults (ACCOUNT_PRIOR, PIXEL_VALUE).
Mat exposureChangeSampledBy(ShotNoiseSampling sampling, const Mat& src, const RawFormat& fmt,
                            const NoiseModel& model, double photonRatio, uint64 seed)
{
    NoiseOptions noise;
    noise.shotSampling = sampling;
    Mat out;
    RawFormat outFmt;
    colorJitter(src, fmt, model, ColorJitter::exposureChange(photonRatio, 1.0), noise, seed, out, outFmt);
    return out;
}

TEST(Augment, exposureChangeThirdCumulantIsWhatTheMathematicsDerives)
{
    // docs/mathematics.md: with pure shot noise (q = 1 DN per electron) an input of Poisson(lambda / p_u)
    // electrons darkened by p_u with PIXEL_VALUE has third cumulant (3 p_u - 2 p_u^2) lambda with Gaussian
    // added noise and (1 + 2 p_u (1 - p_u)) lambda with POISSON counts; the capture has lambda. These pin
    // the documented departure from the capture (POISSON overshoots a mild darkening's skewness by half),
    // so that a change of either sampling shows here. 2 M pixels: the standard error of k3 / lambda is
    // sqrt(6 lambda / n) (a near-normal sample of variance lambda), 0.017 at lambda = 100; the bound is 4
    // of them, and the two samplings differ by 0.5 lambda at p_u = 1/2.
    const double lambda = 100;
    RawFormat fmt;
    fmt.blackLevel = Vec4d::all(100);
    fmt.whiteLevel = 1e6;
    fmt.gain = 1;
    const NoiseModel model(1.0, 0.0, 1e-6);
    std::mt19937_64 engine(7);
    for (double pu : {0.5, 0.2, 0.05}) {
        Mat bright(1000, 2000, CV_32FC1);
        std::poisson_distribution<int> electrons(lambda / pu);
        for (int r = 0; r < bright.rows; ++r)
            for (int c = 0; c < bright.cols; ++c)
                bright.at<float>(r, c) = static_cast<float>(100 + electrons(engine));
        for (ShotNoiseSampling sampling : {ShotNoiseSampling::GAUSSIAN, ShotNoiseSampling::POISSON}) {
            const Mat out = exposureChangeSampledBy(sampling, bright, fmt, model, pu, 3);
            double s1 = 0, s2 = 0, s3 = 0;
            for (int r = 0; r < out.rows; ++r)
                for (int c = 0; c < out.cols; ++c) {
                    const double v = out.at<float>(r, c) - 100 - lambda;
                    s1 += v;
                    s2 += v * v;
                    s3 += v * v * v;
                }
            const double n = static_cast<double>(out.total()), m = s1 / n;
            const double k3 = s3 / n - 3 * m * s2 / n + 2 * m * m * m;
            const double predicted =
                sampling == ShotNoiseSampling::GAUSSIAN ? 3 * pu - 2 * pu * pu : 1 + 2 * pu * (1 - pu);
            EXPECT_NEAR(k3 / lambda, predicted, 4 * std::sqrt(6 * lambda / n))
                << "p_u " << pu << (sampling == ShotNoiseSampling::GAUSSIAN ? " GAUSSIAN" : " POISSON");
            EXPECT_NEAR((s2 / n - m * m) / lambda, 1.0, 4 * std::sqrt(2.0 / n)) << "p_u " << pu;
        }
    }
}

TEST(Augment, jitterAddsRowROfItsOwnStreamValueForValue)
{
    // The noise the jitter adds must be row r of its stream, value for value: a row that reused another
    // row's numbers, or restarted its stream part-way, would pass statistical tests. IGNORE_PRIOR on
    // float input with no clipping lets the test read the normal back: z = (out - black - c x) /
    // sqrt(v), v the model's variance at the new mean.
    const int rows = 5, cols = 1000; // rows of both CFA parities; 1000 is not a whole number of blocks
    RawFormat fmt;
    fmt.blackLevel = Vec4d::all(100);
    fmt.whiteLevel = 1e6;
    fmt.gain = 1;
    const NoiseModel model(0.5, 1.5, 3.0);
    Mat src(rows, cols, CV_32FC1);
    randu(src, 1000, 3000);
    ColorJitter jitter;
    jitter.contrast = Vec4d::all(0.5);
    const uint64 seed = 99;
    Mat out;
    RawFormat outFmt;
    colorJitter(src, fmt, model, jitter, NoiseAlignment::IGNORE_PRIOR, seed, out, outFmt);
    Mat z;
    fillStandardNormal(z, Size(cols, rows), detail::stepKey(seed, detail::RandomStream::JITTER_GAUSSIAN));
    const NoiseLine line = model.lineAtGain(1.0);
    double worst = 0;
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) {
            const double mean = 0.5 * (src.at<float>(r, c) - 100);
            const double added = out.at<float>(r, c) - 100 - mean;
            worst = std::max(worst, std::abs(added / std::sqrt(line.a * mean + line.b) - z.at<float>(r, c)));
        }
    // Float arithmetic of values near 1000 (ulp 6e-5) divided by a standard deviation near 25.
    EXPECT_LT(worst, 1e-4);
}

//! Counts of the integer values v - black in [lo, hi] of a CV_16UC1 frame.
std::vector<double> valueHistogram(const Mat& raw, double black, int lo, int hi)
{
    std::vector<double> counts(static_cast<size_t>(hi - lo + 1), 0.0);
    for (int r = 0; r < raw.rows; ++r)
        for (int c = 0; c < raw.cols; ++c) {
            const int v = static_cast<int>(raw.at<ushort>(r, c)) - static_cast<int>(black);
            if (v >= lo && v <= hi)
                counts[static_cast<size_t>(v - lo)] += 1;
        }
    return counts;
}

//! KL(p || q) in nats of two histograms; half a count is added to every bin of q (an empty bin of the
//! model where the truth has mass would make the divergence infinite, which says nothing useful).
double klDivergence(const std::vector<double>& p, const std::vector<double>& q)
{
    double np = 0, nq = 0;
    for (size_t i = 0; i < p.size(); ++i) {
        np += p[i];
        nq += q[i] + 0.5;
    }
    double kl = 0;
    for (size_t i = 0; i < p.size(); ++i)
        if (p[i] > 0)
            kl += p[i] / np * std::log((p[i] / np) / ((q[i] + 0.5) / nq));
    return kl;
}

TEST(Augment, poissonShotNoiseGivesTheElectronLatticeOfARealDarkCapture)
{
    // A sensor whose read noise (0.5 DN) is small next to its 4 DN per electron at gain 4: a capture of
    // two electrons per pixel puts its values on a lattice of 4 DN, the shape that matters at very low
    // light and that a Gaussian does not have.
    SensorParams params = test::referenceSensorParams();
    params.noise = NoiseModel(1.0, 0.01, 0.05);
    const Size size(256, 256);
    const SensorSimulator sensor(params, size);
    const NoiseModel model = sensor.effectiveModel();
    const double gain = 4, photonRatio = 0.01;
    const RawFormat fmt = sensor.rawFormat(gain);
    const Mat scene(size, CV_32FC1, Scalar(200)); // 200 electrons; x 0.01 = 2 electrons
    Mat bright, truth, truthAgain;
    sensor.capture(scene, gain, 1.0, 1, 0, bright);
    sensor.capture(scene, gain, photonRatio, 2, 0, truth);
    sensor.capture(scene, gain, photonRatio, 3, 0, truthAgain);
    const int lo = -24, hi = 64; // 2 electrons + 8 sigma of Poisson(2), in DN
    const std::vector<double> truthCounts = valueHistogram(truth, fmt.blackLevel[0], lo, hi);
    // The floor: two independent true captures differ by this much through sampling alone.
    const double klFloor = klDivergence(truthCounts, valueHistogram(truthAgain, fmt.blackLevel[0], lo, hi));
    double truthMean = 0, truthVar = 0;
    spatialStats(truth, fmt, truthMean, truthVar);
    double kl[2] = {0, 0};
    for (ShotNoiseSampling sampling : {ShotNoiseSampling::GAUSSIAN, ShotNoiseSampling::POISSON}) {
        const Mat out = exposureChangeSampledBy(sampling, bright, fmt, model, photonRatio, 7);
        const int i = static_cast<int>(sampling);
        kl[i] = klDivergence(truthCounts, valueHistogram(out, fmt.blackLevel[0], lo, hi));
        double mean = 0, var = 0;
        spatialStats(out, fmt, mean, var);
        // Both samplings add the same variance. A sample variance of N = 65536 values of a Poisson-like
        // variable (excess kurtosis 1/2 at 2 electrons) has relative spread sqrt((2 + 0.5) / N) = 0.6%;
        // the difference of two has sqrt(2) times that; 5 of those: 4.4%.
        const double tolerance = 5 * std::sqrt(2.0) * std::sqrt(2.5 / static_cast<double>(size.area()));
        EXPECT_NEAR(var / truthVar, 1.0, tolerance) << "sampling " << i;
        EXPECT_NEAR(mean, truthMean, 5 * std::sqrt(2 * truthVar / static_cast<double>(size.area())));
    }
    std::cout << "KL(true capture || augmented) at 2 electrons: GAUSSIAN " << kl[0] << ", POISSON " << kl[1]
              << ", between two true captures " << klFloor << "\n";
    // The Gaussian misses the lattice entirely (KL of order log 4: the truth's mass sits on one value in
    // four); the Poisson sampling reproduces it up to the scaled prior's 0.57 DN smear, comparable to
    // the truth's own 0.5 DN read noise. An order of magnitude between them is the claim.
    EXPECT_GT(kl[0], 0.3);
    EXPECT_LT(kl[1], kl[0] / 10);
}

//! The 3x3 same-site mean of each pixel of a float mosaic (offsets -2, 0, 2), mirrored at the edges.
Mat sameSiteLocalMean(const Mat& x)
{
    const auto mirror = [](int i, int n) { return i < 0 ? -i : (i >= n ? 2 * (n - 1) - i : i); };
    Mat mean(x.size(), CV_32FC1);
    for (int r = 0; r < x.rows; ++r)
        for (int c = 0; c < x.cols; ++c) {
            double sum = 0;
            for (int dy = -2; dy <= 2; dy += 2)
                for (int dx = -2; dx <= 2; dx += 2)
                    sum += x.at<float>(mirror(r + dy, x.rows), mirror(c + dx, x.cols));
            mean.at<float>(r, c) = static_cast<float>(sum / 9);
        }
    return mean;
}

TEST(Augment, localPriorMeanRemovesTheClipBiasAtBlack)
{
    // A black frame at 18 dB: the true mean is 0, so the target of a x0.5 exposure has no shot noise.
    // mu_x = max(x, 0) of a noisy pixel is E[max(x, 0)] = sigma / sqrt(2 pi) on average, adding shot
    // variance that is not there; the mean of nine same-site pixels has a third of the spread.
    const Size size(512, 512);
    const SensorSimulator sensor(test::referenceSensorParams(), size);
    const NoiseModel model = sensor.effectiveModel();
    const double gain = 8, photonRatio = 0.5;
    const RawFormat fmt = sensor.rawFormat(gain);
    Mat raw;
    sensor.capture(Mat::zeros(size, CV_32FC1), gain, 1.0, 11, 0, raw);
    raw.convertTo(raw, CV_32F); // float output: no second rounding in the variance
    double inMean = 0, inVar = 0;
    spatialStats(raw, fmt, inMean, inVar);
    Mat x;
    subtractBlackLevel(raw, fmt, x);
    const NoiseLine line = model.lineAtGain(gain);
    double excess[2] = {0, 0};
    for (PriorMeanEstimate prior : {PriorMeanEstimate::PIXEL_VALUE, PriorMeanEstimate::LOCAL_MEAN}) {
        NoiseOptions noise;
        noise.priorMean = prior;
        Mat out;
        RawFormat outFmt;
        colorJitter(raw, fmt, model, ColorJitter::exposureChange(photonRatio, 1.0), noise, 12, out, outFmt);
        double mean = 0, var = 0;
        spatialStats(out, fmt, mean, var);
        // Eq. 11 with this estimate, averaged over the frame: p^2 v_in + E[v], where
        // v = p_u (1 - p_u) g alpha mu + (1 - p_u^2) b (p_g = 1, so p_u = p and v > 0 everywhere).
        const Mat mu = max(prior == PriorMeanEstimate::LOCAL_MEAN ? sameSiteLocalMean(x) : x, 0.0);
        const double shotTerm = photonRatio * (1 - photonRatio) * line.a * cv::mean(mu)[0];
        const double predicted =
            photonRatio * photonRatio * inVar + shotTerm + (1 - photonRatio * photonRatio) * line.b;
        // Sample variance of 262144 near-Gaussian values: relative spread sqrt(2 / N) = 0.28%; 5 of it.
        EXPECT_NEAR(var / predicted, 1.0, 5 * std::sqrt(2.0 / static_cast<double>(size.area())))
            << "prior " << static_cast<int>(prior);
        excess[static_cast<int>(prior)] = shotTerm / line.b;
    }
    std::cout << "Shot variance added at black (relative to the read noise): PIXEL_VALUE " << excess[0]
              << ", LOCAL_MEAN " << excess[1] << "\n";
    // sigma / sqrt(2 pi) against (sigma / 3) / sqrt(2 pi): a third, give or take the mirrored borders.
    EXPECT_GT(excess[0], 0.03);
    EXPECT_LT(excess[1], 0.4 * excess[0]);
}

TEST(Augment, poissonJitterAddsExactPoissonCountsAtEveryMean)
{
    // End to end through the POISSON rows of colorJitter (split, vector draws, noise pass): a sensor
    // without read noise at 1 DN per electron, a noiseless float input, exposure x0.2. ACCOUNT_PRIOR adds
    // shot variance p_u (1 - p_u) x = 0.16 x, drawn as K - m with m = 0.16 x electrons, so each output is
    // 0.2 x + K - 0.16 x = 0.04 x + K: an integer K above 0.04 x that must be Poisson(0.16 x). Means on
    // both sides of the inversion/rejection switch at 10 and far above it.
    const std::vector<double> means = {2.0, 8.0, 10.0, 40.0, 1000.0};
    const int blockCols = 100, rows = 400;
    Mat src(rows, blockCols * static_cast<int>(means.size()), CV_32FC1);
    for (int c = 0; c < src.cols; ++c)
        src.col(c).setTo(means[static_cast<size_t>(c / blockCols)] / 0.16);
    const NoiseModel model(1.0, 0.0, 0.0);
    RawFormat fmt;
    fmt.blackLevel = Vec4d::all(0);
    fmt.whiteLevel = 1e9;
    fmt.gain = 1;
    const Mat out = exposureChangeSampledBy(ShotNoiseSampling::POISSON, src, fmt, model, 0.2, 11);
    for (size_t m = 0; m < means.size(); ++m) {
        const double lambda = means[m];
        std::map<int64_t, int> hist;
        double worst = 0;
        for (int r = 0; r < rows; ++r)
            for (int c = static_cast<int>(m) * blockCols; c < static_cast<int>(m + 1) * blockCols; ++c) {
                const double k = out.at<float>(r, c) - 0.04 * src.at<float>(r, c);
                const double rounded = std::round(k);
                worst = std::max(worst, std::abs(k - rounded));
                ++hist[static_cast<int64_t>(rounded)];
            }
        // The float output holds 0.04 x + K to a few float ulps of values below 1100 (1e-4).
        EXPECT_LT(worst, 1e-3) << "mean " << lambda;
        int dof = 0;
        const double chi2 = test::poissonChiSquare(hist, lambda, static_cast<double>(rows * blockCols), dof);
        // chi^2 with dof degrees of freedom: mean dof, sd sqrt(2 dof); 6 sd, as the samplers' own tests.
        EXPECT_LT(chi2, dof + 6 * std::sqrt(2.0 * dof)) << "mean " << lambda << ", dof " << dof;
    }
}

TEST(Augment, darkeningAddsTheDarkFrameComponentsATargetCaptureHas)
{
    const Size size(256, 256);
    const int T = 32;
    const SensorParams params = darkComponentSensor(size);
    const SensorSimulator sensor(params, size);
    const NoiseModel model = sensor.effectiveModel();
    const RawFormat fmt = sensor.rawFormat(1.0);
    const double black = fmt.blackLevel[0];
    const Mat scene(size, CV_32FC1, Scalar(400));
    std::vector<Mat> bright;
    sensor.captureBurst(scene, 1.0, 1.0, T, 7, bright);
    NoiseModel gaussianRead = model;
    gaussianRead.tukeyRead = false;
    struct Case
    {
        double photonRatio, gainRatio;
        bool priorMatters; // whether the scaled prior is a sizeable part of the target (IGNORE_PRIOR shows)
    };
    for (const Case& c : {Case{1.0 / 200, 8, false}, Case{0.5, 2, true}}) {
        SCOPED_TRACE(testing::Message() << "photons x" << c.photonRatio << ", gain x" << c.gainRatio);
        std::vector<Mat> target;
        sensor.captureBurst(scene, c.gainRatio, c.photonRatio, T, 8, target);
        const DarkStats truth = darkStats(target, black);
        const ColorJitter jitter = ColorJitter::exposureChange(c.photonRatio, c.gainRatio);
        auto augmented = [&](const NoiseModel& m, const NoiseOptions& options) {
            std::vector<Mat> out(T);
            RawFormat outFmt;
            for (int t = 0; t < T; ++t)
                colorJitter(bright[t], fmt, m, jitter, options, 100 + t, out[t], outFmt);
            return darkStats(out, black);
        };
        // Row-mean variances of (T - 1) H Gaussian row means: relative standard error sqrt(2 / dof) each;
        // pixel variances: sqrt((2 + kurtosis) / n) each with n = (T - 1) H (W - 1) (a sample variance of
        // heavy-tailed data). Five standard errors of the difference of two such estimates.
        const double rowTol = 5 * std::sqrt(2.0) * std::sqrt(2.0 / truth.dof);
        const double pixTol =
            5 * std::sqrt(2.0) *
            std::sqrt((2 + std::max(truth.kurtosis, 0.0)) / (truth.dof * (size.width - 1.0)));
        // The fixed-pattern excess is a mean of H W squared normal differences: standard error
        // sqrt(2 / (H W)) (0.55%); 5 of them.
        const double patternTol = 5 * std::sqrt(2.0 / size.area());
        const DarkStats account = augmented(model, NoiseAlignment::ACCOUNT_PRIOR);
        EXPECT_NEAR(account.rowMeanVar / truth.rowMeanVar, 1, rowTol) << "row-mean variance";
        EXPECT_NEAR(account.pixelVar / truth.pixelVar, 1, pixTol) << "per-pixel variance";
        EXPECT_NEAR(fixedPatternExcess(account, truth, T, size.width), 0, patternTol) << "fixed pattern";
        // The capture's shot noise is a Poisson count (excess kurtosis 1 / electrons: 0.2 at 5 electrons,
        // 0.07 of the total's kurtosis here), which Gaussian shot draws lack: the kurtosis is compared
        // with Poisson shot draws, so that only the read part's tails are under test.
        NoiseOptions poisson;
        poisson.shotSampling = ShotNoiseSampling::POISSON;
        const DarkStats accountPoisson = augmented(model, poisson);
        const double kurtosisTol = 5 * std::hypot(accountPoisson.kurtosisSE, truth.kurtosisSE);
        EXPECT_NEAR(accountPoisson.kurtosis, truth.kurtosis, kurtosisTol) << "excess kurtosis";
        EXPECT_NEAR(accountPoisson.pixelVar / truth.pixelVar, 1, pixTol) << "per-pixel variance (Poisson)";
        const DarkStats none = augmented(model, NoiseAlignment::NONE);
        EXPECT_LT(none.rowMeanVar / truth.rowMeanVar, 1 - rowTol) << "NONE keeps only the scaled rows";
        EXPECT_LT(none.pixelVar / truth.pixelVar, 1 - pixTol) << "NONE keeps only the scaled prior";
        EXPECT_GT(fixedPatternExcess(none, truth, T, size.width), patternTol)
            << "NONE keeps the scaled pattern";
        const DarkStats ignore = augmented(model, NoiseAlignment::IGNORE_PRIOR);
        if (c.priorMatters) {
            EXPECT_GT(ignore.rowMeanVar / truth.rowMeanVar, 1 + rowTol) << "IGNORE_PRIOR doubles the rows";
            EXPECT_GT(ignore.pixelVar / truth.pixelVar, 1 + pixTol) << "IGNORE_PRIOR doubles the noise";
            EXPECT_GT(fixedPatternExcess(ignore, truth, T, size.width), patternTol)
                << "IGNORE_PRIOR adds the pattern on top of the scaled one";
        } else {
            // Where the target's read noise dominates, the tails must come from the added part: Gaussian
            // draws of the same variance leave the result less heavy-tailed than the capture.
            const DarkStats gaussian = augmented(gaussianRead, poisson);
            EXPECT_LT(gaussian.kurtosis,
                      truth.kurtosis - 5 * std::hypot(gaussian.kurtosisSE, truth.kurtosisSE))
                << "Gaussian read noise";
            EXPECT_NEAR(gaussian.pixelVar / truth.pixelVar, 1, pixTol) << "its variance is still right";
        }
        std::cout << "photons x" << c.photonRatio << " gain x" << c.gainRatio << ": row-mean var (capture "
                  << truth.rowMeanVar << ") NONE " << none.rowMeanVar << ", IGNORE " << ignore.rowMeanVar
                  << ", ACCOUNT " << account.rowMeanVar << "; kurtosis (capture " << truth.kurtosis << " +- "
                  << truth.kurtosisSE << ") NONE " << none.kurtosis << ", IGNORE " << ignore.kurtosis
                  << ", ACCOUNT " << account.kurtosis << " (Poisson shot " << accountPoisson.kurtosis
                  << "); pattern excess NONE " << fixedPatternExcess(none, truth, T, size.width)
                  << ", IGNORE " << fixedPatternExcess(ignore, truth, T, size.width) << ", ACCOUNT "
                  << fixedPatternExcess(account, truth, T, size.width) << "\n";
    }
}

} // namespace
} // namespace rawgment
} // namespace cv
