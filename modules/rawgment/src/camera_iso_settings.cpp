// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Which of a camera's ISOs are analog steps: the expanded low settings and the digital settings told from
// darktable's green shot slopes (normalised to the white level), so that Eq. 5 is fitted to the analog ones.
#include "camera_profiles_detail.hpp"
#include "precomp.hpp"

#include <algorithm>
#include <cmath>

namespace cv {
namespace rawgment {

namespace {

/* An expanded low ISO's slope falls less than its ISO towards the next ISO down: (a_k / a_k+1) / (s_k /
 * s_k+1) above this, where an analog step gives 1 and a setting whose raw is the next ISO's gives s_k+1 /
 * s_k, 1.26 a third of a stop below and 2 a stop below. */
constexpr double EXPANDED_SLOPE_OVER_ISO = 1.15;
/* Two ISOs at least MIN_DIGITAL_STEP apart (a little under a third of a stop, 1.26) whose slopes differ by
 * less than SAME_RAW_SLOPE share one raw: an analog third of a stop raises the slope by 26%, while the
 * 107 ISOs that darktable 4.2.1's file measured twice differ by 0.9% (median) and 2.4% (75th percentile)
 * between their two green slopes. */
constexpr double MIN_DIGITAL_STEP = 1.2;
constexpr double SAME_RAW_SLOPE = 0.08;

} // namespace

double medianOf(std::vector<double> values)
{
    if (values.empty())
        return 0;
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/* Expanded low settings: from the lowest ISO up, each whose slope falls less than its ISO (the Canon EOS 5D
 * Mark III's ISO 50, the Nikon D3's ISO 100 to 159); two ISOs are always kept.
 *
 * Digital settings: above those, runs of neighbouring ISOs a third of a stop or more apart with one slope.
 * darktable normalises each file by its own white level, so a setting that scales an analog ISO's raw and
 * its white level together, or that only marks the raw for brightening, has that ISO's slope: Canon's
 * third stops 160, 320, 640, ... (the raw of 200, 400, 800 scaled by 0.8 with a white level lowered to
 * match) and Fujifilm's high settings that keep the raw of a lower ISO. In each run the analog member is
 * the one nearest the camera's trend, the median of slope / ISO over the ISOs in no run; the others are
 * digital, named with the analog member's ISO. Two analog ISOs are always kept. A digital push that scales
 * the raw but keeps the white level raises the slope as an analog gain does, so it is not found here. */
IsoSettings classifyIsoSettings(const std::vector<double>& isos, const std::vector<double>& slopes)
{
    IsoSettings settings;
    const size_t n = isos.size();
    size_t first = 0;
    for (; first + 2 < n; ++first) {
        if (!((slopes[first] / slopes[first + 1]) / (isos[first] / isos[first + 1]) >
              EXPANDED_SLOPE_OVER_ISO))
            break;
        settings.expanded.insert(isos[first]);
    }
    const auto sameRaw = [&](size_t k) {
        return isos[k + 1] / isos[k] >= MIN_DIGITAL_STEP &&
               std::abs(slopes[k + 1] / slopes[k] - 1) < SAME_RAW_SLOPE;
    };
    std::vector<std::pair<size_t, size_t>> runs;
    std::vector<bool> inRun(n, false);
    for (size_t k = first; k < n;) {
        size_t last = k;
        while (last + 1 < n && sameRaw(last))
            ++last;
        if (last > k) {
            runs.emplace_back(k, last);
            std::fill(inRun.begin() + long(k), inRun.begin() + long(last) + 1, true);
        }
        k = last + 1;
    }
    if (runs.empty())
        return settings;
    std::vector<double> perIso;
    for (size_t k = first; k < n; ++k)
        if (!inRun[k])
            perIso.push_back(slopes[k] / isos[k]);
    if (perIso.empty())
        for (size_t k = first; k < n; ++k)
            perIso.push_back(slopes[k] / isos[k]);
    const double trend = medianOf(perIso);
    std::map<double, double> digital;
    for (const auto& run : runs) {
        size_t analog = run.first;
        for (size_t k = run.first; k <= run.second; ++k)
            if (std::abs(std::log(slopes[k] / isos[k] / trend)) <
                std::abs(std::log(slopes[analog] / isos[analog] / trend)))
                analog = k;
        for (size_t k = run.first; k <= run.second; ++k)
            if (k != analog)
                digital[isos[k]] = isos[analog];
    }
    if (n - first - digital.size() >= 2)
        settings.digital = digital;
    return settings;
}

} // namespace rawgment
} // namespace cv
