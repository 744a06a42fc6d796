// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Python bindings of augmentation (noise steps, scenes, policies), RAW and mosaic files, and the ISP.
#include "binding_tools.hpp"

#include <climits>
#include <cmath>

namespace rawgment_python {

using namespace cv::rawgment;

namespace {

const std::vector<int> kMosaicDepths{CV_16U, CV_32F};

//! Boxes as C++ Rects: a sequence of (x, y, w, h), or an N x 4 integer array (what detectors keep).
std::vector<cv::Rect> boxesFrom(const py::object& boxes)
{
    std::vector<cv::Rect> out;
    if (boxes.is_none())
        return out;
    if (py::isinstance<py::array>(boxes)) {
        // Read as doubles, which hold every int32 exactly, and checked one by one: a cast would wrap
        // 2^32 + 5 to 5 and turn NaN into 0 without a word, where the list form raises.
        const char kind = py::array(boxes).dtype().kind();
        if (kind != 'i' && kind != 'u' && kind != 'f' && kind != 'b')
            throw py::type_error("argument 'boxes' must be an N x 4 array of integers (x, y, w, h)");
        const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(boxes);
        if (!a)
            throw py::value_error("argument 'boxes' must be an N x 4 array of (x, y, w, h)");
        if (a.size() == 0)
            return out;
        if (a.ndim() != 2 || a.shape(1) != 4)
            throw py::value_error("argument 'boxes' must be an N x 4 array of (x, y, w, h)");
        for (py::ssize_t i = 0; i < a.shape(0); ++i) {
            int v[4];
            for (py::ssize_t j = 0; j < 4; ++j) {
                const double x = a.at(i, j);
                if (!(x == std::floor(x)) || x < INT_MIN || x > INT_MAX)
                    throw py::value_error(
                        cv::format("argument 'boxes' row %zd column %zd is %.17g: each value "
                                   "must be an integer in the 32-bit range",
                                   i, j, x));
                v[j] = static_cast<int>(x);
            }
            out.emplace_back(v[0], v[1], v[2], v[3]);
        }
        return out;
    }
    try {
        return boxes.cast<std::vector<cv::Rect>>();
    } catch (const py::cast_error&) {
        throw py::type_error(
            "argument 'boxes' must be a sequence of (x, y, w, h) integer tuples or an N x 4 array");
    }
}

//! How the noise steps draw and account for noise, and what they report.
void bindNoiseOptions(py::module_& m)
{
    py::enum_<NoiseAlignment>(m, "NoiseAlignment", doc("NoiseAlignment"))
        .value("NONE", NoiseAlignment::NONE, doc("NoiseAlignment::NONE"))
        .value("IGNORE_PRIOR", NoiseAlignment::IGNORE_PRIOR, doc("NoiseAlignment::IGNORE_PRIOR"))
        .value("ACCOUNT_PRIOR", NoiseAlignment::ACCOUNT_PRIOR, doc("NoiseAlignment::ACCOUNT_PRIOR"));
    py::enum_<ShotNoiseSampling>(m, "ShotNoiseSampling", doc("ShotNoiseSampling"))
        .value("GAUSSIAN", ShotNoiseSampling::GAUSSIAN, doc("ShotNoiseSampling::GAUSSIAN"))
        .value("POISSON", ShotNoiseSampling::POISSON, doc("ShotNoiseSampling::POISSON"));
    py::enum_<PriorMeanEstimate>(m, "PriorMeanEstimate", doc("PriorMeanEstimate"))
        .value("PIXEL_VALUE", PriorMeanEstimate::PIXEL_VALUE, doc("PriorMeanEstimate::PIXEL_VALUE"))
        .value("LOCAL_MEAN", PriorMeanEstimate::LOCAL_MEAN, doc("PriorMeanEstimate::LOCAL_MEAN"));
    py::enum_<BlurNoiseSum>(m, "BlurNoiseSum", doc("BlurNoiseSum"))
        .value("EXACT", BlurNoiseSum::EXACT, doc("BlurNoiseSum::EXACT"))
        .value("FROM_BLURRED_MEAN", BlurNoiseSum::FROM_BLURRED_MEAN, doc("BlurNoiseSum::FROM_BLURRED_MEAN"));

    py::class_<NoiseOptions>(m, "NoiseOptions",
                             doc("NoiseOptions",
                                 "Python: NoiseOptions(alignment=..., shotSampling=..., ...); a "
                                 "NoiseAlignment is accepted wherever NoiseOptions are."))
        .def(keywordInit<NoiseOptions>())
        .def(py::init<NoiseAlignment>(), py::arg("alignment"))
        .def_readwrite("alignment", &NoiseOptions::alignment, doc("NoiseOptions::alignment"))
        .def_readwrite("shotSampling", &NoiseOptions::shotSampling, doc("NoiseOptions::shotSampling"))
        .def_readwrite("priorMean", &NoiseOptions::priorMean, doc("NoiseOptions::priorMean"))
        .def_readwrite("blurNoiseSum", &NoiseOptions::blurNoiseSum, doc("NoiseOptions::blurNoiseSum"))
        .def_readwrite("darkBank", &NoiseOptions::darkBank, doc("NoiseOptions::darkBank"))
        .def_readwrite("darkBankTied", &NoiseOptions::darkBankTied, doc("NoiseOptions::darkBankTied"))
        .def("validate", &NoiseOptions::validate, doc("NoiseOptions::validate"));
    py::implicitly_convertible<NoiseAlignment, NoiseOptions>();

    py::class_<AugmentReport>(m, "AugmentReport", doc("AugmentReport"))
        .def(keywordInit<AugmentReport>())
        .def_readwrite("brighteningPixels", &AugmentReport::brighteningPixels,
                       doc("AugmentReport::brighteningPixels"))
        .def_readwrite("saturatedPixels", &AugmentReport::saturatedPixels,
                       doc("AugmentReport::saturatedPixels"))
        .def_readwrite("readBrighteningPixels", &AugmentReport::readBrighteningPixels,
                       doc("AugmentReport::readBrighteningPixels"))
        .def_readwrite("steps", &AugmentReport::steps, doc("AugmentReport::steps"))
        .def_readwrite("stepSeconds", &AugmentReport::stepSeconds, doc("AugmentReport::stepSeconds"));
}

//! Colour jitter, motion blur and scaling.
void bindNoiseSteps(py::module_& m)
{
    py::class_<ColorJitter>(m, "ColorJitter", doc("ColorJitter"))
        .def(keywordInit<ColorJitter>())
        .def_readwrite("contrast", &ColorJitter::contrast, doc("ColorJitter::contrast"))
        .def_readwrite("brightness", &ColorJitter::brightness, doc("ColorJitter::brightness"))
        .def_readwrite("gainRatio", &ColorJitter::gainRatio, doc("ColorJitter::gainRatio"))
        .def_readwrite("exposureTime", &ColorJitter::exposureTime, doc("ColorJitter::exposureTime"))
        .def_static("exposureChange", &ColorJitter::exposureChange, py::arg("photonRatio"),
                    py::arg("gainRatio"), doc("ColorJitter::exposureChange"))
        .def("isIdentity", &ColorJitter::isIdentity, doc("ColorJitter::isIdentity"));
    m.def(
        "colorJitter",
        [](const py::object& src, const RawFormat& format, const NoiseModel& model, const ColorJitter& jitter,
           const NoiseOptions& noise, uint64 seed, bool saturatedMask, const py::object& dst) -> py::tuple {
            const cv::Mat in = matFromArray(src, "src", kMosaicDepths);
            const cv::Mat target = outputMatLike(dst, "dst", in);
            cv::Mat out = target, mask;
            RawFormat dstFormat;
            AugmentReport report;
            withoutGil("colorJitter", [&] {
                colorJitter(in, format, model, jitter, noise, seed, out, dstFormat, &report,
                            saturatedMask ? cv::_OutputArray(mask) : cv::_OutputArray(cv::noArray()));
            });
            if (saturatedMask)
                return py::make_tuple(resultInto(dst, target, out), dstFormat, report, arrayFromMat(mask));
            return py::make_tuple(resultInto(dst, target, out), dstFormat, report);
        },
        py::arg("src"), py::arg("format"), py::arg("model"), py::arg("jitter"),
        py::arg("noise") = NoiseOptions(), py::kw_only(), py::arg("seed"), py::arg("saturatedMask") = false,
        py::arg("dst") = py::none(),
        doc("colorJitter",
            "Python: colorJitter(src, format, model, jitter, noise=NoiseOptions(), *, seed, "
            "saturatedMask=False, dst=None) returns (dst, dstFormat, report), and the mask last when "
            "saturatedMask is True. dst is a new array (a copy of src for an identity step), or the "
            "caller's dst (an array of src's shape and dtype, padded rows allowed), written in place."));
    m.attr("MAX_MOTION_LENGTH") = MAX_MOTION_LENGTH;
    m.def(
        "linearMotionKernel",
        [](double length, double angleDegrees, CfaPattern pattern) {
            return arrayFromMat(linearMotionKernel(length, angleDegrees, pattern));
        },
        py::arg("length"), py::arg("angleDegrees"), py::arg("pattern") = CFA_RGGB,
        doc("linearMotionKernel", "Python: returns the float32 kernel."));
    m.def(
        "motionBlur",
        [](const py::object& src, const RawFormat& format, const NoiseModel& model, const py::object& kernel,
           const NoiseOptions& noise, uint64 seed, const py::object& dst) {
            const cv::Mat in = matFromArray(src, "src", kMosaicDepths);
            const cv::Mat k = matFromArray(kernel, "kernel", {CV_32F, CV_64F});
            const cv::Mat target = outputMatLike(dst, "dst", in);
            cv::Mat out = target;
            AugmentReport report;
            withoutGil("motionBlur", [&] { motionBlur(in, format, model, k, noise, seed, out, &report); });
            return py::make_tuple(resultInto(dst, target, out), report);
        },
        py::arg("src"), py::arg("format"), py::arg("model"), py::arg("kernel"),
        py::arg("noise") = NoiseOptions(), py::kw_only(), py::arg("seed"), py::arg("dst") = py::none(),
        doc("motionBlur", "Python: motionBlur(src, format, model, kernel, noise=NoiseOptions(), *, seed, "
                          "dst=None) returns (dst, report); dst as colorJitter's."));
    m.def(
        "scaleMosaic",
        [](const py::object& src, const RawFormat& format, const NoiseModel& model, double scale,
           const NoiseOptions& noise, uint64 seed) {
            const cv::Mat in = matFromArray(src, "src", kMosaicDepths);
            cv::Mat dst;
            AugmentReport report;
            withoutGil("scaleMosaic",
                       [&] { scaleMosaic(in, format, model, scale, noise, seed, dst, &report); });
            return py::make_tuple(arrayFromMat(dst), report);
        },
        py::arg("src"), py::arg("format"), py::arg("model"), py::arg("scale"),
        py::arg("noise") = NoiseOptions(), py::kw_only(), py::arg("seed"),
        doc("scaleMosaic", "Python: returns (dst, report)."));
    m.def("scaleBox", &scaleBox, py::arg("box"), py::arg("size"), py::arg("scale"), doc("scaleBox"));
}

//! Scenes, their seeds, and the random policy.
void bindScenes(py::module_& m)
{
    py::class_<Scene> scene(m, "Scene", doc("Scene"));
    scene.def(keywordInit<Scene>())
        .def_readwrite("shift", &Scene::shift, doc("Scene::shift"))
        .def_readwrite("scale", &Scene::scale, doc("Scene::scale"))
        .def_readwrite("jitter", &Scene::jitter, doc("Scene::jitter"))
        .def_readwrite("noise", &Scene::noise, doc("Scene::noise"))
        .def("isIdentity", &Scene::isIdentity, doc("Scene::isIdentity"));
    defMatProperty(scene, "motionKernel", &Scene::motionKernel, doc("Scene::motionKernel"), {CV_32F, CV_64F});
    m.def(
        "applyScene",
        [](const py::object& src, const RawFormat& format, const NoiseModel& model, const Scene& scene,
           uint64 seed, const py::object& boxes) {
            const cv::Mat in = matFromArray(src, "src", kMosaicDepths);
            std::vector<cv::Rect> rects = boxesFrom(boxes);
            cv::Mat dst;
            RawFormat dstFormat;
            AugmentReport report;
            withoutGil("applyScene",
                       [&] { applyScene(in, format, model, scene, seed, dst, dstFormat, &report, &rects); });
            return py::make_tuple(arrayFromMat(dst), dstFormat, report, rects);
        },
        py::arg("src"), py::arg("format"), py::arg("model"), py::arg("scene"), py::kw_only(), py::arg("seed"),
        py::arg("boxes") = py::none(),
        doc("applyScene",
            "Python: applyScene(src, format, model, scene, *, seed, boxes=None) returns (dst, "
            "dstFormat, report, boxes); boxes are (x, y, w, h) tuples or an N x 4 array, and come "
            "back as a list of tuples."));
    m.def("augmentedOutputSeed", &augmentedOutputSeed, py::arg("seed"), py::arg("inputName"),
          py::arg("variant"), doc("augmentedOutputSeed"));

    py::class_<RandomScenePolicy>(m, "RandomScenePolicy", doc("RandomScenePolicy"))
        .def(keywordInit<RandomScenePolicy>())
        .def_readwrite("contrastMin", &RandomScenePolicy::contrastMin, doc("RandomScenePolicy::contrastMin"))
        .def_readwrite("contrastMax", &RandomScenePolicy::contrastMax, doc("RandomScenePolicy::contrastMax"))
        .def_readwrite("brightnessMin", &RandomScenePolicy::brightnessMin,
                       doc("RandomScenePolicy::brightnessMin"))
        .def_readwrite("brightnessMax", &RandomScenePolicy::brightnessMax,
                       doc("RandomScenePolicy::brightnessMax"))
        .def_readwrite("hueProbability", &RandomScenePolicy::hueProbability,
                       doc("RandomScenePolicy::hueProbability"))
        .def_readwrite("hueMin", &RandomScenePolicy::hueMin, doc("RandomScenePolicy::hueMin"))
        .def_readwrite("hueMax", &RandomScenePolicy::hueMax, doc("RandomScenePolicy::hueMax"))
        .def_readwrite("gainDbMin", &RandomScenePolicy::gainDbMin, doc("RandomScenePolicy::gainDbMin"))
        .def_readwrite("gainDbMax", &RandomScenePolicy::gainDbMax, doc("RandomScenePolicy::gainDbMax"))
        .def_readwrite("blurProbability", &RandomScenePolicy::blurProbability,
                       doc("RandomScenePolicy::blurProbability"))
        .def_readwrite("blurLengthMax", &RandomScenePolicy::blurLengthMax,
                       doc("RandomScenePolicy::blurLengthMax"))
        .def_readwrite("geometryProbability", &RandomScenePolicy::geometryProbability,
                       doc("RandomScenePolicy::geometryProbability"))
        .def_readwrite("maxShift", &RandomScenePolicy::maxShift, doc("RandomScenePolicy::maxShift"))
        .def_readwrite("maxScale", &RandomScenePolicy::maxScale, doc("RandomScenePolicy::maxScale"))
        .def_readwrite("noise", &RandomScenePolicy::noise, doc("RandomScenePolicy::noise"))
        .def("validate", &RandomScenePolicy::validate, doc("RandomScenePolicy::validate"))
        .def(
            "draw",
            [](const RandomScenePolicy& self, const py::object& src, const RawFormat& format, uint64 seed) {
                const cv::Mat in = matFromArray(src, "src", kMosaicDepths);
                return withoutGil("RandomScenePolicy.draw", [&] { return self.draw(in, format, seed); });
            },
            py::arg("src"), py::arg("format"), py::arg("seed"), doc("RandomScenePolicy::draw"))
        .def("save", &RandomScenePolicy::save, py::arg("path"), doc("RandomScenePolicy::save"))
        .def_static("load", &RandomScenePolicy::load, py::arg("path"), doc("RandomScenePolicy::load"));
}

//! Camera RAW files, DNGs and the noise profiles of darktable.
void bindRawIo(py::module_& m)
{
    py::class_<DngTag>(m, "DngTag", doc("DngTag"))
        .def(keywordInit<DngTag>())
        .def_readwrite("tag", &DngTag::tag, doc("DngTag::tag"))
        .def_readwrite("type", &DngTag::type, doc("DngTag::type"))
        .def_readwrite("count", &DngTag::count, doc("DngTag::count"))
        .def_readwrite("values", &DngTag::values, doc("DngTag::values"))
        .def("validate", &DngTag::validate, py::arg("what"), doc("DngTag::validate"));
    py::class_<RawImage> rawImage(m, "RawImage", doc("RawImage"));
    rawImage.def(keywordInit<RawImage>())
        .def_readwrite("format", &RawImage::format, doc("RawImage::format"))
        .def_readwrite("iso", &RawImage::iso, doc("RawImage::iso"))
        .def_readwrite("exposureTime", &RawImage::exposureTime, doc("RawImage::exposureTime"))
        .def_readwrite("make", &RawImage::make, doc("RawImage::make"))
        .def_readwrite("model", &RawImage::model, doc("RawImage::model"))
        .def_readwrite("whiteBalance", &RawImage::whiteBalance, doc("RawImage::whiteBalance"))
        .def_readwrite("cameraToSrgb", &RawImage::cameraToSrgb, doc("RawImage::cameraToSrgb"))
        .def_readwrite("noiseProfile", &RawImage::noiseProfile, doc("RawImage::noiseProfile"))
        .def_readwrite("colorTags", &RawImage::colorTags, doc("RawImage::colorTags"))
        .def("formatFor", &RawImage::formatFor, py::arg("model"), doc("RawImage::formatFor"));
    defMatProperty(rawImage, "mosaic", &RawImage::mosaic, doc("RawImage::mosaic"), {CV_16U});
    m.def("formatAtIso", &formatAtIso, py::arg("format"), py::arg("iso"), py::arg("model"),
          doc("formatAtIso"));
    m.def(
        "readRaw",
        [](const std::string& path) { return withoutGil("readRaw", [&] { return readRaw(path); }); },
        py::arg("path"), doc("readRaw"));
    m.def("dngNoiseProfile", &dngNoiseProfile, py::arg("model"), py::arg("format"), doc("dngNoiseProfile"));
    m.def("noiseLineFromDngProfile", &noiseLineFromDngProfile, py::arg("profile"), py::arg("format"),
          py::arg("channel"), doc("noiseLineFromDngProfile"));
    m.def("withDngNoiseProfileLine", &withDngNoiseProfileLine, py::arg("model"), py::arg("image"),
          doc("withDngNoiseProfileLine"));
    m.def("darktableNoiseProfiles", &darktableNoiseProfiles, py::arg("model"), py::arg("format"),
          py::arg("baseIso"), py::arg("isos"), py::arg("maker"), py::arg("cameraModel"),
          py::arg("haarVarianceRatio") = DARKTABLE_HAAR_VARIANCE_RATIO, doc("darktableNoiseProfiles"));
    m.def("noiseModelFromDarktableExport", &noiseModelFromDarktableExport, py::arg("path"), py::arg("format"),
          py::arg("baseIso"), py::arg("maker"), py::arg("cameraModel"),
          py::arg("haarVarianceRatio") = DARKTABLE_HAAR_VARIANCE_RATIO, doc("noiseModelFromDarktableExport"));
}

//! Real cameras from darktable's measured profiles: the catalogue, lookup and draws.
void bindCameraCatalogue(py::module_& m)
{
    py::enum_<CameraProfileVerdict>(m, "CameraProfileVerdict", doc("CameraProfileVerdict"))
        .value("CAMERA_PROFILE_GOOD", CAMERA_PROFILE_GOOD, doc("CameraProfileVerdict::CAMERA_PROFILE_GOOD"))
        .value("CAMERA_PROFILE_ROUGH", CAMERA_PROFILE_ROUGH,
               doc("CameraProfileVerdict::CAMERA_PROFILE_ROUGH"))
        .value("CAMERA_PROFILE_REFUSED", CAMERA_PROFILE_REFUSED,
               doc("CameraProfileVerdict::CAMERA_PROFILE_REFUSED"))
        .export_values();
    m.def("cameraProfileVerdictName", &cameraProfileVerdictName, py::arg("verdict"),
          doc("cameraProfileVerdictName"));
    m.attr("DARKTABLE_HAAR_VARIANCE_RATIO") = DARKTABLE_HAAR_VARIANCE_RATIO;
    m.attr("DARKTABLE_RCD_HAAR_VARIANCE_RATIO") = DARKTABLE_RCD_HAAR_VARIANCE_RATIO;
    py::enum_<ProfileDemosaic>(m, "ProfileDemosaic", doc("ProfileDemosaic"))
        .value("PROFILE_DEMOSAIC_UNDECIDED", PROFILE_DEMOSAIC_UNDECIDED,
               doc("ProfileDemosaic::PROFILE_DEMOSAIC_UNDECIDED"))
        .value("PROFILE_DEMOSAIC_PPG", PROFILE_DEMOSAIC_PPG, doc("ProfileDemosaic::PROFILE_DEMOSAIC_PPG"))
        .value("PROFILE_DEMOSAIC_NEITHER", PROFILE_DEMOSAIC_NEITHER,
               doc("ProfileDemosaic::PROFILE_DEMOSAIC_NEITHER"))
        .export_values();
    m.def("profileDemosaicName", &profileDemosaicName, py::arg("demosaic"), doc("profileDemosaicName"));
    py::class_<DarktableImportParams>(m, "DarktableImportParams", doc("DarktableImportParams"))
        .def(keywordInit<DarktableImportParams>())
        .def_readwrite("haarVarianceRatio", &DarktableImportParams::haarVarianceRatio,
                       doc("DarktableImportParams::haarVarianceRatio"))
        .def_readwrite("offsetReferenceLevel", &DarktableImportParams::offsetReferenceLevel,
                       doc("DarktableImportParams::offsetReferenceLevel"))
        .def_readwrite("goodMedianSlopeResidual", &DarktableImportParams::goodMedianSlopeResidual,
                       doc("DarktableImportParams::goodMedianSlopeResidual"))
        .def_readwrite("goodWorstSlopeResidual", &DarktableImportParams::goodWorstSlopeResidual,
                       doc("DarktableImportParams::goodWorstSlopeResidual"))
        .def_readwrite("goodWorstOffsetResidual", &DarktableImportParams::goodWorstOffsetResidual,
                       doc("DarktableImportParams::goodWorstOffsetResidual"))
        .def_readwrite("goodMinIsos", &DarktableImportParams::goodMinIsos,
                       doc("DarktableImportParams::goodMinIsos"))
        .def("validate", &DarktableImportParams::validate, doc("DarktableImportParams::validate"));
    py::class_<CameraIsoFit>(m, "CameraIsoFit", doc("CameraIsoFit"))
        .def(keywordInit<CameraIsoFit>())
        .def_readwrite("iso", &CameraIsoFit::iso, doc("CameraIsoFit::iso"))
        .def_readwrite("gain", &CameraIsoFit::gain, doc("CameraIsoFit::gain"))
        .def_readwrite("slope", &CameraIsoFit::slope, doc("CameraIsoFit::slope"))
        .def_readwrite("offset", &CameraIsoFit::offset, doc("CameraIsoFit::offset"))
        .def_readwrite("slopeResidual", &CameraIsoFit::slopeResidual, doc("CameraIsoFit::slopeResidual"))
        .def_readwrite("offsetResidual", &CameraIsoFit::offsetResidual, doc("CameraIsoFit::offsetResidual"))
        .def_readwrite("colourSpread", &CameraIsoFit::colourSpread, doc("CameraIsoFit::colourSpread"))
        .def_readwrite("expanded", &CameraIsoFit::expanded, doc("CameraIsoFit::expanded"))
        .def_readwrite("inconsistent", &CameraIsoFit::inconsistent, doc("CameraIsoFit::inconsistent"))
        .def_readwrite("colourSlopeRatios", &CameraIsoFit::colourSlopeRatios,
                       doc("CameraIsoFit::colourSlopeRatios"))
        .def_readwrite("rawIso", &CameraIsoFit::rawIso, doc("CameraIsoFit::rawIso"))
        .def("digital", &CameraIsoFit::digital, doc("CameraIsoFit::digital"))
        .def("fitted", &CameraIsoFit::fitted, doc("CameraIsoFit::fitted"));
    py::class_<CameraNoiseProfile>(m, "CameraNoiseProfile", doc("CameraNoiseProfile"))
        .def(keywordInit<CameraNoiseProfile>())
        .def_readwrite("maker", &CameraNoiseProfile::maker, doc("CameraNoiseProfile::maker"))
        .def_readwrite("model", &CameraNoiseProfile::model, doc("CameraNoiseProfile::model"))
        .def_readwrite("place", &CameraNoiseProfile::place, doc("CameraNoiseProfile::place"))
        .def_readwrite("verdict", &CameraNoiseProfile::verdict, doc("CameraNoiseProfile::verdict"))
        .def_readwrite("reason", &CameraNoiseProfile::reason, doc("CameraNoiseProfile::reason"))
        .def_readwrite("noise", &CameraNoiseProfile::noise, doc("CameraNoiseProfile::noise"))
        .def_readwrite("isos", &CameraNoiseProfile::isos, doc("CameraNoiseProfile::isos"))
        .def_readwrite("skippedProfiles", &CameraNoiseProfile::skippedProfiles,
                       doc("CameraNoiseProfile::skippedProfiles"))
        .def_readwrite("medianSlopeResidual", &CameraNoiseProfile::medianSlopeResidual,
                       doc("CameraNoiseProfile::medianSlopeResidual"))
        .def_readwrite("worstSlopeResidual", &CameraNoiseProfile::worstSlopeResidual,
                       doc("CameraNoiseProfile::worstSlopeResidual"))
        .def_readwrite("worstSlopeIso", &CameraNoiseProfile::worstSlopeIso,
                       doc("CameraNoiseProfile::worstSlopeIso"))
        .def_readwrite("worstOffsetResidual", &CameraNoiseProfile::worstOffsetResidual,
                       doc("CameraNoiseProfile::worstOffsetResidual"))
        .def_readwrite("worstOffsetIso", &CameraNoiseProfile::worstOffsetIso,
                       doc("CameraNoiseProfile::worstOffsetIso"))
        .def_readwrite("medianColourSpread", &CameraNoiseProfile::medianColourSpread,
                       doc("CameraNoiseProfile::medianColourSpread"))
        .def_readwrite("negativeOffsets", &CameraNoiseProfile::negativeOffsets,
                       doc("CameraNoiseProfile::negativeOffsets"))
        .def_readwrite("expandedIsos", &CameraNoiseProfile::expandedIsos,
                       doc("CameraNoiseProfile::expandedIsos"))
        .def_readwrite("monotoneSlope", &CameraNoiseProfile::monotoneSlope,
                       doc("CameraNoiseProfile::monotoneSlope"))
        .def_readwrite("digitalIsos", &CameraNoiseProfile::digitalIsos,
                       doc("CameraNoiseProfile::digitalIsos"))
        .def_readwrite("inconsistentProfiles", &CameraNoiseProfile::inconsistentProfiles,
                       doc("CameraNoiseProfile::inconsistentProfiles"))
        .def_readwrite("colourSlopeRatios", &CameraNoiseProfile::colourSlopeRatios,
                       doc("CameraNoiseProfile::colourSlopeRatios"))
        .def_readwrite("balancePpg", &CameraNoiseProfile::balancePpg, doc("CameraNoiseProfile::balancePpg"))
        .def_readwrite("balanceRcd", &CameraNoiseProfile::balanceRcd, doc("CameraNoiseProfile::balanceRcd"))
        .def_readwrite("demosaic", &CameraNoiseProfile::demosaic, doc("CameraNoiseProfile::demosaic"))
        .def_readwrite("demosaicReason", &CameraNoiseProfile::demosaicReason,
                       doc("CameraNoiseProfile::demosaicReason"))
        .def_readwrite("haarVarianceRatio", &CameraNoiseProfile::haarVarianceRatio,
                       doc("CameraNoiseProfile::haarVarianceRatio"))
        .def("name", &CameraNoiseProfile::name, doc("CameraNoiseProfile::name"))
        .def("usable", &CameraNoiseProfile::usable, doc("CameraNoiseProfile::usable"))
        .def("modelFor", &CameraNoiseProfile::modelFor, py::arg("format"),
             doc("CameraNoiseProfile::modelFor"));
    m.def(
        "readCameraProfiles",
        [](const std::string& path, const DarktableImportParams& params) {
            return withoutGil("readCameraProfiles", [&] { return readCameraProfiles(path, params); });
        },
        py::arg("path"), py::arg("params") = DarktableImportParams(), doc("readCameraProfiles"));
    m.def("findCameraProfile", &findCameraProfile, py::arg("cameras"), py::arg("name"),
          doc("findCameraProfile"));
    m.def("selectCameraProfiles", &selectCameraProfiles, py::arg("cameras"), py::arg("selection"),
          doc("selectCameraProfiles"));
    m.def("drawCameraIndex", &drawCameraIndex, py::arg("count"), py::arg("seed"), doc("drawCameraIndex"));
    m.def("darktableProfilesPath", &darktableProfilesPath, doc("darktableProfilesPath"));
}

//! Every model file through one call, and Android's camera-test form.
void bindModelFiles(py::module_& m)
{
    py::enum_<NoiseModelFileKind>(m, "NoiseModelFileKind", doc("NoiseModelFileKind"))
        .value("NOISE_MODEL_FILE", NOISE_MODEL_FILE, doc("NoiseModelFileKind::NOISE_MODEL_FILE"))
        .value("ANDROID_PROFILE_FILE", ANDROID_PROFILE_FILE, doc("NoiseModelFileKind::ANDROID_PROFILE_FILE"))
        .value("DARKTABLE_PROFILE_FILE", DARKTABLE_PROFILE_FILE,
               doc("NoiseModelFileKind::DARKTABLE_PROFILE_FILE"))
        .export_values();
    m.def("noiseModelFileKind", &noiseModelFileKind, py::arg("path"), doc("noiseModelFileKind"));
    m.def("noiseModelFromAndroidFile", &noiseModelFromAndroidFile, py::arg("path"), py::arg("format"),
          doc("noiseModelFromAndroidFile"));
    m.def("loadAnyNoiseModel", &loadAnyNoiseModel, py::arg("path"), py::arg("camera") = std::string(),
          py::arg("format") = RawFormat(), py::arg("acceptFailedCalibration") = false,
          doc("loadAnyNoiseModel"));
    py::class_<AndroidNoiseProfile>(m, "AndroidNoiseProfile", doc("AndroidNoiseProfile"))
        .def(keywordInit<AndroidNoiseProfile>())
        .def_readwrite("A", &AndroidNoiseProfile::A, doc("AndroidNoiseProfile::A"))
        .def_readwrite("B", &AndroidNoiseProfile::B, doc("AndroidNoiseProfile::B"))
        .def_readwrite("C", &AndroidNoiseProfile::C, doc("AndroidNoiseProfile::C"))
        .def_readwrite("D", &AndroidNoiseProfile::D, doc("AndroidNoiseProfile::D"));
    m.def("androidNoiseProfile", &androidNoiseProfile, py::arg("model"), py::arg("format"),
          py::arg("baseIso"), doc("androidNoiseProfile"));
    m.def("noiseModelFromAndroid", &noiseModelFromAndroid, py::arg("profile"), py::arg("format"),
          py::arg("baseIso"), doc("noiseModelFromAndroid"));
    m.def(
        "writeDng",
        [](const std::string& path, const RawImage& image) {
            withoutGil("writeDng", [&] { writeDng(path, image); });
        },
        py::arg("path"), py::arg("image"), doc("writeDng"));
    m.def(
        "writeFileAtomically",
        [](const std::string& path, const py::bytes& data, bool replace) {
            const std::string bytes = data;
            withoutGil("writeFileAtomically",
                       [&] { writeFileAtomically(path, bytes.data(), bytes.size(), replace); });
        },
        py::arg("path"), py::arg("data"), py::arg("replace") = false,
        doc("writeFileAtomically", "Python: `data` is a bytes object."));
    m.attr("MAX_TEXT_FILE_BYTES") = MAX_TEXT_FILE_BYTES;
}

//! Camera tags and mosaics with their sidecars.
void bindMosaicFiles(py::module_& m)
{
    py::class_<CameraTags>(m, "CameraTags", doc("CameraTags"))
        .def(keywordInit<CameraTags>())
        .def_readwrite("make", &CameraTags::make, doc("CameraTags::make"))
        .def_readwrite("model", &CameraTags::model, doc("CameraTags::model"))
        .def_readwrite("iso", &CameraTags::iso, doc("CameraTags::iso"))
        .def_readwrite("exposureTime", &CameraTags::exposureTime, doc("CameraTags::exposureTime"))
        .def_readwrite("whiteBalance", &CameraTags::whiteBalance, doc("CameraTags::whiteBalance"))
        .def_readwrite("cameraToSrgb", &CameraTags::cameraToSrgb, doc("CameraTags::cameraToSrgb"))
        .def_readwrite("noiseProfile", &CameraTags::noiseProfile, doc("CameraTags::noiseProfile"))
        .def_readwrite("colorTags", &CameraTags::colorTags, doc("CameraTags::colorTags"))
        .def_static("of", &CameraTags::of, py::arg("image"), doc("CameraTags::of"))
        .def("applyTo", &CameraTags::applyTo, py::arg("image"), doc("CameraTags::applyTo"));
    py::class_<MosaicMetadata>(m, "MosaicMetadata", doc("MosaicMetadata"))
        .def(keywordInit<MosaicMetadata>())
        .def_readonly_static("FORMAT_VERSION", &MosaicMetadata::FORMAT_VERSION,
                             doc("MosaicMetadata::FORMAT_VERSION"))
        .def_readwrite("format", &MosaicMetadata::format, doc("MosaicMetadata::format"))
        .def_readwrite("hasScene", &MosaicMetadata::hasScene, doc("MosaicMetadata::hasScene"))
        .def_readwrite("scene", &MosaicMetadata::scene, doc("MosaicMetadata::scene"))
        .def_readwrite("seed", &MosaicMetadata::seed, doc("MosaicMetadata::seed"))
        .def_readwrite("source", &MosaicMetadata::source, doc("MosaicMetadata::source"))
        .def_readwrite("hasCamera", &MosaicMetadata::hasCamera, doc("MosaicMetadata::hasCamera"))
        .def_readwrite("camera", &MosaicMetadata::camera, doc("MosaicMetadata::camera"))
        .def_readwrite("noiseCamera", &MosaicMetadata::noiseCamera, doc("MosaicMetadata::noiseCamera"))
        .def_readwrite("gainFromIso", &MosaicMetadata::gainFromIso, doc("MosaicMetadata::gainFromIso"))
        .def_readwrite("size", &MosaicMetadata::size, doc("MosaicMetadata::size"))
        .def_readwrite("type", &MosaicMetadata::type, doc("MosaicMetadata::type"))
        .def("formatFor", &MosaicMetadata::formatFor, py::arg("model"), doc("MosaicMetadata::formatFor"));
    py::class_<MosaicContainer>(m, "MosaicContainer", doc("MosaicContainer"))
        .def_readonly("name", &MosaicContainer::name, doc("MosaicContainer::name"))
        .def_readonly("extensions", &MosaicContainer::extensions, doc("MosaicContainer::extensions"))
        .def_readonly("readsMosaic", &MosaicContainer::readsMosaic, doc("MosaicContainer::readsMosaic"))
        .def_readonly("writes", &MosaicContainer::writes, doc("MosaicContainer::writes"))
        .def_readonly("float32", &MosaicContainer::float32, doc("MosaicContainer::float32"))
        .def_readonly("cameraRaw", &MosaicContainer::cameraRaw, doc("MosaicContainer::cameraRaw"));
    m.def("mosaicContainers", &mosaicContainers, doc("mosaicContainers"));
    m.def(
        "mosaicContainerOf",
        [](const std::string& path) -> py::object {
            const MosaicContainer* c = mosaicContainerOf(path);
            return c ? py::cast(*c) : py::none();
        },
        py::arg("path"), doc("mosaicContainerOf", "Python: None when no container has the extension."));
    m.def("sidecarPathOf", &sidecarPathOf, py::arg("path"), doc("sidecarPathOf"));
    m.def(
        "writeMosaic",
        [](const std::string& path, const py::object& mosaic, const MosaicMetadata& metadata) {
            const cv::Mat in = matFromArray(mosaic, "mosaic", kMosaicDepths);
            withoutGil("writeMosaic", [&] { writeMosaic(path, in, metadata); });
        },
        py::arg("path"), py::arg("mosaic"), py::arg("metadata"), doc("writeMosaic"));
    m.def(
        "readMosaic",
        [](const std::string& path) {
            cv::Mat mosaic;
            MosaicMetadata meta = withoutGil("readMosaic", [&] { return readMosaic(path, mosaic); });
            return py::make_tuple(arrayFromMat(mosaic), meta);
        },
        py::arg("path"), doc("readMosaic", "Python: returns (mosaic, metadata)."));
}

//! The simple ISPs: tone curves, demosaicing, previews.
void bindIsp(py::module_& m)
{
    py::class_<ToneCurve>(m, "ToneCurve", doc("ToneCurve"))
        .def(keywordInit<ToneCurve>())
        .def_readwrite("gamma", &ToneCurve::gamma, doc("ToneCurve::gamma"))
        .def_readwrite("breakPoint", &ToneCurve::breakPoint, doc("ToneCurve::breakPoint"))
        .def_readwrite("toeSlope", &ToneCurve::toeSlope, doc("ToneCurve::toeSlope"))
        .def_static("simpleGamma", &ToneCurve::simpleGamma, py::arg("gamma") = 5.0,
                    doc("ToneCurve::simpleGamma"))
        .def_static("parametric", &ToneCurve::parametric, py::arg("gamma"), py::arg("breakPoint"),
                    py::arg("toeSlope"), doc("ToneCurve::parametric"))
        .def_static("srgb", &ToneCurve::srgb, doc("ToneCurve::srgb"))
        .def("offset", &ToneCurve::offset, doc("ToneCurve::offset"))
        .def("__call__", &ToneCurve::operator(), py::arg("x"), doc("ToneCurve::operator()"))
        .def("validate", &ToneCurve::validate, doc("ToneCurve::validate"));
    m.def(
        "applyToneCurve",
        [](const py::object& linear, const ToneCurve& curve, int ddepth) {
            const cv::Mat in = matFromArray(linear, "linear", {CV_32F, CV_64F}, true);
            return arrayFromCall("applyToneCurve",
                                 [&](cv::Mat& dst) { applyToneCurve(in, dst, curve, ddepth); });
        },
        py::arg("linear"), py::arg("curve"), py::arg("ddepth") = -1,
        doc("applyToneCurve", "Python: applyToneCurve(linear, curve, ddepth=-1) returns dst."));
    py::enum_<DemosaicMethod>(m, "DemosaicMethod", doc("DemosaicMethod"))
        .value("DEMOSAIC_BILINEAR", DEMOSAIC_BILINEAR, doc("DemosaicMethod::DEMOSAIC_BILINEAR"))
        .value("DEMOSAIC_EDGE_AWARE", DEMOSAIC_EDGE_AWARE, doc("DemosaicMethod::DEMOSAIC_EDGE_AWARE"))
        .value("DEMOSAIC_HALF_SIZE", DEMOSAIC_HALF_SIZE, doc("DemosaicMethod::DEMOSAIC_HALF_SIZE"))
        .export_values();
    py::class_<IspParams>(m, "IspParams", doc("IspParams"))
        .def(keywordInit<IspParams>())
        .def_readwrite("tone", &IspParams::tone, doc("IspParams::tone"))
        .def_readwrite("whiteBalance", &IspParams::whiteBalance, doc("IspParams::whiteBalance"))
        .def_readwrite("colorMatrix", &IspParams::colorMatrix, doc("IspParams::colorMatrix"))
        .def_readwrite("exposure", &IspParams::exposure, doc("IspParams::exposure"))
        .def_readwrite("demosaic", &IspParams::demosaic, doc("IspParams::demosaic"))
        .def_readwrite("outputDepth", &IspParams::outputDepth, doc("IspParams::outputDepth"))
        .def("validate", &IspParams::validate, doc("IspParams::validate"));
    m.def(
        "renderSimpleIsp",
        [](const py::object& mosaic, const RawFormat& format, const IspParams& params) {
            const cv::Mat in = matFromArray(mosaic, "mosaic", kMosaicDepths);
            return arrayFromCall("renderSimpleIsp",
                                 [&](cv::Mat& bgr) { renderSimpleIsp(in, format, bgr, params); });
        },
        py::arg("mosaic"), py::arg("format"), py::arg("params") = IspParams(),
        doc("renderSimpleIsp", "Python: returns the HxWx3 BGR array (as cv2 images are)."));
}

} // namespace

void bindAugment(py::module_& m)
{
    bindNoiseOptions(m);
    bindNoiseSteps(m);
    bindScenes(m);
    bindRawIo(m);
    bindCameraCatalogue(m);
    bindModelFiles(m);
    bindMosaicFiles(m);
    bindIsp(m);
}

} // namespace rawgment_python
