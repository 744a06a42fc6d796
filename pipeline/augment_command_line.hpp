// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The augment command line, once: rawgment_augment and `python3 -m rawgment.batch` build their parsers from
// this table and give every value to AugmentOptions through one setter, so a flag added here appears in both
// with the same help and the same rules.
#ifndef RAWGMENT_PIPELINE_AUGMENT_COMMAND_LINE_HPP
#define RAWGMENT_PIPELINE_AUGMENT_COMMAND_LINE_HPP

#include "augment_jobs.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace rawgment_pipeline {

//! One flag of the augment command line.
struct AugmentFlag
{
    std::string name;         //!< without dashes ("dark_bank")
    std::string shortName;    //!< one letter, or empty
    std::string defaultValue; //!< as text ("1"), empty for none; a switch's is "false"
    bool isSwitch = false;    //!< true or false (the app: --preview=true; Python: --preview)
    bool required = false;    //!< every run gives it
    std::string oneOf;        //!< a group of which a run gives exactly one ("recipe": --scene or --policy)
    std::string help;
};

//! The flags of the augment command line, in the order --help lists them.
const std::vector<AugmentFlag>& augmentFlags();

/** Gives a flag's text to the options, by the flag's rules (--variants a whole number >= 1, --seed one from 0
 * to 2^64 - 1, --format a container writeMosaic() writes, a switch true or false). Throws
 * std::invalid_argument naming the flag and the value for a value it does not take, and for a flag the table
 * does not hold. */
void setAugmentOption(AugmentOptions& options, const std::string& flag, const std::string& value);

//! A --seed: an integer from 0 to 2^64 - 1, digits only; throws std::invalid_argument naming the flag.
uint64_t parseSeed(const std::string& text);

//! The names of the containers writeMosaic() writes, from the library's table: "dng, npy, png or tif".
std::string writtenContainerNames();
//! The extension a --format names ("tif" -> ".tif"); empty when no written container has that name.
std::string writtenContainerExtension(const std::string& name);

} // namespace rawgment_pipeline

#endif // RAWGMENT_PIPELINE_AUGMENT_COMMAND_LINE_HPP
