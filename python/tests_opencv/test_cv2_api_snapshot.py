"""The public surface of cv2.rawgment (every name, its kind and docstring, and every class member's), as
OpenCV's generator makes it from the module's headers, is the one recorded in data/cv2_rawgment_api.txt:
splitting a header (calibration.hpp along its seams, kept as the umbrella) must change no name and no
docstring. A deliberate change records it again with python/tools/api_snapshot.py."""
import difflib
import os
import sys

import pytest

cv2 = pytest.importorskip("cv2")
if not hasattr(cv2, "rawgment"):
    pytest.skip("this cv2 (%s) has no rawgment module: run scripts/build-in-opencv.sh" % cv2.__file__,
                allow_module_level=True)

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tools"))
from api_snapshot import snapshot  # noqa: E402


def test_the_public_surface_is_the_recorded_one():
    recorded = open(os.path.join(os.path.dirname(__file__), "data", "cv2_rawgment_api.txt"),
                    encoding="utf-8").read()
    today = snapshot(cv2.rawgment)
    diff = list(difflib.unified_diff(recorded.splitlines(), today.splitlines(), "recorded", "today", lineterm=""))
    assert not diff, "\n".join(diff[:80])
