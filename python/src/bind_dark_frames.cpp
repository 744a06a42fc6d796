// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Python bindings of the dark-frame topic: a bank of real dark frames and its statistics.
#include "binding_tools.hpp"

namespace rawgment_python {

using namespace cv::rawgment;

namespace {

DarkFrameBank deepCopyOf(const DarkFrameBank& bank)
{
    DarkFrameBank copy = bank;
    for (DarkFrameGroup& g : copy.groups) {
        g.statistics.pattern = g.statistics.pattern.clone();
        g.statistics.mean = g.statistics.mean.clone();
        g.statistics.rowVariance = g.statistics.rowVariance.clone();
    }
    return copy;
}

} // namespace

void bindDarkFrames(py::module_& m)
{
    py::class_<DarkFrameStatistics> stats(m, "DarkFrameStatistics", doc("DarkFrameStatistics"));
    stats.def(keywordInit<DarkFrameStatistics>())
        .def_readwrite("frames", &DarkFrameStatistics::frames, doc("DarkFrameStatistics::frames"))
        .def_readwrite("degreesOfFreedom", &DarkFrameStatistics::degreesOfFreedom,
                       doc("DarkFrameStatistics::degreesOfFreedom"))
        .def_readwrite("noisyPixels", &DarkFrameStatistics::noisyPixels,
                       doc("DarkFrameStatistics::noisyPixels", "Python: a list of (x, y) tuples."))
        .def_readwrite("noisyVariance", &DarkFrameStatistics::noisyVariance,
                       doc("DarkFrameStatistics::noisyVariance"))
        .def_readwrite("level", &DarkFrameStatistics::level, doc("DarkFrameStatistics::level"))
        .def_readwrite("temporalVariance", &DarkFrameStatistics::temporalVariance,
                       doc("DarkFrameStatistics::temporalVariance"))
        .def_readwrite("rowNoiseVariance", &DarkFrameStatistics::rowNoiseVariance,
                       doc("DarkFrameStatistics::rowNoiseVariance"))
        .def_readwrite("meanVariance", &DarkFrameStatistics::meanVariance,
                       doc("DarkFrameStatistics::meanVariance"))
        .def_readwrite("patternVariance", &DarkFrameStatistics::patternVariance,
                       doc("DarkFrameStatistics::patternVariance"))
        .def("fixedPatternRms", &DarkFrameStatistics::fixedPatternRms,
             doc("DarkFrameStatistics::fixedPatternRms"));
    defMatProperty(stats, "pattern", &DarkFrameStatistics::pattern, doc("DarkFrameStatistics::pattern"),
                   {CV_32F});
    defMatProperty(stats, "mean", &DarkFrameStatistics::mean, doc("DarkFrameStatistics::mean"), {CV_32F});
    defMatProperty(stats, "rowVariance", &DarkFrameStatistics::rowVariance,
                   doc("DarkFrameStatistics::rowVariance"), {CV_64F});

    py::class_<DarkFrameGroup>(m, "DarkFrameGroup", doc("DarkFrameGroup"))
        .def(keywordInit<DarkFrameGroup>())
        .def_readwrite("gain", &DarkFrameGroup::gain, doc("DarkFrameGroup::gain"))
        .def_readwrite("exposureTime", &DarkFrameGroup::exposureTime, doc("DarkFrameGroup::exposureTime"))
        .def_readwrite("files", &DarkFrameGroup::files, doc("DarkFrameGroup::files"))
        .def_readwrite("fileBytes", &DarkFrameGroup::fileBytes, doc("DarkFrameGroup::fileBytes"))
        .def_readwrite("fingerprints", &DarkFrameGroup::fingerprints, doc("DarkFrameGroup::fingerprints"))
        .def_readwrite("statistics", &DarkFrameGroup::statistics, doc("DarkFrameGroup::statistics"));

    py::class_<DarkFrameBank>(m, "DarkFrameBank",
                              doc("DarkFrameBank",
                                  "Python: pickled as its path (load() in the other process); "
                                  "a bank not saved yet cannot be pickled."))
        .def(keywordInit<DarkFrameBank>())
        .def_readonly_static("FORMAT_VERSION", &DarkFrameBank::FORMAT_VERSION,
                             doc("DarkFrameBank::FORMAT_VERSION"))
        .def_readwrite("path", &DarkFrameBank::path, doc("DarkFrameBank::path"))
        .def_readwrite("format", &DarkFrameBank::format, doc("DarkFrameBank::format"))
        .def_readwrite("size", &DarkFrameBank::size,
                       doc("DarkFrameBank::size", "Python: a tuple (width, height)."))
        .def_readwrite("groups", &DarkFrameBank::groups, doc("DarkFrameBank::groups"))
        .def("empty", &DarkFrameBank::empty, doc("DarkFrameBank::empty"))
        .def_static(
            "create",
            [](const std::vector<std::string>& files, const NoiseModel& model, double falseAlarm) {
                const std::vector<cv::String> paths(files.begin(), files.end());
                return withoutGil("DarkFrameBank.create",
                                  [&] { return DarkFrameBank::create(paths, model, falseAlarm); });
            },
            py::arg("files"), py::arg("model"), py::arg("falseAlarm") = 1e-6, doc("DarkFrameBank::create"))
        .def_static(
            "createFromFolder",
            [](const std::string& folder, const NoiseModel& model, double falseAlarm) {
                return withoutGil("DarkFrameBank.createFromFolder",
                                  [&] { return DarkFrameBank::createFromFolder(folder, model, falseAlarm); });
            },
            py::arg("folder"), py::arg("model"), py::arg("falseAlarm") = 1e-6,
            doc("DarkFrameBank::createFromFolder"))
        .def_static(
            "load",
            [](const std::string& path) {
                return withoutGil("DarkFrameBank.load", [&] { return DarkFrameBank::load(path); });
            },
            py::arg("path"), doc("DarkFrameBank::load"))
        .def(
            "save",
            [](DarkFrameBank& self, const std::string& path) {
                withoutGil("DarkFrameBank.save", [&] { self.save(path); });
            },
            py::arg("path"), doc("DarkFrameBank::save"))
        .def("validate", &DarkFrameBank::validate, doc("DarkFrameBank::validate"))
        .def("nearestGroup", &DarkFrameBank::nearestGroup, py::arg("gain"), py::arg("exposureTime") = 0.0,
             doc("DarkFrameBank::nearestGroup"))
        .def(
            "readFrame",
            [](const DarkFrameBank& self, int group, int index) {
                cv::Mat frame;
                withoutGil("DarkFrameBank.readFrame", [&] { frame = self.readFrame(group, index); });
                return arrayFromMat(frame);
            },
            py::arg("group"), py::arg("index"),
            doc("DarkFrameBank::readFrame", "Python: the uint16 or float32 array."))
        // Copies are made in memory, maps and all: a copy through __reduce__ reloaded the file, which undid
        // every edit since loading and refused a bank not saved (#79 item 11).
        .def("__copy__", [](const DarkFrameBank& self) { return deepCopyOf(self); })
        .def("__deepcopy__", [](const DarkFrameBank& self, py::object) { return deepCopyOf(self); })
        .def("__reduce__", [](const DarkFrameBank& self) {
            if (self.path.empty())
                throw py::type_error("a DarkFrameBank goes to other processes by its path: save() it first");
            // By an absolute path (load and save make it so), and only as the file holds it: an edited bank,
            // or one whose file was replaced, would arrive in the other process as another bank (item 9).
            bool matches = false;
            withoutGil("DarkFrameBank pickling", [&] { matches = self.matchesItsFile(); });
            if (!matches)
                throw py::type_error(
                    "this DarkFrameBank is not its file '" + self.path +
                    "' (edited since it was loaded or saved, or the file replaced): save() it "
                    "to pass it to other processes");
            return py::make_tuple(py::module_::import("rawgment").attr("_load_dark_frame_bank"),
                                  py::make_tuple(self.path));
        });
}

} // namespace rawgment_python
