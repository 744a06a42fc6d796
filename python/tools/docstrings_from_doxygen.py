#!/usr/bin/env python3
"""Turns Doxygen's XML of the public headers into a C++ table of docstrings for the Python module.

The Python docstrings are the C++ documentation itself, converted at build time, so the two never
drift apart. Usage: docstrings_from_doxygen.py <doxygen xml folder> <output .hpp>

Each entry is keyed by the C++ qualified name without ``cv::rawgment::`` (``NoiseModel::variance``);
overloads are joined, each introduced by its C++ signature. Formulas stay in their LaTeX form, which is
what a reader of a terminal can read best.
"""
import os
import sys
import textwrap
import xml.etree.ElementTree as ET

PREFIX = "cv::rawgment::"


def inline_text(node):
    """The plain text of a description node, with paragraphs, lists and parameter lists laid out."""
    out = []

    def contents(n):
        if n.text:
            out.append(n.text)
        for child in n:
            walk(child)

    def section(n):
        start = len(out)
        contents(n)
        text = normalise("".join(out[start:]))
        del out[start:]
        return text

    def walk(n):
        tag = n.tag
        if tag == "parameterlist":
            title = {"param": "Parameters", "retval": "Returns", "exception": "Raises"}.get(n.get("kind"), "Parameters")
            out.append("\n\n" + title + ":\n")
            for item in n.findall("parameteritem"):
                names = ", ".join("".join(p.itertext()).strip() for p in item.iter("parametername"))
                d = item.find("parameterdescription")
                desc = section(d) if d is not None else ""
                out.append("    " + names + ": " + desc + "\n")
            out.append("\n")
        elif tag == "simplesect":
            kind = n.get("kind")
            title = {"return": "Returns", "note": "Note", "see": "See also", "warning": "Warning"}.get(kind, kind)
            out.append("\n\n" + title + ": " + section(n) + "\n\n")
        elif tag == "formula":
            text = (n.text or "").strip()
            for delim in ("\\[", "\\]", "$"):
                text = text.replace(delim, "")
            out.append(" " + " ".join(text.split()) + " ")
        else:
            contents(n)
            if tag == "para":
                out.append("\n\n")
            elif tag == "listitem":
                out.append("\n")
        if n.tail:
            out.append(n.tail)

    contents(node)
    return "".join(out)


def normalise(text):
    return " ".join(text.split())


def describe(member):
    """Brief and detailed description as wrapped paragraphs; parameter lists keep their lines."""
    parts = []
    for which in ("briefdescription", "detaileddescription"):
        node = member.find(which)
        if node is None:
            continue
        raw = inline_text(node)
        for block in raw.split("\n\n"):
            lines = [ln for ln in block.split("\n") if ln.strip()]
            if not lines:
                continue
            if lines[0].rstrip().endswith(":") and len(lines) > 1 and lines[1].startswith("    "):
                parts.append("\n".join([lines[0].strip()] + [ln.rstrip() for ln in lines[1:]]))
            else:
                parts.append(textwrap.fill(normalise(block), 100))
    return "\n\n".join(parts)


def collect(xml_dir):
    docs = {}

    def add(key, text, signature=None):
        if not text:
            return
        if signature:
            text = signature + "\n\n" + text
        docs.setdefault(key, []).append(text)

    for fname in sorted(os.listdir(xml_dir)):
        if not fname.endswith(".xml") or fname == "index.xml":
            continue
        root = ET.parse(os.path.join(xml_dir, fname)).getroot()
        for compound in root.iter("compounddef"):
            kind = compound.get("kind")
            if kind in ("struct", "class"):
                name = compound.findtext("compoundname", "")
                if name.startswith(PREFIX):
                    add(name[len(PREFIX):], describe(compound))
            if kind not in ("struct", "class", "namespace"):
                continue  # group and file pages repeat the namespace's members
            for member in compound.iter("memberdef"):
                qualified = member.findtext("qualifiedname") or ""
                if not qualified.startswith(PREFIX) or member.get("prot", "public") != "public":
                    continue
                key = qualified[len(PREFIX):]
                text = describe(member)
                mkind = member.get("kind")
                if mkind == "function":
                    signature = (member.findtext("name") or "") + (member.findtext("argsstring") or "")
                    add(key, text, "C++: " + " ".join(signature.split()))
                else:
                    add(key, text)
                if mkind == "enum":
                    for value in member.findall("enumvalue"):
                        add(key + "::" + value.findtext("name", ""), describe(value))
    return {k: "\n\n".join(v) for k, v in docs.items()}


def cxx_string(text):
    # A raw string cannot hold its own delimiter; the documentation never contains it.
    assert ')DOC"' not in text
    return 'R"DOC(' + text + ')DOC"'


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: docstrings_from_doxygen.py <doxygen xml folder> <output .hpp>")
    docs = collect(sys.argv[1])
    if len(docs) < 50:
        sys.exit("docstrings_from_doxygen.py: only %d documented symbols found in %s" % (len(docs), sys.argv[1]))
    lines = [
        "// Generated by python/tools/docstrings_from_doxygen.py from the public headers; do not edit.",
        "#pragma once",
        "#include <map>",
        "#include <string>",
        "namespace rawgment_python {",
        "inline const std::map<std::string, const char*>& cxxDocstrings()",
        "{",
        "    static const std::map<std::string, const char*> docs = {",
    ]
    for key in sorted(docs):
        lines.append("        {%s, %s}," % ('"' + key + '"', cxx_string(docs[key])))
    lines += ["    };", "    return docs;", "}", "} // namespace rawgment_python", ""]
    text = "\n".join(lines)
    # Rewrite only on change, so that a rebuild does not recompile the bindings for nothing.
    out = sys.argv[2]
    if not os.path.exists(out) or open(out, encoding="utf-8").read() != text:
        tmp = out + ".tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, out)


if __name__ == "__main__":
    main()
