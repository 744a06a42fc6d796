// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "opencv2/rawgment/augment.hpp"
#include "precomp.hpp"
#include "random.hpp"

#include <opencv2/imgproc.hpp>

#include <atomic>

namespace cv {
namespace rawgment {

namespace {

// Each step draws from its own family of streams: (step seed, row) with the step's seed derived from
// the user's seed, so that jitter and blur of one call never reuse random numbers.
uint64_t stepSeed(uint64 seed, uint64_t step)
{
    // SplitMix64 finaliser: distinct, well-mixed keys for nearby (seed, step).
    uint64_t z = seed + 0x9E3779B97F4A7C15ull * (step + 1);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

void checkMosaicInput(const Mat& src, const char* who)
{
    if (src.empty())
        CV_Error(Error::StsBadArg, format("%s: src is empty", who));
    if (src.type() != CV_16UC1 && src.type() != CV_32FC1)
        CV_Error(Error::StsBadArg, format("%s: src type %s is not supported; expected CV_16UC1 or CV_32FC1",
                                          who, typeToString(src.type()).c_str()));
    if (src.type() == CV_32FC1 && !checkRange(src, true))
        CV_Error(Error::StsBadArg, format("%s: src contains NaN or Inf", who));
}

void checkAlignment(NoiseAlignment a)
{
    if (a != NoiseAlignment::NONE && a != NoiseAlignment::IGNORE_PRIOR && a != NoiseAlignment::ACCOUNT_PRIOR)
        CV_Error(Error::StsBadArg, format("unknown NoiseAlignment %d", static_cast<int>(a)));
}

template <typename T> inline T storeValue(float v, float white);
template <> inline ushort storeValue<ushort>(float v, float white)
{
    return static_cast<ushort>(cvRound(std::min(std::max(v, 0.f), white)));
}
template <> inline float storeValue<float>(float v, float white)
{
    return std::min(std::max(v, 0.f), white);
}

struct JitterConstants
{
    float pc[4], black[4];
    float pb, pg, white;
    float shot, read, post; // g alpha, g^2 sigma_d^2, sigma_r^2 at the input gain
    NoiseAlignment alignment;
};

template <typename T>
void jitterRows(const Mat& src, Mat& dst, Mat* mask, const JitterConstants& k, uint64_t seed,
                const Range& rows, std::atomic<int64>& brightening, std::atomic<int64>& saturated)
{
    const int cols = src.cols;
    std::vector<float> z(cols);
    int64 localBright = 0, localSat = 0;
    const float pg2 = k.pg * k.pg;
    for (int r = rows.start; r < rows.end; ++r) {
        if (k.alignment != NoiseAlignment::NONE)
            detail::fillGaussian(seed, static_cast<uint64_t>(r), z.data(), cols);
        const T* s = src.ptr<T>(r);
        T* d = dst.ptr<T>(r);
        uchar* m = mask ? mask->ptr<uchar>(r) : nullptr;
        const int site0 = 2 * (r & 1);
        for (int c = 0; c < cols; ++c) {
            const int site = site0 + (c & 1);
            const float raw = static_cast<float>(s[c]);
            const float x = raw - k.black[site];
            const bool sat = raw >= k.white;
            localSat += sat ? 1 : 0;
            if (m)
                m[c] = sat ? 255 : 0;
            const float mean = k.pc[site] * x + k.pb;
            float v = 0;
            if (k.alignment == NoiseAlignment::ACCOUNT_PRIOR) {
                const float xf = std::max(x, 1.0f);
                const float pu = std::max((k.pc[site] * xf + k.pb) / (xf * k.pg), 0.0f);
                const float mu = std::max(x, 0.0f);
                v = pu * (1 - pu) * pg2 * k.shot * mu + (1 - pu * pu) * pg2 * k.read +
                    (1 - pu * pu * pg2) * k.post;
            } else if (k.alignment == NoiseAlignment::IGNORE_PRIOR) {
                v = k.pg * k.shot * std::max(mean, 0.0f) + pg2 * k.read + k.post;
            }
            localBright += v < 0 ? 1 : 0;
            v = std::max(v, 0.0f);
            const float out = mean + std::sqrt(v) * z[c] + k.black[site];
            d[c] = storeValue<T>(out, k.white);
        }
    }
    brightening += localBright;
    saturated += localSat;
}

} // namespace

ColorJitter ColorJitter::exposureChange(double photonRatio, double gainRatio)
{
    detail::checkFinitePositive(photonRatio, "exposureChange: photonRatio");
    detail::checkFinitePositive(gainRatio, "exposureChange: gainRatio");
    ColorJitter j;
    j.contrast = Vec4d::all(photonRatio * gainRatio);
    j.gainRatio = gainRatio;
    return j;
}

bool ColorJitter::isIdentity() const
{
    return contrast == Vec4d::all(1) && brightness == 0 && gainRatio == 1;
}

void colorJitter(InputArray _src, const RawFormat& format, const NoiseModel& model, const ColorJitter& jitter,
                 NoiseAlignment alignment, uint64 seed, OutputArray _dst, RawFormat& dstFormat,
                 AugmentReport* report, OutputArray saturatedMask)
{
    const Mat src = _src.getMat();
    checkMosaicInput(src, "colorJitter");
    format.validate();
    model.validate();
    checkAlignment(alignment);
    for (int s = 0; s < 4; ++s)
        detail::checkFinitePositive(jitter.contrast[s], "colorJitter: contrast");
    if (!std::isfinite(jitter.brightness))
        CV_Error(Error::StsBadArg, "colorJitter: brightness must be finite");
    detail::checkFinitePositive(jitter.gainRatio, "colorJitter: gainRatio");
    const double newGain = format.gain * jitter.gainRatio;
    detail::checkFinitePositive(newGain, "colorJitter: the new gain");

    if (jitter.isIdentity()) {
        // Skipped entirely: no copy, no random draw.
        _dst.assign(src);
        dstFormat = format;
        if (saturatedMask.needed())
            compare(src, format.whiteLevel, saturatedMask, CMP_GE);
        if (report)
            report->saturatedPixels += countNonZero(src >= format.whiteLevel);
        return;
    }
    const NoiseLine line = model.lineAtGain(format.gain);
    JitterConstants k;
    for (int s = 0; s < 4; ++s) {
        k.pc[s] = static_cast<float>(jitter.contrast[s]);
        k.black[s] = static_cast<float>(format.blackLevel[s]);
    }
    k.pb = static_cast<float>(jitter.brightness);
    k.pg = static_cast<float>(jitter.gainRatio);
    k.white = static_cast<float>(format.whiteLevel);
    k.shot = static_cast<float>(line.a);
    k.read = static_cast<float>(format.gain * format.gain * model.sigmaD2);
    k.post = static_cast<float>(model.sigmaR2);
    k.alignment = alignment;

    Mat dst(src.size(), src.type());
    Mat mask;
    if (saturatedMask.needed())
        mask.create(src.size(), CV_8UC1);
    std::atomic<int64> brightening{0}, saturated{0};
    const uint64_t key = stepSeed(seed, 1);
    parallel_for_(Range(0, src.rows), [&](const Range& rows) {
        if (src.depth() == CV_16U)
            jitterRows<ushort>(src, dst, mask.empty() ? nullptr : &mask, k, key, rows, brightening,
                               saturated);
        else
            jitterRows<float>(src, dst, mask.empty() ? nullptr : &mask, k, key, rows, brightening, saturated);
    });
    _dst.assign(dst);
    if (saturatedMask.needed())
        saturatedMask.assign(mask);
    dstFormat = format;
    dstFormat.gain = newGain;
    if (report) {
        report->brighteningPixels += brightening.load();
        report->saturatedPixels += saturated.load();
        report->steps.push_back("colorJitter");
    }
}

Mat linearMotionKernel(double length, double angleDegrees)
{
    if (!std::isfinite(length) || length < 0)
        CV_Error(Error::StsBadArg,
                 format("linearMotionKernel: length must be finite and >= 0 (got %g)", length));
    if (!std::isfinite(angleDegrees))
        CV_Error(Error::StsBadArg, "linearMotionKernel: angle must be finite");
    const double planeLength = length / 2; // the CFA planes have half the resolution
    if (planeLength <= 1)
        return Mat::ones(1, 1, CV_32FC1);
    const int radius = static_cast<int>(std::ceil(planeLength / 2));
    const int size = 2 * radius + 1;
    Mat k = Mat::zeros(size, size, CV_64FC1);
    const double a = angleDegrees * CV_PI / 180, ca = std::cos(a), sa = -std::sin(a); // image y points down
    // The segment, supersampled and splatted bilinearly.
    const int samples = std::max(64, static_cast<int>(16 * planeLength));
    for (int i = 0; i < samples; ++i) {
        const double t = ((i + 0.5) / samples - 0.5) * planeLength;
        const double x = radius + t * ca, y = radius + t * sa;
        const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
        const double fx = x - x0, fy = y - y0;
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) {
                const int yy = std::min(size - 1, std::max(0, y0 + dy)),
                          xx = std::min(size - 1, std::max(0, x0 + dx));
                k.at<double>(yy, xx) += (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy);
            }
    }
    k /= sum(k)[0];
    Mat out;
    k.convertTo(out, CV_32F);
    return out;
}

namespace {

Mat normalisedKernel(InputArray _kernel, const char* who)
{
    Mat kernel;
    _kernel.getMat().convertTo(kernel, CV_64F);
    if (kernel.empty() || !checkRange(kernel, true))
        CV_Error(Error::StsBadArg, format("%s: kernel must be non-empty and finite", who));
    double lo = 0;
    minMaxLoc(kernel, &lo);
    const double total = sum(kernel)[0];
    if (lo < 0 || !(total > 0))
        CV_Error(Error::StsBadArg, format("%s: kernel must be non-negative with a positive sum", who));
    return kernel / total;
}

bool isIdentityKernel(const Mat& kernel)
{
    return kernel.empty() || kernel.total() == 1;
}

} // namespace

void motionBlur(InputArray _src, const RawFormat& format, const NoiseModel& model, InputArray _kernel,
                NoiseAlignment alignment, uint64 seed, OutputArray _dst, AugmentReport* report)
{
    const Mat src = _src.getMat();
    checkMosaicInput(src, "motionBlur");
    format.validate();
    model.validate();
    checkAlignment(alignment);
    const Mat w = normalisedKernel(_kernel, "motionBlur");
    if (w.total() == 1) {
        _dst.assign(src);
        return;
    }
    Mat x;
    subtractBlackLevel(src, format, x);
    std::vector<Mat> planes;
    splitCfaPlanes(x, planes);
    const NoiseLine line = model.lineAtGain(format.gain);
    const double sumW2 = w.dot(w);
    Mat shotKernel = w.mul(1.0 - w); // w_k (1 - w_k): the exact per-pixel shot-noise sum of Eq. 15
    const float shot = static_cast<float>(line.a), readFloor = static_cast<float>((1 - sumW2) * line.b);
    const uint64_t key = stepSeed(seed, 2);
    std::vector<Mat> out(4);
    for (int p = 0; p < 4; ++p) {
        Mat mean, shotSum;
        filter2D(planes[p], mean, CV_32F, w, Point(-1, -1), 0, BORDER_REPLICATE);
        if (alignment == NoiseAlignment::ACCOUNT_PRIOR)
            filter2D(max(planes[p], 0.0), shotSum, CV_32F, shotKernel, Point(-1, -1), 0, BORDER_REPLICATE);
        if (alignment != NoiseAlignment::NONE) {
            parallel_for_(Range(0, mean.rows), [&](const Range& rows) {
                std::vector<float> z(mean.cols);
                for (int r = rows.start; r < rows.end; ++r) {
                    detail::fillGaussian(key, (static_cast<uint64_t>(p) << 32) | static_cast<uint64_t>(r),
                                         z.data(), mean.cols);
                    float* m = mean.ptr<float>(r);
                    const float* s = shotSum.empty() ? nullptr : shotSum.ptr<float>(r);
                    for (int c = 0; c < mean.cols; ++c) {
                        const float v = s ? shot * s[c] + readFloor
                                          : shot * std::max(m[c], 0.0f) + static_cast<float>(line.b);
                        m[c] += std::sqrt(std::max(v, 0.0f)) * z[c];
                    }
                }
            });
        }
        out[p] = mean;
    }
    Mat merged;
    mergeCfaPlanes(out, merged);
    Mat dst;
    addBlackLevel(merged, format, dst, src.depth());
    _dst.assign(dst);
    if (report)
        report->steps.push_back("motionBlur");
}

// ---------------------------------------------------------------------------------------------------
// Scenes

bool Scene::isIdentity() const
{
    return shift == Point(0, 0) && jitter.isIdentity() && isIdentityKernel(motionKernel);
}

void Scene::write(FileStorage& fs, const String& name) const
{
    fs << name << "{";
    fs << "shift" << shift;
    fs << "contrast"
       << "[" << jitter.contrast[0] << jitter.contrast[1] << jitter.contrast[2] << jitter.contrast[3] << "]";
    fs << "brightness" << jitter.brightness << "gain_ratio" << jitter.gainRatio;
    fs << "alignment" << static_cast<int>(alignment);
    fs << "motion_kernel" << (motionKernel.empty() ? Mat::ones(1, 1, CV_32F) : motionKernel);
    fs << "}";
}

Scene Scene::read(const FileNode& node)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError, "scene: expected a map");
    Scene s;
    node["shift"] >> s.shift;
    const FileNode c = node["contrast"];
    if (!c.isSeq() || c.size() != 4)
        CV_Error(Error::StsParseError, "scene: field 'contrast' must be a list of 4 numbers (one per site)");
    for (int i = 0; i < 4; ++i)
        s.jitter.contrast[i] = static_cast<double>(c[i]);
    s.jitter.brightness = detail::readRealField(node, "brightness");
    s.jitter.gainRatio = detail::readRealField(node, "gain_ratio");
    s.alignment = static_cast<NoiseAlignment>(static_cast<int>(detail::readRealField(node, "alignment")));
    checkAlignment(s.alignment);
    node["motion_kernel"] >> s.motionKernel;
    return s;
}

void applyScene(InputArray _src, const RawFormat& format, const NoiseModel& model, const Scene& scene,
                uint64 seed, OutputArray _dst, RawFormat& dstFormat, AugmentReport* report,
                std::vector<Rect>* boxes)
{
    Mat current = _src.getMat();
    checkMosaicInput(current, "applyScene");
    format.validate();
    model.validate();
    if (current.rows % 2 || current.cols % 2)
        CV_Error(Error::StsBadArg, "applyScene: the mosaic needs even sides");
    RawFormat fmt = format;
    const Point shift(2 * cvRound(scene.shift.x / 2.0), 2 * cvRound(scene.shift.y / 2.0));
    if (shift != Point(0, 0)) {
        // Shift each CFA plane by half the (even) offset: the phase of the mosaic is kept.
        std::vector<Mat> planes;
        splitCfaPlanes(current, planes);
        const Matx23d m(1, 0, shift.x / 2, 0, 1, shift.y / 2);
        for (Mat& p : planes) {
            Mat moved;
            warpAffine(p, moved, m, p.size(), INTER_NEAREST, BORDER_REPLICATE);
            p = moved;
        }
        // Into a new Mat: `current` still shares the caller's data, which must never be written.
        Mat shifted;
        mergeCfaPlanes(planes, shifted);
        current = shifted;
        if (boxes)
            for (Rect& b : *boxes)
                b = (b + shift) & Rect(0, 0, current.cols, current.rows);
        if (report)
            report->steps.push_back("shift");
    }
    colorJitter(current, fmt, model, scene.jitter, scene.alignment, seed, current, fmt, report);
    if (!isIdentityKernel(scene.motionKernel))
        motionBlur(current, fmt, model, scene.motionKernel, scene.alignment, seed, current, report);
    _dst.assign(current);
    dstFormat = fmt;
}

// ---------------------------------------------------------------------------------------------------
// Random policy

void RandomScenePolicy::validate() const
{
    const auto range = [](double lo, double hi, const char* what) {
        if (!std::isfinite(lo) || !std::isfinite(hi) || lo > hi)
            CV_Error(Error::StsBadArg,
                     format("RandomScenePolicy: %s range [%g, %g] is not a finite interval", what, lo, hi));
    };
    const auto probability = [](double p, const char* what) {
        if (!(p >= 0 && p <= 1))
            CV_Error(Error::StsBadArg, format("RandomScenePolicy: %s must lie in [0, 1] (got %g)", what, p));
    };
    range(contrastMin, contrastMax, "contrast");
    if (!(contrastMin > 0))
        CV_Error(Error::StsBadArg, "RandomScenePolicy: contrastMin must be > 0");
    range(brightnessMin, brightnessMax, "brightness");
    range(hueMin, hueMax, "hue");
    if (!(hueMin > 0))
        CV_Error(Error::StsBadArg, "RandomScenePolicy: hueMin must be > 0");
    range(gainDbMin, gainDbMax, "gain (dB)");
    range(0, blurLengthMax, "blur length");
    range(0, maxShift, "shift");
    probability(hueProbability, "hueProbability");
    probability(blurProbability, "blurProbability");
    probability(shiftProbability, "shiftProbability");
    checkAlignment(alignment);
}

Scene RandomScenePolicy::draw(InputArray _src, const RawFormat& format, uint64 seed) const
{
    validate();
    const Mat src = _src.getMat();
    checkMosaicInput(src, "RandomScenePolicy::draw");
    Mat x;
    subtractBlackLevel(src, format, x);
    double minX = 0;
    minMaxLoc(x, &minX);
    detail::CounterRng rng(stepSeed(seed, 3), 0);
    const auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * rng.uniform(); };
    Scene s;
    s.alignment = alignment;
    if (rng.uniform() < shiftProbability)
        s.shift = Point(cvRound(uniform(-maxShift, maxShift) * src.cols),
                        cvRound(uniform(-maxShift, maxShift) * src.rows));
    const double contrast = std::exp(uniform(std::log(contrastMin), std::log(contrastMax)));
    s.jitter.contrast = Vec4d::all(contrast);
    if (rng.uniform() < hueProbability)
        for (int i = 0; i < 4; ++i)
            s.jitter.contrast[i] *= uniform(hueMin, hueMax);
    s.jitter.brightness = uniform(brightnessMin, brightnessMax) * minX;
    s.jitter.gainRatio = dbToLinearGain(uniform(gainDbMin, gainDbMax));
    if (rng.uniform() < blurProbability)
        s.motionKernel = linearMotionKernel(uniform(0, blurLengthMax), uniform(0, 180));
    return s;
}

void RandomScenePolicy::write(FileStorage& fs, const String& name) const
{
    fs << name << "{";
    fs << "contrast_min" << contrastMin << "contrast_max" << contrastMax;
    fs << "brightness_min" << brightnessMin << "brightness_max" << brightnessMax;
    fs << "hue_probability" << hueProbability << "hue_min" << hueMin << "hue_max" << hueMax;
    fs << "gain_db_min" << gainDbMin << "gain_db_max" << gainDbMax;
    fs << "blur_probability" << blurProbability << "blur_length_max" << blurLengthMax;
    fs << "shift_probability" << shiftProbability << "max_shift" << maxShift;
    fs << "alignment" << static_cast<int>(alignment);
    fs << "}";
}

RandomScenePolicy RandomScenePolicy::read(const FileNode& node)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError, "random scene policy: expected a map");
    RandomScenePolicy p;
    const auto field = [&](const char* name, double& value) {
        const FileNode f = node[name];
        if (f.empty() || f.isNone())
            return;
        if (!f.isReal() && !f.isInt())
            CV_Error(Error::StsParseError, format("random scene policy: field '%s' is not a number", name));
        value = static_cast<double>(f);
    };
    field("contrast_min", p.contrastMin);
    field("contrast_max", p.contrastMax);
    field("brightness_min", p.brightnessMin);
    field("brightness_max", p.brightnessMax);
    field("hue_probability", p.hueProbability);
    field("hue_min", p.hueMin);
    field("hue_max", p.hueMax);
    field("gain_db_min", p.gainDbMin);
    field("gain_db_max", p.gainDbMax);
    field("blur_probability", p.blurProbability);
    field("blur_length_max", p.blurLengthMax);
    field("shift_probability", p.shiftProbability);
    field("max_shift", p.maxShift);
    double alignmentValue = static_cast<double>(p.alignment);
    field("alignment", alignmentValue);
    p.alignment = static_cast<NoiseAlignment>(static_cast<int>(alignmentValue));
    p.validate();
    return p;
}

void RandomScenePolicy::save(const String& path) const
{
    validate();
    detail::writeFileStorageAtomically(path, [&](FileStorage& fs) { write(fs, "random_scene_policy"); });
}

RandomScenePolicy RandomScenePolicy::load(const String& path)
{
    return detail::loadFileStorage(path, "random_scene_policy", "random scene policy",
                                   [](const FileNode& n) { return read(n); });
}

} // namespace rawgment
} // namespace cv
