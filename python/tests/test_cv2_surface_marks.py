"""cv2.rawgment's surface in every build, without building OpenCV (#79 item 28): the names and kinds that
OpenCV's generator makes of the headers' marks, read by python/tools/cv2_surface_from_headers.py, are the
ones scripts/build-in-opencv.sh recorded from the real cv2 (python/tests_opencv/data/cv2_rawgment_api.txt,
whose docstrings the opt-in build still checks). A mark added, renamed or dropped without recording the
surface again fails here. And every class cv2 gives can be constructed into a valid object (item 30)."""
import difflib
import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tools"))
import cv2_surface_from_headers as marks  # noqa: E402

RECORD = os.path.join(HERE, "..", "tests_opencv", "data", "cv2_rawgment_api.txt")


def test_the_marks_give_the_recorded_cv2_surface():
    recorded = marks.recorded_names_and_kinds(open(RECORD, encoding="utf-8").read())
    today = marks.surface_from_headers().lines()
    diff = list(difflib.unified_diff(recorded, today, "recorded by build-in-opencv.sh", "the headers' marks",
                                     lineterm=""))
    assert not diff, ("the cv2 surface the headers mark is not the recorded one: record it again with "
                      "scripts/build-in-opencv.sh and python/tools/api_snapshot.py\n" + "\n".join(diff[:80]))


def test_every_class_of_the_cv2_surface_constructs_a_valid_object():
    surface = marks.surface_from_headers()
    held_without_constructor = sorted(c for c, ok in surface.constructible.items() if not ok)
    assert not held_without_constructor, (
        "CV_EXPORTS_W classes without a CV_WRAP constructor: cv2 makes an object holding no C++ object of "
        "them, and its first method call crashes: %s" % held_without_constructor)


@pytest.mark.parametrize("header, message", [
    ("namespace cv { namespace rawgment { namespace detail {\nCV_EXPORTS_W int f();\n} } }", "outside"),
    ("namespace cv { namespace rawgment {\nCV_EXPORTS_AS(g) int f();\n} }", "CV_EXPORTS_AS"),
    ("namespace cv { namespace rawgment {\nclass Hidden { public: CV_WRAP int f(); };\n} }", "not exported"),
    ("namespace cv { namespace rawgment {\nstruct CV_EXPORTS_W_SIMPLE S { CV_PROP_RW int a;\n} }", "open"),
])
def test_a_form_the_reading_does_not_know_is_an_error_not_a_guess(tmp_path, header, message):
    path = tmp_path / "h.hpp"
    path.write_text(header)
    with pytest.raises(marks.SurfaceError, match=message):
        marks.read_header(str(path), marks.Surface())


def test_the_reading_knows_the_generators_forms(tmp_path):
    path = tmp_path / "h.hpp"
    path.write_text("""namespace cv { namespace rawgment {
enum class SomeKind { FIRST = 0, SECOND };
enum Plain: int { PLAIN_A = 1, PLAIN_B };
struct CV_EXPORTS_W_SIMPLE Simple {
    CV_PROP_RW std::vector<std::pair<int, int>> pairs{{1, 2}};
    CV_PROP_RW double a = 1, b;
    CV_WRAP double sum(const Size& s = Size(1, 2)) const { return a + b; }
    CV_WRAP static Simple load(const String& path = "{");
    enum { INNER };
    double hidden;
};
class CV_EXPORTS_W Held { public: CV_WRAP Held(); CV_WRAP void run(); };
CV_EXPORTS_W std::vector<Simple>
readAll(const String& folder, int n = 2);
} }""")
    surface = marks.Surface()
    marks.read_header(str(path), surface)
    assert surface.lines() == [
        "Held: class", "    run: function", "PLAIN_A: int", "PLAIN_B: int", "SOME_KIND_FIRST: int",
        "SOME_KIND_SECOND: int", "Simple: class", "    a: getset_descriptor", "    b: getset_descriptor",
        "    load: function", "    pairs: getset_descriptor", "    sum: function", "Simple_INNER: int",
        "Simple_load: function", "SomeKind_FIRST: int", "SomeKind_SECOND: int", "readAll: function"]
    assert surface.constructible == {"Held": True, "Simple": True}
