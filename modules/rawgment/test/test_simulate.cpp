// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "test_common.hpp"

#include "../src/random.hpp"
#include <opencv2/core/utility.hpp>
#include <opencv2/rawgment/cpu.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <cstring>
#include <map>
#include <set>

namespace cv {
namespace rawgment {
namespace {

TEST(Simulate, philoxMatchesTheKnownAnswerVectors)
{
    // Known-answer tests of Random123 for Philox4x32-10 (counter, key -> output).
    using A4 = std::array<uint32_t, 4>;
    using A2 = std::array<uint32_t, 2>;
    EXPECT_EQ(detail::philox4x32(A4{0, 0, 0, 0}, A2{0, 0}),
              (A4{0x6627e8d5, 0xe169c58d, 0xbc57ac4c, 0x9b00dbd8}));
    EXPECT_EQ(
        detail::philox4x32(A4{0xffffffff, 0xffffffff, 0xffffffff, 0xffffffff}, A2{0xffffffff, 0xffffffff}),
        (A4{0x408f276d, 0x41c83b0e, 0xa20bc7c6, 0x6d5451fd}));
    EXPECT_EQ(
        detail::philox4x32(A4{0x243f6a88, 0x85a308d3, 0x13198a2e, 0x03707344}, A2{0xa4093822, 0x299f31d0}),
        (A4{0xd16cfe09, 0x94fdcceb, 0x5001e420, 0x24126ea1}));
}

TEST(Simulate, everyPhiloxVersionGivesTheBlocksOfTheScalarOne)
{
    // fillGaussian draws from one of these per CpuPath: each must be Philox4x32-10 itself, word for word.
    using A4 = std::array<uint32_t, 4>;
    using A2 = std::array<uint32_t, 2>;
    typedef void (*EightBlocks)(uint32_t, uint64_t, const A2&, uint32_t*);
    std::vector<std::pair<const char*, EightBlocks>> versions = {
        {"vector extensions",
         [](uint32_t f, uint64_t s, const A2& k, uint32_t* w) { detail::philox8Blocks(f, s, k, w); }}};
#if RAWGMENT_HAVE_CPU_PATHS
    versions.push_back({"SSE2", detail::philox8BlocksSse2});
    if (isCpuPathAvailable(CpuPath::AVX2))
        versions.push_back({"AVX2", detail::philox8BlocksAvx2});
    if (isCpuPathAvailable(CpuPath::AVX512))
        versions.push_back({"AVX-512", detail::philox8BlocksAvx512});
#endif
    for (const auto& version : versions)
        for (const A2 key : {A2{0, 0}, A2{42, 7}, A2{0xffffffff, 0xffffffff}})
            for (const uint64_t stream : {uint64_t(0), uint64_t(5), uint64_t(0xfedcba9876543210ull)})
                for (const uint32_t first : {0u, 8u, 0xfffffffcu}) {
                    uint32_t words[32];
                    version.second(first, stream, key, words);
                    for (uint32_t b = 0; b < 8; ++b) {
                        const A4 block = detail::philox4x32(A4{first + b, 0, static_cast<uint32_t>(stream),
                                                               static_cast<uint32_t>(stream >> 32)},
                                                            key);
                        for (int j = 0; j < 4; ++j)
                            ASSERT_EQ(words[8 * j + b], block[static_cast<size_t>(j)])
                                << version.first << ", block " << b << ", word " << j;
                    }
                }
    // One block of eight streams (fillPoisson's retries), with streams whose high words differ too.
    typedef void (*EightStreams)(uint32_t, const uint64_t*, const A2&, uint32_t*);
    std::vector<std::pair<const char*, EightStreams>> streamVersions = {
        {"vector extensions", [](uint32_t b, const uint64_t* s, const A2& k, uint32_t* w) {
             detail::philox8Streams(b, s, k, w);
         }}};
#if RAWGMENT_HAVE_CPU_PATHS
    streamVersions.push_back({"SSE2", detail::philox8StreamsSse2});
    if (isCpuPathAvailable(CpuPath::AVX2))
        streamVersions.push_back({"AVX2", detail::philox8StreamsAvx2});
    if (isCpuPathAvailable(CpuPath::AVX512))
        streamVersions.push_back({"AVX-512", detail::philox8StreamsAvx512});
#endif
    const uint64_t streams[8] = {0, 1, 7, 4000, 0xffffffffull, 0x100000000ull, 0xfedcba9876543210ull, 42};
    for (const auto& version : streamVersions)
        for (const A2 key : {A2{0, 0}, A2{42, 7}, A2{0xffffffff, 0xffffffff}})
            for (const uint32_t block : {0u, 3u, 0xffffffffu}) {
                uint32_t words[32];
                version.second(block, streams, key, words);
                for (int b = 0; b < 8; ++b) {
                    const A4 expected = detail::philox4x32(A4{block, 0, static_cast<uint32_t>(streams[b]),
                                                              static_cast<uint32_t>(streams[b] >> 32)},
                                                           key);
                    for (int j = 0; j < 4; ++j)
                        ASSERT_EQ(words[8 * j + b], expected[static_cast<size_t>(j)])
                            << version.first << ", stream " << streams[b] << ", word " << j;
                }
            }
}

//! A noiseless-readout sensor: with alpha = 1 and no rounding, a capture is Poisson(mean) + black.
SensorSimulator poissonOnlySensor(Size size)
{
    SensorParams p;
    p.noise = NoiseModel(1.0, 0.0, 0.0);
    p.quantize = false;
    p.bitDepth = 16;
    p.blackLevel = Vec4d::all(0);
    return SensorSimulator(p, size);
}

TEST(Simulate, poissonSamplingIsExactAtEveryMean)
{
    const Size size(200, 200);
    const SensorSimulator sensor = poissonOnlySensor(size);
    // Inversion below 10, rejection (PTRS) above: test both sides of the switch and its edges.
    for (double lambda : {0.05, 0.7, 3.0, 9.99, 10.0, 37.5, 5000.0}) {
        Mat raw;
        sensor.capture(Mat(size, CV_32FC1, Scalar(lambda)), 1.0, 1.0, 17, 0, raw);
        Scalar mean, sd;
        meanStdDev(raw, mean, sd);
        const double n = static_cast<double>(size.area());
        // Mean and variance of a Poisson are both lambda; the standard error of the sample mean is
        // sqrt(lambda / n), of the sample variance sqrt((2 lambda^2 + lambda) / n): 5 standard errors.
        EXPECT_NEAR(mean[0], lambda, 5 * std::sqrt(lambda / n)) << lambda;
        EXPECT_NEAR(sd[0] * sd[0], lambda, 5 * std::sqrt((2 * lambda * lambda + lambda) / n)) << lambda;
        // Integer-valued, as photon counts are.
        Mat rounded;
        raw.convertTo(rounded, CV_32S);
        rounded.convertTo(rounded, CV_32F);
        EXPECT_EQ(norm(rounded, raw, NORM_INF), 0) << lambda;
    }
}

TEST(Simulate, poissonHistogramPassesChiSquare)
{
    const Size size(200, 200);
    const SensorSimulator sensor = poissonOnlySensor(size);
    for (double lambda : {3.0, 40.0}) {
        Mat raw;
        sensor.capture(Mat(size, CV_32FC1, Scalar(lambda)), 1.0, 1.0, 99, 0, raw);
        std::map<int64_t, int> counts;
        for (auto it = raw.begin<float>(); it != raw.end<float>(); ++it)
            ++counts[static_cast<int64_t>(*it)];
        int dof = 0;
        double mass = 0;
        const double chi2 =
            test::poissonChiSquare(counts, lambda, static_cast<double>(size.area()), dof, &mass);
        // chi^2 with dof degrees of freedom has mean dof and sd sqrt(2 dof): 6 sd covers any sane run
        // and still catches a Gaussian approximation (which fails at lambda = 3 by hundreds).
        EXPECT_LT(chi2, dof + 6 * std::sqrt(2.0 * dof)) << "lambda " << lambda << " dof " << dof;
        EXPECT_GT(mass, 1 - 1e-9);
    }
}

SensorParams typicalParams()
{
    SensorParams p;
    p.noise = NoiseModel(0.5, 2.0, 1.0);
    p.blackLevel = Vec4d(64, 65, 66, 67);
    p.bitDepth = 14;
    return p;
}

TEST(Simulate, burstVarianceFollowsTheEffectiveModelAtEveryGain)
{
    const Size size(64, 64);
    const SensorSimulator sensor(typicalParams(), size);
    const int frames = 64;
    for (double db : {0.0, 12.0, 24.0}) {
        const double g = dbToLinearGain(db);
        Mat mean(size, CV_32FC1);
        for (int c = 0; c < size.width; ++c)
            mean.col(c).setTo(5.0 + 30.0 * c); // 5 to ~1900 DN at gain 1
        std::vector<Mat> burst;
        sensor.captureBurst(mean, g, 1.0, frames, 3, burst);
        const RawFormat fmt = sensor.rawFormat(g);
        // Temporal statistics of each column (64 rows x 64 frames = 4096 samples of one mean).
        for (int c = 0; c < size.width; c += 9) {
            double s = 0, s2 = 0;
            int n = 0;
            for (const Mat& f : burst)
                for (int r = 0; r < size.height; ++r) {
                    const double x = f.at<ushort>(r, c) - fmt.blackAt(r, c);
                    s += x;
                    s2 += x * x;
                    ++n;
                }
            const double m = s / n, v = (s2 - s * s / n) / (n - 1);
            const double trueMean = g * mean.at<float>(0, c);
            const double trueVar = sensor.effectiveModel().variance(trueMean, g);
            if (trueMean + 6 * std::sqrt(trueVar) > fmt.whiteLevel - 67)
                continue; // clipping would bias both
            // Standard errors with n = 4096: mean sqrt(v / n); variance v sqrt(2 / (n - 1)); 5 of each.
            EXPECT_NEAR(m, trueMean, 5 * std::sqrt(trueVar / n)) << db << " dB, column " << c;
            EXPECT_NEAR(v, trueVar, 5 * trueVar * std::sqrt(2.0 / (n - 1))) << db << " dB, column " << c;
        }
    }
}

TEST(Simulate, sameSeedIsBitIdenticalOnAnyThreadCount)
{
    const Size size(96, 64);
    const SensorSimulator sensor(typicalParams(), size);
    const Mat mean(size, CV_32FC1, Scalar(300));
    const int saved = getNumThreads();
    std::vector<Mat> runs;
    for (int threads : {1, 2, 8}) {
        setNumThreads(threads);
        runs.emplace_back();
        sensor.capture(mean, 4.0, 1.0, 1234, 5, runs.back());
    }
    setNumThreads(saved);
    EXPECT_EQ(norm(runs[0], runs[1], NORM_INF), 0);
    EXPECT_EQ(norm(runs[0], runs[2], NORM_INF), 0);
    Mat otherFrame, otherSeed;
    sensor.capture(mean, 4.0, 1.0, 1234, 6, otherFrame);
    sensor.capture(mean, 4.0, 1.0, 1235, 5, otherSeed);
    EXPECT_GT(norm(runs[0], otherFrame, NORM_L1), 0);
    EXPECT_GT(norm(runs[0], otherSeed, NORM_L1), 0);
}

TEST(Simulate, clippingAtWhiteAndZero)
{
    SensorParams p = typicalParams();
    p.bitDepth = 10;
    const SensorSimulator sensor(p, Size(8, 8));
    Mat raw;
    sensor.capture(Mat(8, 8, CV_32FC1, Scalar(5000)), 1.0, 1.0, 1, 0, raw);
    EXPECT_EQ(countNonZero(raw != 1023), 0);
    p.blackLevel = Vec4d::all(0);
    p.noise = NoiseModel(0.5, 50.0, 50.0);
    const SensorSimulator dark(p, Size(8, 8));
    dark.capture(Mat(8, 8, CV_32FC1, Scalar(0)), 1.0, 1.0, 1, 0, raw);
    double lo, hi;
    minMaxLoc(raw, &lo, &hi);
    EXPECT_EQ(lo, 0); // negative read noise clips at zero rather than wrapping
    EXPECT_GT(hi, 0);
}

TEST(Simulate, fixedPatternDefectsAndNonUniformity)
{
    SensorParams p = typicalParams();
    p.hotPixelFraction = 0.02;
    p.deadPixelFraction = 0.01;
    p.noisyPixelFraction = 0.03;
    p.prnu = 0.01;
    p.dsnu = 0.5;
    const Size size(200, 100);
    const SensorSimulator sensor(p, size);
    Mat gainFactor, offset, defects;
    sensor.fixedPattern(gainFactor, offset, defects);
    const double n = size.area();
    // Binomial counts: 5 standard errors around the fraction.
    for (int code = 1; code <= 3; ++code) {
        const double f = code == 1 ? 0.02 : code == 2 ? 0.01 : 0.03;
        EXPECT_NEAR(countNonZero(defects == code), f * n, 5 * std::sqrt(n * f * (1 - f))) << code;
    }
    Scalar m, sd;
    meanStdDev(gainFactor, m, sd);
    EXPECT_NEAR(sd[0], 0.01, 0.01 * 5 / std::sqrt(2 * n));
    meanStdDev(offset, m, sd);
    EXPECT_NEAR(sd[0], 0.5, 0.5 * 5 / std::sqrt(2 * n));
    // Hot pixels are stuck near white, dead ones at black: no temporal noise.
    std::vector<Mat> burst;
    sensor.captureBurst(Mat(size, CV_32FC1, Scalar(500)), 2.0, 1.0, 3, 8, burst);
    const RawFormat fmt = sensor.rawFormat(2.0);
    for (int r = 0; r < size.height; ++r)
        for (int c = 0; c < size.width; ++c) {
            const uchar d = defects.at<uchar>(r, c);
            if (d == 1) {
                ASSERT_EQ(burst[0].at<ushort>(r, c), std::round(0.9 * fmt.whiteLevel));
                ASSERT_EQ(burst[1].at<ushort>(r, c), burst[0].at<ushort>(r, c));
            } else if (d == 2) {
                ASSERT_EQ(burst[2].at<ushort>(r, c), fmt.blackAt(r, c));
            }
        }
}

TEST(Simulate, blurredCaptureBlursPhotonsNotNoise)
{
    // Eq. 14: a blurred capture has the blurred mean and the *full* noise of that mean: blur the scene,
    // not the noisy frame.
    SensorParams p = typicalParams();
    p.noise = NoiseModel(1.0, 4.0, 2.0);
    const Size size(128, 128);
    const SensorSimulator sensor(p, size);
    Mat mean(size, CV_32FC1, Scalar(100));
    mean.colRange(64, 128).setTo(900);
    const Mat kernel = Mat::ones(1, 7, CV_32F);
    const int frames = 40;
    Mat sum(size, CV_64F, Scalar(0)), sum2(size, CV_64F, Scalar(0));
    for (int t = 0; t < frames; ++t) {
        Mat raw, x;
        sensor.captureBlurred(mean, kernel, 1.0, 1.0, 21, t, raw);
        subtractBlackLevel(raw, sensor.rawFormat(1.0), x);
        x.convertTo(x, CV_64F);
        sum += x;
        sum2 += x.mul(x);
    }
    const Mat m = sum / frames;
    const Mat v = (sum2 - sum.mul(sum) / frames) / (frames - 1);
    // Far from the edge: mean 100 or 900, variance of the model at that mean (no 1/7 reduction).
    for (int col : {10, 120}) {
        const double trueMean = col < 64 ? 100 : 900;
        const double trueVar = sensor.effectiveModel().variance(trueMean, 1.0);
        const Scalar colMean = cv::mean(m.col(col)), colVar = cv::mean(v.col(col));
        // 128 rows x 40 frames: standard errors sqrt(v / 5120) and v sqrt(2 / 39) / sqrt(128).
        EXPECT_NEAR(colMean[0], trueMean, 5 * std::sqrt(trueVar / 5120.0));
        EXPECT_NEAR(colVar[0], trueVar, 5 * trueVar * std::sqrt(2.0 / 39) / std::sqrt(128.0));
    }
    // At the edge the plane-grid kernel of 7 mixes the two levels: the mosaic column 64 (plane column
    // 32) is the average of plane columns 29..35, 3 dark and 4 bright.
    const double edgeMean = cv::mean(m.col(64))[0];
    EXPECT_NEAR(edgeMean, (3 * 100 + 4 * 900) / 7.0, 10);
}

/* Column banding: each column of a frame shares one offset of the stated variance. Over 64 float frames of 96
 * rows the column means vary by the offset's variance plus the pixel noise over the rows; their average over
 * 128 columns has a relative standard error of about sqrt(2 / 63 / 128) = 1.6%, so 5% is 3 of them. */
TEST(Simulate, columnNoiseIsAnOffsetSharedByEachColumnOfAFrame)
{
    SensorParams p;
    p.quantize = false;
    p.columnNoiseVariance = 4;
    const Size size(128, 96);
    const SensorSimulator sensor(p, size);
    const int frames = 64;
    std::vector<double> sum(size.width, 0), sum2(size.width, 0);
    double pixelVariance = 0;
    for (int t = 0; t < frames; ++t) {
        Mat raw;
        sensor.capture(Mat::zeros(size, CV_32F), 2.0, 1.0, 3, t, raw);
        Mat columns;
        reduce(raw, columns, 0, REDUCE_AVG, CV_64F);
        for (int c = 0; c < size.width; ++c) {
            sum[c] += columns.at<double>(0, c);
            sum2[c] += columns.at<double>(0, c) * columns.at<double>(0, c);
        }
    }
    pixelVariance = sensor.effectiveModel().variance(0, 2.0);
    double columnVariance = 0;
    for (int c = 0; c < size.width; ++c)
        columnVariance += (sum2[c] - sum[c] * sum[c] / frames) / (frames - 1) / size.width;
    EXPECT_NEAR(columnVariance - pixelVariance / size.height, 4.0, 0.05 * 4.0);
    p.columnNoiseVariance = -1;
    EXPECT_CV_ERROR_CONTAINS(SensorSimulator(p, size), "columnNoiseVariance");
}

TEST(Simulate, rejectsBadInput)
{
    SensorParams p = typicalParams();
    p.bitDepth = 17;
    EXPECT_CV_ERROR_CONTAINS(SensorSimulator(p, Size(4, 4)), "bitDepth");
    p = typicalParams();
    p.hotPixelFraction = 0.7;
    p.deadPixelFraction = 0.7;
    EXPECT_CV_ERROR_CONTAINS(SensorSimulator(p, Size(4, 4)), "hotPixelFraction + deadPixelFraction");
    p = typicalParams();
    p.blackLevel[1] = 1e6;
    EXPECT_CV_ERROR_CONTAINS(SensorSimulator(p, Size(4, 4)), "blackLevel[1]");
    EXPECT_CV_ERROR_CONTAINS(SensorSimulator(typicalParams(), Size(5, 4)), "positive and even");
    const SensorSimulator sensor(typicalParams(), Size(4, 4));
    Mat raw;
    EXPECT_CV_ERROR_CONTAINS(sensor.capture(Mat(4, 4, CV_16UC1), 1, 1, 0, 0, raw), "CV_32FC1 of 4x4");
    EXPECT_CV_ERROR_CONTAINS(sensor.capture(Mat(4, 4, CV_32FC1, Scalar(-1)), 1, 1, 0, 0, raw), ">= 0");
    Mat withNan(4, 4, CV_32FC1, Scalar(1));
    withNan.at<float>(2, 2) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_CV_ERROR_CONTAINS(sensor.capture(withNan, 1, 1, 0, 0, raw), "finite");
    EXPECT_CV_ERROR_CONTAINS(sensor.capture(Mat(4, 4, CV_32FC1, Scalar(1)), 0, 1, 0, 0, raw), "gain");
    EXPECT_CV_ERROR_CONTAINS(sensor.capture(Mat(4, 4, CV_32FC1, Scalar(1)), 1, -1, 0, 0, raw), "exposure");
    EXPECT_CV_ERROR_CONTAINS(
        sensor.captureBlurred(Mat(4, 4, CV_32FC1, Scalar(1)), Mat::zeros(1, 3, CV_32F), 1, 1, 0, 0, raw),
        "positive sum");
}

TEST(Simulate, colorCheckerLayoutAndValues)
{
    ColorCheckerOptions o;
    o.pattern = CFA_GRBG;
    o.patchSize = 24;
    o.border = 6;
    o.illumination = 1000;
    const ColorCheckerScene scene = makeColorCheckerScene(o);
    ASSERT_EQ(scene.patches.size(), 24u);
    ASSERT_EQ(scene.reflectance.size(), 24u);
    EXPECT_EQ(scene.meanAtUnitGain.size(), Size(6 * 30 + 6, 4 * 30 + 6));
    const Rect frame(Point(0, 0), scene.meanAtUnitGain.size());
    for (size_t i = 0; i < 24; ++i) {
        const Rect& a = scene.patches[i];
        EXPECT_EQ(a & frame, a);
        EXPECT_EQ(a.x % 2, 0); // CFA-aligned
        EXPECT_EQ(a.y % 2, 0);
        for (size_t j = i + 1; j < 24; ++j)
            EXPECT_EQ((a & scene.patches[j]).area(), 0);
        // Each site sees its channel's reflectance.
        for (int r = 0; r < 2; ++r)
            for (int c = 0; c < 2; ++c) {
                const CfaChannel ch = cfaChannelAt(o.pattern, a.y + r, a.x + c);
                const int k = ch == CFA_R ? 0 : ch == CFA_B ? 2 : 1;
                EXPECT_NEAR(scene.meanAtUnitGain.at<float>(a.y + r, a.x + c), 1000 * scene.reflectance[i][k],
                            1e-3);
            }
    }
    // The grey row darkens from white (18) to black (23).
    for (int i = 18; i < 23; ++i)
        EXPECT_GT(scene.reflectance[i][1], scene.reflectance[i + 1][1]);
    EXPECT_NEAR(scene.reflectance[18][1], 0.896, 0.01); // white: about 90%
    // Vignetting darkens the corners, not the centre.
    o.vignetting = 0.4;
    const ColorCheckerScene shaded = makeColorCheckerScene(o);
    EXPECT_LT(shaded.meanAtUnitGain.at<float>(0, 0), scene.meanAtUnitGain.at<float>(0, 0) * 0.65);
    EXPECT_CV_ERROR_CONTAINS(makeColorCheckerScene(ColorCheckerOptions{CFA_RGGB, 5}),
                             "patchSize must be even");
    // A sensor without a filter sees the luminance of the three bands (Rec. 709 weights) on every site.
    o.pattern = CFA_MONO;
    o.vignetting = 0;
    const ColorCheckerScene mono = makeColorCheckerScene(o);
    for (size_t i = 0; i < 24; ++i) {
        const Vec3d& rho = scene.reflectance[i];
        const double luminance = 0.2126 * rho[0] + 0.7152 * rho[1] + 0.0722 * rho[2];
        for (int s = 0; s < 4; ++s)
            EXPECT_NEAR(mono.meanAtUnitGain.at<float>(mono.patches[i].y + s / 2, mono.patches[i].x + s % 2),
                        1000 * luminance, 1e-3)
                << "patch " << i << ", site " << s;
    }
    SensorParams unequal;
    unequal.pattern = CFA_MONO;
    unequal.blackLevel = Vec4d(256, 256, 256, 250);
    EXPECT_CV_ERROR_CONTAINS(SensorSimulator(unequal, Size(8, 8)),
                             "one value on all four sites for CFA_MONO");
}

TEST(Simulate, fillGaussianIsBoxMullerOfItsPhiloxWordsOnEveryPath)
{
    // Each value against Box-Muller in double precision on the same Philox words, in the layout
    // random.hpp documents: value i of a chunk of 64 is the cosine (i < 32) or sine (i >= 32) of pair
    // i % 32, whose radius word is word i % 32 and whose angle word is word 32 + i % 32.
    // fillStandardNormal's row r is stream r: row 1 of a two-row matrix tests a stream other than 0.
    const uint64_t seed = 0x0123456789abcdefull, stream = 1;
    const int n = 64 * 4096 + 37; // a partial last chunk too
    const std::array<uint32_t, 2> key = {static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32)};
    auto word = [&](int chunk, int w) {
        const uint32_t block = static_cast<uint32_t>(16 * chunk + 8 * (w / 32) + w % 8);
        const std::array<uint32_t, 4> counter = {block, 0, static_cast<uint32_t>(stream),
                                                 static_cast<uint32_t>(stream >> 32)};
        return detail::philox4x32(counter, key)[static_cast<size_t>((w % 32) / 8)];
    };
    std::vector<double> reference(static_cast<size_t>(n)), radius(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
        const int chunk = i / 64, h = i % 32;
        const uint32_t w1 = word(chunk, h), w2 = word(chunk, 32 + h);
        const double u1 = (static_cast<double>(w1 >> 8) + 1) / 16777216.0;
        const double phi = (static_cast<double>((w2 >> 8) & 0x3fffff) / 4194304.0 - 0.5) * (CV_PI / 2);
        const double angle = static_cast<double>(w2 >> 30) * (CV_PI / 2) + phi;
        radius[static_cast<size_t>(i)] = std::sqrt(-2 * std::log(u1));
        reference[static_cast<size_t>(i)] =
            radius[static_cast<size_t>(i)] * (i % 64 < 32 ? std::cos(angle) : std::sin(angle));
    }
    // The float transform rounds about ten times along the way (the log's split and polynomial, its
    // scaling, the square root, the angle, the sine or cosine and the product), each by at most half
    // an ulp of a value no larger than the radius, and the polynomials are good to about an ulp: 8 ulps
    // of the radius (2^-23 relative each) bound the error with room (1.4 seen on every path), far below
    // the errors of a wrong word, quadrant or sign (of order one) or of a low-order polynomial term.
    const double kUlps = 8;
    Mat rows(2, n, CV_32FC1);
    const float* z = rows.ptr<float>(1);
    for (CpuPath path : availableCpuPaths()) {
        setCpuPath(path);
        fillStandardNormal(rows, Size(), seed);
        double worst = 0;
        for (int i = 0; i < n; ++i) {
            const double bound = kUlps * std::ldexp(1.0, -23) * std::max(1.0, radius[static_cast<size_t>(i)]);
            const double error = std::abs(z[i] - reference[static_cast<size_t>(i)]);
            worst = std::max(worst, error / bound);
            ASSERT_LE(error, bound) << cpuPathName(path) << ", value " << i;
        }
        std::cout << cpuPathName(path) << ": largest error " << worst * kUlps << " ulps of the radius\n";
    }
    setCpuPath(CpuPath::AUTO);
}

TEST(Simulate, fillStandardNormalIsStandardAndReproducible)
{
    Mat z;
    fillStandardNormal(z, Size(512, 512), 42);
    ASSERT_EQ(z.type(), CV_32FC1);
    Scalar mean, stddev;
    meanStdDev(z, mean, stddev);
    // N = 2^18: the mean's standard error is 1/sqrt(N) = 0.002 and the variance's sqrt(2/N) = 0.0028;
    // five of each.
    EXPECT_NEAR(mean[0], 0.0, 0.01);
    EXPECT_NEAR(stddev[0] * stddev[0], 1.0, 0.014);
    const int saved = getNumThreads();
    setNumThreads(1);
    Mat again(512, 512, CV_32FC1);
    fillStandardNormal(again, Size(), 42);
    setNumThreads(saved);
    EXPECT_EQ(0, norm(z, again, NORM_INF)) << "the same seed, other numbers on one thread";
    // A row is its own stream: a narrower matrix holds the first numbers of each row.
    Mat narrow;
    fillStandardNormal(narrow, Size(100, 3), 42);
    EXPECT_EQ(0, norm(narrow, z(Rect(0, 0, 100, 3)), NORM_INF));
    Mat wrong(4, 4, CV_64F);
    EXPECT_CV_ERROR_CONTAINS(fillStandardNormal(wrong, Size(), 1), "expected CV_32FC1");
    Mat none;
    EXPECT_CV_ERROR_CONTAINS(fillStandardNormal(none, Size(), 1), "is empty");
}

} // namespace
} // namespace rawgment
} // namespace cv
