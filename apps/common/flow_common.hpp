// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What the app flows (simulate, calibrate, validate, augment) share: manifests, file lists, the
// refusal to overwrite, chart squares. Private to apps/common.
#ifndef RAWGMENT_APPS_FLOW_COMMON_HPP
#define RAWGMENT_APPS_FLOW_COMMON_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/noise_model.hpp>

#include <functional>
#include <string>
#include <vector>

namespace rawgment_apps {

//! A manifest's non-empty list of files, resolved against `base`; errors name `where`.
std::vector<std::string> readFileList(const cv::FileNode& node, const std::string& base,
                                      const std::string& where);
//! cv::rawgment::rejectUnknownKeys(), as a std::runtime_error naming `where`.
void requireKnownKeys(const cv::FileNode& map, const std::vector<std::string>& valid,
                      const std::string& where);
//! Throws when any of the outputs exists: outputs are never overwritten.
void refuseExisting(const std::vector<std::string>& outputs);
/** Squares from a manifest's `patches` entry: the path of a file written by writeChartPatches(), or
 * "detect" (cv::mcc on the first frame, noted in `notes`). */
std::vector<cv::Rect> manifestSquares(const std::string& patches, const std::string& firstFrame, int side,
                                      std::vector<std::string>& notes);

/** Gives `model` a dark-shading pattern of `size` (NoiseModel::darkShadingPerGain and Offset), as a
 * sensor's might look: B_r a vertical gradient plus per-pixel scatter of `amplitude` DN, B_d a
 * horizontal ramp with scatter of a quarter of it (so that at gain 4 both are alike). Drawn from `seed`. */
void addDarkShadingPattern(cv::Size size, double amplitude, uint64_t seed, cv::rawgment::NoiseModel& model);

} // namespace rawgment_apps

#endif // RAWGMENT_APPS_FLOW_COMMON_HPP
