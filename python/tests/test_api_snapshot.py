"""The public surface of `rawgment` (every name, its kind and docstring, and every class member's) is the
one recorded in data/rawgment_api.txt: restructuring the C++ headers (calibration.hpp split along its
seams, kept as the umbrella) must not change a name or a word of it. A deliberate change of the API
records it again with python/tools/api_snapshot.py (the command is in its docstring)."""
import difflib
import os
import sys

import rawgment as rg

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tools"))
from api_snapshot import snapshot  # noqa: E402


def test_the_public_surface_is_the_recorded_one():
    recorded = open(os.path.join(os.path.dirname(__file__), "data", "rawgment_api.txt"), encoding="utf-8").read()
    today = snapshot(rg)
    diff = list(difflib.unified_diff(recorded.splitlines(), today.splitlines(), "recorded", "today", lineterm=""))
    assert not diff, "\n".join(diff[:80])
