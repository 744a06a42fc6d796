// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// A bank of dark frames (opencv2/rawgment/dark_frames.hpp): made from files, grouped by gain and exposure,
// saved beside its frames and loaded with every field checked.
#include "dark_frames.hpp"

#include "file_access.hpp"
#include "map_images.hpp"
#include "precomp.hpp"

#include <opencv2/rawgment/files.hpp>
#include <opencv2/rawgment/mosaic_files.hpp>
#include <opencv2/rawgment/raw_io.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

namespace cv {
namespace rawgment {

namespace detail {

int nearestGainGroup(const std::vector<DarkFrameGroup>& groups, double gain, double exposureTime,
                     const String& bankPath)
{
    const auto logDistance = [](double a, double b) { return std::abs(std::log(std::max(a, 1e-300) / b)); };
    int nearest = 0;
    for (int i = 1; i < static_cast<int>(groups.size()); ++i)
        if (logDistance(groups[static_cast<size_t>(i)].gain, gain) <
            logDistance(groups[static_cast<size_t>(nearest)].gain, gain) - 1e-12)
            nearest = i;
    const double atGain = groups[static_cast<size_t>(nearest)].gain;
    std::vector<int> sameGain;
    for (int i = 0; i < static_cast<int>(groups.size()); ++i)
        if (logDistance(groups[static_cast<size_t>(i)].gain, atGain) <= 1e-12)
            sameGain.push_back(i);
    const auto exposuresText = [&]() {
        String text;
        for (int i : sameGain) {
            const double t = groups[static_cast<size_t>(i)].exposureTime;
            text += (text.empty() ? "" : ", ") + (t > 0 ? format("%g s", t) : String("an unstated one"));
        }
        return text;
    };
    const String where = bankPath.empty() ? String() : " ('" + bankPath + "')";
    if (exposureTime == 0) {
        if (sameGain.size() == 1)
            return sameGain.front();
        CV_Error(Error::StsBadArg,
                 format("the mosaic states no exposure time (RawFormat::exposureTime), and the dark-frame "
                        "bank%s has frames of %zu exposures at gain %g (%s): dark current grows with the "
                        "exposure, so state it",
                        where.c_str(), sameGain.size(), atGain, exposuresText().c_str()));
    }
    int best = -1, unstated = -1;
    for (int i : sameGain) {
        const double t = groups[static_cast<size_t>(i)].exposureTime;
        if (t == 0)
            unstated = i;
        else if (best < 0 || logDistance(t, exposureTime) <
                                 logDistance(groups[static_cast<size_t>(best)].exposureTime, exposureTime))
            best = i;
    }
    if (best >= 0 && logDistance(groups[static_cast<size_t>(best)].exposureTime, exposureTime) <=
                         std::log(kExposureMatchFactor) + 1e-12)
        return best;
    if (unstated >= 0)
        return unstated;
    CV_Error(
        Error::StsBadArg,
        format("the dark-frame bank%s has no frames within a third of a stop of exposure %g s at gain %g; it "
               "has %s there: dark current grows with the exposure, so add dark frames at %g s",
               where.c_str(), exposureTime, atGain, exposuresText().c_str(), exposureTime));
}

DarkFrame readDarkFrame(const String& path, const NoiseModel& model)
{
    DarkFrame f;
    if (pathExists(sidecarPathOf(path))) {
        const MosaicMetadata meta = readMosaic(path, f.mosaic);
        f.format = meta.formatFor(model);
    } else {
        const RawImage raw = readRaw(path);
        f.mosaic = raw.mosaic;
        f.format = raw.formatFor(model);
    }
    // The bank's format is its sensor's; each group holds its exposure.
    f.exposureTime = f.format.exposureTime;
    f.format.exposureTime = 0;
    return f;
}

} // namespace detail

namespace {

const char* const kTopLevelName = "dark_frame_bank";
const char* const kPatternTag = "dark_frame_pattern_";
const char* const kMeanTag = "dark_frame_mean_";

String formatText(const RawFormat& f, Size size)
{
    return format("%dx%d %s, black %g/%g/%g/%g, white %g", size.width, size.height,
                  cfaPatternName(f.pattern).c_str(), f.blackLevel[0], f.blackLevel[1], f.blackLevel[2],
                  f.blackLevel[3], f.whiteLevel);
}

bool sameSensor(const RawFormat& a, const RawFormat& b)
{
    return a.pattern == b.pattern && a.blackLevel == b.blackLevel && a.whiteLevel == b.whiteLevel;
}

String groupName(const DarkFrameGroup& g)
{
    return g.exposureTime > 0 ? format("gain %g, exposure %g s", g.gain, g.exposureTime)
                              : format("gain %g", g.gain);
}

double fileBytesOf(const String& path)
{
    detail::FileStamp stamp;
    if (!detail::fileStampOf(path, stamp))
        CV_Error(Error::StsError, format("DarkFrameBank: dark frame '%s' is missing", path.c_str()));
    return static_cast<double>(stamp.bytes);
}

bool allFinite(const Vec4d& v, bool nonNegative)
{
    for (int s = 0; s < 4; ++s)
        if (!std::isfinite(v[s]) || (nonNegative && v[s] < 0))
            return false;
    return true;
}

// `<bank file name>.dark_frame_<pattern or mean>_<group>.<checksum>.tiff`, a group's map
// (detail::mapImageName()).
bool isBankImageOf(const String& bankPath, const String& name)
{
    for (const char* tag : {kPatternTag, kMeanTag}) {
        const String prefix = detail::baseNameOf(bankPath) + "." + tag;
        if (name.compare(0, prefix.size(), prefix) != 0)
            continue;
        const size_t end = name.find('.', prefix.size());
        if (end == String::npos || end == prefix.size())
            continue;
        const String digits = name.substr(prefix.size(), end - prefix.size());
        if (std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }) &&
            detail::isMapImageOf(bankPath, name, {tag + digits}))
            return true;
    }
    return false;
}

// A frame's path as the bank file names it: relative to the bank's folder when it lies inside it, so that a
// bank moves with its frames; absolute otherwise.
String pathInBankFile(const String& frame, const String& bankPath)
{
    return detail::pathAsNamedBy(frame, bankPath);
}

std::vector<double> readList(const FileNode& node, const char* field, size_t most)
{
    const FileNode list = node[field];
    if (!list.isSeq())
        CV_Error(Error::StsParseError, format("field '%s' must be a list of numbers", field));
    if (list.size() > most)
        CV_Error(Error::StsParseError,
                 format("field '%s' has %zu values, more than %zu", field, list.size(), most));
    const std::vector<double> values = detail::readRealList(node, field, static_cast<int>(list.size()));
    for (double v : values)
        if (!std::isfinite(v))
            CV_Error(Error::StsParseError, format("field '%s' holds a value that is not finite", field));
    return values;
}

Vec4d readSites(const FileNode& node, const char* field)
{
    const std::vector<double> v = detail::readRealList(node, field, 4);
    return Vec4d(v[0], v[1], v[2], v[3]);
}

bool isFingerprint(const String& text)
{
    return text.size() == 16 && std::all_of(text.begin(), text.end(), [](char c) {
               return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
           });
}

DarkFrameGroup readGroup(const FileNode& n, const String& folder, Size size, int index, int version)
{
    if (!n.isMap())
        CV_Error(Error::StsParseError, "each entry of groups must be a map");
    std::vector<String> keys = {"gain",
                                "exposure_time",
                                "frames",
                                "file_bytes",
                                "degrees_of_freedom",
                                "level",
                                "temporal_variance",
                                "row_noise_variance",
                                "mean_variance",
                                "pattern_variance",
                                "pattern",
                                "mean",
                                "row_variance",
                                "noisy_pixels"};
    // Version 1 recorded no fingerprints: its frames are held to their sizes, as it stated.
    if (version >= 2)
        keys.push_back("fingerprints");
    rejectUnknownKeys(n, keys);
    DarkFrameGroup g;
    g.gain = detail::readRealField(n, "gain");
    g.exposureTime = detail::readRealField(n, "exposure_time");
    const FileNode frames = n["frames"];
    if (!frames.isSeq())
        CV_Error(Error::StsParseError, "field 'frames' must be a list of file names");
    for (const FileNode& f : frames) {
        if (!f.isString() || f.string().empty())
            CV_Error(Error::StsParseError, "field 'frames' must hold non-empty file names");
        const String name = f.string();
        g.files.push_back(name[0] == '/' ? name : folder + name);
    }
    g.fileBytes = readList(n, "file_bytes", g.files.size());
    if (g.fileBytes.size() != g.files.size())
        CV_Error(Error::StsParseError, "field 'file_bytes' must have one size per frame");
    if (version >= 2) {
        const FileNode prints = n["fingerprints"];
        if (!prints.isSeq() || prints.size() != g.files.size())
            CV_Error(Error::StsParseError,
                     "field 'fingerprints' must be a list of one fingerprint per frame");
        for (const FileNode& f : prints) {
            if (!f.isString() || !isFingerprint(f.string()))
                CV_Error(Error::StsParseError,
                         "field 'fingerprints' must hold 16 lower-case hex digits (FNV-1a 64) per frame");
            g.fingerprints.push_back(f.string());
        }
    }
    DarkFrameStatistics& s = g.statistics;
    s.frames = static_cast<int>(g.files.size());
    s.degreesOfFreedom = detail::readOptionalIntField(n, "degrees_of_freedom", 0);
    s.level = readSites(n, "level");
    s.temporalVariance = readSites(n, "temporal_variance");
    s.rowNoiseVariance = readSites(n, "row_noise_variance");
    s.meanVariance = readSites(n, "mean_variance");
    s.patternVariance = readSites(n, "pattern_variance");
    s.pattern = detail::readMapImage(n["pattern"], format("groups[%d].pattern", index), folder, size);
    s.mean = detail::readMapImage(n["mean"], format("groups[%d].mean", index), folder, size);
    const std::vector<double> rows = readList(n, "row_variance", 2 * static_cast<size_t>(size.height));
    if (rows.size() != 2 * static_cast<size_t>(size.height))
        CV_Error(Error::StsParseError,
                 format("field 'row_variance' must hold %d values (two per row)", 2 * size.height));
    s.rowVariance = Mat(rows, true).reshape(1, size.height);
    const std::vector<double> noisy = readList(n, "noisy_pixels", 3 * size.area());
    if (noisy.size() % 3 != 0)
        CV_Error(Error::StsParseError, "field 'noisy_pixels' must hold x, y and variance per pixel");
    for (size_t i = 0; i < noisy.size(); i += 3) {
        const double x = noisy[i], y = noisy[i + 1];
        if (x != std::floor(x) || y != std::floor(y) || x < 0 || y < 0 || x >= size.width || y >= size.height)
            CV_Error(Error::StsParseError,
                     format("field 'noisy_pixels': (%g, %g) is not a pixel of the %dx%d frames", x, y,
                            size.width, size.height));
        s.noisyPixels.emplace_back(static_cast<int>(x), static_cast<int>(y));
        s.noisyVariance.push_back(noisy[i + 2]);
    }
    return g;
}

} // namespace

DarkFrameBank DarkFrameBank::create(const std::vector<String>& files, const NoiseModel& model,
                                    double falseAlarm)
{
    if (files.empty())
        CV_Error(Error::StsBadArg, "DarkFrameBank::create: no dark frames (an empty bank)");
    if (!(falseAlarm > 0 && falseAlarm < 0.5))
        CV_Error(Error::StsOutOfRange,
                 cv::format("DarkFrameBank::create: falseAlarm %g must lie in (0, 0.5)", falseAlarm));
    refuseRepeatedFiles(files, "DarkFrameBank::create");
    DarkFrameBank bank;
    // The statistics per (gain, exposure time), fed one frame at a time.
    std::map<std::pair<double, double>,
             std::pair<std::unique_ptr<detail::DarkFrameAccumulator>, DarkFrameGroup>>
        groups;
    String first;
    for (const String& path : files) {
        const detail::DarkFrame f = detail::readDarkFrame(path, model);
        if (first.empty()) {
            first = path;
            bank.format = f.format;
            bank.format.gain = 1;
            bank.size = f.mosaic.size();
        } else if (!sameSensor(f.format, bank.format) || f.mosaic.size() != bank.size) {
            CV_Error(
                Error::StsBadArg,
                cv::format("DarkFrameBank::create: '%s' is %s, but '%s' is %s: one bank holds one sensor's "
                           "frames",
                           path.c_str(), formatText(f.format, f.mosaic.size()).c_str(), first.c_str(),
                           formatText(bank.format, bank.size).c_str()));
        }
        auto& g = groups[{f.format.gain, f.exposureTime}];
        if (!g.first) {
            g.first.reset(new detail::DarkFrameAccumulator(f.format));
            g.second.gain = f.format.gain;
            g.second.exposureTime = f.exposureTime;
        }
        try {
            g.first->add(f.mosaic);
        } catch (const Exception& e) {
            CV_Error(e.code, "DarkFrameBank::create: '" + path + "': " + e.err);
        }
        g.second.files.push_back(path);
        g.second.fileBytes.push_back(fileBytesOf(path));
        g.second.fingerprints.push_back(detail::contentFingerprintOf(path, "dark frame"));
    }
    for (auto& entry : groups) {
        DarkFrameGroup& g = entry.second.second;
        if (g.files.size() < 2)
            CV_Error(Error::StsBadArg,
                     cv::format(
                         "DarkFrameBank::create: %s has one frame ('%s'); its temporal noise needs at least "
                         "two",
                         groupName(g).c_str(), g.files[0].c_str()));
        g.statistics = entry.second.first->estimate(falseAlarm);
        bank.groups.push_back(std::move(g));
    }
    return bank;
}

DarkFrameBank DarkFrameBank::createFromFolder(const String& folder, const NoiseModel& model,
                                              double falseAlarm)
{
    if (!detail::isFolder(folder))
        CV_Error(Error::StsBadArg,
                 cv::format("DarkFrameBank::createFromFolder: '%s' is not a folder", folder.c_str()));
    // Entries as the folder was named: "dark/" and "dark" give "dark/f.npy".
    const String prefix = folder.empty() || folder.back() == '/' ? folder : folder + "/";
    std::vector<String> files;
    for (const String& name : detail::folderEntryNames(folder, "DarkFrameBank::createFromFolder")) {
        const String ext = detail::lowerExtensionOf(name);
        if (name.empty() || name[0] == '.' || ext == ".yml" || ext == ".yaml" || ext == ".json" ||
            name.find(String(".") + kPatternTag) != String::npos ||
            name.find(String(".") + kMeanTag) != String::npos || !isRegularFile(prefix + name))
            continue;
        files.push_back(prefix + name);
    }
    std::sort(files.begin(), files.end());
    if (files.empty())
        CV_Error(Error::StsBadArg,
                 cv::format("DarkFrameBank::createFromFolder: '%s' holds no dark frames (an empty bank)",
                            folder.c_str()));
    return create(files, model, falseAlarm);
}

void DarkFrameBank::validate() const
{
    if (empty())
        return;
    format.validate();
    if (size.width <= 0 || size.height <= 0)
        CV_Error(Error::StsBadArg,
                 cv::format("DarkFrameBank: size %dx%d must be positive", size.width, size.height));
    for (size_t i = 0; i < groups.size(); ++i) {
        const DarkFrameGroup& g = groups[i];
        const DarkFrameStatistics& s = g.statistics;
        const String who = cv::format("DarkFrameBank: groups[%zu] (%s)", i, groupName(g).c_str());
        if (!(std::isfinite(g.gain) && g.gain > 0) || !(std::isfinite(g.exposureTime) && g.exposureTime >= 0))
            CV_Error(Error::StsBadArg, who + ": gain must be finite and > 0, exposure time finite and >= 0");
        if (i > 0 && std::make_pair(groups[i - 1].gain, groups[i - 1].exposureTime) >=
                         std::make_pair(g.gain, g.exposureTime))
            CV_Error(Error::StsBadArg, who + ": groups must be by increasing gain, then exposure time");
        if (g.files.size() < 2 || g.fileBytes.size() != g.files.size() || s.frames != int(g.files.size()))
            CV_Error(
                Error::StsBadArg,
                who + cv::format(": %zu frames, %zu file sizes and statistics of %d frames: a group needs at "
                                 "least two frames, and one size each",
                                 g.files.size(), g.fileBytes.size(), s.frames));
        if (!g.fingerprints.empty() &&
            (g.fingerprints.size() != g.files.size() ||
             !std::all_of(g.fingerprints.begin(), g.fingerprints.end(), isFingerprint)))
            CV_Error(Error::StsBadArg,
                     who + ": fingerprints must be empty (a bank of format_version 1) or 16 lower-case hex "
                           "digits (FNV-1a 64) per frame");
        if ((g.fingerprints.empty()) != (groups[0].fingerprints.empty()))
            CV_Error(Error::StsBadArg, who + ": every group or none has its frames' fingerprints");
        if (s.degreesOfFreedom < 1 || s.degreesOfFreedom > s.frames - 1)
            CV_Error(Error::StsBadArg, who + cv::format(": degrees of freedom %d must lie in [1, %d]",
                                                        s.degreesOfFreedom, s.frames - 1));
        if (!allFinite(s.level, false) || !allFinite(s.temporalVariance, true) ||
            !allFinite(s.rowNoiseVariance, true) || !allFinite(s.meanVariance, true) ||
            !allFinite(s.patternVariance, true))
            CV_Error(Error::StsBadArg, who + ": a level must be finite, a variance finite and >= 0");
        for (const Mat* map : {&s.pattern, &s.mean})
            if (map->type() != CV_32FC1 || map->size() != size || !checkRange(*map))
                CV_Error(Error::StsBadArg,
                         who + cv::format(": the pattern and the mean must be finite CV_32FC1 maps of %dx%d",
                                          size.width, size.height));
        if (s.rowVariance.type() != CV_64FC1 || s.rowVariance.rows != size.height ||
            s.rowVariance.cols != 2 || !checkRange(s.rowVariance, true, nullptr, 0, DBL_MAX))
            CV_Error(Error::StsBadArg,
                     who + cv::format(": rowVariance must be a CV_64FC1 map of %d x 2 finite values >= 0",
                                      size.height));
        if (s.noisyVariance.size() != s.noisyPixels.size())
            CV_Error(Error::StsBadArg, who + ": one noisyVariance per noisy pixel");
        for (size_t p = 0; p < s.noisyPixels.size(); ++p)
            if (!Rect(Point(), size).contains(s.noisyPixels[p]) ||
                !(std::isfinite(s.noisyVariance[p]) && s.noisyVariance[p] >= 0))
                CV_Error(Error::StsBadArg,
                         who + ": a noisy pixel outside the frames, or its variance not finite "
                               "and >= 0");
    }
}

namespace {

//! The text save() writes for `bank` at `bankPath`, and its maps with the names the text gives them: the
//! names hold each map's checksum, so two banks of one text are one bank, maps included.
std::string bankFileText(const DarkFrameBank& bank, const String& bankPath, std::vector<String>& images,
                         std::vector<const Mat*>& maps)
{
    for (size_t i = 0; i < bank.groups.size(); ++i) {
        maps.push_back(&bank.groups[i].statistics.pattern);
        images.push_back(detail::mapImageName(bankPath, cv::format("%s%zu", kPatternTag, i), *maps.back()));
        maps.push_back(&bank.groups[i].statistics.mean);
        images.push_back(detail::mapImageName(bankPath, cv::format("%s%zu", kMeanTag, i), *maps.back()));
    }
    return fileStorageText(bankPath, [&](FileStorage& fs) {
        fs << kTopLevelName << "{";
        // A bank loaded from version 1 has no fingerprints to write: it stays what it was.
        const bool fingerprinted = !bank.groups.empty() && !bank.groups[0].fingerprints.empty();
        fs << "format_version" << (fingerprinted ? DarkFrameBank::FORMAT_VERSION : 1);
        bank.format.write(fs, "format");
        fs << "width" << bank.size.width << "height" << bank.size.height;
        fs << "groups"
           << "[";
        for (size_t i = 0; i < bank.groups.size(); ++i) {
            const DarkFrameGroup& g = bank.groups[i];
            const DarkFrameStatistics& s = g.statistics;
            fs << "{";
            fs << "gain" << g.gain << "exposure_time" << g.exposureTime;
            std::vector<String> frames;
            for (const String& f : g.files)
                frames.push_back(pathInBankFile(f, bankPath));
            writeStringList(fs, "frames", frames);
            fs << "file_bytes" << g.fileBytes;
            if (fingerprinted)
                writeStringList(fs, "fingerprints", g.fingerprints);
            fs << "degrees_of_freedom" << s.degreesOfFreedom;
            fs << "level" << s.level << "temporal_variance" << s.temporalVariance << "row_noise_variance"
               << s.rowNoiseVariance << "mean_variance" << s.meanVariance << "pattern_variance"
               << s.patternVariance;
            fs << "pattern";
            detail::writeMapImageEntry(fs, images[2 * i], s.pattern);
            fs << "mean";
            detail::writeMapImageEntry(fs, images[2 * i + 1], s.mean);
            fs << "row_variance"
               << std::vector<double>(s.rowVariance.begin<double>(), s.rowVariance.end<double>());
            std::vector<double> noisy;
            for (size_t p = 0; p < s.noisyPixels.size(); ++p)
                noisy.insert(noisy.end(),
                             {double(s.noisyPixels[p].x), double(s.noisyPixels[p].y), s.noisyVariance[p]});
            fs << "noisy_pixels" << noisy;
            fs << "}";
        }
        fs << "]";
        fs << "}";
    });
}

//! A bank's path made absolute: it is how the bank reaches other processes, whose working folder differs.
String absoluteBankPath(const String& bankPath)
{
    return detail::absolutePathOf(bankPath);
}

} // namespace

bool DarkFrameBank::matchesItsFile() const
{
    if (path.empty())
        return false;
    std::string onDisk;
    try {
        onDisk = detail::readTextFile(path);
    } catch (const Exception&) {
        return false;
    }
    std::vector<String> images;
    std::vector<const Mat*> maps;
    return bankFileText(*this, path, images, maps) == onDisk;
}

void DarkFrameBank::save(const String& bankPath)
{
    checkPathHasNoNul(bankPath); // before the text, which names the maps after the path
    if (empty())
        CV_Error(Error::StsBadArg, "DarkFrameBank::save: an empty bank");
    validate();
    std::vector<String> images;
    std::vector<const Mat*> maps;
    const std::string text = bankFileText(*this, bankPath, images, maps);
    detail::saveWithMapImages(
        bankPath, text, maps, images, [&](const String& name) { return isBankImageOf(bankPath, name); },
        "DarkFrameBank::save");
    path = absoluteBankPath(bankPath);
}

DarkFrameBank DarkFrameBank::load(const String& bankPath)
{
    DarkFrameBank bank =
        detail::loadFileStorage(bankPath, kTopLevelName, "dark-frame bank file", [&](const FileNode& n) {
            if (n.empty() || !n.isMap())
                CV_Error(Error::StsParseError, "dark-frame bank: expected a map with format_version, format, "
                                               "width, height and groups");
            rejectUnknownKeys(n, {"format_version", "format", "width", "height", "groups"});
            const FileNode version = n["format_version"];
            if (version.empty() || !version.isInt())
                CV_Error(Error::StsParseError,
                         "dark-frame bank: field 'format_version' is missing or not an integer");
            if (int(version) < 1 || int(version) > FORMAT_VERSION)
                CV_Error(Error::StsParseError,
                         cv::format(
                             "dark-frame bank: format_version %d is not supported; this build reads versions "
                             "1 to %d",
                             int(version), FORMAT_VERSION));
            DarkFrameBank b;
            b.format = RawFormat::read(n["format"]);
            b.size.width = detail::readOptionalIntField(n, "width", 0);
            b.size.height = detail::readOptionalIntField(n, "height", 0);
            if (b.size.width <= 0 || b.size.height <= 0 || b.size.area() > (1LL << 28))
                CV_Error(Error::StsParseError,
                         "dark-frame bank: width and height must be > 0, and the frames at most 2^28 pixels");
            const FileNode list = n["groups"];
            if (!list.isSeq() || list.size() == 0)
                CV_Error(Error::StsParseError, "dark-frame bank: field 'groups' must be a non-empty list");
            // Frames resolved against the absolute folder: a later change of working folder moves nothing.
            const String folder = detail::folderOf(absoluteBankPath(bankPath));
            int index = 0;
            for (const FileNode& g : list) {
                try {
                    b.groups.push_back(readGroup(g, folder, b.size, index, int(version)));
                } catch (const Exception& e) {
                    CV_Error(e.code, cv::format("dark-frame bank: groups[%d]: ", index) + e.err);
                }
                ++index;
            }
            b.validate();
            return b;
        });
    bank.path = absoluteBankPath(bankPath);
    return bank;
}

int DarkFrameBank::nearestGroup(double gain, double exposureTime) const
{
    if (empty())
        CV_Error(Error::StsBadArg, "DarkFrameBank: an empty bank has no frames to draw");
    if (!(std::isfinite(gain) && gain > 0) || !(std::isfinite(exposureTime) && exposureTime >= 0))
        CV_Error(Error::StsBadArg,
                 cv::format("DarkFrameBank: gain %g must be finite and > 0, exposure time %g finite "
                            "and >= 0",
                            gain, exposureTime));
    const double lowest = groups.front().gain, highest = groups.back().gain;
    // 0.1%: a gain computed from an ISO (200 / 100) is still the bank's gain after rounding.
    if (gain < lowest * (1 - 1e-3) || gain > highest * (1 + 1e-3))
        CV_Error(
            Error::StsOutOfRange,
            cv::format(
                "DarkFrameBank: gain %g lies outside the bank's gains [%g, %g]%s: its frames say nothing of "
                "it; add dark frames at that gain",
                gain, lowest, highest, path.empty() ? "" : (" ('" + path + "')").c_str()));
    return detail::nearestGainGroup(groups, gain, exposureTime, path);
}

Mat DarkFrameBank::readFrame(int group, int index) const
{
    if (group < 0 || group >= static_cast<int>(groups.size()))
        CV_Error(Error::StsOutOfRange,
                 cv::format("DarkFrameBank::readFrame: group %d of a bank of %zu", group, groups.size()));
    const DarkFrameGroup& g = groups[static_cast<size_t>(group)];
    if (index < 0 || index >= static_cast<int>(g.files.size()))
        CV_Error(Error::StsOutOfRange,
                 cv::format("DarkFrameBank::readFrame: frame %d of a group of %zu", index, g.files.size()));
    const String& file = g.files[static_cast<size_t>(index)];
    const double bytes = fileBytesOf(file);
    if (index < static_cast<int>(g.fileBytes.size()) && bytes != g.fileBytes[static_cast<size_t>(index)])
        CV_Error(
            Error::StsError,
            cv::format(
                "DarkFrameBank: dark frame '%s' is %.0f bytes, but %.0f when the bank was made: the file "
                "was replaced; make the bank again",
                file.c_str(), bytes, g.fileBytes[static_cast<size_t>(index)]));
    if (index < static_cast<int>(g.fingerprints.size())) {
        const std::string now = detail::contentFingerprintOf(file, "dark frame");
        if (now != g.fingerprints[static_cast<size_t>(index)])
            CV_Error(
                Error::StsError,
                cv::format("DarkFrameBank: dark frame '%s' holds other bytes than when the bank was made "
                           "(FNV-1a 64 %s, the bank's %s): the file was replaced; make the bank again",
                           file.c_str(), now.c_str(), g.fingerprints[static_cast<size_t>(index)].c_str()));
    }
    Mat mosaic;
    if (pathExists(sidecarPathOf(file)))
        readMosaic(file, mosaic);
    else
        mosaic = readRaw(file).mosaic;
    if (mosaic.size() != size)
        CV_Error(Error::StsError,
                 cv::format("DarkFrameBank: dark frame '%s' is %dx%d, the bank's frames %dx%d", file.c_str(),
                            mosaic.cols, mosaic.rows, size.width, size.height));
    return mosaic;
}

} // namespace rawgment
} // namespace cv
