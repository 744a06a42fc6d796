#!/usr/bin/python3
# This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
"""The public surface of a Python binding as text: every name of dir(module) with its kind and
docstring, and for each class every member's. A restructuring of the C++ headers (one header per seam,
an umbrella kept) must leave it unchanged; python/tests/test_api_snapshot.py holds the pybind module
`rawgment` to python/tests/data/rawgment_api.txt, and python/tests_opencv/test_cv2_api_snapshot.py
holds cv2.rawgment to python/tests_opencv/data/cv2_rawgment_api.txt.

    PYTHONPATH=build/release/python /usr/bin/python3 python/tools/api_snapshot.py rawgment > python/tests/data/rawgment_api.txt
    PYTHONPATH=<opencv prefix>/lib/python3.11/dist-packages /usr/bin/python3 python/tools/api_snapshot.py cv2.rawgment \\
        > python/tests_opencv/data/cv2_rawgment_api.txt
"""
import importlib
import inspect
import re
import sys


def kind(obj):
    if inspect.isclass(obj):
        return "class"
    if callable(obj):
        return "function"
    return type(obj).__name__


def documented(name, obj, indent):
    lines = ["%s%s: %s" % (indent, name, kind(obj))]
    if inspect.isclass(obj) or callable(obj):
        doc = (obj.__doc__ or "").rstrip()
        lines += [indent + "  | " + line.rstrip() for line in doc.splitlines()]
    elif isinstance(obj, (int, float, str)):
        lines.append("%s  = %r" % (indent, obj))
    return lines


def snapshot(module):
    """The module's public surface, one name per entry, sorted; dunder names left out."""
    lines = []
    for name in sorted(n for n in dir(module) if not n.startswith("__")):
        obj = getattr(module, name)
        if inspect.ismodule(obj):
            continue  # a submodule is an attribute only once something imported it
        lines += documented(name, obj, "")
        if inspect.isclass(obj):
            for member in sorted(n for n in vars(obj) if not n.startswith("__")):
                lines += documented(member, getattr(obj, member), "    ")
    # pybind's default arguments print as "<... object at 0x7f...>": the address differs every run.
    return re.sub(r" object at 0x[0-9a-f]+>", " object>", "\n".join(lines) + "\n")


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: api_snapshot.py MODULE (rawgment or cv2.rawgment)")
    path = sys.argv[1].split(".")
    module = importlib.import_module(path[0])
    for part in path[1:]:
        module = getattr(module, part)
    sys.stdout.write(snapshot(module))


if __name__ == "__main__":
    main()
