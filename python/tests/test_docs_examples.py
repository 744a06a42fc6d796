"""Every example in README.md and docs/ works as shown: Python blocks run, C++ blocks compile against
this build and run, and every flag shown for an app or a Python command line is one its --help lists.
An example that rots fails here, naming the file and line."""
import glob
import os
import re
import subprocess
import sys

import numpy as np
import pytest

import rawgment as rg

APPS = ("rawgment_augment", "rawgment_calibrate", "rawgment_demo", "rawgment_simulate", "rawgment_tradeoffs",
        "rawgment_validate")
MODULES = ("rawgment.batch", "rawgment.ablation")


def documents():
    source = os.environ.get("RAWGMENT_SOURCE_DIR")
    if not source:
        pytest.fail("RAWGMENT_SOURCE_DIR is not set: run the Python tests through ctest (python_tests)")
    return [os.path.join(source, "README.md")] + sorted(glob.glob(os.path.join(source, "docs", "*.md")))


def fenced_blocks(language):
    """(file, first line, text) of every fenced block of `language` ("" for blocks without one)."""
    found = []
    for path in documents():
        lines = open(path, encoding="utf-8").read().split("\n")
        k = 0
        while k < len(lines):
            if lines[k].startswith("```"):
                lang, start, body = lines[k][3:].strip(), k + 1, []
                k += 1
                while k < len(lines) and not lines[k].startswith("```"):
                    body.append(lines[k])
                    k += 1
                if lang == language:
                    found.append((os.path.basename(path), start + 1, "\n".join(body)))
            k += 1
    return found


def command_lines():
    """(file, line, command) of every shown command of an app or a Python command line: in shell blocks,
    in indented blocks and in inline code, with backslash continuations joined."""
    commands = []
    names = "|".join(re.escape(n) for n in APPS + MODULES)
    for path in documents():
        text = open(path, encoding="utf-8").read()
        lines = text.split("\n")
        in_fence = False
        k = 0
        while k < len(lines):
            line = lines[k]
            if line.startswith("```"):
                in_fence = not in_fence
                k += 1
                continue
            start = k
            candidates = []
            if in_fence or line.startswith("    "):
                while line.endswith("\\") and k + 1 < len(lines):
                    k += 1
                    line = line[:-1] + " " + lines[k].strip()
                candidates.append(line)
            else:
                candidates += re.findall(r"`([^`]+)`", line)
            for c in candidates:
                if re.search(r"(^|[/\s])(%s)\b" % names, c) and "--" in c:
                    commands.append((os.path.basename(path), start + 1, c))
            k += 1
    return commands


def program_of(command):
    for name in MODULES:
        if "-m " + name in command:
            return name
    for name in APPS:
        if re.search(r"(^|[/\s])%s\b" % re.escape(name), command):
            return name
    return None


_help_cache = {}


def flags_of(program):
    if program not in _help_cache:
        if program in APPS:
            cmd = [os.path.join(os.environ["RAWGMENT_APP_DIR"], program), "--help"]
        else:
            cmd = [sys.executable, "-m", program, "--help"]
        run = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
        _help_cache[program] = set(re.findall(r"--([a-z][\w-]*)", run.stdout + run.stderr))
    return _help_cache[program]


def shown_flags(command):
    # Everything after the program's name; '--' inside comments after '#' is prose.
    command = command.split(" #", 1)[0]
    return set(re.findall(r"(?<![\w-])--([a-z][\w-]*)", command))


def test_the_docs_show_commands_and_blocks():
    # The collectors find what the docs hold: a parser that found nothing would make every test pass.
    assert len(command_lines()) >= 10
    assert fenced_blocks("python") and fenced_blocks("cpp")


@pytest.mark.parametrize("where, line, command", command_lines(), ids=lambda v: str(v)[:60])
def test_every_flag_shown_is_one_the_program_has(where, line, command):
    program = program_of(command)
    assert program is not None, command
    unknown = sorted(shown_flags(command) - flags_of(program) - {"help"})
    assert not unknown, "%s:%d shows %s for %s, whose --help lists no such flag" % (
        where, line, ", ".join("--" + f for f in unknown), program)


@pytest.fixture
def example_files(tmp_path, sensor, monkeypatch):
    """The files the examples name, made from the simulated sensor, in a folder of their own."""
    from conftest import chart_mean

    _, mean = chart_mean()
    raw = sensor.capture(mean, 2.0, 1.0, seed=5)
    rg.writeDng(str(tmp_path / "IMG_0001.dng"), rg.RawImage(mosaic=raw, format=sensor.rawFormat(2.0)))
    for name in ("camera.yml", "noise_model.yml"):
        sensor.effectiveModel().save(str(tmp_path / name))
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize("where, line, code", fenced_blocks("python"), ids=lambda v: str(v)[:40])
def test_every_python_example_runs(where, line, code, example_files):
    namespace = {"__name__": "docs_example"}
    try:
        exec(compile(code, "%s:%d" % (where, line), "exec"), namespace)
    except Exception as e:  # the failure names the example, not this harness
        pytest.fail("%s:%d: the example raised %s: %s" % (where, line, type(e).__name__, e))


@pytest.mark.parametrize("where, line, code", fenced_blocks("cpp"), ids=lambda v: str(v)[:40])
def test_every_cxx_example_compiles_and_runs(where, line, code, example_files):
    source_dir, build_dir = os.environ["RAWGMENT_SOURCE_DIR"], os.environ["RAWGMENT_BUILD_DIR"]
    includes = [l for l in code.split("\n") if l.startswith("#include")]
    body = [l for l in code.split("\n") if not l.startswith("#include")]
    # A snippet of statements becomes the body of main(); a whole program stays as it is.
    program = code if "int main" in code else "\n".join(includes) + "\nint main()\n{\n" + "\n".join(body) + \
        "\n    return 0;\n}\n"
    (example_files / "example.cpp").write_text(program)
    compile_cmd = ["c++", "-std=c++17", "-o", "example", "example.cpp",
                   "-I" + os.path.join(source_dir, "modules", "rawgment", "include"), "-I/usr/include/opencv4",
                   "-L" + os.path.join(build_dir, "lib"), "-Wl,-rpath," + os.path.join(build_dir, "lib"),
                   "-lopencv_rawgment", "-lopencv_imgproc", "-lopencv_core"]
    built = subprocess.run(compile_cmd, capture_output=True, text=True)
    assert built.returncode == 0, "%s:%d does not compile:\n%s" % (where, line, built.stderr)
    run = subprocess.run(["./example"], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, "%s:%d fails when run:\n%s" % (where, line, run.stderr)
