// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Scenes (what one augmentation simulates, applied step by step) and the random scene policy.
#include "augment_steps.hpp"
#include "resample_rows.hpp"

#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment/seeds.hpp>

#include <atomic>
#include <cmath>
#include <cstring>
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

namespace {

/* Where each output pixel of a shift reads: each CFA plane (of step 2; a monochrome frame is one plane of
 * step 1, PlaneGrid) moved by shift / step, vacated pixels replicating the plane's edge. Output pixel
 * (r, c) is source pixel (step clamp(r/step - shift.y/step) + r%step, step clamp(c/step - shift.x/step) +
 * c%step), the clamps to the plane's rows and columns; output columns [first, last) read source column
 * c - shift.x, those left of them the first step of source columns, those right of them the last. */
struct ShiftSource
{
    int step, planeRows, planeCols, planeShiftY, shiftX, first, last;

    ShiftSource(Size size, Point shift, int gridStep)
        : step(gridStep), planeRows(size.height / gridStep), planeCols(size.width / gridStep),
          planeShiftY(shift.y / gridStep), shiftX(shift.x), first(std::min(std::max(shift.x, 0), size.width)),
          last(std::max(std::min(size.width + shift.x, size.width), 0))
    {
    }
    int row(int r) const
    {
        return step * std::min(std::max(r / step - planeShiftY, 0), planeRows - 1) + r % step;
    }
    int column(int c) const
    {
        return c < first ? c % step : c < last ? c - shiftX : step * (planeCols - 1) + c % step;
    }
};

/* The shift in one pass (ShiftSource): the same values as splitting the planes, moving each with
 * warpAffine (INTER_NEAREST, BORDER_REPLICATE) and merging them (Augment.shiftMatchesThePlaneWise
 * Composition), at the cost of a copy: the inner columns of a row are one memcpy. */
void shiftMosaic(const Mat& src, Point shift, int gridStep, Mat& dst)
{
    CV_Assert(shift.x % gridStep == 0 && shift.y % gridStep == 0 && src.rows % 2 == 0 && src.cols % 2 == 0);
    dst.create(src.size(), src.type());
    detail::adviseHugePages(dst);
    const ShiftSource from(src.size(), shift, gridStep);
    const size_t esz = src.elemSize();
    const bool checkValues = src.depth() == CV_32F;
    std::atomic<bool> nonFinite{false};
    parallel_for_(Range(0, src.rows), [&](const Range& rows) {
        for (int r = rows.start; r < rows.end; ++r) {
            const uchar* s = src.ptr(from.row(r));
            // The shift is the scene's first step: it checks each source row whole, while it is in cache.
            if (checkValues && !detail::rowIsFinite(reinterpret_cast<const float*>(s), src.cols))
                nonFinite = true;
            uchar* d = dst.ptr(r);
            for (int c = 0; c < from.first; ++c)
                std::memcpy(d + c * esz, s + from.column(c) * esz, esz);
            if (from.last > from.first)
                std::memcpy(d + from.first * esz, s + from.column(from.first) * esz,
                            (from.last - from.first) * esz);
            for (int c = std::max(from.last, from.first); c < src.cols; ++c)
                std::memcpy(d + c * esz, s + from.column(c) * esz, esz);
        }
    });
    if (checkValues) {
        // The rows the shift moved out of the frame, which no output row read.
        std::vector<uchar> read(static_cast<size_t>(src.rows), 0);
        for (int r = 0; r < src.rows; ++r)
            read[static_cast<size_t>(from.row(r))] = 1;
        for (int r = 0; r < src.rows; ++r)
            if (!read[static_cast<size_t>(r)] && !detail::rowIsFinite(src.ptr<float>(r), src.cols))
                nonFinite = true;
    }
    if (nonFinite)
        detail::throwNonFiniteInput("applyScene");
}

/* The sensor's dark shading S stays where the sensor has it: the shifted content carries the input's S
 * of its source pixel, which is swapped for the S of the pixel it lands on, dst(x) = src(x - d) - S(x - d)
 * + S(x) (float arithmetic, the same on every path; integer mosaics rounded to nearest, ties to even, and
 * kept in range). Clipped pixels stay clipped. Row by row, from ShiftSource's pixels as shiftMosaic() copied
 * them. */
template <typename T>
void swapShiftedShading(const Mat& src, const RawFormat& format, const detail::DarkShading& shading,
                        Point shift, int gridStep, Mat& dst)
{
    const ShiftSource from(src.size(), shift, gridStep);
    const float white = static_cast<float>(format.whiteLevel);
    const float highest = src.depth() == CV_16U ? 65535.f : std::numeric_limits<float>::max();
    const float lowest = src.depth() == CV_16U ? 0.f : -std::numeric_limits<float>::max();
    std::atomic<bool> nonFinite{false};
    parallel_for_(Range(0, src.rows), [&](const Range& rows) {
        for (int r = rows.start; r < rows.end; ++r) {
            const int sr = from.row(r);
            const float *bdSrc = shading.perGainRow(sr), *brSrc = shading.offsetRow(sr);
            const float *bdDst = shading.perGainRow(r), *brDst = shading.offsetRow(r);
            T* d = dst.ptr<T>(r);
            for (int c = 0; c < src.cols; ++c) {
                const int sc = from.column(c);
                const float value = static_cast<float>(d[c]);
                const float swapped = value - shading.at(bdSrc, brSrc, sc) + shading.at(bdDst, brDst, c);
                if (!std::isfinite(swapped)) {
                    nonFinite = true;
                    return;
                }
                if (value >= white)
                    continue;
                const float kept = std::min(std::max(swapped, lowest), highest);
                d[c] = static_cast<T>(src.depth() == CV_16U ? std::nearbyint(kept) : kept);
            }
        }
    });
    if (nonFinite)
        detail::throwNonFiniteShading("applyScene");
}

} // namespace

void applyScene(InputArray _src, const RawFormat& format, const NoiseModel& model, const Scene& scene,
                uint64 seed, OutputArray _dst, RawFormat& dstFormat, AugmentReport* report,
                std::vector<Rect>* boxes)
{
    Mat current = detail::twoDimensional(_src, "applyScene: src");
    // Its first step checks a float mosaic's values as it reads them (augment_steps.hpp).
    detail::checkMosaicType(current, "applyScene");
    format.validate();
    const detail::ValidatedNoiseModel valid(model); // once for every step of the scene
    if (current.rows % 2 || current.cols % 2)
        CV_Error(Error::StsBadArg, "applyScene: the mosaic needs even sides");
    RawFormat fmt = format;
    if (std::abs(static_cast<double>(scene.shift.x)) > current.cols ||
        std::abs(static_cast<double>(scene.shift.y)) > current.rows)
        CV_Error(Error::StsBadArg, cv::format("applyScene: shift (%d, %d) is larger than the %dx%d mosaic",
                                              scene.shift.x, scene.shift.y, current.cols, current.rows));
    // Every box is checked and clipped to the frame on every path, whichever steps the scene has.
    if (boxes)
        for (size_t i = 0; i < boxes->size(); ++i) {
            Rect& b = (*boxes)[i];
            if (b.width < 0 || b.height < 0)
                CV_Error(Error::StsBadArg,
                         cv::format("applyScene: box %zu (%d, %d, %d x %d) has a negative size", i, b.x, b.y,
                                    b.width, b.height));
            b &= Rect(0, 0, current.cols, current.rows);
        }
    // A Bayer mosaic moves by whole 2x2 blocks so that its CFA phase stays; a monochrome frame has none.
    const int gridStep = detail::PlaneGrid(fmt).step;
    const Point shift = gridStep == 1
                            ? scene.shift
                            : Point(2 * cvRound(scene.shift.x / 2.0), 2 * cvRound(scene.shift.y / 2.0));
    // The steps write into two buffers in turn, the last into the caller's dst when it is a Mat to reuse (as
    // a single step's dst is): a new 48 MB float frame per step cost more in page faults than the step itself
    // (glibc maps blocks over 32 MB afresh on every allocation). The first step reads the caller's src, which
    // no step writes (stepOutput() gives a new Mat for a dst that overlaps it).
    const bool jitters = !scene.jitter.isIdentity(), blurs = !isIdentityKernel(scene.motionKernel);
    int stepsLeft = (shift != Point(0, 0)) + (scene.scale != 1) + jitters + blurs;
    Mat buffers[2];
    if (_dst.kind() == _InputArray::MAT) {
        const Mat given = _dst.getMat();
        // Never the caller's src (an in-place call, dst = src): a later step would write into it.
        const bool overlaps = given.datastart < current.dataend && current.datastart < given.dataend;
        if (!overlaps && given.size() == current.size() && given.type() == current.type())
            buffers[0] = given;
    }
    const auto nextBuffer = [&]() -> Mat& { return buffers[--stepsLeft % 2]; };
    // A tied bank takes the input's fixed pattern out where the sensor has it; a shift moves the pattern with
    // the content, and the bank's pattern is not moved back as the dark shading is.
    if (shift != Point(0, 0) && scene.noise.darkBankTied && !scene.noise.darkBank.empty() &&
        scene.noise.alignment != NoiseAlignment::NONE)
        CV_Error(Error::StsBadArg,
                 "applyScene: a tied dark-frame bank (NoiseOptions::darkBankTied) cannot follow "
                 "a shifted scene, which moves the input's fixed pattern; untie the bank or "
                 "drop the shift");
    if (shift != Point(0, 0)) {
        const auto start = std::chrono::steady_clock::now();
        Mat& shifted = nextBuffer();
        shiftMosaic(current, shift, gridStep, shifted);
        // The dark shading belongs to the sensor, not to the content: it must not move with the shift.
        const detail::StepNoise step(valid, fmt, scene.noise, 1, current.size(), "applyScene");
        if (!step.shading.empty()) {
            if (current.depth() == CV_16U)
                swapShiftedShading<ushort>(current, fmt, step.shading, shift, gridStep, shifted);
            else
                swapShiftedShading<float>(current, fmt, step.shading, shift, gridStep, shifted);
        }
        current = shifted;
        if (boxes)
            for (Rect& b : *boxes)
                b = (b + shift) & Rect(0, 0, current.cols, current.rows);
        detail::recordStep(report, "shift", start);
    }
    // The first step that runs checks the input's values as it reads them all; its output, finite, is what
    // the later steps read, unchecked.
    bool valuesChecked = shift != Point(0, 0);
    if (scene.scale != 1) {
        Mat& scaled = nextBuffer();
        detail::scaleMosaicStep(current, fmt, valid, scene.scale, scene.noise, seed, scaled, report,
                                valuesChecked);
        valuesChecked = true;
        current = scaled;
        if (boxes)
            for (Rect& b : *boxes)
                b = scaleBox(b, current.size(), scene.scale);
    }
    // An identity jitter reads nothing: the blur after it checks then.
    Mat unchanged;
    Mat& jittered = jitters ? nextBuffer() : unchanged;
    detail::colorJitterStep(current, fmt, valid, scene.jitter, scene.noise, seed, jittered, fmt, report,
                            noArray(), valuesChecked || (!jitters && blurs));
    valuesChecked = valuesChecked || jitters;
    current = jittered;
    if (blurs) {
        Mat& blurred = nextBuffer();
        detail::motionBlurStep(current, fmt, valid, scene.motionKernel, scene.noise, seed, blurred, report,
                               valuesChecked);
        current = blurred;
    }
    _dst.assign(current);
    dstFormat = fmt;
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
