// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What every binding file of the Python module shares: numpy <-> cv::Mat without copies, tuples for
// OpenCV's small types, keyword construction of option structs, the C++ docstrings, and the proof
// that heavy calls run without the GIL.
#ifndef RAWGMENT_PYTHON_BINDING_TOOLS_HPP
#define RAWGMENT_PYTHON_BINDING_TOOLS_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment.hpp>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <memory>
#include <string>
#include <utility>

namespace py = pybind11;

namespace rawgment_python {

/** The C++ documentation of a public symbol (its qualified name without cv::rawgment::), after an
 * optional note on how the Python call differs. A name without documentation stops the import: the
 * docstring test then fails instead of a symbol shipping undocumented. */
const char* doc(const std::string& cxxName, const std::string& pythonNote = std::string());

//! The numpy dtype name of an OpenCV depth ("uint16", ...).
const char* dtypeName(int depth);

/** Wraps a numpy array as a Mat without copying. The array must be 2-D (HxW), or 3-D (HxWxC, C <= 4)
 * when `allowChannels`, of one of `depths`, with contiguous elements in each row (rows may be padded,
 * as in a crop of a larger array). Anything else is a TypeError (not an array, wrong dtype) or a
 * ValueError (shape, layout) naming `argument`. The Mat is valid while the array lives. */
cv::Mat matFromArray(const py::handle& array, const char* argument, const std::vector<int>& depths,
                     bool allowChannels = false);

/** Wraps a numpy array of any shape as one 1 x N row, for the statistics that treat it as a sample.
 * It must be C-contiguous. */
cv::Mat sampleFromArray(const py::handle& array, const char* argument);

//! A Python list of numpy arrays, each wrapped as by matFromArray() (HxW).
std::vector<cv::Mat> matsFromList(const py::handle& list, const char* argument,
                                  const std::vector<int>& depths);

/** The Mat over a caller's output array (the `dst=` keyword, as cv2's dst arguments): of the dtype and
 * shape of `like` (the input), contiguous rows and writable, else a TypeError or ValueError naming
 * `argument`. None gives an empty Mat, which the call allocates. */
cv::Mat outputMatLike(const py::object& dst, const char* argument, const cv::Mat& like);

/** The result of a call that wrote `out`, given the caller's output `dst` and its Mat `target`
 * (outputMatLike()): dst itself, with out copied in where the call could not write in place (an
 * identity step returns the input; dst sharing memory with the input), or a new array without dst. */
py::object resultInto(const py::object& dst, const cv::Mat& target, const cv::Mat& out);

/** A numpy array of a Mat: shares the data when OpenCV allocated it (no copy), copies it when the Mat
 * points into memory it does not own (an input's, which an identity step returns). */
py::array arrayFromMat(const cv::Mat& mat);

//! Records that the named call ran with the GIL released (rawgment._testing.callsWithoutGil()).
void noteCallWithoutGil(const char* name);

/** Runs `f` with the GIL released and checks that it was, so that Python threads run heavy calls in
 * parallel; the record is the evidence the tests read. */
template <class F> auto withoutGil(const char* name, F&& f) -> decltype(f())
{
    py::gil_scoped_release release;
    if (!PyGILState_Check())
        noteCallWithoutGil(name);
    return f();
}

//! The numpy result of a call that fills one Mat, run without the GIL (withoutGil()).
template <class F> py::array arrayFromCall(const char* name, F&& fill)
{
    cv::Mat dst;
    withoutGil(name, [&] { fill(dst); });
    return arrayFromMat(dst);
}

//! True for the names a keyword constructor accepts: the class's data properties.
bool isDataProperty(const py::handle& type, const std::string& name);

template <class T, class = void> struct HasValidate : std::false_type
{
};
template <class T>
struct HasValidate<T, std::void_t<decltype(std::declval<const T&>().validate())>> : std::true_type
{
};

/** `T(field=value, ...)`: every keyword names a field (an unknown one is a TypeError naming it), the
 * rest keep the C++ defaults, and a struct with validate() is validated, so a bad value is reported
 * where it is made. */
template <class T> auto keywordInit()
{
    return py::init([](const py::kwargs& kwargs) {
        auto value = std::make_unique<T>();
        {
            py::object self = py::cast(value.get(), py::return_value_policy::reference);
            const py::handle type = py::type::of(self);
            for (const auto& item : kwargs) {
                const std::string key = py::str(item.first);
                if (!isDataProperty(type, key))
                    throw py::type_error(std::string(py::str(type.attr("__name__"))) +
                                         "() got an unexpected keyword argument '" + key + "'");
                py::setattr(self, key.c_str(), item.second);
            }
        }
        if constexpr (HasValidate<T>::value)
            value->validate();
        return value;
    });
}

/** A Mat field as a numpy property: the getter shares the Mat's data, the setter copies the array
 * (the struct must own what it holds). */
template <class T>
void defMatProperty(py::class_<T>& cls, const char* name, cv::Mat T::*field, const char* docstring,
                    const std::vector<int>& depths)
{
    cls.def_property(
        name, [field](const T& self) { return arrayFromMat(self.*field); },
        [field, name, depths](T& self, const py::object& value) {
            // None or an empty array (what the getter gives for an empty Mat) empties the field.
            if (value.is_none() || (py::isinstance<py::array>(value) && py::array(value).size() == 0))
                (self.*field).release();
            else
                self.*field = matFromArray(value, name, depths).clone();
        },
        docstring);
}

void bindCore(py::module_& m);        // bayer, noise_model, cpu, simulate
void bindCalibration(py::module_& m); // calibration, normality
void bindAugment(py::module_& m);     // augment, raw_io, isp
void bindBatch(py::module_& m);       // the apps' batch jobs and the benchmark hooks
void bindEmva1288(py::module_& m);    // the EMVA 1288 descriptor and figures
void bindDarkFrames(py::module_& m);  // the dark-frame bank

} // namespace rawgment_python

namespace pybind11 {
namespace detail {

//! Whether `src` is a sequence (not a string) of `n` items; `seq` is it then.
inline bool sequenceOfLength(handle src, size_t n, sequence& seq)
{
    if (!src || !PySequence_Check(src.ptr()) || PyUnicode_Check(src.ptr()))
        return false;
    seq = reinterpret_borrow<sequence>(src);
    return seq.size() == n;
}

//! cv::Vec<double, N> <-> a tuple of N floats (any sequence of N numbers is accepted).
template <int N> struct type_caster<cv::Vec<double, N>>
{
    using Vector = cv::Vec<double, N>;
    PYBIND11_TYPE_CASTER(Vector, const_name("Tuple[float, ...]"));
    bool load(handle src, bool)
    {
        sequence seq;
        if (!sequenceOfLength(src, N, seq))
            return false;
        for (int i = 0; i < N; ++i) {
            const object item = seq[static_cast<size_t>(i)];
            if (!PyFloat_Check(item.ptr()) && !PyLong_Check(item.ptr()) && !PyNumber_Check(item.ptr()))
                return false;
            value[i] = item.cast<double>();
        }
        return true;
    }
    static handle cast(const cv::Vec<double, N>& v, return_value_policy, handle)
    {
        tuple t(N);
        for (int i = 0; i < N; ++i)
            t[static_cast<size_t>(i)] = float_(v[i]);
        return t.release();
    }
};

//! cv::Matx33d <-> a 3x3 float64 numpy array (any 3x3 nested sequence of numbers is accepted).
template <> struct type_caster<cv::Matx33d>
{
    PYBIND11_TYPE_CASTER(cv::Matx33d, const_name("numpy.ndarray"));
    bool load(handle src, bool)
    {
        if (!src)
            return false;
        const auto arr = array_t<double, array::c_style | array::forcecast>::ensure(src);
        if (!arr || arr.ndim() != 2 || arr.shape(0) != 3 || arr.shape(1) != 3)
            return false;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                value(r, c) = arr.at(r, c);
        return true;
    }
    static handle cast(const cv::Matx33d& m, return_value_policy, handle)
    {
        array_t<double> out({3, 3});
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                out.mutable_at(r, c) = m(r, c);
        return out.release();
    }
};

//! How OpenCV's small integer types read as tuples: Point (x, y), Size (width, height), Rect (x, y, w, h).
template <class T> struct IntTuple
{
    static constexpr int N = 0;
};
template <> struct IntTuple<cv::Point>
{
    static constexpr int N = 2;
    static cv::Point make(const int* v) { return cv::Point(v[0], v[1]); }
    static std::array<int, N> values(const cv::Point& p) { return {p.x, p.y}; }
};
template <> struct IntTuple<cv::Size>
{
    static constexpr int N = 2;
    static cv::Size make(const int* v) { return cv::Size(v[0], v[1]); }
    static std::array<int, N> values(const cv::Size& s) { return {s.width, s.height}; }
};
template <> struct IntTuple<cv::Rect>
{
    static constexpr int N = 4;
    static cv::Rect make(const int* v) { return cv::Rect(v[0], v[1], v[2], v[3]); }
    static std::array<int, N> values(const cv::Rect& r) { return {r.x, r.y, r.width, r.height}; }
};

template <class T> struct type_caster<T, enable_if_t<(IntTuple<T>::N > 0)>>
{
    static constexpr int N = IntTuple<T>::N;
    PYBIND11_TYPE_CASTER(T, const_name<N == 2>("Tuple[int, int]", "Tuple[int, int, int, int]"));
    bool load(handle src, bool)
    {
        sequence seq;
        if (!sequenceOfLength(src, N, seq))
            return false;
        int v[N];
        for (int i = 0; i < N; ++i) {
            const object item = seq[static_cast<size_t>(i)];
            if (!PyLong_Check(item.ptr()) && !PyIndex_Check(item.ptr()))
                return false;
            v[i] = item.cast<int>();
        }
        value = IntTuple<T>::make(v);
        return true;
    }
    static handle cast(const T& v, return_value_policy, handle)
    {
        tuple t(N);
        const std::array<int, N> values = IntTuple<T>::values(v);
        for (int i = 0; i < N; ++i)
            t[static_cast<size_t>(i)] = int_(values[static_cast<size_t>(i)]);
        return t.release();
    }
};

} // namespace detail
} // namespace pybind11

#endif // RAWGMENT_PYTHON_BINDING_TOOLS_HPP
