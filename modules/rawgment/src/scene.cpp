// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Scenes (what one augmentation simulates, applied step by step) and the random scene policy.
#include "augment_steps.hpp"
#include "noise_step.hpp"

#include <opencv2/rawgment/seeds.hpp>

#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>

namespace cv {
namespace rawgment {

using detail::isIdentityKernel;

namespace {

/* A kernel from a file, checked before OpenCV allocates it: a hostile `cols: ~` or `rows: 1e9` would
 * otherwise ask for gigabytes. A motion kernel is at most MAX_MOTION_KERNEL_SIDE plane pixels on a side;
 * the data must hold rows x cols numbers. */
void readMotionKernel(const FileNode& node, Mat& kernel)
{
    kernel.release();
    if (node.empty() || node.isNone())
        return;
    const int maxSide = MAX_MOTION_KERNEL_SIDE;
    const FileNode rows = node["rows"], cols = node["cols"], data = node["data"];
    if (!node.isMap() || !rows.isInt() || !cols.isInt() || !data.isSeq() || static_cast<int>(rows) < 1 ||
        static_cast<int>(cols) < 1 || static_cast<int>(rows) > maxSide || static_cast<int>(cols) > maxSide ||
        data.size() !=
            static_cast<size_t>(static_cast<int>(rows)) * static_cast<size_t>(static_cast<int>(cols)))
        CV_Error(Error::StsParseError,
                 format("scene: field 'motion_kernel' must be a matrix of 1 to %d rows and columns with "
                        "rows x cols numbers",
                        maxSide));
    // One channel of floats, decided before OpenCV's reader sizes the matrix from `dt`.
    const FileNode dt = node["dt"];
    if (!dt.isString() || (dt.string() != "f" && dt.string() != "d"))
        CV_Error(Error::StsParseError, "scene: field 'motion_kernel' must have dt 'f' or 'd' (one channel)");
    node >> kernel;
    double lo = 0;
    if (kernel.channels() != 1 || !checkRange(kernel))
        CV_Error(Error::StsParseError, "scene: field 'motion_kernel' must be one channel of finite numbers");
    minMaxLoc(kernel, &lo);
    if (lo < 0 || !(sum(kernel)[0] > 0))
        CV_Error(Error::StsParseError,
                 "scene: field 'motion_kernel' must be non-negative with a positive sum");
}

} // namespace

bool Scene::isIdentity() const
{
    return shift == Point(0, 0) && scale == 1 && jitter.isIdentity() && isIdentityKernel(motionKernel);
}

void Scene::write(FileStorage& fs, const String& name) const
{
    fs << name << "{";
    fs << "shift" << shift << "scale" << scale;
    fs << "contrast"
       << "[" << jitter.contrast[0] << jitter.contrast[1] << jitter.contrast[2] << jitter.contrast[3] << "]";
    fs << "brightness" << jitter.brightness << "gain_ratio" << jitter.gainRatio;
    // Only when stated, so that every scene without one keeps its bytes.
    if (jitter.exposureTime > 0)
        fs << "exposure_time" << jitter.exposureTime;
    noise.writeFields(fs);
    fs << "motion_kernel" << (motionKernel.empty() ? Mat::ones(1, 1, CV_32F) : motionKernel);
    fs << "}";
}

Scene Scene::read(const FileNode& node)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError, "scene: expected a map");
    Scene s;
    try {
        const FileNode shift = node["shift"];
        if (!shift.empty()) {
            if (!shift.isSeq() || shift.size() != 2 || !shift[0].isInt() || !shift[1].isInt())
                CV_Error(Error::StsParseError, "field 'shift' must be a list of two integers (x, y)");
            s.shift = Point(static_cast<int>(shift[0]), static_cast<int>(shift[1]));
        }
        rejectUnknownKeys(node, {"shift", "scale", "contrast", "brightness", "gain_ratio", "exposure_time",
                                 "motion_kernel", "alignment", "shot_sampling", "prior_mean",
                                 "blur_noise_sum", "dark_bank", "dark_bank_tied"});
        s.scale = detail::readOptionalRealField(node, "scale", s.scale);
        const std::vector<double> contrast = detail::readRealList(node, "contrast", 4);
        for (int i = 0; i < 4; ++i)
            s.jitter.contrast[i] = contrast[static_cast<size_t>(i)];
        s.jitter.brightness = detail::readRealField(node, "brightness");
        s.jitter.gainRatio = detail::readRealField(node, "gain_ratio");
        s.jitter.exposureTime = detail::readOptionalRealField(node, "exposure_time", 0);
        if (!(std::isfinite(s.jitter.exposureTime) && s.jitter.exposureTime >= 0))
            CV_Error(Error::StsParseError, "field 'exposure_time' must be a finite number of seconds >= 0");
    } catch (const Exception& e) {
        CV_Error(e.code, "scene: " + e.err);
    }
    if (!std::isfinite(s.scale) || !(s.scale > 0))
        CV_Error(Error::StsParseError, "scene: field 'scale' must be a finite number > 0");
    s.noise = NoiseOptions::readFields(node);
    readMotionKernel(node["motion_kernel"], s.motionKernel);
    return s;
}

void applyScene(InputArray _src, const RawFormat& format, const NoiseModel& model, const Scene& scene,
                uint64 seed, OutputArray dst, RawFormat& dstFormat, AugmentReport* report,
                std::vector<Rect>* boxes)
{
    const Mat src = detail::twoDimensional(_src, "applyScene: src");
    // Its first step checks a float mosaic's values as it reads them (augment_steps.hpp).
    detail::checkMosaicType(src, "applyScene");
    const detail::ValidatedNoiseModel valid(model); // once for every step of the scene
    if (src.rows % 2 || src.cols % 2)
        CV_Error(Error::StsBadArg, "applyScene: the mosaic needs even sides");
    if (std::abs(static_cast<double>(scene.shift.x)) > src.cols ||
        std::abs(static_cast<double>(scene.shift.y)) > src.rows)
        CV_Error(Error::StsBadArg, cv::format("applyScene: shift (%d, %d) is larger than the %dx%d mosaic",
                                              scene.shift.x, scene.shift.y, src.cols, src.rows));
    // Every box is checked and clipped to the frame on every path, whichever steps the scene has.
    if (boxes)
        for (size_t i = 0; i < boxes->size(); ++i) {
            Rect& b = (*boxes)[i];
            if (b.width < 0 || b.height < 0)
                CV_Error(Error::StsBadArg,
                         cv::format("applyScene: box %zu (%d, %d, %d x %d) has a negative size", i, b.x, b.y,
                                    b.width, b.height));
            b &= Rect(0, 0, src.cols, src.rows);
        }
    // The scene's steps in their order; the jitter always, since it reports the saturated pixels of its
    // input and decides for itself whether it is the identity (an exposure time with a bank is not).
    detail::NoiseSteps steps;
    if (scene.shift != Point(0, 0))
        steps.push_back(detail::makeShiftStep(scene.shift));
    if (scene.scale != 1)
        steps.push_back(detail::makeScaleStep(scene.scale));
    steps.push_back(detail::makeColorJitterStep(scene.jitter, nullptr));
    if (!isIdentityKernel(scene.motionKernel))
        steps.push_back(detail::makeMotionBlurStep(scene.motionKernel));
    detail::runNoiseSteps(steps, src, format, valid, scene.noise, seed, dst, dstFormat, report, boxes,
                          "applyScene");
}

namespace {

// The smallest value of each CFA site (index cfaSite(row, col) of a 2x2 block), rows split among
// threads. A row is read in blocks of 16 values whose element i always holds column parity i % 2: a plain
// array the compiler vectorises (pminuw, minps). A vector type of 32 bytes in this baseline-compiled file was
// taken apart lane by lane through the stack, at 2 GB/s. The row's tail, fewer than 16 values, goes one by
// one.
template <typename T> void siteMinima(const Mat& src, const Range& rows, T lowest[4])
{
    for (int r = rows.start; r < rows.end; ++r) {
        const T* p = src.ptr<T>(r);
        T* lo = lowest + 2 * (r & 1);
        T acc[16];
        std::fill(acc, acc + 16, std::numeric_limits<T>::max());
        int c = 0;
        for (; c + 16 <= src.cols; c += 16)
            for (int i = 0; i < 16; ++i)
                acc[i] = std::min(acc[i], p[c + i]);
        for (int i = 0; i < 16; ++i)
            lo[i & 1] = std::min(lo[i & 1], acc[i]);
        for (; c < src.cols; ++c)
            lo[c & 1] = std::min(lo[c & 1], p[c]);
    }
}

// min over pixels of (value - black of its site), without a black-subtracted copy of the frame.
template <typename T> double minimumAboveBlackOf(const Mat& src, const RawFormat& format)
{
    std::mutex mutex;
    T lowest[4];
    std::fill(lowest, lowest + 4, std::numeric_limits<T>::max());
    std::atomic<bool> nonFinite{false};
    parallel_for_(Range(0, src.rows), [&](const Range& rows) {
        T local[4];
        std::fill(local, local + 4, std::numeric_limits<T>::max());
        for (int r = rows.start; r < rows.end; ++r) {
            siteMinima(src, Range(r, r + 1), local);
            // The values' check, on the row this pass has just read (in cache, a second look costs little).
            if (std::is_same<T, float>::value &&
                !detail::rowIsFinite(reinterpret_cast<const float*>(src.ptr<T>(r)), src.cols))
                nonFinite = true;
        }
        const std::lock_guard<std::mutex> lock(mutex);
        for (int i = 0; i < 4; ++i)
            lowest[i] = std::min(lowest[i], local[i]);
    });
    if (nonFinite)
        detail::throwNonFiniteInput("RandomScenePolicy::draw");
    double result = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 4; ++i)
        if (i / 2 < src.rows && i % 2 < src.cols) // a site the frame has
            result = std::min(result, static_cast<double>(lowest[i]) - format.blackAt(i / 2, i % 2));
    return result;
}

double minimumAboveBlack(const Mat& src, const RawFormat& format)
{
    return src.depth() == CV_16U ? minimumAboveBlackOf<ushort>(src, format)
                                 : minimumAboveBlackOf<float>(src, format);
}

} // namespace

uint64 augmentedOutputSeed(uint64 seed, const String& inputName, int variant)
{
    if (variant < 0)
        CV_Error(Error::StsBadArg, format("augmentedOutputSeed: variant must be >= 0 (got %d)", variant));
    // FNV-1a of the name: a stable 64-bit key for any string, then the registered derivation.
    uint64_t nameKey = 1469598103934665603ull;
    for (unsigned char c : inputName) {
        nameKey ^= c;
        nameKey *= 1099511628211ull;
    }
    return deriveSeed(deriveSeed(seed, SEED_AUGMENTED_OUTPUT, nameKey), SEED_AUGMENTED_OUTPUT,
                      static_cast<uint64_t>(variant));
}

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
    if (blurLengthMax > MAX_MOTION_LENGTH)
        CV_Error(Error::StsBadArg,
                 format("RandomScenePolicy: blurLengthMax must be <= %g mosaic pixels (got %g)",
                        MAX_MOTION_LENGTH, blurLengthMax));
    // A fraction of each side: from 1 on, a draw can shift the content off the frame, and applyScene
    // refuses it only after some outputs are written.
    if (!(maxShift >= 0 && maxShift < 1))
        CV_Error(Error::StsBadArg,
                 format("RandomScenePolicy: maxShift must lie in [0, 1), a fraction of each side (got %g)",
                        maxShift));
    if (!(maxScale >= 0 && maxScale < 1))
        CV_Error(Error::StsBadArg,
                 format("RandomScenePolicy: maxScale must lie in [0, 1) (got %g)", maxScale));
    probability(hueProbability, "hueProbability");
    probability(blurProbability, "blurProbability");
    probability(geometryProbability, "geometryProbability");
    noise.validate();
}

Scene RandomScenePolicy::draw(InputArray _src, const RawFormat& format, uint64 seed) const
{
    validate();
    format.validate();
    const Mat src = detail::twoDimensional(_src, "RandomScenePolicy::draw: src");
    detail::checkMosaicType(src, "RandomScenePolicy::draw"); // the values: minimumAboveBlack()
    const double minX = minimumAboveBlack(src, format);
    detail::CounterRng rng(detail::stepKey(seed, detail::RandomStream::POLICY_DRAW), 0);
    const auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * rng.uniform(); };
    Scene s;
    s.noise = noise;
    if (rng.uniform() < geometryProbability) {
        s.shift = Point(cvRound(uniform(-maxShift, maxShift) * src.cols),
                        cvRound(uniform(-maxShift, maxShift) * src.rows));
        s.scale = uniform(1 - maxScale, 1 + maxScale);
    }
    const double contrast = std::exp(uniform(std::log(contrastMin), std::log(contrastMax)));
    s.jitter.contrast = Vec4d::all(contrast);
    if (rng.uniform() < hueProbability && !format.isMonochrome())
        for (int i = 0; i < 4; ++i)
            s.jitter.contrast[i] *= uniform(hueMin, hueMax);
    s.jitter.brightness = uniform(brightnessMin, brightnessMax) * minX;
    s.jitter.gainRatio = dbToLinearGain(uniform(gainDbMin, gainDbMax));
    if (rng.uniform() < blurProbability)
        s.motionKernel = linearMotionKernel(uniform(0, blurLengthMax), uniform(0, 180), format.pattern);
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
    fs << "geometry_probability" << geometryProbability << "max_shift" << maxShift << "max_scale" << maxScale;
    noise.writeFields(fs);
    fs << "}";
}

RandomScenePolicy RandomScenePolicy::read(const FileNode& node)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError, "random scene policy: expected a map");
    RandomScenePolicy p;
    const auto field = [&](const char* name, double& value) {
        try {
            value = detail::readOptionalRealField(node, name, value);
        } catch (const Exception& e) {
            CV_Error(e.code, "random scene policy: " + e.err);
        }
    };
    try {
        rejectUnknownKeys(node,
                          {"contrast_min",    "contrast_max",     "brightness_min",  "brightness_max",
                           "hue_probability", "hue_min",          "hue_max",         "gain_db_min",
                           "gain_db_max",     "blur_probability", "blur_length_max", "geometry_probability",
                           "max_shift",       "max_scale",        "alignment",       "shot_sampling",
                           "prior_mean",      "blur_noise_sum",   "dark_bank",       "dark_bank_tied"});
    } catch (const Exception& e) {
        CV_Error(e.code, "random scene policy: " + e.err);
    }
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
    field("geometry_probability", p.geometryProbability);
    field("max_shift", p.maxShift);
    field("max_scale", p.maxScale);
    p.noise = NoiseOptions::readFields(node);
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
    RandomScenePolicy p = detail::loadFileStorage(path, "random_scene_policy", "random scene policy",
                                                  [](const FileNode& n) { return read(n); });
    // A bank named by the file lies relative to the file, as a model's images do.
    if (!p.noise.darkBank.empty() && p.noise.darkBank[0] != '/')
        p.noise.darkBank = detail::folderOf(path) + p.noise.darkBank;
    return p;
}

} // namespace rawgment
} // namespace cv
