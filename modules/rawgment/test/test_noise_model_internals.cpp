// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The noise model's private terms (src/noise_terms.hpp): the offset of a measured line split before and
// after the gain, and the Tukey-lambda moments and quantiles against SciPy. Private functions: the
// standalone build links rawgment_internal, and the OpenCV build leaves this file out of
// opencv_test_rawgment (docs/architecture.md).
#include "test_common.hpp"

#include "../src/noise_terms.hpp"
#include <opencv2/rawgment/noise_model.hpp>

#include <cmath>

namespace cv {
namespace rawgment {
namespace {

TEST(NoiseModel, aMeasuredLinesOffsetIsSplitBeforeAndAfterTheGainAsEq5AtThatGain)
{
    // Eq. 5 (0.4, 0.5, 2.0), and a measured line at gain 2 whose offset 4.5 leaves Eq. 5's 4.0.
    NoiseModel m(0.4, 0.5, 2.0);
    for (const double g : {1.0, 2.0}) {
        MeasuredNoiseLine entry;
        entry.gain = g;
        entry.line.a = 0.4 * g;
        entry.line.b = g == 1 ? 2.6 : 4.5;
        m.measuredLines.push_back(entry);
    }
    const detail::NoiseTerms<double> terms = detail::checkedNoiseTerms(m, 2);
    EXPECT_NEAR(4.5 * 2.0 / 4.0, terms.readBeforeGain, 1e-12) << "Eq. 5's share g^2 sigma_d^2 / b at gain 2";
    EXPECT_EQ(4.5, terms.read());
}

// Reference values from SciPy (scipy.stats.tukeylambda, 1.10), produced by
//   /usr/bin/python3 -c "from scipy.stats import tukeylambda as t; [print(l, *map(float, t.stats(l,
//   moments='vk')), t.ppf(0.9, l), t.ppf(0.001, l)) for l in (-0.2, -0.05, 0.0, 0.1349, 0.3, 1.0)]"
TEST(NoiseModel, tukeyLambdaMomentsAndQuantilesMatchScipy)
{
    struct Reference
    {
        double lambda, variance, kurtosis, q90, q001;
    };
    const Reference refs[] = {
        {-0.2, 7.485121693687224, 19.212645820411677, 2.817987524304892, -14.90435792723451},
        {-0.05, 3.936722678907758, 2.131297930577237, 2.334730561453274, -8.249750367096063},
        {0.0, 3.289868133696453, 1.2, 2.1972245773362196, -6.906754778648553},
        {0.1349, 2.142062315583447, 6.731396968762127e-05, 1.8746783137461684, -4.4925353408366595},
        {0.3, 1.3688395477826087, -0.5924829106006726, 1.558996425233304, -2.912691179203477},
        {1.0, 0.3333333333333333, -1.1999999999999997, 0.8, -0.998}};
    // The two ways of computing the moments meet at |lambda| = 0.02.
    for (double l : {0.019999999, -0.019999999})
        EXPECT_NEAR(detail::tukeyLambdaExcessKurtosis(l), detail::tukeyLambdaExcessKurtosis(l * 1.00000005),
                    1e-7)
            << l;
    for (const Reference& r : refs) {
        // Closed forms and quadrature in double: 1e-9 relative leaves room only for lgamma's rounding and
        // the cancellation bounded in tukeyMoments() (6e-10 at |lambda| = 0.02).
        EXPECT_NEAR(r.variance, detail::tukeyLambdaVariance(r.lambda), 1e-9 * r.variance) << r.lambda;
        EXPECT_NEAR(r.kurtosis, detail::tukeyLambdaExcessKurtosis(r.lambda),
                    1e-8 * (1 + std::abs(r.kurtosis)))
            << r.lambda;
        EXPECT_NEAR(r.q90, detail::tukeyLambdaQuantile(0.9, r.lambda), 1e-12 * (1 + std::abs(r.q90)))
            << r.lambda;
        EXPECT_NEAR(r.q001, detail::tukeyLambdaQuantile(0.001, r.lambda), 1e-12 * (1 + std::abs(r.q001)))
            << r.lambda;
        if (r.lambda >= detail::kTukeyLambdaMin) {
            EXPECT_NEAR(r.lambda, detail::tukeyLambdaOfExcessKurtosis(r.kurtosis), 1e-9) << r.lambda;
        }
    }
    // The added part needs more kurtosis than the whole when the prior keeps part of the tails, and the
    // model's own lambda when nothing of the prior is kept.
    EXPECT_NEAR(-0.05, detail::addedReadLambda(-0.05, 10, 0, 10), 1e-9);
    EXPECT_LT(detail::addedReadLambda(-0.05, 10, 0.25 * 0.25 * 100, 10 - 0.25 * 10), -0.05);
    EXPECT_EQ(-0.05, detail::addedReadLambda(-0.05, 10, 0, 0));
}

} // namespace
} // namespace rawgment
} // namespace cv
