// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "camera_profiles_detail.hpp"
#include "precomp.hpp"

#include <algorithm>
#include <cmath>

namespace cv {
namespace rawgment {

String profileDemosaicName(int demosaic)
{
    switch (demosaic) {
    case PROFILE_DEMOSAIC_UNDECIDED:
        return "undecided";
    case PROFILE_DEMOSAIC_PPG:
        return "PPG";
    case PROFILE_DEMOSAIC_NEITHER:
        return "neither";
    default:
        CV_Error(Error::StsBadArg, format("unknown ProfileDemosaic %d", demosaic));
    }
}

namespace {

/* A demosaic's red or blue over green slope ratio as a line in the colour balance k (green's raw level over
 * the colour's): measured by `python/tools/darktable_haar_ratio.py --demosaics 4` on flat fields with
 * k = 1 .. 3, red and blue pooled (the two lines differ by less than 0.03 at every k). */
struct RatioLine
{
    double intercept, slope;
    double at(double balance) const { return intercept + slope * balance; }
    double balanceOf(double ratio) const { return (ratio - intercept) / slope; }
};
constexpr RatioLine PPG_RATIO{0.284, 0.946};
constexpr RatioLine RCD_RATIO{0.592, 0.962};

/* How far below a demosaic's grey ratio a camera's median may lie and still fit it. One profile's ratio
 * scatters by about 0.03 (standard deviation of three simulated profiles per demosaic, measured the way
 * darktable measures), so 0.1 is three of them for a single ISO and more for a median over ISOs. */
constexpr double RATIO_MARGIN = 0.1;

} // namespace

void judgeProfileDemosaic(CameraNoiseProfile& cam)
{
    std::vector<double> red, blue;
    bool copies = true;
    for (const CameraIsoFit& f : cam.isos)
        if (f.fitted() && f.colourSlopeRatios[0] > 0 && f.colourSlopeRatios[1] > 0) {
            red.push_back(f.colourSlopeRatios[0]);
            blue.push_back(f.colourSlopeRatios[1]);
            // darktable's oldest profiles copy green's a to every colour.
            copies = copies && std::abs(f.colourSlopeRatios[0] - 1) < 1e-6 &&
                     std::abs(f.colourSlopeRatios[1] - 1) < 1e-6;
        }
    cam.demosaic = PROFILE_DEMOSAIC_UNDECIDED;
    if (red.empty()) {
        cam.demosaicReason = "no fitted ISO has positive red and blue slopes";
        return;
    }
    if (copies) {
        cam.demosaicReason = "red and blue are copies of green at every ISO: no evidence";
        return;
    }
    cam.colourSlopeRatios = Vec2d(medianOf(red), medianOf(blue));
    for (int k = 0; k < 2; ++k) {
        cam.balancePpg[k] = PPG_RATIO.balanceOf(cam.colourSlopeRatios[k]);
        cam.balanceRcd[k] = RCD_RATIO.balanceOf(cam.colourSlopeRatios[k]);
    }
    const int low = cam.colourSlopeRatios[0] <= cam.colourSlopeRatios[1] ? 0 : 1;
    const char* colour = low == 0 ? "red" : "blue";
    const double ratio = cam.colourSlopeRatios[low];
    if (ratio < PPG_RATIO.at(1) - RATIO_MARGIN) {
        cam.demosaic = PROFILE_DEMOSAIC_NEITHER;
        cam.demosaicReason =
            format("%s's slope is %.2f of green's, below PPG's %.2f on grey: neither demosaic "
                   "fits a raw with green brightest",
                   colour, ratio, PPG_RATIO.at(1));
    } else if (ratio < RCD_RATIO.at(1) - RATIO_MARGIN) {
        cam.demosaic = PROFILE_DEMOSAIC_PPG;
        cam.demosaicReason = format(
            "%s's slope is %.2f of green's: with RCD (%.2f on grey) %s would be brighter "
            "than green in the raw (green/%s %.2f); with PPG green/%s is %.2f",
            colour, ratio, RCD_RATIO.at(1), colour, colour, cam.balanceRcd[low], colour, cam.balancePpg[low]);
    } else {
        cam.demosaicReason =
            format("both fit: PPG with green/red %.2f and green/blue %.2f, RCD with %.2f and %.2f",
                   cam.balancePpg[0], cam.balancePpg[1], cam.balanceRcd[0], cam.balanceRcd[1]);
    }
}

} // namespace rawgment
} // namespace cv
