// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_SEEDS_HPP
#define OPENCV_RAWGMENT_SEEDS_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/export.hpp>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_seeds
//! @{

/** @brief What a seed derived from a user's seed drives (see deriveSeed()).
 *
 * Every random number of the library comes from a registered family of counter-based streams; these
 * are the families of the library, its apps and its Python package (and of programs built on them), so that
 * one seed reproduces a whole run and no two uses of it share random numbers. */
// OpenCV 4.6's binding parser reads an enum's base only with no space before ':'.
// clang-format off
enum SeedPurpose: int
// clang-format on
{
    SEED_SIMULATED_BURST = 16,            //!< a simulated burst; index: the burst's number in the run
    SEED_SIMULATED_VALIDATION_BURST = 17, //!< a validation burst; index: 0 bright, 1 and 2 the darker ones
    SEED_VALIDATION_CONVERSION = 18,      //!< the conversion of a bright frame; index: the frame
    SEED_AUGMENTED_OUTPUT = 19,           //!< an augmented file: see augmentedOutputSeed()
    SEED_DEMO = 20,                       //!< the demo's own captures and gallery; index: what it draws
    SEED_STUDY = 21,                      //!< accuracy studies (rawgment_tradeoffs); index: the measurement
    SEED_TRAINING_EPOCH = 22,             //!< a training epoch (Python's rawgment.torch); index: the epoch
    SEED_TRAINING_SAMPLE = 23             //!< a sample of an epoch's seed; index: the sample's index
    // 24 is reserved: the project's ablation study (studies/, not installed) derives its seeds under it with
    // the same mixing, so no purpose of the library may take it.
};

/** @brief A seed for one use of a user's seed: a well-mixed (SplitMix64) function of (seed, purpose,
 * index), distinct from the library's internal streams, the same on every machine and thread count.
 * @param seed the user's seed
 * @param purpose what the derived seed drives
 * @param index which one of that purpose (a burst, a frame, ...)
 */
CV_RAWGMENT_EXPORTS uint64 deriveSeed(uint64 seed, SeedPurpose purpose, uint64 index = 0);

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SEEDS_HPP
