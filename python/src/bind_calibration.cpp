// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Python bindings of calibration (burst statistics, samples, fits) and normality (Shapiro-Wilk).
#include "binding_tools.hpp"

namespace rawgment_python {

using namespace cv::rawgment;

namespace {

const std::vector<int> kNumericDepths{CV_8U, CV_8S, CV_16U, CV_16S, CV_32S, CV_32F, CV_64F};

//! Burst statistics and the noise samples of bursts, squares and single frames.
void bindBurstSampling(py::module_& m)
{
    py::class_<BurstStatistics>(m, "BurstStatistics", doc("BurstStatistics"))
        .def(py::init<const RawFormat&, int, int>(), py::arg("format"), py::arg("groupFrames") = 8,
             py::arg("stateDepth") = int(CV_64F), doc("BurstStatistics::BurstStatistics"))
        .def(
            "add",
            [](BurstStatistics& self, const py::object& frame) {
                const cv::Mat in = matFromArray(frame, "frame", {CV_16U, CV_32F});
                withoutGil("BurstStatistics.add", [&] { self.add(in); });
            },
            py::arg("frame"), doc("BurstStatistics::add"))
        .def(
            "reset", [](BurstStatistics& self, const RawFormat& format) { self.reset(format); },
            py::arg("format"), doc("BurstStatistics::reset"))
        .def("frames", &BurstStatistics::frames, doc("BurstStatistics::frames"))
        .def("size", &BurstStatistics::size, doc("BurstStatistics::size"))
        .def("format", &BurstStatistics::format, doc("BurstStatistics::format"))
        .def(
            "mean",
            [](const BurstStatistics& self) {
                return arrayFromCall("BurstStatistics.mean", [&](cv::Mat& dst) { self.mean(dst); });
            },
            doc("BurstStatistics::mean", "Python: returns the float64 array."))
        .def(
            "variance",
            [](const BurstStatistics& self) {
                return arrayFromCall("BurstStatistics.variance", [&](cv::Mat& dst) { self.variance(dst); });
            },
            doc("BurstStatistics::variance", "Python: returns the float64 array."))
        .def(
            "clippedMask",
            [](const BurstStatistics& self) {
                cv::Mat dst;
                self.clippedMask(dst);
                return arrayFromMat(dst);
            },
            doc("BurstStatistics::clippedMask", "Python: returns the uint8 array."));

    py::class_<NoiseSample>(m, "NoiseSample", doc("NoiseSample"))
        .def(keywordInit<NoiseSample>())
        .def_readwrite("mean", &NoiseSample::mean, doc("NoiseSample::mean"))
        .def_readwrite("variance", &NoiseSample::variance, doc("NoiseSample::variance"))
        .def_readwrite("gain", &NoiseSample::gain, doc("NoiseSample::gain"))
        .def_readwrite("dof", &NoiseSample::dof, doc("NoiseSample::dof"))
        .def_readwrite("channel", &NoiseSample::channel, doc("NoiseSample::channel"))
        .def_readwrite("pixel", &NoiseSample::pixel, doc("NoiseSample::pixel"));
    m.def("cfaAlignedSquares", &cfaAlignedSquares, py::arg("patches"), py::arg("side") = 24,
          doc("cfaAlignedSquares"));
    m.def(
        "sampleBurstPatches",
        [](const BurstStatistics& stats, const std::vector<cv::Rect>& squares, double gain) {
            return withoutGil("sampleBurstPatches", [&] { return sampleBurstPatches(stats, squares, gain); });
        },
        py::arg("stats"), py::arg("squares"), py::arg("gain"), doc("sampleBurstPatches"));
    m.def(
        "sampleDarkBurst",
        [](const BurstStatistics& stats, const std::vector<cv::Rect>& squares, double gain) {
            return withoutGil("sampleDarkBurst", [&] { return sampleDarkBurst(stats, squares, gain); });
        },
        py::arg("stats"), py::arg("squares"), py::arg("gain"), doc("sampleDarkBurst"));
    m.def(
        "sampleStaticScene",
        [](const BurstStatistics& stats, double gain, int maxSamples) {
            return withoutGil("sampleStaticScene",
                              [&] { return sampleStaticScene(stats, gain, maxSamples); });
        },
        py::arg("stats"), py::arg("gain"), py::arg("maxSamples") = 100000, doc("sampleStaticScene"));
    m.def(
        "sampleSingleFramePatches",
        [](const py::object& raw, const RawFormat& format, const std::vector<cv::Rect>& squares,
           double gain) {
            const cv::Mat in = matFromArray(raw, "raw", {CV_16U, CV_32F});
            return withoutGil("sampleSingleFramePatches",
                              [&] { return sampleSingleFramePatches(in, format, squares, gain); });
        },
        py::arg("raw"), py::arg("format"), py::arg("squares"), py::arg("gain"),
        doc("sampleSingleFramePatches"));
}

//! Per-gain line fits and the calibration parameters.
void bindLineFits(py::module_& m)
{
    py::class_<LineFitParams>(m, "LineFitParams", doc("LineFitParams"))
        .def(keywordInit<LineFitParams>())
        .def_readwrite("robust", &LineFitParams::robust, doc("LineFitParams::robust"))
        .def_readwrite("ransacIterations", &LineFitParams::ransacIterations,
                       doc("LineFitParams::ransacIterations"))
        .def_readwrite("inlierThreshold", &LineFitParams::inlierThreshold,
                       doc("LineFitParams::inlierThreshold"))
        .def_readwrite("seed", &LineFitParams::seed, doc("LineFitParams::seed"))
        .def_readwrite("readExcessKurtosis", &LineFitParams::readExcessKurtosis,
                       doc("LineFitParams::readExcessKurtosis"));
    py::class_<NoiseLineFit>(m, "NoiseLineFit", doc("NoiseLineFit"))
        .def(keywordInit<NoiseLineFit>())
        .def_readwrite("gain", &NoiseLineFit::gain, doc("NoiseLineFit::gain"))
        .def_readwrite("line", &NoiseLineFit::line, doc("NoiseLineFit::line"))
        .def_readwrite("rSquared", &NoiseLineFit::rSquared, doc("NoiseLineFit::rSquared"))
        .def_readwrite("inliers", &NoiseLineFit::inliers, doc("NoiseLineFit::inliers"))
        .def_readwrite("samples", &NoiseLineFit::samples, doc("NoiseLineFit::samples"))
        .def_readwrite("slopeStdError", &NoiseLineFit::slopeStdError, doc("NoiseLineFit::slopeStdError"))
        .def_readwrite("offsetStdError", &NoiseLineFit::offsetStdError, doc("NoiseLineFit::offsetStdError"))
        .def_readwrite("slopeOffsetCorrelation", &NoiseLineFit::slopeOffsetCorrelation,
                       doc("NoiseLineFit::slopeOffsetCorrelation"));
    m.def(
        "fitNoiseLine",
        [](const std::vector<NoiseSample>& samples, const LineFitParams& params) {
            return withoutGil("fitNoiseLine", [&] { return fitNoiseLine(samples, params); });
        },
        py::arg("samples"), py::arg("params") = LineFitParams(), doc("fitNoiseLine"));

    py::enum_<NoiseFitMethod>(m, "NoiseFitMethod", doc("NoiseFitMethod"))
        .value("NOISE_FIT_JOINT", NOISE_FIT_JOINT, doc("NoiseFitMethod::NOISE_FIT_JOINT"))
        .value("NOISE_FIT_TWO_STAGE", NOISE_FIT_TWO_STAGE, doc("NoiseFitMethod::NOISE_FIT_TWO_STAGE"))
        .export_values();
    py::class_<CalibrationParams>(m, "CalibrationParams", doc("CalibrationParams"))
        .def(keywordInit<CalibrationParams>())
        .def_readwrite("method", &CalibrationParams::method, doc("CalibrationParams::method"))
        .def_readwrite("line", &CalibrationParams::line, doc("CalibrationParams::line"))
        .def_readwrite("reweightIterations", &CalibrationParams::reweightIterations,
                       doc("CalibrationParams::reweightIterations"))
        .def_readwrite("lossScale", &CalibrationParams::lossScale, doc("CalibrationParams::lossScale"))
        .def_readwrite("minGainRatio", &CalibrationParams::minGainRatio,
                       doc("CalibrationParams::minGainRatio"))
        .def_readwrite("readExcessKurtosis", &CalibrationParams::readExcessKurtosis,
                       doc("CalibrationParams::readExcessKurtosis"))
        .def_readwrite("bootstrapReplicates", &CalibrationParams::bootstrapReplicates,
                       doc("CalibrationParams::bootstrapReplicates"));
}

//! The calibration, its uncertainty, its report and what more data would buy.
void bindCalibrationReport(py::module_& m)
{
    py::enum_<NoiseModelParameter>(m, "NoiseModelParameter", doc("NoiseModelParameter"))
        .value("NOISE_PARAM_ALPHA", NOISE_PARAM_ALPHA, doc("NoiseModelParameter::NOISE_PARAM_ALPHA"))
        .value("NOISE_PARAM_SIGMA_D2", NOISE_PARAM_SIGMA_D2, doc("NoiseModelParameter::NOISE_PARAM_SIGMA_D2"))
        .value("NOISE_PARAM_SIGMA_R2", NOISE_PARAM_SIGMA_R2, doc("NoiseModelParameter::NOISE_PARAM_SIGMA_R2"))
        .export_values();
    py::enum_<UncertaintySource>(m, "UncertaintySource", doc("UncertaintySource"))
        .value("UNCERTAINTY_NONE", UNCERTAINTY_NONE, doc("UncertaintySource::UNCERTAINTY_NONE"))
        .value("UNCERTAINTY_COVARIANCE", UNCERTAINTY_COVARIANCE,
               doc("UncertaintySource::UNCERTAINTY_COVARIANCE"))
        .value("UNCERTAINTY_BOOTSTRAP", UNCERTAINTY_BOOTSTRAP,
               doc("UncertaintySource::UNCERTAINTY_BOOTSTRAP"))
        .export_values();
    py::class_<ModelUncertainty>(m, "ModelUncertainty", doc("ModelUncertainty"))
        .def(keywordInit<ModelUncertainty>())
        .def_readwrite("source", &ModelUncertainty::source, doc("ModelUncertainty::source"))
        .def_readwrite("stdError", &ModelUncertainty::stdError, doc("ModelUncertainty::stdError"))
        .def_readwrite("covariance", &ModelUncertainty::covariance, doc("ModelUncertainty::covariance"))
        .def_readwrite("fitStdError", &ModelUncertainty::fitStdError, doc("ModelUncertainty::fitStdError"))
        .def_readwrite("bootstrapStdError", &ModelUncertainty::bootstrapStdError,
                       doc("ModelUncertainty::bootstrapStdError"))
        .def_readwrite("bootstrapReplicates", &ModelUncertainty::bootstrapReplicates,
                       doc("ModelUncertainty::bootstrapReplicates"))
        .def("correlation", &ModelUncertainty::correlation, py::arg("first"), py::arg("second"),
             doc("ModelUncertainty::correlation"));
    py::class_<CalibrationReport>(m, "CalibrationReport", doc("CalibrationReport"))
        .def(keywordInit<CalibrationReport>())
        .def_readonly_static("FORMAT_VERSION", &CalibrationReport::FORMAT_VERSION,
                             doc("CalibrationReport::FORMAT_VERSION"))
        .def_readwrite("method", &CalibrationReport::method, doc("CalibrationReport::method"))
        .def_readwrite("model", &CalibrationReport::model, doc("CalibrationReport::model"))
        .def_readwrite("separable", &CalibrationReport::separable, doc("CalibrationReport::separable"))
        .def_readwrite("perGain", &CalibrationReport::perGain, doc("CalibrationReport::perGain"))
        .def_readwrite("rSquaredSlope", &CalibrationReport::rSquaredSlope,
                       doc("CalibrationReport::rSquaredSlope"))
        .def_readwrite("rSquaredOffset", &CalibrationReport::rSquaredOffset,
                       doc("CalibrationReport::rSquaredOffset"))
        .def_readwrite("samples", &CalibrationReport::samples, doc("CalibrationReport::samples"))
        .def_readwrite("samplesUsed", &CalibrationReport::samplesUsed, doc("CalibrationReport::samplesUsed"))
        .def_readwrite("notes", &CalibrationReport::notes, doc("CalibrationReport::notes"))
        .def_readwrite("readExcessKurtosis", &CalibrationReport::readExcessKurtosis,
                       doc("CalibrationReport::readExcessKurtosis"))
        .def_readwrite("readExcessKurtosisEstimated", &CalibrationReport::readExcessKurtosisEstimated,
                       doc("CalibrationReport::readExcessKurtosisEstimated"))
        .def_readwrite("uncertainty", &CalibrationReport::uncertainty, doc("CalibrationReport::uncertainty"))
        .def("interval", &CalibrationReport::interval, py::arg("parameter"), py::arg("level") = 0.95,
             doc("CalibrationReport::interval"))
        .def("save", &CalibrationReport::save, py::arg("path"), doc("CalibrationReport::save"))
        .def_static("load", &CalibrationReport::load, py::arg("path"), doc("CalibrationReport::load"));
    py::class_<CalibrationPlan>(m, "CalibrationPlan", doc("CalibrationPlan"))
        .def(keywordInit<CalibrationPlan>())
        .def_readwrite("frameFactor", &CalibrationPlan::frameFactor, doc("CalibrationPlan::frameFactor"))
        .def_readwrite("pixelFactor", &CalibrationPlan::pixelFactor, doc("CalibrationPlan::pixelFactor"))
        .def_readwrite("addDarkFrames", &CalibrationPlan::addDarkFrames,
                       doc("CalibrationPlan::addDarkFrames"))
        .def_readwrite("addGain", &CalibrationPlan::addGain, doc("CalibrationPlan::addGain"));
    m.def(
        "projectedStdError",
        [](const std::vector<NoiseSample>& samples, const CalibrationReport& report,
           const CalibrationPlan& plan) {
            return withoutGil("projectedStdError", [&] { return projectedStdError(samples, report, plan); });
        },
        py::arg("samples"), py::arg("report"), py::arg("plan"), doc("projectedStdError"));
    m.def(
        "calibrateNoiseModel",
        [](const std::vector<NoiseSample>& samples, const CalibrationParams& params) {
            return withoutGil("calibrateNoiseModel", [&] { return calibrateNoiseModel(samples, params); });
        },
        py::arg("samples"), py::arg("params") = CalibrationParams(), doc("calibrateNoiseModel"));
}

//! Shapiro-Wilk results and the dark-frame components from dark bursts.
void bindDarkCalibration(py::module_& m)
{
    py::class_<ShapiroWilkResult>(m, "ShapiroWilkResult", doc("ShapiroWilkResult"))
        .def(keywordInit<ShapiroWilkResult>())
        .def_readwrite("W", &ShapiroWilkResult::W, doc("ShapiroWilkResult::W"))
        .def_readwrite("pValue", &ShapiroWilkResult::pValue, doc("ShapiroWilkResult::pValue"))
        .def_readwrite("n", &ShapiroWilkResult::n, doc("ShapiroWilkResult::n"))
        .def_readwrite("constant", &ShapiroWilkResult::constant, doc("ShapiroWilkResult::constant"));
    // The dark-frame calibration after ShapiroWilkResult, which its statistics hold (the stub names the
    // Python type only of classes already bound).
    py::class_<DarkCalibrationParams>(m, "DarkCalibrationParams", doc("DarkCalibrationParams"))
        .def(keywordInit<DarkCalibrationParams>())
        .def_readwrite("rowNoise", &DarkCalibrationParams::rowNoise, doc("DarkCalibrationParams::rowNoise"))
        .def_readwrite("darkShading", &DarkCalibrationParams::darkShading,
                       doc("DarkCalibrationParams::darkShading"))
        .def_readwrite("tukeyShape", &DarkCalibrationParams::tukeyShape,
                       doc("DarkCalibrationParams::tukeyShape"))
        .def_readwrite("lambdaMin", &DarkCalibrationParams::lambdaMin,
                       doc("DarkCalibrationParams::lambdaMin"))
        .def_readwrite("lambdaMax", &DarkCalibrationParams::lambdaMax,
                       doc("DarkCalibrationParams::lambdaMax"))
        .def_readwrite("ppccSamples", &DarkCalibrationParams::ppccSamples,
                       doc("DarkCalibrationParams::ppccSamples"))
        .def("validate", &DarkCalibrationParams::validate, doc("DarkCalibrationParams::validate"));
    py::class_<DarkGainStatistics>(m, "DarkGainStatistics", doc("DarkGainStatistics"))
        .def(keywordInit<DarkGainStatistics>())
        .def_readwrite("gain", &DarkGainStatistics::gain, doc("DarkGainStatistics::gain"))
        .def_readwrite("frames", &DarkGainStatistics::frames, doc("DarkGainStatistics::frames"))
        .def_readwrite("rowMeanVar", &DarkGainStatistics::rowMeanVar, doc("DarkGainStatistics::rowMeanVar"))
        .def_readwrite("rowVariance", &DarkGainStatistics::rowVariance,
                       doc("DarkGainStatistics::rowVariance"))
        .def_readwrite("rowVarianceSE", &DarkGainStatistics::rowVarianceSE,
                       doc("DarkGainStatistics::rowVarianceSE"))
        .def_readwrite("pixelVariance", &DarkGainStatistics::pixelVariance,
                       doc("DarkGainStatistics::pixelVariance"))
        .def_readwrite("excessKurtosis", &DarkGainStatistics::excessKurtosis,
                       doc("DarkGainStatistics::excessKurtosis"))
        .def_readwrite("before", &DarkGainStatistics::before, doc("DarkGainStatistics::before"))
        .def_readwrite("after", &DarkGainStatistics::after, doc("DarkGainStatistics::after"));
    py::class_<DarkCalibrationReport>(m, "DarkCalibrationReport", doc("DarkCalibrationReport"))
        .def(keywordInit<DarkCalibrationReport>())
        .def_readwrite("model", &DarkCalibrationReport::model, doc("DarkCalibrationReport::model"))
        .def_readwrite("gains", &DarkCalibrationReport::gains, doc("DarkCalibrationReport::gains"))
        .def_readwrite("ppcc", &DarkCalibrationReport::ppcc, doc("DarkCalibrationReport::ppcc"))
        .def_readwrite("lambdaOfResiduals", &DarkCalibrationReport::lambdaOfResiduals,
                       doc("DarkCalibrationReport::lambdaOfResiduals"))
        .def_readwrite("ppccBest", &DarkCalibrationReport::ppccBest, doc("DarkCalibrationReport::ppccBest"))
        .def_readwrite("ppccGaussian", &DarkCalibrationReport::ppccGaussian,
                       doc("DarkCalibrationReport::ppccGaussian"))
        .def_readwrite("notes", &DarkCalibrationReport::notes, doc("DarkCalibrationReport::notes"));
    m.def(
        "calibrateDarkNoise",
        [](const py::list& bursts, const std::vector<double>& gains, const RawFormat& format,
           const NoiseModel& base, const DarkCalibrationParams& params) {
            std::vector<std::vector<cv::Mat>> frames;
            for (const py::handle& burst : bursts)
                frames.push_back(matsFromList(burst, "bursts", {CV_16U, CV_32F}));
            return withoutGil("calibrateDarkNoise",
                              [&] { return calibrateDarkNoise(frames, gains, format, base, params); });
        },
        py::arg("bursts"), py::arg("gains"), py::arg("format"), py::arg("base"),
        py::arg("params") = DarkCalibrationParams(),
        doc("calibrateDarkNoise",
            "Python: `bursts` is a list (one per gain) of lists of uint16 or float32 HxW "
            "arrays."));
}

//! The verdict of a calibration, and light and dark samples calibrated in one call.
void bindVerdictAndDarkFrames(py::module_& m)
{
    py::class_<CalibrationBurstFacts>(m, "CalibrationBurstFacts", doc("CalibrationBurstFacts"))
        .def(keywordInit<CalibrationBurstFacts>())
        .def_readwrite("name", &CalibrationBurstFacts::name, doc("CalibrationBurstFacts::name"))
        .def_readwrite("gainDb", &CalibrationBurstFacts::gainDb, doc("CalibrationBurstFacts::gainDb"))
        .def_readwrite("frames", &CalibrationBurstFacts::frames, doc("CalibrationBurstFacts::frames"))
        .def_readwrite("clippedFraction", &CalibrationBurstFacts::clippedFraction,
                       doc("CalibrationBurstFacts::clippedFraction"))
        .def_readwrite("dark", &CalibrationBurstFacts::dark, doc("CalibrationBurstFacts::dark"));
    py::class_<VerdictCheck>(m, "VerdictCheck", doc("VerdictCheck"))
        .def(keywordInit<VerdictCheck>())
        .def_readwrite("name", &VerdictCheck::name, doc("VerdictCheck::name"))
        .def_readwrite("passed", &VerdictCheck::pass,
                       doc("VerdictCheck::pass", "Python: `passed` (pass is a keyword)."))
        .def_readwrite("figure", &VerdictCheck::figure, doc("VerdictCheck::figure"));
    py::class_<CalibrationVerdict>(m, "CalibrationVerdict", doc("CalibrationVerdict"))
        .def(keywordInit<CalibrationVerdict>())
        .def_readwrite("passed", &CalibrationVerdict::pass,
                       doc("CalibrationVerdict::pass", "Python: `passed` (pass is a keyword)."))
        .def_readwrite("checks", &CalibrationVerdict::checks, doc("CalibrationVerdict::checks"));
    m.def("fittedVariance", &fittedVariance, py::arg("report"), py::arg("mean"), py::arg("gain"),
          doc("fittedVariance"));
    m.def(
        "judgeCalibration",
        [](const std::vector<NoiseSample>& samples, const CalibrationReport& report,
           const std::vector<CalibrationBurstFacts>& bursts, double signalRange) {
            return withoutGil("judgeCalibration",
                              [&] { return judgeCalibration(samples, report, bursts, signalRange); });
        },
        py::arg("samples"), py::arg("report"), py::arg("bursts"), py::arg("signalRange"),
        doc("judgeCalibration"));
    py::class_<DarkFrameCalibration>(m, "DarkFrameCalibration", doc("DarkFrameCalibration"))
        .def(keywordInit<DarkFrameCalibration>())
        .def_readwrite("report", &DarkFrameCalibration::report, doc("DarkFrameCalibration::report"))
        .def_readwrite("dark", &DarkFrameCalibration::dark, doc("DarkFrameCalibration::dark"))
        .def_readwrite("notes", &DarkFrameCalibration::notes, doc("DarkFrameCalibration::notes"))
        .def_readwrite("samples", &DarkFrameCalibration::samples, doc("DarkFrameCalibration::samples"));
    m.def(
        "calibrateWithDarkFrames",
        [](const std::vector<NoiseSample>& lightSamples, const std::vector<NoiseSample>& darkSamples,
           const py::list& darkBursts, const std::vector<double>& darkGains, const RawFormat& format,
           const CalibrationParams& params, const DarkCalibrationParams& darkParams,
           const std::vector<cv::Size>& lightFrames) {
            std::vector<std::vector<cv::Mat>> frames;
            for (const py::handle& burst : darkBursts)
                frames.push_back(matsFromList(burst, "darkBursts", {CV_16U, CV_32F}));
            return withoutGil("calibrateWithDarkFrames", [&] {
                return calibrateWithDarkFrames(lightSamples, darkSamples, frames, darkGains, format, params,
                                               darkParams, lightFrames);
            });
        },
        py::arg("lightSamples"), py::arg("darkSamples"), py::arg("darkBursts"), py::arg("darkGains"),
        py::arg("format"), py::arg("params") = CalibrationParams(),
        py::arg("darkParams") = DarkCalibrationParams(), py::arg("lightFrames") = std::vector<cv::Size>(),
        doc("calibrateWithDarkFrames", "Python: `darkBursts` is a list (one per gain) of lists of uint16 or "
                                       "float32 HxW arrays; `lightFrames` a list of (width, height)."));
    m.def(
        "darkBurstStatistics",
        [](const py::handle& frames, const RawFormat& format, double gain) {
            const std::vector<cv::Mat> in = matsFromList(frames, "frames", {CV_16U, CV_32F});
            cv::Mat pixelMean;
            const DarkGainStatistics stats = withoutGil(
                "darkBurstStatistics", [&] { return darkBurstStatistics(in, format, gain, pixelMean); });
            return py::make_tuple(stats, arrayFromMat(pixelMean));
        },
        py::arg("frames"), py::arg("format"), py::arg("gain"),
        doc("darkBurstStatistics", "Python: returns (stats, pixelMean); `frames` is a list of uint16 or "
                                   "float32 HxW arrays."));

    m.def(
        "shapiroWilk",
        [](const py::object& samples) {
            cv::Mat in;
            if (py::isinstance<py::array>(samples))
                in = sampleFromArray(samples, "samples");
            else
                in = cv::Mat(samples.cast<std::vector<double>>(), true).reshape(1, 1);
            return withoutGil("shapiroWilk", [&] { return shapiroWilk(in); });
        },
        py::arg("samples"),
        doc("shapiroWilk", "Python: `samples` is a numeric numpy array of any shape (C-contiguous) or a "
                           "sequence of numbers."));
}

//! Shapiro-Wilk of samples, batches and bursts, and its summary by mean.
void bindNormality(py::module_& m)
{
    py::enum_<ShapiroWilkLayout>(m, "ShapiroWilkLayout", doc("ShapiroWilkLayout"))
        .value("SW_SERIES_IN_COLUMNS", SW_SERIES_IN_COLUMNS, doc("ShapiroWilkLayout::SW_SERIES_IN_COLUMNS"))
        .value("SW_SERIES_IN_ROWS", SW_SERIES_IN_ROWS, doc("ShapiroWilkLayout::SW_SERIES_IN_ROWS"))
        .export_values();
    m.def(
        "shapiroWilkBatch",
        [](const py::object& series, ShapiroWilkLayout layout) {
            const cv::Mat in = matFromArray(series, "series", kNumericDepths);
            std::vector<ShapiroWilkResult> results;
            withoutGil("shapiroWilkBatch", [&] { shapiroWilkBatch(in, results, layout); });
            return results;
        },
        py::arg("series"), py::arg("layout") = SW_SERIES_IN_COLUMNS,
        doc("shapiroWilkBatch", "Python: returns the list of results."));
    py::class_<BurstNormality>(m, "BurstNormality", doc("BurstNormality"))
        .def(keywordInit<BurstNormality>())
        .def_readwrite("positions", &BurstNormality::positions, doc("BurstNormality::positions"))
        .def_readwrite("mean", &BurstNormality::mean, doc("BurstNormality::mean"))
        .def_readwrite("distinctValues", &BurstNormality::distinctValues,
                       doc("BurstNormality::distinctValues"))
        .def_readwrite("results", &BurstNormality::results, doc("BurstNormality::results"));
    m.def(
        "shapiroWilkBurst",
        [](const py::object& frames, const std::vector<cv::Point>& positions) {
            const std::vector<cv::Mat> in = matsFromList(frames, "frames", kNumericDepths);
            return withoutGil("shapiroWilkBurst", [&] { return shapiroWilkBurst(in, positions); });
        },
        py::arg("frames"), py::arg("positions") = std::vector<cv::Point>(), doc("shapiroWilkBurst"));
    py::class_<NormalityBin>(m, "NormalityBin", doc("NormalityBin"))
        .def(keywordInit<NormalityBin>())
        .def_readwrite("meanLow", &NormalityBin::meanLow, doc("NormalityBin::meanLow"))
        .def_readwrite("meanHigh", &NormalityBin::meanHigh, doc("NormalityBin::meanHigh"))
        .def_readwrite("count", &NormalityBin::count, doc("NormalityBin::count"))
        .def_readwrite("fractionAboveAlpha", &NormalityBin::fractionAboveAlpha,
                       doc("NormalityBin::fractionAboveAlpha"))
        .def_readwrite("medianPValue", &NormalityBin::medianPValue, doc("NormalityBin::medianPValue"))
        .def_readwrite("meanDistinctValues", &NormalityBin::meanDistinctValues,
                       doc("NormalityBin::meanDistinctValues"));
    m.def("summarizeNormality", &summarizeNormality, py::arg("burst"), py::arg("bins"),
          py::arg("alpha") = 0.05, doc("summarizeNormality"));
}

} // namespace

void bindCalibration(py::module_& m)
{
    bindBurstSampling(m);
    bindLineFits(m);
    bindCalibrationReport(m);
    bindDarkCalibration(m);
    bindVerdictAndDarkFrames(m);
    bindNormality(m);
}

} // namespace rawgment_python
