// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "opencv2/rawgment/simulate.hpp"
#include "noise_terms.hpp"
#include "precomp.hpp"
#include "random.hpp"

#include <opencv2/imgproc.hpp>

namespace cv {
namespace rawgment {

namespace {

enum DefectCode : uchar
{
    DEFECT_NONE = 0,
    DEFECT_HOT = 1,
    DEFECT_DEAD = 2,
    DEFECT_NOISY = 3
};

void checkFraction(double v, const char* what)
{
    if (!(v >= 0 && v <= 1))
        CV_Error(Error::StsBadArg, format("SensorParams.%s must lie in [0, 1] (got %g)", what, v));
}

double srgbToLinear(double v8)
{
    const double v = v8 / 255.0;
    return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

} // namespace

void SensorParams::validate() const
{
    noise.validate();
    if (pattern < CFA_RGGB || pattern > CFA_MONO)
        CV_Error(Error::StsBadArg,
                 format("SensorParams.pattern %d is not a CFA pattern", static_cast<int>(pattern)));
    if (pattern == CFA_MONO && blackLevel != Vec4d::all(blackLevel[0]))
        CV_Error(Error::StsBadArg,
                 "SensorParams.blackLevel must be one value on all four sites for CFA_MONO");
    if (bitDepth < 1 || bitDepth > 16)
        CV_Error(Error::StsBadArg, format("SensorParams.bitDepth must lie in [1, 16] (got %d)", bitDepth));
    const double white = std::ldexp(1.0, bitDepth) - 1;
    for (int s = 0; s < 4; ++s)
        if (!(blackLevel[s] >= 0 && blackLevel[s] < white))
            CV_Error(Error::StsBadArg, format("SensorParams.blackLevel[%d] must lie in [0, %g) (got %g)", s,
                                              white, blackLevel[s]));
    detail::checkFiniteNonNegative(prnu, "SensorParams.prnu");
    detail::checkFiniteNonNegative(dsnu, "SensorParams.dsnu");
    checkFraction(hotPixelFraction, "hotPixelFraction");
    checkFraction(deadPixelFraction, "deadPixelFraction");
    checkFraction(noisyPixelFraction, "noisyPixelFraction");
    checkFraction(hotPixelFraction + deadPixelFraction + noisyPixelFraction,
                  "hotPixelFraction + deadPixelFraction + noisyPixelFraction");
    detail::checkFiniteNonNegative(noisyPixelVariance, "SensorParams.noisyPixelVariance");
    detail::checkFiniteNonNegative(columnNoiseVariance, "SensorParams.columnNoiseVariance");
}

SensorSimulator::SensorSimulator(const SensorParams& params, Size size) : params_(params), size_(size)
{
    params_.validate();
    detail::checkDarkShadingFinite(params_.noise);
    if (size.width <= 0 || size.height <= 0 || size.width % 2 || size.height % 2)
        CV_Error(Error::StsBadArg,
                 format("SensorSimulator: size %dx%d must be positive and even", size.width, size.height));
    prnu_.create(size, CV_32FC1);
    dsnu_.create(size, CV_32FC1);
    defects_.create(size, CV_8UC1);
    const double hot = params_.hotPixelFraction, dead = hot + params_.deadPixelFraction;
    const double noisy = dead + params_.noisyPixelFraction;
    parallel_for_(Range(0, size.height), [&](const Range& rows) {
        for (int r = rows.start; r < rows.end; ++r) {
            detail::CounterRng rng(params_.fixedPatternSeed, detail::fixedPatternStream(r));
            float* g = prnu_.ptr<float>(r);
            float* o = dsnu_.ptr<float>(r);
            uchar* d = defects_.ptr<uchar>(r);
            for (int c = 0; c < size.width; ++c) {
                g[c] = static_cast<float>(std::max(0.0, 1.0 + params_.prnu * rng.gaussian()));
                o[c] = static_cast<float>(params_.dsnu * rng.gaussian());
                const double u = rng.uniform();
                d[c] = u < hot ? DEFECT_HOT : u < dead ? DEFECT_DEAD : u < noisy ? DEFECT_NOISY : DEFECT_NONE;
            }
        }
    });
}

RawFormat SensorSimulator::rawFormat(double gain) const
{
    RawFormat f;
    f.pattern = params_.pattern;
    f.blackLevel = params_.blackLevel;
    f.whiteLevel = std::ldexp(1.0, params_.bitDepth) - 1;
    f.gain = gain;
    f.validate();
    return f;
}

NoiseModel SensorSimulator::effectiveModel() const
{
    NoiseModel m = params_.noise;
    if (params_.quantize) {
        m.sigmaR2 += 1.0 / 12.0;
        for (MeasuredNoiseLine& l : m.measuredLines)
            l.line.b += 1.0 / 12.0;
    }
    return m;
}

namespace {

void checkCaptureArguments(const Mat& mean, Size size, double gain, double exposure, int frameIndex)
{
    if (mean.type() != CV_32FC1 || mean.size() != size)
        CV_Error(Error::StsBadArg,
                 format("SensorSimulator::capture: meanAtUnitGain must be CV_32FC1 of %dx%d "
                        "(got %s, %dx%d)",
                        size.width, size.height, typeToString(mean.type()).c_str(), mean.cols, mean.rows));
    double lo = 0;
    minMaxLoc(mean, &lo);
    if (!checkRange(mean, true) || lo < 0)
        CV_Error(Error::StsBadArg, "SensorSimulator::capture: meanAtUnitGain must be finite and >= 0");
    detail::checkFinitePositive(gain, "SensorSimulator::capture: gain");
    detail::checkFinitePositive(exposure, "SensorSimulator::capture: exposure");
    if (frameIndex < 0)
        CV_Error(Error::StsBadArg,
                 format("SensorSimulator::capture: frameIndex must be >= 0 (got %d)", frameIndex));
}

// Column offsets of one frame, from a stream of their own beside the rows' (drawn only when asked, so frames
// without them keep their bits).
std::vector<double> columnOffsetsOf(double variance, int columns, uint64 seed, int frameIndex)
{
    std::vector<double> offsets;
    if (!(variance > 0))
        return offsets;
    detail::CounterRng rng(
        detail::stepKey(seed, static_cast<uint64_t>(detail::RandomStream::SIMULATOR_COLUMNS)),
        static_cast<uint64_t>(frameIndex));
    const double sigma = std::sqrt(variance);
    for (int c = 0; c < columns; ++c)
        offsets.push_back(sigma * rng.gaussian());
    return offsets;
}

} // namespace

void SensorSimulator::capture(InputArray _mean, double gain, double exposure, uint64 seed, int frameIndex,
                              OutputArray _raw) const
{
    const Mat mean = detail::twoDimensional(_mean, "SensorSimulator::capture: meanAtUnitGain");
    checkCaptureArguments(mean, size_, gain, exposure, frameIndex);

    const SensorParams& p = params_;
    double prnuMax = 0, meanMax = 0;
    minMaxLoc(prnu_, nullptr, &prnuMax);
    minMaxLoc(mean, nullptr, &meanMax);
    // With measured lines the terms at this gain are the lines' (NoiseModel::measuredLines): the shot
    // slope is the DN per electron at the gain, and the signal is counted in those electrons.
    const bool measured = p.noise.hasMeasuredLines();
    const detail::NoiseTerms<double> atGain =
        measured ? detail::checkedNoiseTerms(p.noise, gain) : detail::NoiseTerms<double>{0, 0, 0};
    const double electronDn = measured ? atGain.shot / gain : p.noise.alpha; // DN at gain 1 per electron
    if (electronDn > 0 && !(meanMax * exposure * prnuMax / electronDn <= detail::kMaxPoissonMean))
        CV_Error(
            Error::StsBadArg,
            format("SensorSimulator::capture: %g electrons per pixel (signal %g DN x exposure %g / alpha %g) "
                   "exceed the simulator's %g: alpha is too small for this signal",
                   meanMax * exposure * prnuMax / electronDn, meanMax, exposure, electronDn,
                   detail::kMaxPoissonMean));
    const double white = std::ldexp(1.0, p.bitDepth) - 1;
    // Each term of the model drawn where it arises: photons (shot), read noise before the gain, noise
    // after it; the terms at gain 1 are the model's parameters, the gain is applied in the loop below.
    const detail::NoiseTerms<double> unit =
        detail::noiseTermsAt(1.0, p.noise.alpha, p.noise.sigmaD2, p.noise.sigmaR2);
    const double alpha = unit.shot, sigmaD = std::sqrt(unit.readBeforeGain),
                 sigmaR = std::sqrt(unit.readAfterGain);
    const double noisySigma = std::sqrt(p.noisyPixelVariance);
    // The dark-frame components (NoiseModel), each drawn only when the model has it: one row offset per
    // (frame, row), the read noise as one Tukey-lambda draw of the same variance, the dark shading.
    const double rowSigma = std::sqrt(p.noise.rowVariance(gain));
    const bool tukey = p.noise.tukeyRead;
    const detail::TukeyUnitSampler tukeyDraw =
        tukey ? detail::TukeyUnitSampler(p.noise.tukeyLambda) : detail::TukeyUnitSampler();
    const double readSigma = std::sqrt(gain * gain * unit.readBeforeGain + unit.readAfterGain);
    const double measuredReadSigma = std::sqrt(atGain.read()),
                 measuredSigmaD = std::sqrt(atGain.readBeforeGain),
                 measuredSigmaR = std::sqrt(atGain.readAfterGain);
    const Mat shading = p.noise.darkShadingAt(gain);
    if (!shading.empty() && shading.size() != size_)
        CV_Error(Error::StsBadArg,
                 format("SensorSimulator::capture: the model's dark shading is %dx%d, the sensor %dx%d",
                        shading.cols, shading.rows, size_.width, size_.height));
    const double hotLevel = std::round(0.9 * white);
    const std::vector<double> columnOffset =
        columnOffsetsOf(p.columnNoiseVariance, size_.width, seed, frameIndex);
    Mat raw(size_, p.quantize ? CV_16UC1 : CV_32FC1);
    parallel_for_(Range(0, size_.height), [&](const Range& rows) {
        for (int r = rows.start; r < rows.end; ++r) {
            detail::CounterRng rng(seed, detail::captureStream(frameIndex, r));
            const float* m = mean.ptr<float>(r);
            const float* prnu = prnu_.ptr<float>(r);
            const float* dsnu = dsnu_.ptr<float>(r);
            const uchar* defect = defects_.ptr<uchar>(r);
            const double rowOffset = p.noise.hasRowNoise() ? rowSigma * rng.gaussian() : 0.0;
            const float* shade = shading.empty() ? nullptr : shading.ptr<float>(r);
            for (int c = 0; c < size_.width; ++c) {
                const double black = p.blackLevel[cfaSite(r, c)];
                double x;
                if (defect[c] == DEFECT_HOT) {
                    x = hotLevel;
                } else if (defect[c] == DEFECT_DEAD) {
                    x = black;
                } else {
                    const double signal = m[c] * exposure * prnu[c];
                    if (measured) {
                        // The electrons at this gain's own DN per electron, then its read noise.
                        const double photoSignal =
                            electronDn > 0
                                ? electronDn * static_cast<double>(rng.poisson(signal / electronDn))
                                : signal;
                        x = tukey ? gain * photoSignal + measuredReadSigma * tukeyDraw(rng.uniform())
                                  : gain * photoSignal + measuredSigmaD * rng.gaussian() +
                                        measuredSigmaR * rng.gaussian();
                    } else {
                        // alpha = 0 is a sensor without shot noise: the signal is then deterministic.
                        const double photoSignal =
                            alpha > 0 ? alpha * static_cast<double>(rng.poisson(signal / alpha)) : signal;
                        x = tukey ? gain * photoSignal + readSigma * tukeyDraw(rng.uniform())
                                  : gain * (photoSignal + sigmaD * rng.gaussian()) + sigmaR * rng.gaussian();
                    }
                    x = x + dsnu[c] + black;
                    if (p.noise.hasRowNoise())
                        x += rowOffset;
                    if (shade)
                        x += shade[c];
                    if (!columnOffset.empty())
                        x += columnOffset[static_cast<size_t>(c)];
                    if (defect[c] == DEFECT_NOISY)
                        x += noisySigma * rng.gaussian();
                }
                x = std::min(white, std::max(0.0, p.quantize ? std::round(x) : x));
                if (p.quantize)
                    raw.at<ushort>(r, c) = static_cast<ushort>(x);
                else
                    raw.at<float>(r, c) = static_cast<float>(x);
            }
        }
    });
    _raw.assign(raw);
}

void SensorSimulator::captureBurst(InputArray mean, double gain, double exposure, int frames, uint64 seed,
                                   std::vector<Mat>& raws) const
{
    if (frames < 1)
        CV_Error(Error::StsBadArg,
                 format("SensorSimulator::captureBurst: frames must be >= 1 (got %d)", frames));
    std::vector<Mat> out(frames);
    for (int t = 0; t < frames; ++t)
        capture(mean, gain, exposure, seed, t, out[t]);
    raws.swap(out);
}

void SensorSimulator::captureBlurred(InputArray _mean, InputArray _kernel, double gain, double exposure,
                                     uint64 seed, int frameIndex, OutputArray raw) const
{
    const bool mono = params_.pattern == CFA_MONO;
    const Mat kernel = detail::normalisedKernel(_kernel, "SensorSimulator::captureBlurred", params_.pattern);
    Mat blurred;
    // The kernel lies on the grid motionBlur() uses: the CFA planes, or a monochrome frame's own pixels.
    if (mono) {
        filter2D(_mean, blurred, CV_32F, kernel, Point(-1, -1), 0, detail::kBlurBorder);
    } else {
        std::vector<Mat> planes;
        splitCfaPlanes(_mean, planes);
        for (Mat& plane : planes)
            filter2D(plane, plane, CV_32F, kernel, Point(-1, -1), 0, detail::kBlurBorder);
        mergeCfaPlanes(planes, blurred);
    }
    capture(blurred, gain, exposure, seed, frameIndex, raw);
}

void SensorSimulator::fixedPattern(OutputArray gainFactor, OutputArray offset, OutputArray defects) const
{
    gainFactor.assign(prnu_);
    offset.assign(dsnu_);
    defects.assign(defects_);
}

static_assert(SEED_SIMULATED_BURST > static_cast<int>(detail::RandomStream::SCALE_POISSON),
              "the apps' seed purposes and the library's streams are one registry: their ids never meet");

void fillStandardNormal(InputOutputArray _dst, Size size, uint64 seed)
{
    if (_dst.empty()) {
        if (size.width <= 0 || size.height <= 0)
            CV_Error(Error::StsBadArg,
                     format("fillStandardNormal: size %dx%d is empty", size.width, size.height));
        _dst.create(size, CV_32FC1);
    }
    if (_dst.type() != CV_32FC1)
        CV_Error(Error::StsBadArg, "fillStandardNormal: dst type " + typeToString(_dst.type()) +
                                       " is not supported; expected CV_32FC1");
    Mat dst = _dst.getMat();
    parallel_for_(Range(0, dst.rows), [&](const Range& rows) {
        for (int r = rows.start; r < rows.end; ++r)
            detail::fillGaussian(seed, static_cast<uint64_t>(r), dst.ptr<float>(r), dst.cols);
    });
}

std::vector<Vec3d> colorCheckerReflectances()
{
    // Published sRGB (8-bit) values of the classic chart, row by row.
    static const int srgb[24][3] = {
        {115, 82, 68},   {194, 150, 130}, {98, 122, 157},  {87, 108, 67},   {133, 128, 177}, {103, 189, 170},
        {214, 126, 44},  {80, 91, 166},   {193, 90, 99},   {94, 60, 108},   {157, 188, 64},  {224, 163, 46},
        {56, 61, 150},   {70, 148, 73},   {175, 54, 60},   {231, 199, 31},  {187, 86, 149},  {8, 133, 161},
        {243, 243, 242}, {200, 200, 200}, {160, 160, 160}, {122, 122, 121}, {85, 85, 85},    {52, 52, 52}};
    std::vector<Vec3d> out(24);
    for (int i = 0; i < 24; ++i)
        out[i] = Vec3d(srgbToLinear(srgb[i][0]), srgbToLinear(srgb[i][1]), srgbToLinear(srgb[i][2]));
    return out;
}

ColorCheckerScene makeColorCheckerScene(const ColorCheckerOptions& o)
{
    if (o.patchSize < 2 || o.patchSize % 2)
        CV_Error(Error::StsBadArg,
                 format("ColorCheckerOptions.patchSize must be even and >= 2 (got %d)", o.patchSize));
    if (o.border < 0 || o.border % 2)
        CV_Error(Error::StsBadArg,
                 format("ColorCheckerOptions.border must be even and >= 0 (got %d)", o.border));
    detail::checkFiniteNonNegative(o.illumination, "ColorCheckerOptions.illumination");
    if (!(o.vignetting >= 0 && o.vignetting < 1))
        CV_Error(Error::StsBadArg,
                 format("ColorCheckerOptions.vignetting must lie in [0, 1) (got %g)", o.vignetting));
    if (!(o.frameReflectance >= 0 && o.frameReflectance <= 1))
        CV_Error(Error::StsBadArg, format("ColorCheckerOptions.frameReflectance must lie in [0, 1] (got %g)",
                                          o.frameReflectance));
    ColorCheckerScene scene;
    scene.reflectance = colorCheckerReflectances();
    const int step = o.patchSize + o.border;
    const Size size(6 * step + o.border, 4 * step + o.border);
    Mat rgb(size, CV_64FC3, Scalar::all(o.frameReflectance));
    for (int i = 0; i < 24; ++i) {
        const Rect patch(o.border + (i % 6) * step, o.border + (i / 6) * step, o.patchSize, o.patchSize);
        scene.patches.push_back(patch);
        rgb(patch).setTo(Scalar(scene.reflectance[i][0], scene.reflectance[i][1], scene.reflectance[i][2]));
    }
    scene.meanAtUnitGain.create(size, CV_32FC1);
    const double cx = 0.5 * (size.width - 1), cy = 0.5 * (size.height - 1);
    for (int r = 0; r < size.height; ++r)
        for (int c = 0; c < size.width; ++c) {
            const CfaChannel ch = cfaChannelAt(o.pattern, r, c);
            const Vec3d& reflectance = rgb.at<Vec3d>(r, c);
            // A sensor without a filter sees all three bands; their Rec. 709 luminance weights stand in
            // for its spectral response.
            const double response =
                ch == CFA_W ? 0.2126 * reflectance[0] + 0.7152 * reflectance[1] + 0.0722 * reflectance[2]
                            : reflectance[ch == CFA_R   ? 0
                                          : ch == CFA_B ? 2
                                                        : 1];
            const double dx = (c - cx) / cx, dy = (r - cy) / cy;
            const double shading = 1.0 - o.vignetting * 0.5 * (dx * dx + dy * dy);
            scene.meanAtUnitGain.at<float>(r, c) = static_cast<float>(o.illumination * shading * response);
        }
    return scene;
}

} // namespace rawgment
} // namespace cv
