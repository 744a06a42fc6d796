// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Python bindings of the EMVA 1288 topic: the standard's descriptor and its figures.
#include "binding_tools.hpp"

namespace rawgment_python {

using namespace cv::rawgment;

void bindEmva1288(py::module_& m)
{
    py::class_<Emva1288Images>(m, "Emva1288Images", doc("Emva1288Images"))
        .def(keywordInit<Emva1288Images>())
        .def_readwrite("exposureNs", &Emva1288Images::exposureNs, doc("Emva1288Images::exposureNs"))
        .def_readwrite("photons", &Emva1288Images::photons, doc("Emva1288Images::photons"))
        .def_readwrite("dark", &Emva1288Images::dark, doc("Emva1288Images::dark"))
        .def_readwrite("images", &Emva1288Images::images, doc("Emva1288Images::images"))
        .def_readwrite("line", &Emva1288Images::line, doc("Emva1288Images::line"));
    py::class_<Emva1288Series>(m, "Emva1288Series", doc("Emva1288Series"))
        .def(keywordInit<Emva1288Series>())
        .def_readwrite("path", &Emva1288Series::path, doc("Emva1288Series::path"))
        .def_readwrite("version", &Emva1288Series::version, doc("Emva1288Series::version"))
        .def_readwrite("bits", &Emva1288Series::bits, doc("Emva1288Series::bits"))
        .def_readwrite("width", &Emva1288Series::width, doc("Emva1288Series::width"))
        .def_readwrite("height", &Emva1288Series::height, doc("Emva1288Series::height"))
        .def_readwrite("temporal", &Emva1288Series::temporal, doc("Emva1288Series::temporal"))
        .def_readwrite("spatial", &Emva1288Series::spatial, doc("Emva1288Series::spatial"));
    m.attr("MAX_EMVA1288_BITS") = MAX_EMVA1288_BITS;
    m.attr("MAX_EMVA1288_PIXELS") = MAX_EMVA1288_PIXELS;
    m.attr("MAX_EMVA1288_IMAGES") = MAX_EMVA1288_IMAGES;
    m.attr("MAX_EMVA1288_PHOTONS") = MAX_EMVA1288_PHOTONS;
    m.attr("MAX_EMVA1288_EXPOSURE") = MAX_EMVA1288_EXPOSURE;
    m.def(
        "readEmva1288",
        [](const std::string& path) {
            return withoutGil("readEmva1288", [&] { return readEmva1288(path); });
        },
        py::arg("path"), doc("readEmva1288"));
    m.def(
        "readEmva1288Image",
        [](const Emva1288Series& series, const std::string& imagePath, int line) {
            cv::Mat image;
            withoutGil("readEmva1288Image", [&] { image = readEmva1288Image(series, imagePath, line); });
            return arrayFromMat(image);
        },
        py::arg("series"), py::arg("imagePath"), py::arg("line") = 0,
        doc("readEmva1288Image", "Python: returns the uint8 or uint16 array."));

    py::class_<Emva1288Pair>(m, "Emva1288Pair", doc("Emva1288Pair"))
        .def(keywordInit<Emva1288Pair>())
        .def_readwrite("exposureNs", &Emva1288Pair::exposureNs, doc("Emva1288Pair::exposureNs"))
        .def_readwrite("photons", &Emva1288Pair::photons, doc("Emva1288Pair::photons"))
        .def_readwrite("dark", &Emva1288Pair::dark, doc("Emva1288Pair::dark"))
        .def_readwrite("mean", &Emva1288Pair::mean, doc("Emva1288Pair::mean"))
        .def_readwrite("variance", &Emva1288Pair::variance, doc("Emva1288Pair::variance"))
        .def_readwrite("varianceStdError", &Emva1288Pair::varianceStdError,
                       doc("Emva1288Pair::varianceStdError"));
    m.def(
        "measureEmva1288Pair",
        [](const py::object& a, const py::object& b, double exposureNs, double photons, bool dark) {
            const cv::Mat ma = matFromArray(a, "a", {CV_8U, CV_16U, CV_32F});
            const cv::Mat mb = matFromArray(b, "b", {CV_8U, CV_16U, CV_32F});
            return withoutGil("measureEmva1288Pair",
                              [&] { return measureEmva1288Pair(ma, mb, exposureNs, photons, dark); });
        },
        py::arg("a"), py::arg("b"), py::arg("exposureNs"), py::arg("photons"), py::arg("dark"),
        doc("measureEmva1288Pair"));
    py::class_<Emva1288Stack>(m, "Emva1288Stack", doc("Emva1288Stack"))
        .def(keywordInit<Emva1288Stack>())
        .def_readwrite("exposureNs", &Emva1288Stack::exposureNs, doc("Emva1288Stack::exposureNs"))
        .def_readwrite("photons", &Emva1288Stack::photons, doc("Emva1288Stack::photons"))
        .def_readwrite("dark", &Emva1288Stack::dark, doc("Emva1288Stack::dark"))
        .def_readwrite("frames", &Emva1288Stack::frames, doc("Emva1288Stack::frames"))
        .def_readwrite("mean", &Emva1288Stack::mean, doc("Emva1288Stack::mean"))
        .def_readwrite("variance", &Emva1288Stack::variance, doc("Emva1288Stack::variance"));
    m.def(
        "measureEmva1288Stack",
        [](const py::object& frames, double exposureNs, double photons, bool dark) {
            const std::vector<cv::Mat> in = matsFromList(frames, "frames", {CV_8U, CV_16U, CV_32F});
            return withoutGil("measureEmva1288Stack",
                              [&] { return measureEmva1288Stack(in, exposureNs, photons, dark); });
        },
        py::arg("frames"), py::arg("exposureNs"), py::arg("photons"), py::arg("dark"),
        doc("measureEmva1288Stack"));

    auto results = py::class_<Emva1288Results>(m, "Emva1288Results", doc("Emva1288Results"));
    results.def(keywordInit<Emva1288Results>());
#define RAWGMENT_EMVA_FIELD(name)                                                                            \
    results.def_readwrite(#name, &Emva1288Results::name, doc("Emva1288Results::" #name))
    RAWGMENT_EMVA_FIELD(K);
    RAWGMENT_EMVA_FIELD(sigmaYDark);
    RAWGMENT_EMVA_FIELD(sigmaD);
    RAWGMENT_EMVA_FIELD(responsivity);
    RAWGMENT_EMVA_FIELD(eta);
    RAWGMENT_EMVA_FIELD(muPSat);
    RAWGMENT_EMVA_FIELD(muESat);
    RAWGMENT_EMVA_FIELD(snrMax);
    RAWGMENT_EMVA_FIELD(snrMaxDb);
    RAWGMENT_EMVA_FIELD(muPMin);
    RAWGMENT_EMVA_FIELD(dynamicRangeDb);
    RAWGMENT_EMVA_FIELD(dsnu1288);
    RAWGMENT_EMVA_FIELD(prnu1288);
    RAWGMENT_EMVA_FIELD(linearityErrorMin);
    RAWGMENT_EMVA_FIELD(linearityErrorMax);
    RAWGMENT_EMVA_FIELD(photonsGiven);
    RAWGMENT_EMVA_FIELD(exposureNs);
    RAWGMENT_EMVA_FIELD(photons);
    RAWGMENT_EMVA_FIELD(mean);
    RAWGMENT_EMVA_FIELD(variance);
    RAWGMENT_EMVA_FIELD(darkMean);
    RAWGMENT_EMVA_FIELD(darkVariance);
    RAWGMENT_EMVA_FIELD(saturationIndex);
    RAWGMENT_EMVA_FIELD(sensitivityMaxIndex);
    RAWGMENT_EMVA_FIELD(linearityMinIndex);
    RAWGMENT_EMVA_FIELD(linearityMaxIndex);
    RAWGMENT_EMVA_FIELD(linearityFitSlope);
    RAWGMENT_EMVA_FIELD(linearityFitOffset);
    RAWGMENT_EMVA_FIELD(linearityDeviation);
    RAWGMENT_EMVA_FIELD(varianceStdError);
    RAWGMENT_EMVA_FIELD(darkVarianceStdError);
    RAWGMENT_EMVA_FIELD(pairs);
    RAWGMENT_EMVA_FIELD(stacks);
#undef RAWGMENT_EMVA_FIELD
    m.def(
        "emva1288Results",
        [](const Emva1288Series& series) {
            return withoutGil("emva1288Results", [&] { return emva1288Results(series); });
        },
        py::arg("series"), doc("emva1288Results"));
    m.def(
        "emva1288Results",
        [](const std::vector<Emva1288Pair>& pairs, const std::vector<Emva1288Stack>& stacks) {
            return withoutGil("emva1288Results", [&] { return emva1288Results(pairs, stacks); });
        },
        py::arg("pairs"), py::arg("stacks") = std::vector<Emva1288Stack>(), doc("emva1288Results"));

    auto darkening = py::class_<Emva1288Darkening>(m, "Emva1288Darkening", doc("Emva1288Darkening"));
    darkening.def(keywordInit<Emva1288Darkening>());
#define RAWGMENT_EMVA_FIELD(name)                                                                            \
    darkening.def_readwrite(#name, &Emva1288Darkening::name, doc("Emva1288Darkening::" #name))
    RAWGMENT_EMVA_FIELD(brightPoint);
    RAWGMENT_EMVA_FIELD(darkPoint);
    RAWGMENT_EMVA_FIELD(photonRatio);
    RAWGMENT_EMVA_FIELD(alignment);
    RAWGMENT_EMVA_FIELD(augmentedVariance);
    RAWGMENT_EMVA_FIELD(augmentedStdError);
    RAWGMENT_EMVA_FIELD(realVariance);
    RAWGMENT_EMVA_FIELD(realStdError);
    RAWGMENT_EMVA_FIELD(ratio);
    RAWGMENT_EMVA_FIELD(ratioStdError);
    RAWGMENT_EMVA_FIELD(pairScatter);
    RAWGMENT_EMVA_FIELD(histogramEdges);
    RAWGMENT_EMVA_FIELD(augmentedHistogram);
    RAWGMENT_EMVA_FIELD(realHistogram);
#undef RAWGMENT_EMVA_FIELD
    m.def("emva1288DarkeningSteps", &emva1288DarkeningSteps, py::arg("results"), py::arg("count") = 5,
          doc("emva1288DarkeningSteps", "Python: returns a list of (bright, dark) points."));
    m.def(
        "emva1288Darkening",
        [](const Emva1288Series& series, const Emva1288Results& results, const NoiseModel& model,
           const std::vector<cv::Point>& steps, uint64 seed) {
            return withoutGil("emva1288Darkening",
                              [&] { return emva1288Darkening(series, results, model, steps, seed); });
        },
        py::arg("series"), py::arg("results"), py::arg("model"), py::arg("steps"), py::arg("seed"),
        doc("emva1288Darkening"));

    py::class_<Emva1288CalibrationParams>(m, "Emva1288CalibrationParams", doc("Emva1288CalibrationParams"))
        .def(keywordInit<Emva1288CalibrationParams>())
        .def_readwrite("maxSignalFraction", &Emva1288CalibrationParams::maxSignalFraction,
                       doc("Emva1288CalibrationParams::maxSignalFraction"))
        .def_readwrite("minGainRatio", &Emva1288CalibrationParams::minGainRatio,
                       doc("Emva1288CalibrationParams::minGainRatio"));
    m.def(
        "calibrateEmva1288",
        [](const std::vector<Emva1288Results>& measurements, const std::vector<double>& gains,
           const Emva1288CalibrationParams& params) {
            return withoutGil("calibrateEmva1288",
                              [&] { return calibrateEmva1288(measurements, gains, params); });
        },
        py::arg("measurements"), py::arg("gains"), py::arg("params") = Emva1288CalibrationParams(),
        doc("calibrateEmva1288"));
    m.def("emva1288LineAtGain", &emva1288LineAtGain, py::arg("report"), py::arg("gain"),
          py::return_value_policy::copy, doc("emva1288LineAtGain"));
    m.def("judgeEmva1288", &judgeEmva1288, py::arg("results"), py::arg("gains"), py::arg("report"),
          py::arg("params") = Emva1288CalibrationParams(), doc("judgeEmva1288"));
}

} // namespace rawgment_python
