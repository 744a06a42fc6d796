// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef RAWGMENT_SRC_CAMERA_PROFILES_DETAIL_HPP
#define RAWGMENT_SRC_CAMERA_PROFILES_DETAIL_HPP

#include <opencv2/rawgment/camera_profiles.hpp>

#include <map>
#include <set>
#include <vector>

namespace cv {
namespace rawgment {

//! The settings of a camera's ISOs that are not analog steps, told from their green shot slopes.
struct IsoSettings
{
    std::set<double> expanded;        //!< expanded low ISOs (CameraIsoFit::expanded)
    std::map<double, double> digital; //!< digital ISO -> the ISO whose raw it is (CameraIsoFit::rawIso)
};

//! The median of `values` (0 for none).
double medianOf(std::vector<double> values);

/** The expanded and digital settings among distinct ISOs in increasing order, each with its mean green
 * slope (camera_iso_settings.cpp says how they are told). */
IsoSettings classifyIsoSettings(const std::vector<double>& isos, const std::vector<double>& slopes);

/** Sets cam.colourSlopeRatios, balancePpg, balanceRcd, demosaic and demosaicReason from the colour slope
 * ratios of its fitted ISOs (CameraIsoFit::colourSlopeRatios). */
void judgeProfileDemosaic(CameraNoiseProfile& cam);

} // namespace rawgment
} // namespace cv

#endif
