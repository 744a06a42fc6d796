// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Dark frames from files, grouped by gain and exposure (dark_frames.hpp): the files of a dark-frame bank.
#include "dark_frames.hpp"

#include <opencv2/rawgment/files.hpp>
#include <opencv2/rawgment/mosaic_files.hpp>
#include <opencv2/rawgment/raw_io.hpp>

#include <map>
#include <memory>

namespace cv {
namespace rawgment {
namespace detail {

namespace {

//! One dark frame as read: its pixels, its format at its gain, and its exposure time (0: not stated).
struct DarkFrame
{
    Mat mosaic;
    RawFormat format;
    double exposureTime = 0;
};

DarkFrame readDarkFrame(const String& path, const NoiseModel& model)
{
    DarkFrame f;
    if (pathExists(sidecarPathOf(path))) {
        const MosaicMetadata meta = readMosaic(path, f.mosaic);
        f.format = meta.formatFor(model);
        f.exposureTime = meta.hasCamera ? meta.camera.exposureTime : 0.0;
    } else {
        const RawImage raw = readRaw(path);
        f.mosaic = raw.mosaic;
        f.format = raw.formatFor(model);
        f.exposureTime = raw.exposureTime;
    }
    return f;
}

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

} // namespace

DarkFrameCollection collectDarkFrames(const std::vector<String>& files, const NoiseModel& model)
{
    if (files.empty())
        CV_Error(Error::StsBadArg, "collectDarkFrames: no dark frames (an empty bank)");
    DarkFrameCollection out;
    // Burst statistics per (gain, exposure time), fed one frame at a time.
    std::map<std::pair<double, double>, std::pair<std::unique_ptr<BurstStatistics>, DarkFrameGroup>> groups;
    String first;
    for (const String& path : files) {
        const DarkFrame f = readDarkFrame(path, model);
        if (first.empty()) {
            first = path;
            out.format = f.format;
            out.format.gain = 1;
            out.size = f.mosaic.size();
        } else if (!sameSensor(f.format, out.format) || f.mosaic.size() != out.size) {
            CV_Error(
                Error::StsBadArg,
                format("collectDarkFrames: '%s' is %s, but '%s' is %s: one bank holds one sensor's frames",
                       path.c_str(), formatText(f.format, f.mosaic.size()).c_str(), first.c_str(),
                       formatText(out.format, out.size).c_str()));
        }
        auto& g = groups[{f.format.gain, f.exposureTime}];
        if (!g.first) {
            g.first.reset(new BurstStatistics(f.format));
            g.second.gain = f.format.gain;
            g.second.exposureTime = f.exposureTime;
        }
        g.first->add(f.mosaic);
        g.second.files.push_back(path);
    }
    for (auto& entry : groups) {
        DarkFrameGroup& g = entry.second.second;
        if (g.files.size() < 2)
            CV_Error(
                Error::StsBadArg,
                format("collectDarkFrames: gain %g%s has one frame ('%s'); its temporal noise needs at least "
                       "two",
                       g.gain, g.exposureTime > 0 ? format(", exposure %g s", g.exposureTime).c_str() : "",
                       g.files[0].c_str()));
        g.estimate = estimateDarkFrames(*entry.second.first);
        out.groups.push_back(std::move(g));
    }
    return out;
}

} // namespace detail
} // namespace rawgment
} // namespace cv
