// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The seeds topic (seeds.hpp): seeds derived from a user's seed, one family per purpose, on the library's
// own key mixing (random.hpp), so that a derived seed never meets an internal stream.
#include "precomp.hpp"
#include "random.hpp"

#include <opencv2/rawgment/seeds.hpp>

namespace cv {
namespace rawgment {

uint64 deriveSeed(uint64 seed, SeedPurpose purpose, uint64 index)
{
    if (purpose < SEED_SIMULATED_BURST || purpose > SEED_TRAINING_SAMPLE)
        CV_Error(Error::StsBadArg, format("deriveSeed: unknown purpose %d", static_cast<int>(purpose)));
    return detail::stepKey(detail::stepKey(seed, static_cast<uint64_t>(purpose)), index);
}

} // namespace rawgment
} // namespace cv
