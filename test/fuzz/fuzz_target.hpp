// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// A fuzz target: what a reader is given, what it may throw, and what an accepted file must satisfy
// (test/fuzz/rawgment_fuzz.cpp runs them; topics with targets of their own define them in targets_*.cpp).
#ifndef RAWGMENT_FUZZ_TARGET_HPP
#define RAWGMENT_FUZZ_TARGET_HPP

#include <functional>
#include <string>
#include <vector>

namespace rawgment_fuzz {

enum class Errors
{
    LIBRARY, //!< cv::Exception only
    APP,     //!< cv::Exception or a plain std::runtime_error (the apps' message for bad input)
};

struct Target
{
    std::string name;
    std::string inputName; //!< the mutated file's name in the work folder (its extension matters)
    bool binary;
    Errors errors;
    //! Makes the seeds (valid files) and whatever the reader needs beside the input, in `work`.
    std::function<std::vector<std::string>(const std::string& work)> seeds;
    //! Reads `input`; throws on rejection; returns a complaint when an accepted file breaks a promise.
    std::function<std::string(const std::string& input)> read;
};

//! The bytes of a file; throws std::runtime_error naming it when it cannot be read.
std::string readBytes(const std::string& path);

/** Every file reader of the module and the apps (models, reports, scenes, policies, sidecars, manifests,
 * camera profiles, .npy, RAW files, and emva1288Targets()), plus the canary: a reader with a planted bug
 * (targets_readers.cpp). `dataDir` holds the shared test data (real RAW files as seeds). */
std::vector<Target> readerTargets(const std::string& dataDir);

//! The EMVA 1288 descriptor (with its figures) and one image of a series (targets_emva1288.cpp).
std::vector<Target> emva1288Targets();

} // namespace rawgment_fuzz

#endif // RAWGMENT_FUZZ_TARGET_HPP
