// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The calibration topic's report file: CalibrationReport as a versioned YAML/JSON map, read back with every
// field checked.
#include "calibration_lines.hpp"
#include "precomp.hpp"

#include <opencv2/rawgment/calibration.hpp>

namespace cv {
namespace rawgment {

using detail::kMaxExcessKurtosis;
using detail::kMinExcessKurtosis;

namespace {

const char* uncertaintySourceName(UncertaintySource source)
{
    return source == UNCERTAINTY_BOOTSTRAP ? "bootstrap" : "covariance";
}

void writeReals(FileStorage& fs, const char* name, const double* values, int count)
{
    fs << name << "[:";
    for (int i = 0; i < count; ++i)
        fs << values[i];
    fs << "]";
}

//! A list of exactly `count` numbers, or an error naming the field.
void readReals(const FileNode& node, const char* field, double* values, int count)
{
    const FileNode list = node[field];
    if (!list.isSeq() || static_cast<int>(list.size()) != count)
        CV_Error(Error::StsParseError,
                 format("calibration report: field '%s' must be a list of %d numbers", field, count));
    for (int i = 0; i < count; ++i) {
        if (!list[i].isReal() && !list[i].isInt())
            CV_Error(Error::StsParseError,
                     format("calibration report: field '%s' holds something other than a number", field));
        values[i] = static_cast<double>(list[i]);
    }
}

ModelUncertainty readUncertainty(const FileNode& node)
{
    if (!node.isMap())
        CV_Error(Error::StsParseError, "calibration report: field 'uncertainty' is missing or not a map");
    try {
        rejectUnknownKeys(node, {"source", "std_error", "covariance", "fit_std_error", "bootstrap_std_error",
                                 "bootstrap_replicates"});
    } catch (const Exception& e) {
        CV_Error(e.code, "calibration report: uncertainty: " + e.err);
    }
    ModelUncertainty u;
    const FileNode source = node["source"];
    if (!source.isString() || (source.string() != "covariance" && source.string() != "bootstrap"))
        CV_Error(Error::StsParseError,
                 "calibration report: uncertainty: field 'source' must be 'covariance' or 'bootstrap'");
    u.source = source.string() == "bootstrap" ? UNCERTAINTY_BOOTSTRAP : UNCERTAINTY_COVARIANCE;
    readReals(node, "std_error", u.stdError.val, 3);
    readReals(node, "covariance", u.covariance.val, 9);
    readReals(node, "fit_std_error", u.fitStdError.val, 3);
    readReals(node, "bootstrap_std_error", u.bootstrapStdError.val, 3);
    u.bootstrapReplicates = static_cast<int>(detail::readRealField(node, "bootstrap_replicates"));
    for (int k = 0; k < 3; ++k)
        if (!(u.stdError[k] >= 0) || !(u.fitStdError[k] >= 0) || !(u.bootstrapStdError[k] >= 0))
            CV_Error(Error::StsParseError, "calibration report: uncertainty: standard errors must be >= 0");
    return u;
}

} // namespace

void CalibrationReport::write(FileStorage& fs, const String& name) const
{
    // Any other value would be written as one of the two and read back as a method that never ran.
    if (method != NOISE_FIT_JOINT && method != NOISE_FIT_TWO_STAGE)
        CV_Error(Error::StsBadArg,
                 format("CalibrationReport::write: method %d is not a NoiseFitMethod", int(method)));
    // The lowest version that holds what the report has: one without errors stays readable by builds
    // that know only version 1.
    const bool withErrors = uncertainty.source != UNCERTAINTY_NONE;
    fs << name << "{";
    fs << "format_version" << (withErrors ? FORMAT_VERSION : 1);
    fs << "method" << (method == NOISE_FIT_JOINT ? "joint" : "two_stage");
    fs << "separable" << static_cast<int>(separable);
    {
        // The dark-shading maps live beside the model file (NoiseModel::save()), not in the report.
        NoiseModel withoutMaps = model;
        withoutMaps.darkShadingPerGain = Mat();
        withoutMaps.darkShadingOffset = Mat();
        withoutMaps.write(fs, "noise_model");
    }
    fs << "r_squared_slope" << rSquaredSlope;
    fs << "r_squared_offset" << rSquaredOffset;
    fs << "samples" << samples;
    fs << "samples_used" << samplesUsed;
    if (withErrors) {
        fs << "uncertainty"
           << "{";
        fs << "source" << uncertaintySourceName(uncertainty.source);
        writeReals(fs, "std_error", uncertainty.stdError.val, 3);
        writeReals(fs, "covariance", uncertainty.covariance.val, 9);
        writeReals(fs, "fit_std_error", uncertainty.fitStdError.val, 3);
        writeReals(fs, "bootstrap_std_error", uncertainty.bootstrapStdError.val, 3);
        fs << "bootstrap_replicates" << uncertainty.bootstrapReplicates;
        fs << "}";
        fs << "read_excess_kurtosis" << readExcessKurtosis;
        fs << "read_excess_kurtosis_estimated" << static_cast<int>(readExcessKurtosisEstimated);
    }
    fs << "per_gain"
       << "[";
    for (const NoiseLineFit& f : perGain) {
        fs << "{";
        fs << "gain" << f.gain << "gain_db" << linearGainToDb(f.gain) << "a" << f.line.a << "b" << f.line.b;
        fs << "r_squared" << f.rSquared << "inliers" << f.inliers << "samples" << f.samples;
        if (withErrors)
            fs << "a_std_error" << f.slopeStdError << "b_std_error" << f.offsetStdError << "ab_correlation"
               << f.slopeOffsetCorrelation;
        fs << "}";
    }
    fs << "]";
    writeStringList(fs, "notes", std::vector<String>(notes.begin(), notes.end()));
    fs << "}";
}

CalibrationReport CalibrationReport::read(const FileNode& node)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError, "calibration report: expected a map");
    const FileNode versionNode = node["format_version"];
    if (!versionNode.isInt())
        CV_Error(Error::StsParseError,
                 "calibration report: field 'format_version' is missing or not an integer");
    if (static_cast<int>(versionNode) < 1 || static_cast<int>(versionNode) > FORMAT_VERSION)
        CV_Error(
            Error::StsParseError,
            format("calibration report: format_version %d is not supported; this build reads versions 1 to "
                   "%d%s",
                   static_cast<int>(versionNode), FORMAT_VERSION,
                   static_cast<int>(versionNode) > FORMAT_VERSION ? " (a newer cv::rawgment wrote the file)"
                                                                  : ""));
    const int version = static_cast<int>(versionNode);
    CalibrationReport r;
    try {
        std::vector<String> keys = {
            "format_version",   "method",  "separable",    "noise_model", "r_squared_slope",
            "r_squared_offset", "samples", "samples_used", "per_gain",    "notes"};
        std::vector<String> gainKeys = {"gain", "gain_db", "a", "b", "r_squared", "inliers", "samples"};
        if (version >= 3)
            keys.insert(keys.end(), {"read_excess_kurtosis", "read_excess_kurtosis_estimated"});
        if (version >= 2) {
            keys.push_back("uncertainty");
            gainKeys.insert(gainKeys.end(), {"a_std_error", "b_std_error", "ab_correlation"});
        }
        rejectUnknownKeys(node, keys);
        for (const FileNode& g : node["per_gain"])
            rejectUnknownKeys(g, gainKeys);
    } catch (const Exception& e) {
        CV_Error(e.code, "calibration report: " + e.err);
    }
    const FileNode method = node["method"];
    if (!method.isString() || (method.string() != "joint" && method.string() != "two_stage"))
        CV_Error(Error::StsParseError, "calibration report: field 'method' must be 'joint' or 'two_stage'");
    r.method = method.string() == "joint" ? NOISE_FIT_JOINT : NOISE_FIT_TWO_STAGE;
    if (node["separable"].empty())
        CV_Error(Error::StsParseError, "field 'separable' is missing");
    r.separable = detail::readOptionalFlagField(node, "separable", false);
    r.model = NoiseModel::read(node["noise_model"]);
    r.rSquaredSlope = detail::readRealField(node, "r_squared_slope");
    r.rSquaredOffset = detail::readRealField(node, "r_squared_offset");
    r.samples = static_cast<int>(detail::readRealField(node, "samples"));
    r.samplesUsed = static_cast<int>(detail::readRealField(node, "samples_used"));
    if (version >= 2)
        r.uncertainty = readUncertainty(node["uncertainty"]);
    if (version >= 3) {
        r.readExcessKurtosis = detail::readRealField(node, "read_excess_kurtosis");
        if (!(r.readExcessKurtosis >= kMinExcessKurtosis && r.readExcessKurtosis <= kMaxExcessKurtosis))
            CV_Error(Error::StsParseError,
                     format("calibration report: field 'read_excess_kurtosis' must lie in "
                            "[%g, %g] (got %g)",
                            kMinExcessKurtosis, kMaxExcessKurtosis, r.readExcessKurtosis));
        r.readExcessKurtosisEstimated = detail::readRealField(node, "read_excess_kurtosis_estimated") != 0;
    }
    const FileNode perGain = node["per_gain"];
    if (!perGain.isSeq())
        CV_Error(Error::StsParseError, "calibration report: field 'per_gain' is missing or not a list");
    for (const FileNode& g : perGain) {
        NoiseLineFit f;
        f.gain = detail::readRealField(g, "gain");
        f.line.a = detail::readRealField(g, "a");
        f.line.b = detail::readRealField(g, "b");
        f.rSquared = detail::readRealField(g, "r_squared");
        f.inliers = static_cast<int>(detail::readRealField(g, "inliers"));
        f.samples = static_cast<int>(detail::readRealField(g, "samples"));
        if (version >= 2) {
            f.slopeStdError = detail::readRealField(g, "a_std_error");
            f.offsetStdError = detail::readRealField(g, "b_std_error");
            f.slopeOffsetCorrelation = detail::readRealField(g, "ab_correlation");
        }
        r.perGain.push_back(f);
    }
    for (const FileNode& n : node["notes"])
        r.notes.push_back(n.string());
    return r;
}

void CalibrationReport::save(const String& path) const
{
    detail::writeFileStorageAtomically(path, [&](FileStorage& fs) { write(fs, "calibration_report"); });
}

CalibrationReport CalibrationReport::load(const String& path)
{
    return detail::loadFileStorage(path, "calibration_report", "calibration report",
                                   [](const FileNode& n) { return read(n); });
}

} // namespace rawgment
} // namespace cv
