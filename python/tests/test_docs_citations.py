"""Every file, test and function the docs cite exists today: a doc that names a file since split or removed,
a test since renamed or a function since gone fails here, naming the doc, its line and the name.

What counts as a citation (text between backquotes in README.md, CHANGELOG.md and docs/*.md):
- a path whose first folder is one of the project's top-level folders (`modules/...`, `test/...`): the file
  or folder must exist (a topic's pair may be cited without its extension, `helpers/chart_patches`); other projects' paths (darktable's `tools/noise/subr.sh`) and outputs
  (`sim/truth_noise_model.yml`) start elsewhere and are not checked;
- `Suite.testName`, Suite one of the GoogleTest suites: a TEST of that name must exist (a call or a member,
  `NoiseModel.load()`, `DarkFrameBank.create`, is not a test: a test name is a camel-case phrase of at
  least three words);
- a Python test's name `test_...`: a test function of that name must exist;
- a function or member, `name()`, `Class::name` or `module.name(...)`: its last name must be defined or used
  in the project's code (C++, Python, CMake, scripts). That cannot tell an external function the project
  never calls from one the project lost; the names of the project's own API are checked exactly by the API
  snapshots, so here a name no code holds is what is refused.
The CHANGELOG's entries are history: its paths and tests are checked only in its Unreleased section."""
import glob
import os
import re

import pytest

ROOT = os.environ.get("RAWGMENT_SOURCE_DIR", "")
CODE_GLOBS = ("**/*.cpp", "**/*.hpp", "**/*.h", "**/*.py", "**/*.pyi", "**/CMakeLists.txt", "**/*.cmake",
              "**/*.sh", "**/*.toml", "**/*.cfg")
TEST_MACRO = re.compile(r"\bTEST(?:_F|_P)?\(\s*(\w+)\s*,\s*(\w+)\s*\)")
PY_TEST = re.compile(r"^\s*def (test_\w+)", re.M)
PATH = re.compile(r"[\w.+-]+(?:/[\w.+*-]+)+/?")
TEST_NAME = re.compile(r"([A-Z]\w*)\.([a-z]\w*)")
FUNCTION = re.compile(r"(?:[A-Za-z_]\w*(?:::|\.))*([A-Za-z_]\w*)(?:\(.*\))?")


def source_root():
    if not ROOT or not os.path.isfile(os.path.join(ROOT, "CMakeLists.txt")):
        pytest.fail("RAWGMENT_SOURCE_DIR is not the project's source tree: run the Python tests through ctest")
    return ROOT


def tracked_files(root):
    found = []
    for pattern in CODE_GLOBS:
        for path in glob.glob(os.path.join(root, pattern), recursive=True):
            rel = os.path.relpath(path, root)
            if not rel.startswith(("build" + os.sep, ".")):
                found.append(path)
    return sorted(set(found))


def citations(path, unreleased_only):
    """(line, text) of every backquoted span of a Markdown file, outside fenced blocks."""
    lines = open(path, encoding="utf-8").read().split("\n")
    inside = not unreleased_only
    spans, fenced = [], False
    for number, line in enumerate(lines, 1):
        if unreleased_only and line.startswith("## "):
            inside = line.startswith("## Unreleased")
        if not inside:
            continue
        if line.startswith("```"):
            fenced = not fenced
            continue
        if not fenced:
            spans.extend((number, m.group(1)) for m in re.finditer(r"`([^`]+)`", line))
    return spans


@pytest.fixture(scope="module")
def project():
    root = source_root()
    files = tracked_files(root)
    tests, py_tests, words = set(), set(), set()
    for path in files:
        if os.path.basename(path) == os.path.basename(__file__):
            continue  # its own test holds names that exist nowhere else
        text = open(path, encoding="utf-8", errors="replace").read()
        if path.endswith((".cpp", ".hpp")):
            tests.update(m.group(1) + "." + m.group(2) for m in TEST_MACRO.finditer(text))
        if os.path.basename(path).startswith("test_") and path.endswith(".py"):
            py_tests.update(PY_TEST.findall(text))
        words.update(re.findall(r"[A-Za-z_]\w*", text))
    top = {name for name in os.listdir(root) if not name.startswith(".") and name != "build"}
    return {"root": root, "tests": tests, "suites": {t.split(".")[0] for t in tests}, "py_tests": py_tests,
            "words": words, "top": top}


def documents(root):
    docs = [(os.path.join(root, "README.md"), False)]
    docs += [(p, False) for p in sorted(glob.glob(os.path.join(root, "docs", "*.md")))]
    docs.append((os.path.join(root, "CHANGELOG.md"), True))
    return docs


def broken_citations(project, path, unreleased_only):
    broken = []
    where = os.path.relpath(path, project["root"])
    for line, span in citations(path, unreleased_only):
        span = span.strip()
        head = re.sub(r"(:\d[\d-]*)+$", "", span)  # a path cited at its lines, `scene.cpp:213-313`
        if PATH.fullmatch(head) and head.split("/")[0] in project["top"]:
            full = os.path.join(project["root"], head)
            # A topic's pair is cited without its extension: `helpers/chart_patches`.
            if "*" not in head and not os.path.exists(full) and not glob.glob(glob.escape(full) + ".*"):
                broken.append(f"{where}:{line}: no file or folder '{head}'")
            continue
        m = TEST_NAME.fullmatch(span)
        if m and m.group(1) in project["suites"] and sum(c.isupper() for c in m.group(2)) >= 2:
            if span not in project["tests"]:
                broken.append(f"{where}:{line}: no test '{span}'")
            continue
        if re.fullmatch(r"test_\w+", span):
            if span not in project["py_tests"]:
                broken.append(f"{where}:{line}: no Python test '{span}'")
            continue
        if unreleased_only:
            continue  # a changelog names what was, functions removed since included
        m = FUNCTION.fullmatch(span)
        if m and ("(" in span or "::" in span) and " " not in span.split("(")[0]:
            if m.group(1) not in project["words"]:
                broken.append(f"{where}:{line}: '{span}': no code holds the name '{m.group(1)}'")
    return broken


def test_every_file_test_and_function_the_docs_cite_exists(project):
    broken = []
    for path, unreleased_only in documents(project["root"]):
        broken += broken_citations(project, path, unreleased_only)
    assert not broken, "\n".join(broken)


def test_a_citation_of_what_is_gone_is_found(project, tmp_path):
    doc = tmp_path / "doc.md"
    suite = sorted(project["suites"])[0]
    doc.write_text("See `test/test_apps.cpp`, `test/test_app_rules.cpp:12`, `" + suite +
                   ".aTestNobodyEverWrote`, `test_nobody_wrote_this`, `cv::rawgment::noSuchFunction()`,\n"
                   "`tools/noise/subr.sh`, `DarkFrameBank.create`, `NoiseModel.load()` and `applyScene()`.\n"
                   "```\n`test/inside_a_block.cpp`\n```\n", encoding="utf-8")
    broken = broken_citations(project, str(doc), False)
    assert [b.split(": ", 1)[1] for b in broken] == [
        "no file or folder 'test/test_apps.cpp'", "no test '" + suite + ".aTestNobodyEverWrote'",
        "no Python test 'test_nobody_wrote_this'",
        "'cv::rawgment::noSuchFunction()': no code holds the name 'noSuchFunction'"]
