// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The augment command line's one table and setter (augment_command_line.hpp).
#include "augment_command_line.hpp"

#include <cerrno>
#include <cstdlib>
#include <stdexcept>

namespace rawgment_pipeline {

const std::vector<AugmentFlag>& augmentFlags()
{
    static const std::vector<AugmentFlag> flags = {
        {"model", "m", "", false, true, "",
         "noise model of the camera (required): a NoiseModel YAML/JSON, an Android profile YAML, or "
         "darktable's "
         "noiseprofiles.json with --camera"},
        {"camera", "", "", false, false, "",
         "with a darktable file: a camera name, a comma-separated list of names, good or usable (several: "
         "each "
         "output draws one, recorded in its sidecar)"},
        {"scene", "", "", false, false, "recipe", "a scene file (map 'scene') applied to every input"},
        {"policy", "", "", false, false, "recipe", "a random policy file (map 'random_scene_policy')"},
        {"out", "o", "", false, true, "", "output directory (required)"},
        {"variants", "n", "1", false, false, "", "variants per input"},
        {"seed", "", "1", false, false, "", "seed: same seed, same outputs, on any number of threads"},
        {"format", "", "", false, false, "",
         "output container: " + writtenContainerNames() +
             " (npy: numpy's uncompressed format, fastest to train from; default: dng for RAW inputs, else "
             "the "
             "input's)"},
        {"preview", "", "false", true, false, "", "also write an sRGB preview PNG of each output"},
        {"accept_failed_calibration", "", "false", true, false, "",
         "also use a model whose calibration's verdict was FAIL"},
        {"dark_bank", "", "", false, false, "",
         "a dark-frame bank file (rawgment_calibrate --dark_bank): its real dark frames are the read noise "
         "of "
         "every output, accounted for the input's own"},
        {"dark_bank_tied", "", "false", true, false, "",
         "the inputs come from the bank's own sensor at its exposure and temperature: their fixed pattern is "
         "swapped for the target's"},
    };
    return flags;
}

uint64_t parseSeed(const std::string& text)
{
    const std::string why = "--seed must be an integer from 0 to 18446744073709551615 (got '" + text + "')";
    if (text.empty() || text.size() > 20 || text.find_first_not_of("0123456789") != std::string::npos)
        throw std::invalid_argument(why);
    errno = 0;
    const unsigned long long value = std::strtoull(text.c_str(), nullptr, 10);
    if (errno == ERANGE)
        throw std::invalid_argument(why);
    return static_cast<uint64_t>(value);
}

std::string writtenContainerNames()
{
    std::vector<std::string> names;
    for (const cv::rawgment::MosaicContainer& c : cv::rawgment::mosaicContainers())
        if (c.writes)
            names.push_back(c.name);
    std::string text;
    for (size_t i = 0; i < names.size(); ++i)
        text += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
    return text;
}

std::string writtenContainerExtension(const std::string& name)
{
    for (const cv::rawgment::MosaicContainer& c : cv::rawgment::mosaicContainers())
        if (c.writes && c.name == name)
            return c.extensions.front();
    return std::string();
}

namespace {

bool switchValue(const std::string& flag, const std::string& value)
{
    if (value == "true" || value == "1")
        return true;
    if (value == "false" || value == "0")
        return false;
    throw std::invalid_argument("--" + flag + " must be true or false (got '" + value + "')");
}

int variantsValue(const std::string& value)
{
    const std::string why = "--variants must be a whole number >= 1 (got '" + value + "')";
    if (value.empty() || value.size() > 9 || value.find_first_not_of("0123456789") != std::string::npos)
        throw std::invalid_argument(why);
    const int n = std::atoi(value.c_str());
    if (n < 1)
        throw std::invalid_argument(why);
    return n;
}

} // namespace

void setAugmentOption(AugmentOptions& o, const std::string& flag, const std::string& value)
{
    if (flag == "model")
        o.model = value;
    else if (flag == "camera")
        o.camera = value;
    else if (flag == "scene")
        o.scene = value;
    else if (flag == "policy")
        o.policy = value;
    else if (flag == "out")
        o.outDir = value;
    else if (flag == "variants")
        o.variants = variantsValue(value);
    else if (flag == "seed")
        o.seed = parseSeed(value);
    else if (flag == "format") {
        o.extension = value.empty() ? std::string() : writtenContainerExtension(value);
        if (!value.empty() && o.extension.empty())
            throw std::invalid_argument("--format must be " + writtenContainerNames() + " (got '" + value +
                                        "')");
    } else if (flag == "preview")
        o.previews = switchValue(flag, value);
    else if (flag == "accept_failed_calibration")
        o.acceptFailedCalibration = switchValue(flag, value);
    else if (flag == "dark_bank")
        o.darkBank = value;
    else if (flag == "dark_bank_tied")
        o.darkBankTied = switchValue(flag, value);
    else
        throw std::invalid_argument("no augment flag --" + flag);
}

} // namespace rawgment_pipeline
