// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "opencv2/rawgment/noise_model.hpp"
#include "noise_terms.hpp"
#include "precomp.hpp"

namespace cv {
namespace rawgment {

namespace {

const char* const kTopLevelName = "noise_model";

template <typename T> void varianceOfMeans(const Mat& mean, Mat& dst, const NoiseLine& line)
{
    const T a = static_cast<T>(line.a), b = static_cast<T>(line.b);
    parallel_for_(Range(0, mean.rows), [&](const Range& rows) {
        for (int r = rows.start; r < rows.end; ++r) {
            const T* m = mean.ptr<T>(r);
            T* d = dst.ptr<T>(r);
            for (int c = 0; c < mean.cols; ++c)
                d[c] = detail::lineVariance(a, b, m[c]);
        }
    });
}

} // namespace

double dbToLinearGain(double db)
{
    if (!std::isfinite(db))
        CV_Error(Error::StsBadArg, format("gain in dB must be finite (got %g)", db));
    const double g = std::pow(10.0, db / 20.0);
    if (!std::isfinite(g) || !(g > 0))
        CV_Error(Error::StsBadArg,
                 format("gain of %g dB is outside what a double holds (about +-6000 dB)", db));
    return g;
}

double linearGainToDb(double gain)
{
    detail::checkFinitePositive(gain, "linear gain");
    return 20.0 * std::log10(gain);
}

NoiseModel::NoiseModel(double alpha_, double sigmaD2_, double sigmaR2_)
    : alpha(alpha_), sigmaD2(sigmaD2_), sigmaR2(sigmaR2_)
{
    validate();
}

void NoiseModel::validate() const
{
    detail::checkFiniteNonNegative(alpha, "NoiseModel.alpha");
    detail::checkFiniteNonNegative(sigmaD2, "NoiseModel.sigmaD2");
    detail::checkFiniteNonNegative(sigmaR2, "NoiseModel.sigmaR2");
    detail::checkFiniteNonNegative(baseIso, "NoiseModel.baseIso");
}

namespace detail {

NoiseTerms<double> checkedNoiseTerms(const NoiseModel& model, double gain)
{
    model.validate();
    checkFinitePositive(gain, "gain");
    const NoiseTerms<double> t = noiseTermsAt(gain, model.alpha, model.sigmaD2, model.sigmaR2);
    if (!std::isfinite(t.shot) || !std::isfinite(t.read()))
        CV_Error(Error::StsBadArg,
                 format("noise line at gain %g overflows (a = %g, b = %g)", gain, t.shot, t.read()));
    return t;
}

} // namespace detail

NoiseLine NoiseModel::lineAtGain(double gain) const
{
    const detail::NoiseTerms<double> t = detail::checkedNoiseTerms(*this, gain);
    NoiseLine line;
    line.a = t.shot;
    line.b = t.read();
    return line;
}

double NoiseModel::variance(double mean, double gain) const
{
    if (!std::isfinite(mean))
        CV_Error(Error::StsBadArg, format("NoiseModel::variance: mean must be finite (got %g)", mean));
    return detail::checkedNoiseTerms(*this, gain).variance(mean);
}

void NoiseModel::variance(InputArray _mean, double gain, OutputArray _dst) const
{
    const NoiseLine line = lineAtGain(gain);
    const Mat mean = _mean.getMat();
    if (mean.empty())
        CV_Error(Error::StsBadArg, "NoiseModel::variance: mean is empty");
    if (mean.type() != CV_32FC1 && mean.type() != CV_64FC1)
        CV_Error(Error::StsBadArg, format("NoiseModel::variance: mean type %s is not supported; expected "
                                          "CV_32FC1 or CV_64FC1",
                                          typeToString(mean.type()).c_str()));
    if (!checkRange(mean, true))
        CV_Error(Error::StsBadArg, "NoiseModel::variance: mean contains NaN or Inf");
    Mat dst(mean.size(), mean.type());
    if (mean.depth() == CV_32F)
        varianceOfMeans<float>(mean, dst, line);
    else
        varianceOfMeans<double>(mean, dst, line);
    _dst.assign(dst);
}

void NoiseModel::write(FileStorage& fs, const String& name) const
{
    validate();
    fs << name << "{";
    fs << "format_version" << (baseIso > 0 ? 2 : 1);
    fs << "alpha" << alpha;
    fs << "sigma_d2" << sigmaD2;
    fs << "sigma_r2" << sigmaR2;
    if (baseIso > 0)
        fs << "base_iso" << baseIso;
    fs << "}";
}

NoiseModel NoiseModel::read(const FileNode& node)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError,
                 "noise model: expected a map with format_version, alpha, sigma_d2, sigma_r2");
    const FileNode versionNode = node["format_version"];
    if (versionNode.empty() || !versionNode.isInt())
        CV_Error(Error::StsParseError, "noise model: field 'format_version' is missing or not an integer");
    const int version = static_cast<int>(versionNode);
    if (version > FORMAT_VERSION || version < 1)
        CV_Error(Error::StsParseError,
                 format("noise model: format_version %d is not supported; this build reads versions 1 to %d "
                        "(a newer cv::rawgment wrote the file)",
                        version, FORMAT_VERSION));
    try {
        if (version == 1)
            rejectUnknownKeys(node, {"format_version", "alpha", "sigma_d2", "sigma_r2"});
        else
            rejectUnknownKeys(node, {"format_version", "alpha", "sigma_d2", "sigma_r2", "base_iso"});
    } catch (const Exception& e) {
        CV_Error(e.code, "noise model: " + e.err);
    }
    NoiseModel m;
    double* const targets[] = {&m.alpha, &m.sigmaD2, &m.sigmaR2};
    const char* const fields[] = {"alpha", "sigma_d2", "sigma_r2"};
    for (int i = 0; i < 3; ++i) {
        try {
            *targets[i] = detail::readRealField(node, fields[i]);
        } catch (const Exception& e) {
            CV_Error(Error::StsParseError, "noise model: " + e.err);
        }
        if (!std::isfinite(*targets[i]) || *targets[i] < 0)
            CV_Error(Error::StsParseError, format("noise model: field '%s' must be finite and >= 0 (got %g)",
                                                  fields[i], *targets[i]));
    }
    if (!node["base_iso"].empty()) {
        try {
            m.baseIso = detail::readRealField(node, "base_iso");
        } catch (const Exception& e) {
            CV_Error(Error::StsParseError, "noise model: " + e.err);
        }
        if (!std::isfinite(m.baseIso) || !(m.baseIso > 0))
            CV_Error(Error::StsParseError,
                     format("noise model: field 'base_iso' must be finite and > 0 (got %g)", m.baseIso));
    }
    return m;
}

void NoiseModel::save(const String& path) const
{
    validate();
    detail::writeFileStorageAtomically(path, [&](FileStorage& fs) { write(fs, kTopLevelName); });
}

NoiseModel NoiseModel::load(const String& path)
{
    return detail::loadFileStorage(path, kTopLevelName, "noise model file",
                                   [](const FileNode& n) { return read(n); });
}

} // namespace rawgment
} // namespace cv
