// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The fuzz stage's differential check of the YAML/JSON reader (test/fuzz/rawgment_fuzz.cpp runs it).
#ifndef RAWGMENT_FUZZ_DIFFERENTIAL_HPP
#define RAWGMENT_FUZZ_DIFFERENTIAL_HPP

#include <string>

namespace rawgment_fuzz {

/** Opens `path` with the module's reader (openFileStorageForReading()): a refusal must name the file, and an
 * opened text must hold, in OpenCV's nodes, the values libyaml or nlohmann-json read from the same bytes
 * (plain YAML scalars typed by YAML 1.2's core schema). Returns the complaint, empty when it holds. */
std::string differentialCheck(const std::string& path);

} // namespace rawgment_fuzz

#endif // RAWGMENT_FUZZ_DIFFERENTIAL_HPP
