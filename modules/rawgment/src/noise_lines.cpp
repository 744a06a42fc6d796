// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Measured noise lines in a NoiseModel (NoiseModel::measuredLines): how the terms at any gain come from
// them, their checks, and their place in the model file. Why each rule is what it is: noise_model.hpp.
#include "noise_terms.hpp"
#include "precomp.hpp"

#include <algorithm>

namespace cv {
namespace rawgment {
namespace detail {

namespace {

//! Eq. 5's offset at gain g: the trend of the offset beyond the measured gains.
double eq5Offset(const NoiseModel& model, double gain)
{
    return noiseTermsAt(gain, model.alpha, model.sigmaD2, model.sigmaR2).read();
}

//! The line at gain g from the measured lines (g > 0).
NoiseLine measuredLineAt(const std::vector<MeasuredNoiseLine>& lines, const NoiseModel& model, double g)
{
    const MeasuredNoiseLine &first = lines.front(), &last = lines.back();
    if (g <= first.gain || g >= last.gain) {
        const MeasuredNoiseLine& edge = g <= first.gain ? first : last;
        if (g == edge.gain)
            return edge.line;
        const double trend = eq5Offset(model, edge.gain);
        NoiseLine out;
        out.a = edge.line.a * (g / edge.gain);
        out.b = trend > 0 ? edge.line.b * (eq5Offset(model, g) / trend) : edge.line.b;
        return out;
    }
    const auto above =
        std::upper_bound(lines.begin(), lines.end(), g,
                         [](double value, const MeasuredNoiseLine& l) { return value < l.gain; });
    const MeasuredNoiseLine &hi = *above, &lo = *(above - 1);
    if (g == lo.gain)
        return lo.line;
    const double t = (g - lo.gain) / (hi.gain - lo.gain);
    const double t2 = (g * g - lo.gain * lo.gain) / (hi.gain * hi.gain - lo.gain * lo.gain);
    NoiseLine out;
    out.a = lo.line.a + t * (hi.line.a - lo.line.a);
    out.b = lo.line.b + t2 * (hi.line.b - lo.line.b);
    return out;
}

void refuseEntry(size_t index, const std::string& why)
{
    CV_Error(Error::StsBadArg, format("NoiseModel.measuredLines[%zu]: %s", index, why.c_str()));
}

double readEntryValue(const FileNode& entry, const char* key, size_t index, bool required)
{
    if (!required && entry[key].empty())
        return 0;
    double v = 0;
    try {
        v = readRealField(entry, key);
    } catch (const Exception& e) {
        CV_Error(Error::StsParseError, format("noise model: measured_lines[%zu]: ", index) + e.err);
    }
    return v;
}

} // namespace

NoiseTerms<double> measuredTermsAt(const NoiseModel& model, double gain)
{
    const NoiseLine line = measuredLineAt(model.measuredLines, model, gain);
    // Eq. 5's split of the offset at this gain; all after the gain when Eq. 5 has no read noise there.
    const NoiseTerms<double> eq5 = noiseTermsAt(gain, model.alpha, model.sigmaD2, model.sigmaR2);
    const double before = eq5.read() > 0 ? line.b * (eq5.readBeforeGain / eq5.read()) : 0.0;
    return {line.a, before, line.b - before};
}

void checkMeasuredLines(const std::vector<MeasuredNoiseLine>& lines)
{
    for (size_t i = 0; i < lines.size(); ++i) {
        const MeasuredNoiseLine& l = lines[i];
        if (!(std::isfinite(l.gain) && l.gain > 0))
            refuseEntry(i, format("gain must be finite and > 0 (got %g)", l.gain));
        if (i > 0 && !(l.gain > lines[i - 1].gain))
            refuseEntry(i, format("gain %g does not follow %g: the lines must be by increasing gain, one per "
                                  "gain",
                                  l.gain, lines[i - 1].gain));
        const double values[5] = {l.line.a, l.line.b, l.slopeStdError, l.offsetStdError, l.iso};
        const char* names[5] = {"slope a", "offset b", "slopeStdError", "offsetStdError", "iso"};
        for (int k = 0; k < 5; ++k)
            if (!(std::isfinite(values[k]) && values[k] >= 0))
                refuseEntry(i, format("%s must be finite and >= 0 (got %g)", names[k], values[k]));
    }
}

void writeMeasuredLines(FileStorage& fs, const std::vector<MeasuredNoiseLine>& lines)
{
    fs << "measured_lines"
       << "[";
    for (const MeasuredNoiseLine& l : lines) {
        fs << "{"
           << "gain" << l.gain << "a" << l.line.a << "b" << l.line.b;
        if (l.slopeStdError > 0 || l.offsetStdError > 0)
            fs << "a_std_error" << l.slopeStdError << "b_std_error" << l.offsetStdError;
        if (l.iso > 0)
            fs << "iso" << l.iso;
        fs << "}";
    }
    fs << "]";
}

std::vector<MeasuredNoiseLine> readMeasuredLines(const FileNode& list)
{
    if (!list.isSeq() || list.size() == 0)
        CV_Error(Error::StsParseError,
                 "noise model: measured_lines must be a non-empty list of maps with gain, "
                 "a and b");
    std::vector<MeasuredNoiseLine> lines;
    for (const FileNode& entry : list) {
        const size_t index = lines.size();
        if (!entry.isMap())
            CV_Error(Error::StsParseError, format("noise model: measured_lines[%zu] must be a map", index));
        try {
            rejectUnknownKeys(entry, {"gain", "a", "b", "a_std_error", "b_std_error", "iso"});
        } catch (const Exception& e) {
            CV_Error(e.code, format("noise model: measured_lines[%zu]: ", index) + e.err);
        }
        if (entry["a_std_error"].empty() != entry["b_std_error"].empty())
            CV_Error(
                Error::StsParseError,
                format("noise model: measured_lines[%zu]: a_std_error and b_std_error come together", index));
        MeasuredNoiseLine l;
        l.gain = readEntryValue(entry, "gain", index, true);
        l.line.a = readEntryValue(entry, "a", index, true);
        l.line.b = readEntryValue(entry, "b", index, true);
        l.slopeStdError = readEntryValue(entry, "a_std_error", index, false);
        l.offsetStdError = readEntryValue(entry, "b_std_error", index, false);
        l.iso = readEntryValue(entry, "iso", index, false);
        lines.push_back(l);
    }
    return lines;
}

} // namespace detail
} // namespace rawgment
} // namespace cv
