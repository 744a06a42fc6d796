#!/usr/bin/env python3
"""Writes the type stub of rawgment._rawgment (for IDEs and type checkers) from the built module.

pybind11 puts each function's Python signature on the first line of its docstring; this turns those
signatures, the classes' properties and the enums into a .pyi file, with the docstrings kept. Usage:
make_stub.py <output .pyi> (with the built package on PYTHONPATH).
"""
import ast
import os
import re
import sys

import rawgment._rawgment as ext

MODULE = "rawgment._rawgment."


def clean_type(text):
    text = text.replace(MODULE, "").replace("rawgment._rawgment", "")
    text = re.sub(r"\bnumpy\.ndarray\[[^\]]*\]", "numpy.ndarray", text)
    return text


def clean_signature(sig):
    """A pybind11 signature as valid Python: defaults become `...`, module prefixes go."""
    sig = clean_type(sig)
    # Defaults may be reprs such as <NoiseOptions object at 0x...>: a stub only needs to know there is one.
    out, depth, i = [], 0, 0
    while i < len(sig):
        c = sig[i]
        if c == "=" and depth == 1:
            out.append("= ...")
            i += 1
            nest = 0
            while i < len(sig):
                d = sig[i]
                if d in "([{<":
                    nest += 1
                elif d in ")]}>":
                    if nest == 0:
                        break
                    nest -= 1
                elif d == "," and nest == 0:
                    break
                i += 1
            continue
        if c == "(":
            depth += 1
        elif c == ")":
            depth -= 1
        out.append(c)
        i += 1
    return "".join(out)


def signatures(name, func):
    doc = func.__doc__ or ""
    lines = doc.splitlines()
    sigs = []
    if lines and lines[0].startswith(name + "("):
        sigs.append(lines[0])
        rest = "\n".join(lines[1:]).strip()
    else:
        for ln in lines:
            m = re.match(r"^\d+\. (" + re.escape(name) + r"\(.*)$", ln)
            if m:
                sigs.append(m.group(1))
        rest = "\n".join(ln for ln in lines if not re.match(r"^(\d+\. )?" + re.escape(name) + r"\(", ln) and
                         ln.strip() != "Overloaded function.").strip()
    return [clean_signature(s) for s in sigs], rest


def docstring(text, indent):
    if not text:
        return ""
    text = text.replace('"""', "'''")
    pad = " " * indent
    body = "\n".join((pad + ln) if ln.strip() else "" for ln in text.splitlines())
    return pad + 'r"""\n' + body + "\n" + pad + '"""\n'


def emit_function(name, func, indent, static=False):
    sigs, rest = signatures(name, func)
    if not sigs:
        sigs = [name + "(*args, **kwargs) -> object"]
    pad = " " * indent
    out = []
    for sig in sigs:
        if len(sigs) > 1:
            out.append(pad + "@overload\n")
        if static:
            out.append(pad + "@staticmethod\n")
        out.append(pad + "def " + sig + ":\n")
        out.append(docstring(rest, indent + 4) if rest else pad + "    ...\n")
        if rest:
            out.append(pad + "    ...\n")
    return "".join(out)


def property_type(prop):
    doc = (prop.fget.__doc__ or "") if prop.fget else ""
    m = re.match(r"^\(self: [^)]*\) -> (.*)$", doc.splitlines()[0] if doc else "")
    return clean_type(m.group(1)) if m else "object"


def emit_class(name, cls):
    out = []
    bases = [b.__name__ for b in cls.__bases__ if b.__module__ == ext.__name__]
    out.append("class %s%s:\n" % (name, "(" + ", ".join(bases) + ")" if bases else ""))
    out.append(docstring(cls.__doc__ or "", 4))
    if hasattr(cls, "__members__"):
        for member in cls.__members__:
            out.append("    %s: %s\n" % (member, name))
        out.append("    def __init__(self, value: int) -> None: ...\n")
        out.append("    def __int__(self) -> int: ...\n")
        out.append("    @property\n    def name(self) -> str: ...\n")
        out.append("    @property\n    def value(self) -> int: ...\n\n")
        return "".join(out)
    for key, value in vars(cls).items():
        if key.startswith("__") and key not in ("__init__", "__call__"):
            continue
        if key.startswith("_") and key not in ("__init__", "__call__"):
            continue
        kind = type(value).__name__
        if type(value) is property:
            out.append("    @property\n")
            out.append("    def %s(self) -> %s:\n" % (key, property_type(value)))
            out.append(docstring(value.__doc__ or "", 8) + "        ...\n")
            out.append("    @%s.setter\n    def %s(self, value: %s) -> None: ...\n" % (key, key, property_type(value)))
        elif kind == "pybind11_static_property":
            out.append("    %s: ClassVar[int]\n" % key)
        elif kind == "instancemethod" or callable(value):
            func = getattr(cls, key)
            static = isinstance(value, staticmethod) or kind == "builtin_function_or_method"
            out.append(emit_function(key, func, 4, static=static))
    out.append("\n")
    return "".join(out)


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: make_stub.py <output .pyi>")
    parts = [
        '"""Type stub of rawgment._rawgment, generated by python/tools/make_stub.py from the built module."""\n',
        "from typing import ClassVar, Dict, List, Set, Tuple, overload\n\nimport numpy\n\n",
    ]
    names = sorted(n for n in dir(ext) if not n.startswith("__"))
    classes = [n for n in names if isinstance(getattr(ext, n), type)]
    # Enums first, then the other classes: annotations may name any class (a stub is not executed).
    for n in sorted(classes, key=lambda n: (not hasattr(getattr(ext, n), "__members__"), n)):
        cls = getattr(ext, n)
        if issubclass(cls, BaseException):
            parts.append("class %s(RuntimeError):\n    err: str\n    code: int\n    func: str\n\n" % n)
        else:
            parts.append(emit_class(n, cls))
    for n in names:
        obj = getattr(ext, n)
        if isinstance(obj, type) or n.startswith("_"):
            continue
        if callable(obj):
            parts.append(emit_function(n, obj, 0) + "\n")
        elif hasattr(type(obj), "__members__"):
            parts.append("%s: %s\n" % (n, type(obj).__name__))
        elif isinstance(obj, (int, float, str)):
            parts.append("%s: %s\n" % (n, type(obj).__name__))
    text = "".join(parts)
    ast.parse(text)  # a stub that is not valid Python is a build error, not a silent IDE failure
    tmp = sys.argv[1] + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, sys.argv[1])


if __name__ == "__main__":
    main()
