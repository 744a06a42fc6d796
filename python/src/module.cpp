// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The Python module `rawgment._rawgment`: shared conversions, errors, and the core topics (Bayer
// layout, noise model, CPU paths, simulator).
#include "binding_tools.hpp"

#include "rawgment_docstrings.hpp"

#include <algorithm>
#include <climits>
#include <cstring>
#include <deque>
#include <mutex>
#include <set>
#include <stdexcept>

namespace rawgment_python {

using namespace cv::rawgment;

namespace {

std::mutex gilRecordMutex;
std::set<std::string>& callsWithoutGil()
{
    static std::set<std::string> calls;
    return calls;
}

//! The numpy dtypes of OpenCV's single-channel depths: one table for both directions.
struct DtypeOfDepth
{
    int depth;
    char kind; // numpy's dtype.kind
    py::ssize_t itemsize;
    const char* name;
};
constexpr DtypeOfDepth kDtypes[] = {{CV_8U, 'u', 1, "uint8"},   {CV_8S, 'i', 1, "int8"},
                                    {CV_16U, 'u', 2, "uint16"}, {CV_16S, 'i', 2, "int16"},
                                    {CV_32S, 'i', 4, "int32"},  {CV_32F, 'f', 4, "float32"},
                                    {CV_64F, 'f', 8, "float64"}};

int depthOfDtype(const py::dtype& dtype)
{
    for (const DtypeOfDepth& d : kDtypes)
        if (d.kind == dtype.kind() && d.itemsize == dtype.itemsize())
            return d.depth;
    return -1;
}

std::string allowedDtypes(const std::vector<int>& depths)
{
    std::string names;
    for (size_t i = 0; i < depths.size(); ++i)
        names += std::string(i == 0 ? "" : (i + 1 == depths.size() ? " or " : ", ")) + dtypeName(depths[i]);
    return names;
}

std::string shapeOf(const py::array& a)
{
    std::string s = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i)
        s += std::to_string(a.shape(i)) + (a.ndim() == 1 ? "," : (i + 1 < a.ndim() ? ", " : ""));
    return s + ")";
}

py::array requireArray(const py::handle& obj, const char* argument, const std::string& expected)
{
    if (!py::isinstance<py::array>(obj))
        throw py::type_error(std::string("argument '") + argument + "' must be a numpy array (" + expected +
                             "), not " + std::string(py::str(obj.get_type().attr("__name__"))));
    const py::array a = py::reinterpret_borrow<py::array>(obj);
    if (a.dtype().attr("isnative").cast<bool>() == false)
        throw py::type_error(
            std::string("argument '") + argument +
            "' has a non-native byte order; convert it with .astype(its dtype.newbyteorder('='))");
    return a;
}

} // namespace

const char* doc(const std::string& cxxName, const std::string& pythonNote)
{
    // pybind11 keeps the pointers it is given for some docstrings: they live as long as the module.
    static std::deque<std::string> kept;
    const auto& docs = cxxDocstrings();
    const auto it = docs.find(cxxName);
    if (it == docs.end())
        throw std::logic_error("rawgment: no C++ documentation for '" + cxxName + "'");
    kept.push_back(pythonNote.empty() ? std::string(it->second) : pythonNote + "\n\n" + it->second);
    return kept.back().c_str();
}

const char* dtypeName(int depth)
{
    for (const DtypeOfDepth& d : kDtypes)
        if (d.depth == depth)
            return d.name;
    return "unsupported";
}

cv::Mat matFromArray(const py::handle& obj, const char* argument, const std::vector<int>& depths,
                     bool allowChannels)
{
    const std::string expected =
        std::string(allowChannels ? "HxW or HxWxC" : "HxW") + " " + allowedDtypes(depths);
    const py::array a = requireArray(obj, argument, expected);
    const int depth = depthOfDtype(a.dtype());
    if (std::find(depths.begin(), depths.end(), depth) == depths.end())
        throw py::type_error(std::string("argument '") + argument + "' has dtype " +
                             std::string(py::str(a.dtype())) + "; expected " + allowedDtypes(depths));
    const bool withChannels = allowChannels && a.ndim() == 3;
    if (a.ndim() != 2 && !withChannels)
        throw py::value_error(std::string("argument '") + argument + "' must be " +
                              (allowChannels ? "2-D (HxW) or 3-D (HxWxC)" : "2-D (HxW)") + ", got shape " +
                              shapeOf(a));
    const int channels = withChannels ? static_cast<int>(a.shape(2)) : 1;
    if (channels < 1 || channels > 4)
        throw py::value_error(std::string("argument '") + argument + "' has " + std::to_string(channels) +
                              " channels; expected 1 to 4");
    const auto rows = a.shape(0), cols = a.shape(1);
    if (rows > INT_MAX || cols > INT_MAX)
        throw py::value_error(std::string("argument '") + argument + "' is too large for OpenCV");
    // An array without elements has no layout to speak of (numpy gives 0x4 strides of 0): the callee
    // says the input is empty, which a copy would not change.
    if (rows == 0 || cols == 0)
        return cv::Mat();
    const auto item = a.itemsize();
    const py::ssize_t pixelStride = withChannels ? item * channels : item;
    const bool elementsContiguous =
        (!withChannels || a.strides(2) == item) && (cols <= 1 || a.strides(1) == pixelStride);
    const py::ssize_t rowStride = rows <= 1 ? cols * pixelStride : a.strides(0);
    if (!elementsContiguous || rowStride < cols * pixelStride || rowStride % item != 0)
        throw py::value_error(
            std::string("argument '") + argument + "' is not contiguous (shape " + shapeOf(a) +
            ", strides in bytes " +
            std::string(py::str(py::cast(std::vector<py::ssize_t>(a.strides(), a.strides() + a.ndim())))) +
            "); pass numpy.ascontiguousarray(" + argument + ")");
    return cv::Mat(static_cast<int>(rows), static_cast<int>(cols), CV_MAKETYPE(depth, channels),
                   const_cast<void*>(a.data()), static_cast<size_t>(rowStride));
}

cv::Mat sampleFromArray(const py::handle& obj, const char* argument)
{
    const std::vector<int> depths{CV_8U, CV_8S, CV_16U, CV_16S, CV_32S, CV_32F, CV_64F};
    const py::array a = requireArray(obj, argument, "any shape, numeric");
    const int depth = depthOfDtype(a.dtype());
    if (depth < 0)
        throw py::type_error(std::string("argument '") + argument + "' has dtype " +
                             std::string(py::str(a.dtype())) + "; expected " + allowedDtypes(depths));
    if (!(a.flags() & py::array::c_style))
        throw py::value_error(std::string("argument '") + argument +
                              "' is not C-contiguous; pass numpy.ascontiguousarray(" + argument + ")");
    if (a.size() > INT_MAX)
        throw py::value_error(std::string("argument '") + argument + "' is too large");
    return cv::Mat(1, static_cast<int>(a.size()), CV_MAKETYPE(depth, 1), const_cast<void*>(a.data()));
}

std::vector<cv::Mat> matsFromList(const py::handle& list, const char* argument,
                                  const std::vector<int>& depths)
{
    if (!py::isinstance<py::sequence>(list) || py::isinstance<py::array>(list) ||
        py::isinstance<py::str>(list))
        throw py::type_error(std::string("argument '") + argument + "' must be a list of numpy arrays");
    std::vector<cv::Mat> mats;
    const py::sequence seq = py::reinterpret_borrow<py::sequence>(list);
    for (size_t i = 0; i < seq.size(); ++i) {
        const std::string name = std::string(argument) + "[" + std::to_string(i) + "]";
        mats.push_back(matFromArray(seq[i], name.c_str(), depths));
    }
    return mats;
}

cv::Mat outputMatLike(const py::object& dst, const char* argument, const cv::Mat& like)
{
    // Without an input there is nothing to be like: the call itself reports the empty input.
    if (dst.is_none() || like.empty())
        return cv::Mat();
    const cv::Mat m = matFromArray(dst, argument, {like.depth()}, like.channels() > 1);
    if (m.size() != like.size() || m.type() != like.type())
        throw py::value_error(std::string("argument '") + argument + "' has shape " +
                              shapeOf(py::reinterpret_borrow<py::array>(dst)) + "; expected " +
                              std::to_string(like.rows) + " x " + std::to_string(like.cols) +
                              ", the shape of src");
    if (!py::reinterpret_borrow<py::array>(dst).writeable())
        throw py::value_error(std::string("argument '") + argument + "' is read-only");
    return m;
}

py::object resultInto(const py::object& dst, const cv::Mat& target, const cv::Mat& out)
{
    if (dst.is_none())
        return arrayFromMat(out);
    if (out.data != target.data)
        out.copyTo(target);
    return dst;
}

py::array arrayFromMat(const cv::Mat& mat)
{
    const int depth = mat.depth();
    const py::dtype dtype(dtypeName(depth));
    if (mat.empty())
        return py::array(dtype, std::vector<py::ssize_t>{0, 0});
    const auto esz1 = static_cast<py::ssize_t>(mat.elemSize1());
    std::vector<py::ssize_t> shape{mat.rows, mat.cols};
    std::vector<py::ssize_t> strides{static_cast<py::ssize_t>(mat.step[0]),
                                     static_cast<py::ssize_t>(mat.elemSize())};
    if (mat.channels() > 1) {
        shape.push_back(mat.channels());
        strides.push_back(esz1);
    }
    if (mat.u != nullptr) {
        // The capsule holds a reference to OpenCV's buffer: the array shares it, no copy.
        auto* owner = new cv::Mat(mat);
        const py::capsule keep(owner, [](void* p) { delete static_cast<cv::Mat*>(p); });
        return py::array(dtype, shape, strides, owner->data, keep);
    }
    py::array copy(dtype, shape);
    const size_t rowBytes = mat.cols * mat.elemSize();
    auto* dst = static_cast<uchar*>(copy.mutable_data());
    for (int r = 0; r < mat.rows; ++r)
        std::memcpy(dst + r * rowBytes, mat.ptr(r), rowBytes);
    return copy;
}

void noteCallWithoutGil(const char* name)
{
    std::lock_guard<std::mutex> lock(gilRecordMutex);
    callsWithoutGil().insert(name);
}

bool isDataProperty(const py::handle& type, const std::string& name)
{
    static const py::object property = py::module_::import("builtins").attr("property");
    for (const py::handle& base : type.attr("__mro__")) {
        const py::dict attributes = base.attr("__dict__");
        // Exactly `property`: pybind11's static properties (FORMAT_VERSION) derive from it.
        if (attributes.contains(name.c_str()))
            return py::type::of(attributes[name.c_str()]).is(property);
    }
    return false;
}

namespace {

//! CFA patterns, formats, planes and black levels.
void bindBayer(py::module_& m)
{
    py::enum_<CfaPattern>(m, "CfaPattern", doc("CfaPattern"))
        .value("CFA_RGGB", CFA_RGGB, doc("CfaPattern::CFA_RGGB"))
        .value("CFA_BGGR", CFA_BGGR, doc("CfaPattern::CFA_BGGR"))
        .value("CFA_GRBG", CFA_GRBG, doc("CfaPattern::CFA_GRBG"))
        .value("CFA_GBRG", CFA_GBRG, doc("CfaPattern::CFA_GBRG"))
        .value("CFA_MONO", CFA_MONO, doc("CfaPattern::CFA_MONO"))
        .export_values();
    py::enum_<CfaChannel>(m, "CfaChannel", doc("CfaChannel"))
        .value("CFA_R", CFA_R, doc("CfaChannel::CFA_R"))
        .value("CFA_G1", CFA_G1, doc("CfaChannel::CFA_G1"))
        .value("CFA_G2", CFA_G2, doc("CfaChannel::CFA_G2"))
        .value("CFA_B", CFA_B, doc("CfaChannel::CFA_B"))
        .value("CFA_W", CFA_W, doc("CfaChannel::CFA_W"))
        .export_values();
    m.def("cfaSite", &cfaSite, py::arg("row"), py::arg("col"), doc("cfaSite"));
    m.def("cfaChannelAt", &cfaChannelAt, py::arg("pattern"), py::arg("row"), py::arg("col"),
          doc("cfaChannelAt"));
    m.def("cfaSiteOfChannel", &cfaSiteOfChannel, py::arg("pattern"), py::arg("channel"),
          doc("cfaSiteOfChannel"));
    m.def("cfaPatternOfCrop", &cfaPatternOfCrop, py::arg("pattern"), py::arg("rowOffset"),
          py::arg("colOffset"), doc("cfaPatternOfCrop"));
    m.def("cfaPatternName", &cfaPatternName, py::arg("pattern"), doc("cfaPatternName"));
    m.def("cfaPatternFromName", &cfaPatternFromName, py::arg("name"), doc("cfaPatternFromName"));

    py::class_<RawFormat>(m, "RawFormat",
                          doc("RawFormat", "Keyword construction: RawFormat(pattern=CFA_GRBG, "
                                           "blackLevel=(64, 64, 64, 64), whiteLevel=1023)."))
        .def(keywordInit<RawFormat>())
        .def_readwrite("pattern", &RawFormat::pattern, doc("RawFormat::pattern"))
        .def_readwrite("blackLevel", &RawFormat::blackLevel, doc("RawFormat::blackLevel"))
        .def_readwrite("whiteLevel", &RawFormat::whiteLevel, doc("RawFormat::whiteLevel"))
        .def_readwrite("gain", &RawFormat::gain, doc("RawFormat::gain"))
        .def_readwrite("sensorOrigin", &RawFormat::sensorOrigin,
                       doc("RawFormat::sensorOrigin", "Python: a tuple (x, y)."))
        .def_readwrite("exposureTime", &RawFormat::exposureTime, doc("RawFormat::exposureTime"))
        .def("validate", &RawFormat::validate, doc("RawFormat::validate"))
        .def("blackAt", &RawFormat::blackAt, py::arg("row"), py::arg("col"), doc("RawFormat::blackAt"))
        .def("isMonochrome", &RawFormat::isMonochrome, doc("RawFormat::isMonochrome"))
        .def("cropped", &RawFormat::cropped, py::arg("rowOffset"), py::arg("colOffset"),
             doc("RawFormat::cropped"));

    m.def(
        "splitCfaPlanes",
        [](const py::object& mosaic) {
            const cv::Mat in =
                matFromArray(mosaic, "mosaic", {CV_8U, CV_16U, CV_16S, CV_32S, CV_32F, CV_64F});
            std::vector<cv::Mat> planes;
            withoutGil("splitCfaPlanes", [&] { splitCfaPlanes(in, planes); });
            py::list out;
            for (const cv::Mat& p : planes)
                out.append(arrayFromMat(p));
            return out;
        },
        py::arg("mosaic"), doc("splitCfaPlanes", "Python: returns a list of the four planes."));
    m.def(
        "mergeCfaPlanes",
        [](const py::object& planes) {
            const std::vector<cv::Mat> in =
                matsFromList(planes, "planes", {CV_8U, CV_16U, CV_16S, CV_32S, CV_32F, CV_64F});
            return arrayFromCall("mergeCfaPlanes", [&](cv::Mat& mosaic) { mergeCfaPlanes(in, mosaic); });
        },
        py::arg("planes"), doc("mergeCfaPlanes", "Python: returns the mosaic."));
    m.def(
        "subtractBlackLevel",
        [](const py::object& src, const RawFormat& format, bool normalize) {
            const cv::Mat in = matFromArray(src, "src", {CV_16U, CV_32F});
            return arrayFromCall("subtractBlackLevel",
                                 [&](cv::Mat& dst) { subtractBlackLevel(in, format, dst, normalize); });
        },
        py::arg("src"), py::arg("format"), py::arg("normalize") = false,
        doc("subtractBlackLevel", "Python: returns dst (float32)."));
    m.def(
        "packCfaPlanes",
        [](const py::object& mosaic, const RawFormat& format, bool normalize, const py::object& out) {
            const cv::Mat in = matFromArray(mosaic, "mosaic", {CV_16U, CV_32F});
            if (out.is_none()) {
                py::array planes = arrayFromCall(
                    "packCfaPlanes", [&](cv::Mat& dst) { packCfaPlanes(in, format, dst, normalize); });
                return py::object(planes.attr("reshape")(4, in.rows / 2, in.cols / 2));
            }
            // The caller's memory (a tensor's numpy view): float32, C-contiguous, 4 x rows/2 x cols/2.
            const auto target = py::array::ensure(out);
            if (!target || !py::isinstance<py::array_t<float>>(target))
                throw py::type_error("packCfaPlanes: out must be a float32 numpy array");
            if (target.ndim() != 3 || target.shape(0) != 4 || target.shape(1) != in.rows / 2 ||
                target.shape(2) != in.cols / 2)
                throw py::value_error(
                    cv::format("packCfaPlanes: out must have shape (4, %d, %d)", in.rows / 2, in.cols / 2));
            if (!(target.flags() & py::array::c_style) || !target.writeable())
                throw py::value_error("packCfaPlanes: out must be C-contiguous and writable");
            cv::Mat dst(2 * in.rows, in.cols / 2, CV_32FC1, const_cast<void*>(target.data()));
            withoutGil("packCfaPlanes", [&] { packCfaPlanes(in, format, dst, normalize); });
            return out;
        },
        py::arg("mosaic"), py::arg("format"), py::arg("normalize") = true, py::arg("out") = py::none(),
        doc("packCfaPlanes",
            "Python: returns a float32 array of shape (4, rows/2, cols/2), or writes into "
            "`out` (such an array: a torch tensor's .numpy(), for example) and returns it."));
    m.def(
        "addBlackLevel",
        [](const py::object& src, const RawFormat& format, int ddepth, bool normalized) {
            const cv::Mat in = matFromArray(src, "src", {CV_32F});
            return arrayFromCall("addBlackLevel",
                                 [&](cv::Mat& dst) { addBlackLevel(in, format, dst, ddepth, normalized); });
        },
        py::arg("src"), py::arg("format"), py::arg("ddepth") = int(CV_16U), py::arg("normalized") = false,
        doc("addBlackLevel", "Python: returns dst; ddepth is rawgment.CV_16U or rawgment.CV_32F."));
}

//! The noise model, its lines and files.
void bindNoiseModel(py::module_& m)
{
    m.def("dbToLinearGain", &dbToLinearGain, py::arg("db"), doc("dbToLinearGain"));
    m.def("linearGainToDb", &linearGainToDb, py::arg("gain"), doc("linearGainToDb"));
    py::class_<NoiseLine>(m, "NoiseLine", doc("NoiseLine"))
        .def(keywordInit<NoiseLine>())
        .def_readwrite("a", &NoiseLine::a, doc("NoiseLine::a"))
        .def_readwrite("b", &NoiseLine::b, doc("NoiseLine::b"));
    py::class_<MeasuredNoiseLine>(m, "MeasuredNoiseLine", doc("MeasuredNoiseLine"))
        .def(keywordInit<MeasuredNoiseLine>())
        .def_readwrite("gain", &MeasuredNoiseLine::gain, doc("MeasuredNoiseLine::gain"))
        .def_readwrite("line", &MeasuredNoiseLine::line, doc("MeasuredNoiseLine::line"))
        .def_readwrite("slopeStdError", &MeasuredNoiseLine::slopeStdError,
                       doc("MeasuredNoiseLine::slopeStdError"))
        .def_readwrite("offsetStdError", &MeasuredNoiseLine::offsetStdError,
                       doc("MeasuredNoiseLine::offsetStdError"))
        .def_readwrite("iso", &MeasuredNoiseLine::iso, doc("MeasuredNoiseLine::iso"));
    py::class_<NoiseModel>(
        m, "NoiseModel",
        doc("NoiseModel", "Python: NoiseModel(alpha, sigmaD2, sigmaR2), by position or keyword."))
        .def(py::init<>())
        .def(py::init<double, double, double>(), py::arg("alpha"), py::arg("sigmaD2"), py::arg("sigmaR2"),
             doc("NoiseModel::NoiseModel"))
        .def_readonly_static("FORMAT_VERSION", &NoiseModel::FORMAT_VERSION, doc("NoiseModel::FORMAT_VERSION"))
        .def_readwrite("alpha", &NoiseModel::alpha, doc("NoiseModel::alpha"))
        .def_readwrite("sigmaD2", &NoiseModel::sigmaD2, doc("NoiseModel::sigmaD2"))
        .def_readwrite("sigmaR2", &NoiseModel::sigmaR2, doc("NoiseModel::sigmaR2"))
        .def_readwrite("baseIso", &NoiseModel::baseIso, doc("NoiseModel::baseIso"))
        .def_readwrite("failedCalibration", &NoiseModel::failedCalibration,
                       doc("NoiseModel::failedCalibration"))
        .def_readwrite("rowSigmaD2", &NoiseModel::rowSigmaD2, doc("NoiseModel::rowSigmaD2"))
        .def_readwrite("rowSigmaR2", &NoiseModel::rowSigmaR2, doc("NoiseModel::rowSigmaR2"))
        .def_readwrite("tukeyRead", &NoiseModel::tukeyRead, doc("NoiseModel::tukeyRead"))
        .def_readwrite("tukeyLambda", &NoiseModel::tukeyLambda, doc("NoiseModel::tukeyLambda"))
        .def_readwrite(
            "measuredLines", &NoiseModel::measuredLines,
            doc("NoiseModel::measuredLines", "Python: a list (a copy); assign a new list to change it."))
        .def("hasMeasuredLines", &NoiseModel::hasMeasuredLines, doc("NoiseModel::hasMeasuredLines"))
        .def_property(
            "darkShadingPerGain",
            [](const NoiseModel& self) -> py::object {
                return self.darkShadingPerGain.empty()
                           ? py::object(py::none())
                           : py::object(arrayFromMat(self.darkShadingPerGain.clone()));
            },
            [](NoiseModel& self, const py::object& map) {
                self.darkShadingPerGain =
                    map.is_none() ? cv::Mat() : matFromArray(map, "darkShadingPerGain", {CV_32F}).clone();
            },
            doc("NoiseModel::darkShadingPerGain", "Python: a float32 HxW array (a copy), or None."))
        .def_property(
            "darkShadingOffset",
            [](const NoiseModel& self) -> py::object {
                return self.darkShadingOffset.empty()
                           ? py::object(py::none())
                           : py::object(arrayFromMat(self.darkShadingOffset.clone()));
            },
            [](NoiseModel& self, const py::object& map) {
                self.darkShadingOffset =
                    map.is_none() ? cv::Mat() : matFromArray(map, "darkShadingOffset", {CV_32F}).clone();
            },
            doc("NoiseModel::darkShadingOffset", "Python: a float32 HxW array (a copy), or None."))
        .def("hasRowNoise", &NoiseModel::hasRowNoise, doc("NoiseModel::hasRowNoise"))
        .def("hasDarkShading", &NoiseModel::hasDarkShading, doc("NoiseModel::hasDarkShading"))
        .def("hasDarkComponents", &NoiseModel::hasDarkComponents, doc("NoiseModel::hasDarkComponents"))
        .def("readExcessKurtosis", &NoiseModel::readExcessKurtosis, doc("NoiseModel::readExcessKurtosis"))
        .def("rowVariance", &NoiseModel::rowVariance, py::arg("gain"), doc("NoiseModel::rowVariance"))
        .def(
            "darkShadingAt",
            [](const NoiseModel& self, double gain) -> py::object {
                const cv::Mat s = self.darkShadingAt(gain);
                return s.empty() ? py::object(py::none()) : py::object(arrayFromMat(s));
            },
            py::arg("gain"), doc("NoiseModel::darkShadingAt", "Python: a float32 array, or None."))
        .def("validate", &NoiseModel::validate, doc("NoiseModel::validate"))
        .def("lineAtGain", &NoiseModel::lineAtGain, py::arg("gain"), doc("NoiseModel::lineAtGain"))
        .def(
            "variance",
            [](const NoiseModel& self, const py::object& mean, double gain) -> py::object {
                if (!py::isinstance<py::array>(mean))
                    return py::float_(self.variance(mean.cast<double>(), gain));
                const cv::Mat in = matFromArray(mean, "mean", {CV_32F, CV_64F});
                return arrayFromCall("NoiseModel.variance",
                                     [&](cv::Mat& dst) { self.variance(in, gain, dst); });
            },
            py::arg("mean"), py::arg("gain"),
            doc("NoiseModel::variance", "Python: `mean` is a number (returns a float) or a float32/float64 "
                                        "array (returns an array of the same shape and dtype)."))
        .def("save", &NoiseModel::save, py::arg("path"), doc("NoiseModel::save"))
        .def_static("load", &NoiseModel::load, py::arg("path"), py::arg("acceptFailedCalibration") = false,
                    doc("NoiseModel::load"));
}

//! The instruction-set paths of the hot loops.
void bindCpu(py::module_& m)
{
    py::enum_<CpuPath>(m, "CpuPath", doc("CpuPath"))
        .value("AUTO", CpuPath::AUTO, doc("CpuPath::AUTO"))
        .value("BASELINE", CpuPath::BASELINE, doc("CpuPath::BASELINE"))
        .value("SSE42", CpuPath::SSE42, doc("CpuPath::SSE42"))
        .value("AVX2", CpuPath::AVX2, doc("CpuPath::AVX2"))
        .value("AVX512", CpuPath::AVX512, doc("CpuPath::AVX512"));
    m.def("isCpuPathAvailable", &isCpuPathAvailable, py::arg("path"), doc("isCpuPathAvailable"));
    m.def("availableCpuPaths", &availableCpuPaths, doc("availableCpuPaths"));
    m.def("setCpuPath", &setCpuPath, py::arg("path"), doc("setCpuPath"));
    m.def("activeCpuPath", &activeCpuPath, doc("activeCpuPath"));
    m.def("cpuPathName", &cpuPathName, py::arg("path"), doc("cpuPathName"));
    // OpenCV's own thread count, which every parallel loop of the library uses: worker processes that
    // already run in parallel (DataLoader workers, Dask workers) set it to 1 instead of oversubscribing.
    m.def("setNumThreads", &cv::setNumThreads, py::arg("nthreads"),
          "OpenCV's cv::setNumThreads: the threads of every parallel loop of the library in this process "
          "(0 or 1: none; negative: OpenCV's default). Results do not depend on it.");
    m.def("getNumThreads", &cv::getNumThreads,
          "OpenCV's cv::getNumThreads: the threads a parallel loop uses.");
}

//! The sensor simulator.
void bindSimulator(py::module_& m)
{
    py::class_<SensorParams>(m, "SensorParams", doc("SensorParams"))
        .def(keywordInit<SensorParams>())
        .def_readwrite("noise", &SensorParams::noise, doc("SensorParams::noise"))
        .def_readwrite("pattern", &SensorParams::pattern, doc("SensorParams::pattern"))
        .def_readwrite("blackLevel", &SensorParams::blackLevel, doc("SensorParams::blackLevel"))
        .def_readwrite("bitDepth", &SensorParams::bitDepth, doc("SensorParams::bitDepth"))
        .def_readwrite("quantize", &SensorParams::quantize, doc("SensorParams::quantize"))
        .def_readwrite("prnu", &SensorParams::prnu, doc("SensorParams::prnu"))
        .def_readwrite("dsnu", &SensorParams::dsnu, doc("SensorParams::dsnu"))
        .def_readwrite("hotPixelFraction", &SensorParams::hotPixelFraction,
                       doc("SensorParams::hotPixelFraction"))
        .def_readwrite("deadPixelFraction", &SensorParams::deadPixelFraction,
                       doc("SensorParams::deadPixelFraction"))
        .def_readwrite("noisyPixelFraction", &SensorParams::noisyPixelFraction,
                       doc("SensorParams::noisyPixelFraction"))
        .def_readwrite("noisyPixelVariance", &SensorParams::noisyPixelVariance,
                       doc("SensorParams::noisyPixelVariance"))
        .def_readwrite("columnNoiseVariance", &SensorParams::columnNoiseVariance,
                       doc("SensorParams::columnNoiseVariance"))
        .def("validate", &SensorParams::validate, doc("SensorParams::validate"));

    py::class_<SensorSimulator>(m, "SensorSimulator", doc("SensorSimulator"))
        .def(py::init<const SensorParams&, cv::Size>(), py::arg("params"), py::arg("size"),
             doc("SensorSimulator::SensorSimulator", "Python: size is (width, height), as in cv2."))
        .def("params", &SensorSimulator::params, doc("SensorSimulator::params"))
        .def("size", &SensorSimulator::size, doc("SensorSimulator::size"))
        .def("rawFormat", &SensorSimulator::rawFormat, py::arg("gain"), doc("SensorSimulator::rawFormat"))
        .def("effectiveModel", &SensorSimulator::effectiveModel, doc("SensorSimulator::effectiveModel"))
        .def(
            "capture",
            [](const SensorSimulator& self, const py::object& meanAtUnitGain, double gain, double exposure,
               uint64 seed, int frameIndex) {
                const cv::Mat mean = matFromArray(meanAtUnitGain, "meanAtUnitGain", {CV_32F});
                return arrayFromCall("SensorSimulator.capture", [&](cv::Mat& raw) {
                    self.capture(mean, gain, exposure, seed, frameIndex, raw);
                });
            },
            py::arg("meanAtUnitGain"), py::arg("gain"), py::arg("exposure"), py::arg("seed"),
            py::arg("frameIndex") = 0, doc("SensorSimulator::capture", "Python: returns raw (uint16)."))
        .def(
            "captureBurst",
            [](const SensorSimulator& self, const py::object& meanAtUnitGain, double gain, double exposure,
               int frames, uint64 seed) {
                const cv::Mat mean = matFromArray(meanAtUnitGain, "meanAtUnitGain", {CV_32F});
                std::vector<cv::Mat> raws;
                withoutGil("SensorSimulator.captureBurst",
                           [&] { self.captureBurst(mean, gain, exposure, frames, seed, raws); });
                py::list out;
                for (const cv::Mat& r : raws)
                    out.append(arrayFromMat(r));
                return out;
            },
            py::arg("meanAtUnitGain"), py::arg("gain"), py::arg("exposure"), py::arg("frames"),
            py::arg("seed"), doc("SensorSimulator::captureBurst", "Python: returns the list of frames."))
        .def(
            "captureBlurred",
            [](const SensorSimulator& self, const py::object& meanAtUnitGain, const py::object& kernel,
               double gain, double exposure, uint64 seed, int frameIndex) {
                const cv::Mat mean = matFromArray(meanAtUnitGain, "meanAtUnitGain", {CV_32F});
                const cv::Mat k = matFromArray(kernel, "kernel", {CV_32F, CV_64F});
                return arrayFromCall("SensorSimulator.captureBlurred", [&](cv::Mat& raw) {
                    self.captureBlurred(mean, k, gain, exposure, seed, frameIndex, raw);
                });
            },
            py::arg("meanAtUnitGain"), py::arg("kernel"), py::arg("gain"), py::arg("exposure"),
            py::arg("seed"), py::arg("frameIndex") = 0,
            doc("SensorSimulator::captureBlurred", "Python: returns raw (uint16)."))
        .def(
            "fixedPattern",
            [](const SensorSimulator& self) {
                cv::Mat gainFactor, offset, defects;
                self.fixedPattern(gainFactor, offset, defects);
                return py::make_tuple(arrayFromMat(gainFactor), arrayFromMat(offset), arrayFromMat(defects));
            },
            doc("SensorSimulator::fixedPattern", "Python: returns (gainFactor, offset, defects)."));
}

//! The ColorChecker scene.
void bindColorChecker(py::module_& m)
{
    py::class_<ColorCheckerOptions>(m, "ColorCheckerOptions", doc("ColorCheckerOptions"))
        .def(keywordInit<ColorCheckerOptions>())
        .def_readwrite("pattern", &ColorCheckerOptions::pattern, doc("ColorCheckerOptions::pattern"))
        .def_readwrite("patchSize", &ColorCheckerOptions::patchSize, doc("ColorCheckerOptions::patchSize"))
        .def_readwrite("border", &ColorCheckerOptions::border, doc("ColorCheckerOptions::border"))
        .def_readwrite("illumination", &ColorCheckerOptions::illumination,
                       doc("ColorCheckerOptions::illumination"))
        .def_readwrite("vignetting", &ColorCheckerOptions::vignetting, doc("ColorCheckerOptions::vignetting"))
        .def_readwrite("frameReflectance", &ColorCheckerOptions::frameReflectance,
                       doc("ColorCheckerOptions::frameReflectance"));
    py::class_<ColorCheckerScene> scene(m, "ColorCheckerScene", doc("ColorCheckerScene"));
    scene.def(keywordInit<ColorCheckerScene>())
        .def_readwrite("patches", &ColorCheckerScene::patches, doc("ColorCheckerScene::patches"))
        .def_readwrite("reflectance", &ColorCheckerScene::reflectance, doc("ColorCheckerScene::reflectance"));
    defMatProperty(scene, "meanAtUnitGain", &ColorCheckerScene::meanAtUnitGain,
                   doc("ColorCheckerScene::meanAtUnitGain"), {CV_32F});
    m.def("colorCheckerReflectances", &colorCheckerReflectances, doc("colorCheckerReflectances"));
    m.def("makeColorCheckerScene", &makeColorCheckerScene, py::arg("options") = ColorCheckerOptions(),
          doc("makeColorCheckerScene"));
}

//! Seeds derived from a user's seed, and the generator's normal numbers.
void bindSeeds(py::module_& m)
{
    py::enum_<SeedPurpose>(m, "SeedPurpose", doc("SeedPurpose"))
        .value("SEED_SIMULATED_BURST", SEED_SIMULATED_BURST, doc("SeedPurpose::SEED_SIMULATED_BURST"))
        .value("SEED_SIMULATED_VALIDATION_BURST", SEED_SIMULATED_VALIDATION_BURST,
               doc("SeedPurpose::SEED_SIMULATED_VALIDATION_BURST"))
        .value("SEED_VALIDATION_CONVERSION", SEED_VALIDATION_CONVERSION,
               doc("SeedPurpose::SEED_VALIDATION_CONVERSION"))
        .value("SEED_AUGMENTED_OUTPUT", SEED_AUGMENTED_OUTPUT, doc("SeedPurpose::SEED_AUGMENTED_OUTPUT"))
        .value("SEED_DEMO", SEED_DEMO, doc("SeedPurpose::SEED_DEMO"))
        .value("SEED_STUDY", SEED_STUDY, doc("SeedPurpose::SEED_STUDY"))
        .value("SEED_TRAINING_EPOCH", SEED_TRAINING_EPOCH, doc("SeedPurpose::SEED_TRAINING_EPOCH"))
        .value("SEED_TRAINING_SAMPLE", SEED_TRAINING_SAMPLE, doc("SeedPurpose::SEED_TRAINING_SAMPLE"))
        .export_values();
    m.def("deriveSeed", &deriveSeed, py::arg("seed"), py::arg("purpose"), py::arg("index") = 0,
          doc("deriveSeed"));
    m.def(
        "fillStandardNormal",
        [](cv::Size size, uint64 seed) {
            return arrayFromCall("fillStandardNormal",
                                 [&](cv::Mat& dst) { fillStandardNormal(dst, size, seed); });
        },
        py::arg("size"), py::arg("seed"),
        doc("fillStandardNormal",
            "Python: fillStandardNormal(size=(width, height), seed) returns the float32 array."));
}

} // namespace

void bindCore(py::module_& m)
{
    bindBayer(m);
    bindNoiseModel(m);
    bindCpu(m);
    bindSimulator(m);
    bindColorChecker(m);
    bindSeeds(m);
}

} // namespace rawgment_python

PYBIND11_MODULE(_rawgment, m)
{
    using namespace rawgment_python;
    m.doc() = "cv::rawgment from Python: noise-accounted RAW augmentation (numpy arrays in and out).";
    m.attr("__version__") = RAWGMENT_VERSION;
    m.attr("CV_8U") = int(CV_8U);
    m.attr("CV_16U") = int(CV_16U);
    m.attr("CV_32F") = int(CV_32F);
    m.attr("CV_64F") = int(CV_64F);

    // cv::Exception -> rawgment.error, a RuntimeError carrying OpenCV's message (`err`) and the
    // C++ function that raised it; the text is the message alone, which names the bad argument.
    static py::exception<cv::Exception> error(m, "error", PyExc_RuntimeError);
    error.attr("__doc__") = "A cv::Exception of the C++ library: str() and `err` are its message, `code` its "
                            "OpenCV error code (-5: bad argument), `func` the C++ function that raised it.";
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p)
                std::rethrow_exception(p);
        } catch (const cv::Exception& e) {
            // As Python's own open() does for a path it cannot pass to the system.
            if (e.code == cv::Error::StsBadArg && e.err.rfind("a path holds a NUL character", 0) == 0) {
                PyErr_SetString(PyExc_ValueError, e.err.c_str());
                return;
            }
            py::object type = error;
            py::object instance = type(e.err);
            instance.attr("err") = e.err;
            instance.attr("code") = e.code;
            instance.attr("func") = e.func;
            PyErr_SetObject(error.ptr(), instance.ptr());
        }
    });

    bindCore(m);
    bindCalibration(m);
    bindAugment(m);
    bindDarkFrames(m);
    bindBatch(m);
    bindEmva1288(m);

    py::module_ testing = m.def_submodule("_testing", "Evidence for the tests (not part of the API).");
    testing.def(
        "callsWithoutGil",
        [] {
            std::lock_guard<std::mutex> lock(gilRecordMutex);
            return callsWithoutGil();
        },
        "The names of the calls that have run with the GIL released in this process.");
}
