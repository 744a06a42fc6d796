// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "opencv2/rawgment/noise_model.hpp"
#include "dark_shading.hpp"
#include "map_images.hpp"
#include "noise_terms.hpp"
#include "precomp.hpp"

#include <algorithm>

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

const char* const kShadingKeys[2] = {"per_gain", "offset"};

void checkShadingMap(const Mat& map, const char* what, Size size)
{
    if (map.type() != CV_32FC1 || map.size() != size)
        CV_Error(Error::StsBadArg,
                 format("NoiseModel.%s must be CV_32FC1 of %dx%d like darkShadingPerGain (got %s, %dx%d)",
                        what, size.width, size.height, typeToString(map.type()).c_str(), map.cols, map.rows));
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

NoiseModel::NoiseModel(double alpha_, double sigmaD2_, double sigmaR2_) : NoiseModel()
{
    alpha = alpha_;
    sigmaD2 = sigmaD2_;
    sigmaR2 = sigmaR2_;
    validate();
}

void NoiseModel::validate() const
{
    detail::checkFiniteNonNegative(alpha, "NoiseModel.alpha");
    detail::checkFiniteNonNegative(sigmaD2, "NoiseModel.sigmaD2");
    detail::checkFiniteNonNegative(sigmaR2, "NoiseModel.sigmaR2");
    detail::checkBaseIso(baseIso, "NoiseModel.baseIso", true);
    detail::checkFiniteNonNegative(rowSigmaD2, "NoiseModel.rowSigmaD2");
    detail::checkFiniteNonNegative(rowSigmaR2, "NoiseModel.rowSigmaR2");
    if (tukeyRead && !(tukeyLambda >= detail::kTukeyLambdaMin && tukeyLambda <= 1))
        CV_Error(Error::StsBadArg, format("NoiseModel.tukeyLambda must lie in [%g, 1] (got %g): below, the "
                                          "kurtosis of the read noise is beyond any sensor's",
                                          detail::kTukeyLambdaMin, tukeyLambda));
    if (darkShadingPerGain.empty() != darkShadingOffset.empty())
        CV_Error(Error::StsBadArg, "NoiseModel: darkShadingPerGain and darkShadingOffset must be both set or "
                                   "both empty");
    if (hasDarkShading()) {
        checkShadingMap(darkShadingPerGain, "darkShadingPerGain", darkShadingPerGain.size());
        checkShadingMap(darkShadingOffset, "darkShadingOffset", darkShadingPerGain.size());
    }
    detail::checkMeasuredLines(measuredLines);
}

double NoiseModel::rowVariance(double gain) const
{
    detail::checkFinitePositive(gain, "gain");
    return gain * gain * rowSigmaD2 + rowSigmaR2;
}

Mat NoiseModel::darkShadingAt(double gain) const
{
    detail::checkFinitePositive(gain, "gain");
    if (!hasDarkShading())
        return Mat();
    // Through the noise steps' own reader of the maps: one formula, the same bits.
    const detail::DarkShading shading(darkShadingPerGain, darkShadingOffset, gain, Point());
    Mat s(darkShadingPerGain.size(), CV_32FC1);
    for (int r = 0; r < s.rows; ++r)
        shading.row(r, s.cols, s.ptr<float>(r));
    return s;
}

namespace detail {

NoiseTerms<double> checkedNoiseTerms(const NoiseModel& model, double gain)
{
    return ValidatedNoiseModel(model).termsAt(gain);
}

NoiseTerms<double> ValidatedNoiseModel::termsAt(double gain) const
{
    const NoiseModel& model = model_;
    checkFinitePositive(gain, "gain");
    const NoiseTerms<double> t = model.hasMeasuredLines()
                                     ? measuredTermsAt(model, gain)
                                     : noiseTermsAt(gain, model.alpha, model.sigmaD2, model.sigmaR2);
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
    const Mat mean = detail::twoDimensional(_mean, "NoiseModel::variance: mean");
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

namespace detail {

void checkBaseIso(double baseIso, const char* what, bool zeroIsUnknown)
{
    if (zeroIsUnknown && baseIso == 0)
        return;
    if (!(baseIso >= NoiseModel::MIN_BASE_ISO && baseIso <= NoiseModel::MAX_BASE_ISO))
        CV_Error(Error::StsBadArg,
                 format("%s must lie in [%g, %g]%s (got %g)", what, NoiseModel::MIN_BASE_ISO,
                        NoiseModel::MAX_BASE_ISO, zeroIsUnknown ? ", or be 0 for unknown" : "", baseIso));
}

void checkDarkShadingFinite(const NoiseModel& model)
{
    if (!model.hasDarkShading())
        return;
    if (!checkRange(model.darkShadingPerGain, true))
        CV_Error(Error::StsBadArg, "NoiseModel.darkShadingPerGain contains NaN or Inf");
    if (!checkRange(model.darkShadingOffset, true))
        CV_Error(Error::StsBadArg, "NoiseModel.darkShadingOffset contains NaN or Inf");
}

} // namespace detail

void NoiseModel::write(FileStorage& fs, const String& name, const std::vector<String>& shadingImages) const
{
    validate();
    detail::checkDarkShadingFinite(*this);
    if (hasDarkShading() && shadingImages.size() != 2)
        CV_Error(Error::StsBadArg, "NoiseModel::write: a model with dark shading needs the names of its two "
                                   "images (save() writes them)");
    const int version = hasMeasuredLines()           ? 5
                        : !failedCalibration.empty() ? 4
                        : hasDarkComponents()        ? 3
                        : baseIso > 0                ? 2
                                                     : 1;
    fs << name << "{";
    fs << "format_version" << version;
    fs << "alpha" << alpha;
    fs << "sigma_d2" << sigmaD2;
    fs << "sigma_r2" << sigmaR2;
    if (baseIso > 0)
        fs << "base_iso" << baseIso;
    if (hasRowNoise())
        fs << "row_sigma_d2" << rowSigmaD2 << "row_sigma_r2" << rowSigmaR2;
    if (tukeyRead)
        fs << "tukey_lambda" << tukeyLambda;
    if (hasDarkShading()) {
        const Mat* maps[2] = {&darkShadingPerGain, &darkShadingOffset};
        fs << "dark_shading"
           << "{";
        fs << "width" << darkShadingPerGain.cols << "height" << darkShadingPerGain.rows;
        for (int i = 0; i < 2; ++i) {
            fs << kShadingKeys[i];
            detail::writeMapImageEntry(fs, shadingImages[static_cast<size_t>(i)], *maps[i]);
        }
        fs << "}";
    }
    if (!failedCalibration.empty())
        writeString(fs, "failed_calibration", failedCalibration);
    if (hasMeasuredLines())
        detail::writeMeasuredLines(fs, measuredLines);
    fs << "}";
}

namespace {

double readNonNegative(const FileNode& node, const char* field)
{
    double v = 0;
    try {
        v = detail::readRealField(node, field);
    } catch (const Exception& e) {
        CV_Error(Error::StsParseError, "noise model: " + e.err);
    }
    if (!std::isfinite(v) || v < 0)
        CV_Error(Error::StsParseError,
                 format("noise model: field '%s' must be finite and >= 0 (got %g)", field, v));
    return v;
}

Mat readShadingImage(const FileNode& entry, const char* key, const String& folder, Size size)
{
    return detail::readMapImage(entry[key], format("noise model: dark_shading.%s", key), folder, size);
}

} // namespace

NoiseModel NoiseModel::read(const FileNode& node, const String& folder)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError,
                 "noise model: expected a map with format_version, alpha, sigma_d2, sigma_r2");
    const FileNode versionNode = node["format_version"];
    if (versionNode.empty() || !versionNode.isInt())
        CV_Error(Error::StsParseError, "noise model: field 'format_version' is missing or not an integer");
    const int version = static_cast<int>(versionNode);
    if (version < 1)
        CV_Error(
            Error::StsParseError,
            format("noise model: format_version %d is not a version of this format (versions start at 1; "
                   "this build reads 1 to %d)",
                   version, FORMAT_VERSION));
    if (version > FORMAT_VERSION)
        CV_Error(Error::StsParseError,
                 format("noise model: format_version %d is not supported; this build reads versions 1 to %d "
                        "(a newer cv::rawgment wrote the file)",
                        version, FORMAT_VERSION));
    try {
        std::vector<String> keys = {"format_version", "alpha", "sigma_d2", "sigma_r2"};
        if (version >= 2)
            keys.push_back("base_iso");
        if (version >= 3)
            keys.insert(keys.end(), {"row_sigma_d2", "row_sigma_r2", "tukey_lambda", "dark_shading"});
        if (version >= 4)
            keys.push_back("failed_calibration");
        if (version >= 5)
            keys.push_back("measured_lines");
        rejectUnknownKeys(node, keys);
    } catch (const Exception& e) {
        CV_Error(e.code, "noise model: " + e.err);
    }
    NoiseModel m;
    m.alpha = readNonNegative(node, "alpha");
    m.sigmaD2 = readNonNegative(node, "sigma_d2");
    m.sigmaR2 = readNonNegative(node, "sigma_r2");
    if (!node["base_iso"].empty()) {
        try {
            m.baseIso = detail::readRealField(node, "base_iso");
        } catch (const Exception& e) {
            CV_Error(Error::StsParseError, "noise model: " + e.err);
        }
        try {
            detail::checkBaseIso(m.baseIso, "field 'base_iso'", false);
        } catch (const Exception& e) {
            CV_Error(Error::StsParseError, "noise model: " + e.err);
        }
    }
    if (node["row_sigma_d2"].empty() != node["row_sigma_r2"].empty())
        CV_Error(Error::StsParseError, "noise model: row_sigma_d2 and row_sigma_r2 come together");
    if (!node["row_sigma_d2"].empty()) {
        m.rowSigmaD2 = readNonNegative(node, "row_sigma_d2");
        m.rowSigmaR2 = readNonNegative(node, "row_sigma_r2");
    }
    if (!node["tukey_lambda"].empty()) {
        try {
            m.tukeyLambda = detail::readRealField(node, "tukey_lambda");
        } catch (const Exception& e) {
            CV_Error(Error::StsParseError, "noise model: " + e.err);
        }
        m.tukeyRead = true;
        if (!(m.tukeyLambda >= detail::kTukeyLambdaMin && m.tukeyLambda <= 1))
            CV_Error(Error::StsParseError,
                     format("noise model: field 'tukey_lambda' must lie in [%g, 1] (got %g)",
                            detail::kTukeyLambdaMin, m.tukeyLambda));
    }
    const FileNode failed = node["failed_calibration"];
    if (!failed.empty()) {
        if (!failed.isString() || failed.string().empty())
            CV_Error(
                Error::StsParseError,
                "noise model: field 'failed_calibration' must be a non-empty string (the failed checks)");
        m.failedCalibration = failed.string();
    }
    if (!node["measured_lines"].empty())
        m.measuredLines = detail::readMeasuredLines(node["measured_lines"]);
    const FileNode shading = node["dark_shading"];
    if (!shading.empty()) {
        if (!shading.isMap())
            CV_Error(Error::StsParseError, "noise model: dark_shading must be a map");
        try {
            rejectUnknownKeys(shading, {"width", "height", kShadingKeys[0], kShadingKeys[1]});
        } catch (const Exception& e) {
            CV_Error(e.code, "noise model: dark_shading: " + e.err);
        }
        const int width = detail::readOptionalIntField(shading, "width", 0),
                  height = detail::readOptionalIntField(shading, "height", 0);
        if (width <= 0 || height <= 0)
            CV_Error(Error::StsParseError, "noise model: dark_shading.width and .height must be > 0");
        m.darkShadingPerGain = readShadingImage(shading, kShadingKeys[0], folder, Size(width, height));
        m.darkShadingOffset = readShadingImage(shading, kShadingKeys[1], folder, Size(width, height));
    }
    try {
        m.validate();
        detail::checkDarkShadingFinite(m);
    } catch (const Exception& e) {
        CV_Error(Error::StsParseError, "noise model: " + e.err);
    }
    return m;
}

namespace {

// `<model file name>.dark_shading_<key>.<checksum>.tiff` (detail::mapImageName()).
String shadingTag(int key)
{
    return String("dark_shading_") + kShadingKeys[key];
}

} // namespace

void NoiseModel::save(const String& path) const
{
    // Everything that can refuse the model runs before the first byte is written; the path first, as the
    // maps' names in the text are made of it.
    checkPathHasNoNul(path);
    validate();
    detail::checkDarkShadingFinite(*this);
    std::vector<String> images;
    std::vector<const Mat*> maps;
    if (hasDarkShading()) {
        maps = {&darkShadingPerGain, &darkShadingOffset};
        for (int i = 0; i < 2; ++i)
            images.push_back(detail::mapImageName(path, shadingTag(i), *maps[static_cast<size_t>(i)]));
    }
    const std::string text =
        fileStorageText(path, [&](FileStorage& fs) { write(fs, kTopLevelName, images); });
    const std::vector<String> tags = {shadingTag(0), shadingTag(1)};
    detail::saveWithMapImages(
        path, text, maps, images, [&](const String& name) { return detail::isMapImageOf(path, name, tags); },
        "NoiseModel::save");
}

double NoiseModel::readExcessKurtosis() const
{
    return tukeyRead ? detail::tukeyLambdaExcessKurtosis(tukeyLambda) : 0.0;
}

NoiseModel NoiseModel::load(const String& path, bool acceptFailedCalibration)
{
    NoiseModel m = detail::loadFileStorage(path, kTopLevelName, "noise model file", [&](const FileNode& n) {
        return read(n, detail::folderOf(path));
    });
    if (!m.failedCalibration.empty() && !acceptFailedCalibration)
        CV_Error(
            Error::StsBadArg,
            format("noise model file '%s' comes from a calibration whose verdict was FAIL (%s): see that "
                   "calibration's report.md and calibrate again; to use it anyway, accept it "
                   "explicitly (NoiseModel::load(path, true), acceptFailedCalibration=True in Python, "
                   "--accept_failed_calibration in the apps)",
                   path.c_str(), m.failedCalibration.c_str()));
    return m;
}

namespace detail {

namespace {

// log B(a, b) for a, b > 0.
double logBeta(double a, double b)
{
    return std::lgamma(a) + std::lgamma(b) - std::lgamma(a + b);
}

// Below this |lambda| the Beta-function moments lose digits to cancellation (E[X^4] is 1/lambda^4 times a
// difference of order lambda^4: 6e-10 relative at 0.02); there the moments are integrated instead.
constexpr double kClosedFormLambda = 0.02;

// E[X^2] and E[X^4] of the unit-scale Tukey-lambda variable.
void tukeyMoments(double l, double& m2, double& m4)
{
    if (std::abs(l) >= kClosedFormLambda) {
        m2 = (2 / (2 * l + 1) - 2 * std::exp(logBeta(l + 1, l + 1))) / (l * l);
        m4 = (2 / (4 * l + 1) - 8 * std::exp(logBeta(3 * l + 1, l + 1)) +
              6 * std::exp(logBeta(2 * l + 1, 2 * l + 1))) /
             (l * l * l * l);
        return;
    }
    // u = 1 / (1 + e^s) over the real line: du = u (1 - u) ds, the integrand is analytic and decays at
    // least as e^{-0.92 |s|}, so the trapezoid rule converges geometrically (step 0.05 over |s| <= 60:
    // below 1e-13 relative, checked against the closed form at |lambda| = 0.02).
    const double h = 0.05;
    m2 = m4 = 0;
    for (int i = -1200; i <= 1200; ++i) {
        const double sv = i * h;
        const double logU = -(sv > 0 ? sv + std::log1p(std::exp(-sv)) : std::log1p(std::exp(sv)));
        const double log1mU = logU + sv; // log(1 - u) = log(u) + s
        const double q = l == 0 ? logU - log1mU : (std::expm1(l * logU) - std::expm1(l * log1mU)) / l;
        const double w = std::exp(logU + log1mU);
        m2 += q * q * w;
        m4 += q * q * q * q * w;
    }
    m2 *= h;
    m4 *= h;
}

} // namespace

double tukeyLambdaVariance(double lambda)
{
    CV_Assert(lambda > -0.5);
    double m2, m4;
    tukeyMoments(lambda, m2, m4);
    return m2;
}

double tukeyLambdaExcessKurtosis(double lambda)
{
    CV_Assert(lambda > -0.25);
    double m2, m4;
    tukeyMoments(lambda, m2, m4);
    return m4 / (m2 * m2) - 3;
}

double tukeyLambdaOfExcessKurtosis(double kurtosis)
{
    double lo = kTukeyLambdaMin, hi = 1; // kurtosis(lo) > kurtosis(hi)
    if (!(kurtosis < tukeyLambdaExcessKurtosis(lo)))
        return lo;
    if (!(kurtosis > tukeyLambdaExcessKurtosis(hi)))
        return hi;
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (tukeyLambdaExcessKurtosis(mid) > kurtosis ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

double tukeyLambdaQuantile(double u, double lambda)
{
    const double a = std::log(u), b = std::log1p(-u);
    if (lambda == 0)
        return a - b;
    return (std::expm1(lambda * a) - std::expm1(lambda * b)) / lambda;
}

double addedReadLambda(double lambda, double targetRead, double priorFourthMoment, double added)
{
    if (!(added > 0))
        return lambda;
    const double kappa = tukeyLambdaExcessKurtosis(lambda);
    return tukeyLambdaOfExcessKurtosis(kappa * (targetRead * targetRead - priorFourthMoment) /
                                       (added * added));
}

} // namespace detail

} // namespace rawgment
} // namespace cv
