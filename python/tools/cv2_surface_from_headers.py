#!/usr/bin/python3
# This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
"""The names and kinds of cv2.rawgment as OpenCV 4.6's generator makes them from the module's marks
(CV_EXPORTS_W*, CV_WRAP, CV_PROP*, enums), read from the headers without building OpenCV, plus the names
the module's Python package (misc/python/package/rawgment) adds.

The opt-in build (scripts/build-in-opencv.sh) records the real cv2.rawgment, docstrings included, in
python/tests_opencv/data/cv2_rawgment_api.txt; python/tests/test_cv2_surface_marks.py holds this reading
to that record's names and kinds in every normal build, so a change of a mark that is not recorded again
fails in CI. It also says which classes cv2 can construct: a class of the surface exported as
CV_EXPORTS_W (held by a Ptr) without a wrapped constructor gives an object holding no C++ object, whose
first method call crashes the interpreter (#79 item 30).

    /usr/bin/python3 python/tools/cv2_surface_from_headers.py [--constructors]

The reading follows the generator's rules for the forms the module uses; a form it does not know (a
nested namespace with marks, CV_EXPORTS_AS, CV_WRAP_AS, CV_EXPORTS_W_MAP) is an error naming the header
and the declaration, never a silent guess.
"""
import ast
import glob
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
MODULE = os.path.join(ROOT, "modules", "rawgment")
NAMESPACE = ["cv", "rawgment"]


class SurfaceError(Exception):
    pass


def strip_comments_and_preprocessor(text):
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r'"(?:\\.|[^"\\])*"', '""', text)  # a brace in a string literal is not a scope
    lines = []
    continued = False
    for line in text.split("\n"):
        directive = continued or line.lstrip().startswith("#")
        continued = directive and line.rstrip().endswith("\\")
        lines.append("" if directive else line)
    return "\n".join(lines)


def matching_brace(text, start):
    depth = 0
    for i in range(start, len(text)):
        if text[i] == "{":
            depth += 1
        elif text[i] == "}":
            depth -= 1
            if depth == 0:
                return i
    raise SurfaceError("unbalanced braces")


def upper_snake(name):
    return re.sub(r"(?<=[a-z0-9])(?=[A-Z])", "_", name).upper()


class Surface:
    def __init__(self):
        self.names = {}  # module-level name -> kind
        self.members = {}  # class name -> {member: kind}
        self.constructible = {}  # class name -> True where cv2 constructs a valid object

    def add(self, name, kind, where):
        if self.names.get(name, kind) != kind:
            raise SurfaceError("%s: %s is both a %s and a %s" % (where, name, self.names[name], kind))
        self.names[name] = kind

    def lines(self):
        out = []
        for name in sorted(self.names):
            out.append("%s: %s" % (name, self.names[name]))
            for member in sorted(self.members.get(name, {})):
                out.append("    %s: %s" % (member, self.members[name][member]))
        return out


def function_name(head):
    before = head.split("(", 1)[0]
    found = re.findall(r"[A-Za-z_]\w*", before)
    return found[-1] if found else None


def property_names(declaration):
    body = re.sub(r"\bCV_PROP(_RW)?\b", "", declaration)
    body = re.sub(r"<[^<>]*>", "", re.sub(r"<[^<>]*>", "", body))  # template arguments hold commas
    names = []
    for part in body.split(","):
        part = re.split(r"[={]", part, 1)[0]
        found = re.findall(r"[A-Za-z_]\w*", part)
        if found:
            names.append(found[-1])
    return names


def read_header(path, surface):
    where = os.path.relpath(path, ROOT)
    text = strip_comments_and_preprocessor(open(path, encoding="utf-8").read())
    scopes = []  # ("namespace", name) or ("class", name, exported, simple)

    def in_module():
        return [s[1] for s in scopes if s[0] == "namespace"] == NAMESPACE

    def current_class():
        return scopes[-1] if scopes and scopes[-1][0] == "class" else None

    def declaration(head):
        head = " ".join(head.split())
        if not head:
            return
        for form in ("CV_EXPORTS_AS", "CV_WRAP_AS", "CV_EXPORTS_W_MAP", "CV_WRAP_MAPPABLE", "CV_WRAP_PHANTOM"):
            if form in head:
                raise SurfaceError("%s: %s is a form this reading does not know: %s" % (where, form, head))
        marked = re.search(r"\bCV_(EXPORTS_W|WRAP|PROP|PROP_RW)\b", head)
        if not marked:
            return
        if not in_module():
            raise SurfaceError("%s: a mark outside namespace cv::rawgment: %s" % (where, head))
        cls = current_class()
        if cls is None:
            if re.search(r"\bCV_EXPORTS_W\b", head) and "(" in head:
                surface.add(function_name(head), "function", where)
            return
        _, cname, exported, _simple = cls
        if not exported:
            raise SurfaceError("%s: a mark in class %s, which is not exported: %s" % (where, cname, head))
        if re.search(r"\bCV_PROP(_RW)?\b", head):
            for name in property_names(head):
                surface.members[cname][name] = "getset_descriptor"
        elif re.search(r"\bCV_WRAP\b", head):
            name = function_name(head)
            if name == cname:
                surface.constructible[cname] = True
            elif "operator" not in head:
                surface.members[cname][name] = "function"
                if re.search(r"\bstatic\b", head):
                    surface.add("%s_%s" % (cname, name), "function", where)

    def enum(head, body):
        scoped = re.match(r"\s*enum\s+(class|struct)\s+(\w+)", head)
        values = [re.split(r"=", v)[0].strip() for v in body.split(",")]
        values = [v for v in values if v]
        if not in_module():
            return
        cls = current_class()
        for value in values:
            if scoped:
                ename = scoped.group(2)
                prefix = "%s_" % cls[1] if cls else ""
                surface.add(prefix + ename + "_" + value, "int", where)
                surface.add(prefix + upper_snake(ename) + "_" + value, "int", where)
            elif cls:
                surface.add("%s_%s" % (cls[1], value), "int", where)
            else:
                surface.add(value, "int", where)

    pos = 0
    head_start = 0
    while pos < len(text):
        c = text[pos]
        if c == ";":
            declaration(text[head_start:pos])
            head_start = pos + 1
        elif c == "{":
            head = text[head_start:pos]
            flat = " ".join(head.split())
            ns = re.match(r"^(inline )?namespace (\w+)$", flat)
            cl = re.match(r"^(?:template ?<.*> )?(class|struct) ((?:CV_EXPORTS\w* )*)(\w+)\b[^()]*$", flat)
            if ns:
                scopes.append(("namespace", ns.group(2)))
            elif cl:
                marks = cl.group(2).split()
                exported = any(m.startswith("CV_EXPORTS_W") for m in marks)
                simple = "CV_EXPORTS_W_SIMPLE" in marks
                cname = cl.group(3)
                scopes.append(("class", cname, exported, simple))
                if exported:
                    if not in_module():
                        raise SurfaceError("%s: class %s is exported outside cv::rawgment" % (where, cname))
                    if len(scopes) > 1 and scopes[-2][0] == "class":
                        raise SurfaceError("%s: nested exported class %s" % (where, cname))
                    surface.add(cname, "class", where)
                    surface.members.setdefault(cname, {})
                    # A simple class is held by value: cv2 default-constructs it, always valid.
                    surface.constructible.setdefault(cname, simple)
            elif re.match(r"^(typedef )?enum\b", flat):
                end = matching_brace(text, pos)
                enum(flat, text[pos + 1:end])
                pos = end
            else:
                # A function body, an initializer or a default argument: its head is a declaration
                # (an inline CV_WRAP method, a CV_PROP_RW with a braced initializer), its inside is not.
                declaration(head)
                end = matching_brace(text, pos)
                pos = end
                head_start = pos + 1
                # What follows a skipped body up to its ';' (") const;" of a default argument) is no head.
                rest = re.match(r"[^;{}]*;", text[pos + 1:])
                if rest and "(" not in rest.group(0) and not re.search(r"\bCV_", rest.group(0)):
                    pos += len(rest.group(0))
                    head_start = pos + 1
                pos += 1
                continue
            head_start = pos + 1
        elif c == "}":
            if not scopes:
                raise SurfaceError("%s: a closing brace with no scope open" % where)
            scopes.pop()
            head_start = pos + 1
        pos += 1
    if scopes:
        raise SurfaceError("%s: scopes left open: %s" % (where, scopes))


def read_package(path, surface):
    tree = ast.parse(open(path, encoding="utf-8").read(), path)
    where = os.path.relpath(path, ROOT)
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            surface.names[node.name] = "function"
        elif isinstance(node, ast.Assign):
            for target in node.targets:
                if not isinstance(target, ast.Name) or target.id.startswith("__"):
                    continue
                if isinstance(node.value, ast.Call):
                    surface.names[target.id] = "function"
                else:
                    try:
                        surface.names[target.id] = type(eval(compile(ast.Expression(node.value), where, "eval"),
                                                             {"__builtins__": {}})).__name__
                    except Exception as error:
                        raise SurfaceError("%s: %s is assigned what this reading cannot evaluate (%s)"
                                           % (where, target.id, error))


def surface_from_headers():
    surface = Surface()
    headers = sorted(glob.glob(os.path.join(MODULE, "include", "opencv2", "rawgment", "*.hpp")))
    headers.append(os.path.join(MODULE, "include", "opencv2", "rawgment.hpp"))
    for header in headers:
        read_header(header, surface)
    read_package(os.path.join(MODULE, "misc", "python", "package", "rawgment", "__init__.py"), surface)
    return surface


def recorded_names_and_kinds(snapshot_text):
    """The recorded snapshot's name and kind lines, docstrings and values dropped."""
    return [line for line in snapshot_text.splitlines() if not line.lstrip().startswith(("|", "="))]


def main():
    surface = surface_from_headers()
    if sys.argv[1:] == ["--constructors"]:
        for cname in sorted(surface.constructible):
            print("%s: %s" % (cname, "constructible" if surface.constructible[cname] else "NOT constructible"))
    elif sys.argv[1:]:
        sys.exit("usage: cv2_surface_from_headers.py [--constructors]")
    else:
        print("\n".join(surface.lines()))


if __name__ == "__main__":
    main()
