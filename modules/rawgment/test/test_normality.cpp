// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "test_common.hpp"

#include <opencv2/core/utility.hpp>
#include <opencv2/rawgment/normality.hpp>

#include <fstream>
#include <random>
#include <sstream>

namespace cv {
namespace rawgment {
namespace {

struct ReferenceCase
{
    std::string distribution;
    int n = 0;
    double W = 0, p = 0;
    std::vector<double> x;
};

//! Cases written by test/data/make_shapiro_reference.R (R's shapiro.test).
std::vector<ReferenceCase> loadReference()
{
    std::ifstream in(std::string(RAWGMENT_MODULE_TEST_DATA_DIR) + "/shapiro_reference.csv");
    std::vector<ReferenceCase> cases;
    std::string line;
    while (std::getline(in, line)) {
        std::stringstream fields(line);
        ReferenceCase c;
        std::string n, w, p, values;
        std::getline(fields, c.distribution, ',');
        std::getline(fields, n, ',');
        std::getline(fields, w, ',');
        std::getline(fields, p, ',');
        std::getline(fields, values);
        c.n = std::stoi(n);
        c.W = std::stod(w);
        c.p = std::stod(p);
        std::stringstream xs(values);
        std::string v;
        while (xs >> v)
            c.x.push_back(std::stod(v));
        cases.push_back(c);
    }
    return cases;
}

TEST(Normality, matchesRShapiroTestOnEveryReferenceCase)
{
    const std::vector<ReferenceCase> cases = loadReference();
    // 17 sizes x 7 distributions: a short file means a broken checkout, not a pass.
    ASSERT_EQ(cases.size(), 119u);
    double worstW = 0, worstP = 0;
    for (const ReferenceCase& c : cases) {
        ASSERT_EQ(static_cast<int>(c.x.size()), c.n) << c.distribution;
        const ShapiroWilkResult r = shapiroWilk(c.x);
        EXPECT_EQ(r.n, c.n);
        EXPECT_FALSE(r.constant);
        // Tolerances of the issue: W to 1e-7 absolute; p to 1e-6 relative, with floors for tiny p.
        const double tolP = 1e-6 * std::max(c.p, 1e-10) + 1e-12;
        EXPECT_NEAR(r.W, c.W, 1e-7) << c.distribution << " n=" << c.n;
        EXPECT_NEAR(r.pValue, c.p, tolP) << c.distribution << " n=" << c.n;
        worstW = std::max(worstW, std::abs(r.W - c.W));
        worstP = std::max(worstP, std::abs(r.pValue - c.p) / tolP);
    }
    std::cout << "largest |W - W_R| = " << worstW << ", largest |p - p_R| / tolerance = " << worstP << "\n";
}

TEST(Normality, invariantUnderShiftScaleAndOrder)
{
    std::mt19937 gen(7);
    std::normal_distribution<double> normal;
    std::vector<double> x(200);
    for (double& v : x)
        v = normal(gen);
    const ShapiroWilkResult base = shapiroWilk(x);
    std::vector<double> moved(x.size()), shuffled = x;
    for (size_t i = 0; i < x.size(); ++i)
        moved[i] = 60000.0 + 3.0 * x[i];
    std::shuffle(shuffled.begin(), shuffled.end(), gen);
    // 60000 + 3x keeps x to about 60000 * 2^-52 / 3 ~ 5e-12 relative to its spread: W moves by that much.
    EXPECT_NEAR(shapiroWilk(moved).W, base.W, 1e-10);
    EXPECT_NEAR(shapiroWilk(moved).pValue, base.pValue, 1e-9);
    EXPECT_EQ(shapiroWilk(shuffled).W, base.W);
}

TEST(Normality, rejectsBadInputWithTheValidRange)
{
    EXPECT_CV_ERROR_CONTAINS(shapiroWilk(std::vector<double>{1, 2}),
                             "between 3 and 5000 values per sample (got 2)");
    EXPECT_CV_ERROR_CONTAINS(shapiroWilk(std::vector<double>(5001, 1.0)), "(got 5001)");
    EXPECT_CV_ERROR_CONTAINS(shapiroWilk(Mat()), "(got 0)");
    EXPECT_CV_ERROR_CONTAINS(shapiroWilk(std::vector<double>{1, std::numeric_limits<double>::quiet_NaN(), 3}),
                             "NaN or Inf");
    EXPECT_CV_ERROR_CONTAINS(shapiroWilk(std::vector<float>{1, 2, std::numeric_limits<float>::infinity()}),
                             "NaN or Inf");
    EXPECT_CV_ERROR_CONTAINS(shapiroWilk(Mat(10, 1, CV_32FC2, Scalar(1, 2))), "2 channels");
    EXPECT_CV_ERROR_CONTAINS(shapiroWilk(Mat(10, 1, CV_16FC1)), "depth");
}

TEST(Normality, acceptsEveryNumericDepthAndShape)
{
    Mat base(1, 60, CV_64FC1);
    theRNG().state = 11;
    randn(base, 100, 20);
    Mat rounded;
    base.convertTo(rounded, CV_32S); // rounding to integers creates ties, on purpose
    rounded.convertTo(rounded, CV_64F);
    const ShapiroWilkResult expected = shapiroWilk(rounded);
    for (int depth : {CV_8U, CV_8S, CV_16U, CV_16S, CV_32S, CV_32F, CV_64F}) {
        Mat m;
        rounded.convertTo(m, depth, 1, depth == CV_8S ? -100 : 0);
        EXPECT_EQ(shapiroWilk(m).W, expected.W) << depth;
        EXPECT_EQ(shapiroWilk(m.reshape(1, 6)).W, expected.W) << "6x10 " << depth;
    }
    // A column of a larger Mat is not continuous.
    Mat wide(60, 3, CV_64FC1, Scalar(0));
    Mat(rounded.t()).copyTo(wide.col(1));
    EXPECT_EQ(shapiroWilk(wide.col(1)).W, expected.W);
}

Mat randomSeries(int n, int count, int depth, uint64 seed)
{
    RNG rng(seed);
    Mat m(n, count, CV_64FC1);
    rng.fill(m, RNG::NORMAL, 200, 15);
    Mat out;
    m.convertTo(out, depth);
    return out;
}

TEST(Normality, batchIsIdenticalToTheSingleForm)
{
    for (int depth : {CV_16U, CV_32F, CV_64F}) {
        // Up to 512 values the batch sorts with a network, above with std::sort: cover both sides.
        for (int n : {3, 4, 11, 12, 100, 512, 513}) {
            const Mat data = randomSeries(n, 37, depth, 1000 + n);
            std::vector<ShapiroWilkResult> byColumn, byRow;
            shapiroWilkBatch(data, byColumn, SW_SERIES_IN_COLUMNS);
            shapiroWilkBatch(data.t(), byRow, SW_SERIES_IN_ROWS);
            ASSERT_EQ(byColumn.size(), 37u);
            ASSERT_EQ(byRow.size(), 37u);
            for (int s = 0; s < 37; ++s) {
                const ShapiroWilkResult single = shapiroWilk(data.col(s));
                EXPECT_EQ(byColumn[s].W, single.W) << "depth " << depth << " n " << n << " series " << s;
                EXPECT_EQ(byColumn[s].pValue, single.pValue);
                EXPECT_EQ(byRow[s].W, single.W);
                EXPECT_EQ(byRow[s].pValue, single.pValue);
                EXPECT_EQ(byColumn[s].n, n);
            }
        }
    }
}

TEST(Normality, batchResultsDoNotDependOnTheThreadCount)
{
    const Mat data = randomSeries(100, 3000, CV_32F, 5);
    const int saved = getNumThreads();
    std::vector<std::vector<ShapiroWilkResult>> runs;
    for (int threads : {1, 2, 8}) {
        setNumThreads(threads);
        runs.emplace_back();
        shapiroWilkBatch(data, runs.back());
    }
    setNumThreads(saved);
    for (size_t k = 1; k < runs.size(); ++k)
        for (size_t s = 0; s < runs[0].size(); ++s) {
            ASSERT_EQ(runs[k][s].W, runs[0][s].W);
            ASSERT_EQ(runs[k][s].pValue, runs[0][s].pValue);
        }
}

TEST(Normality, batchRejectsBadInputNamingTheSeries)
{
    std::vector<ShapiroWilkResult> r;
    Mat data = randomSeries(10, 5, CV_32F, 1);
    data.at<float>(4, 3) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_CV_ERROR_CONTAINS(shapiroWilkBatch(data, r), "series 3 contains NaN");
    EXPECT_CV_ERROR_CONTAINS(shapiroWilkBatch(data, r, SW_SERIES_IN_ROWS), "series 4 contains NaN");
    EXPECT_CV_ERROR_CONTAINS(shapiroWilkBatch(Mat(), r), "series is empty");
    EXPECT_CV_ERROR_CONTAINS(shapiroWilkBatch(Mat(2, 50, CV_32F, Scalar(0)), r), "(got 2)");
    EXPECT_CV_ERROR_CONTAINS(shapiroWilkBatch(Mat(5, 5, CV_32F), r, static_cast<ShapiroWilkLayout>(3)),
                             "layout 3");
    // A constant series in a batch is flagged, the others are tested.
    Mat mixed = randomSeries(20, 3, CV_64F, 2);
    mixed.col(1).setTo(65535);
    shapiroWilkBatch(mixed, r);
    EXPECT_FALSE(r[0].constant);
    EXPECT_TRUE(r[1].constant);
    EXPECT_FALSE(r[2].constant);
}

/** A burst of a physical sensor (paper Eq. 1): Poisson photo-electrons, read noise before and after
 * the gain, rounding to DN. The scene is a ramp of means from `darkest` to `brightest` electrons. */
std::vector<Mat> physicalBurst(int frames, Size size, double darkest, double brightest, double gain,
                               double sigmaD, double sigmaR, unsigned seed)
{
    std::mt19937_64 gen(seed);
    std::normal_distribution<double> normal;
    std::vector<Mat> burst;
    for (int t = 0; t < frames; ++t) {
        Mat f(size, CV_32FC1);
        for (int r = 0; r < size.height; ++r)
            for (int c = 0; c < size.width; ++c) {
                const double electrons = darkest + (brightest - darkest) * c / (size.width - 1);
                std::poisson_distribution<int> photons(electrons);
                const double x = gain * (photons(gen) + sigmaD * normal(gen)) + sigmaR * normal(gen);
                f.at<float>(r, c) = static_cast<float>(std::round(x));
            }
        burst.push_back(f);
    }
    return burst;
}

TEST(Normality, brightPixelsOfAPhysicalBurstLookGaussianDarkOnesDoNotBecauseOfTies)
{
    // 100 frames as in the paper. Left half dark (0.3 to 1 electron, read noise well below one DN:
    // values are a few integers), right half bright (2000 to 4000 electrons).
    const int frames = 100;
    std::vector<Mat> dark = physicalBurst(frames, Size(40, 25), 0.3, 1.0, 1.0, 0.2, 0.2, 1);
    std::vector<Mat> bright = physicalBurst(frames, Size(40, 25), 2000, 4000, 1.0, 2.0, 1.0, 2);
    std::vector<Mat> burst(frames);
    for (int t = 0; t < frames; ++t)
        hconcat(dark[t], bright[t], burst[t]);
    const BurstNormality result = shapiroWilkBurst(burst);
    ASSERT_EQ(result.results.size(), 2000u);
    // Four even bins over [0.3, ~4000] electrons: bin 0 holds exactly the dark half, bins 1-3 the bright.
    const std::vector<NormalityBin> bins = summarizeNormality(result, 4);
    ASSERT_EQ(bins.size(), 4u);
    NormalityBin brightBins;
    for (int b = 1; b < 4; ++b) {
        brightBins.count += bins[b].count;
        brightBins.fractionAboveAlpha += bins[b].fractionAboveAlpha * bins[b].count;
        brightBins.meanDistinctValues += bins[b].meanDistinctValues * bins[b].count;
    }
    brightBins.fractionAboveAlpha /= brightBins.count;
    brightBins.meanDistinctValues /= brightBins.count;
    // Bright: Poisson of >= 2000 electrons is Gaussian to a skewness of 0.02, invisible at n = 100,
    // so p is uniform and P(p > 0.05) = 0.95. Over 1000 pixels its binomial standard error is 0.0069:
    // 0.92 is more than 4 standard errors below.
    EXPECT_EQ(brightBins.count, 1000);
    EXPECT_GT(brightBins.fractionAboveAlpha, 0.92) << "bright bins";
    EXPECT_GT(brightBins.meanDistinctValues, 50); // sigma ~ 45 DN spreads 100 values over ~80 integers
    // Dark: Poisson(<= 1) plus 0.3 DN of read noise gives integers from -1 to about 5 in 100 draws, so
    // fewer than 10 distinct values; those ties reject normality almost always.
    const NormalityBin& darkBin = bins[0];
    EXPECT_EQ(darkBin.count, 1000);
    EXPECT_LT(darkBin.fractionAboveAlpha, 0.05) << "dark bin";
    EXPECT_LT(darkBin.meanDistinctValues, 10);
    std::cout << "dark: " << darkBin.fractionAboveAlpha << " with p > 0.05, " << darkBin.meanDistinctValues
              << " distinct values; bright: " << brightBins.fractionAboveAlpha << ", "
              << brightBins.meanDistinctValues << "\n";
}

TEST(Normality, burstMatchesTheBatchAndChecksItsInput)
{
    std::vector<Mat> burst = physicalBurst(20, Size(6, 4), 50, 500, 2.0, 1.0, 1.0, 3);
    const std::vector<Point> positions = {Point(0, 0), Point(5, 3), Point(2, 1)};
    const BurstNormality subset = shapiroWilkBurst(burst, positions);
    ASSERT_EQ(subset.positions, positions);
    for (size_t i = 0; i < positions.size(); ++i) {
        std::vector<double> series;
        double sum = 0;
        for (const Mat& f : burst) {
            series.push_back(f.at<float>(positions[i]));
            sum += series.back();
        }
        EXPECT_EQ(subset.results[i].W, shapiroWilk(series).W);
        EXPECT_NEAR(subset.mean[i], sum / series.size(), 1e-9 * std::abs(sum));
    }
    EXPECT_CV_ERROR_CONTAINS(shapiroWilkBurst(burst, {Point(6, 0)}), "outside the 6x4 frame");
    std::vector<Mat> two(burst.begin(), burst.begin() + 2);
    EXPECT_CV_ERROR_CONTAINS(shapiroWilkBurst(two), "(got 2)");
    burst[7] = Mat(4, 6, CV_16UC1, Scalar(0));
    EXPECT_CV_ERROR_CONTAINS(shapiroWilkBurst(burst), "frame 7");
    burst[7] = Mat(4, 6, CV_32FC1, Scalar(std::numeric_limits<float>::infinity()));
    EXPECT_CV_ERROR_CONTAINS(shapiroWilkBurst(burst, {Point(1, 2)}), "(1, 2) contains NaN or Inf");
}

TEST(Normality, summaryBinsAndArguments)
{
    BurstNormality b;
    for (int i = 0; i < 10; ++i) {
        b.positions.emplace_back(i, 0);
        b.mean.push_back(i);
        b.distinctValues.push_back(i + 1);
        ShapiroWilkResult r;
        r.pValue = i < 5 ? 0.01 : 0.5;
        b.results.push_back(r);
    }
    const std::vector<NormalityBin> bins = summarizeNormality(b, 2, 0.05);
    EXPECT_EQ(bins[0].count, 5);
    EXPECT_EQ(bins[1].count, 5);
    EXPECT_EQ(bins[0].fractionAboveAlpha, 0.0);
    EXPECT_EQ(bins[1].fractionAboveAlpha, 1.0);
    EXPECT_EQ(bins[0].meanDistinctValues, 3.0);
    EXPECT_EQ(bins[1].medianPValue, 0.5);
    EXPECT_EQ(bins[1].meanHigh, 9.0);
    // All means equal: everything in the first bin, no division by a zero width.
    BurstNormality flat = b;
    std::fill(flat.mean.begin(), flat.mean.end(), 3.0);
    EXPECT_EQ(summarizeNormality(flat, 4)[0].count, 10);
    EXPECT_CV_ERROR_CONTAINS(summarizeNormality(b, 0), "bins must be >= 1");
    EXPECT_CV_ERROR_CONTAINS(summarizeNormality(b, 3, 1.0), "alpha must lie in (0, 1)");
    b.mean.pop_back();
    EXPECT_CV_ERROR_CONTAINS(summarizeNormality(b, 3), "differ in length");
}

} // namespace
} // namespace rawgment
} // namespace cv
