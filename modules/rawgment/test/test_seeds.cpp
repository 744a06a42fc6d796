// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The seeds topic: derived seeds are a pure function of (seed, purpose, index), distinct across them.
#include "test_common.hpp"

#include <opencv2/rawgment/seeds.hpp>

#include <set>

namespace cv {
namespace rawgment {
namespace {

TEST(Seeds, derivedSeedsAreStableAndDistinctPerPurposeAndIndex)
{
    // A pure function of (seed, purpose, index): the same on every call, and no two of 8 purposes x
    // 1000 indices x 3 seeds collide (a 64-bit hash collides among 24,000 values with odds ~1e-11).
    EXPECT_EQ(deriveSeed(1, SEED_SIMULATED_BURST, 3), deriveSeed(1, SEED_SIMULATED_BURST, 3));
    std::set<uint64> seen;
    for (uint64 seed : {0ull, 1ull, 2ull})
        for (int p = SEED_SIMULATED_BURST; p <= SEED_TRAINING_SAMPLE; ++p)
            for (uint64 index = 0; index < 1000; ++index)
                seen.insert(deriveSeed(seed, static_cast<SeedPurpose>(p), index));
    EXPECT_EQ(seen.size(), 3u * 8u * 1000u);
    EXPECT_CV_ERROR_CONTAINS(deriveSeed(1, static_cast<SeedPurpose>(3), 0), "unknown purpose 3");
    // 24, the value the project's ablation study derives under, is no purpose of the library.
    EXPECT_CV_ERROR_CONTAINS(deriveSeed(1, static_cast<SeedPurpose>(24), 0), "unknown purpose 24");
}

} // namespace
} // namespace rawgment
} // namespace cv
