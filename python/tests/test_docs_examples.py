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
from conftest import env_path

APPS = ("rawgment_augment", "rawgment_calibrate", "rawgment_cameras", "rawgment_demo", "rawgment_simulate",
        "rawgment_tradeoffs", "rawgment_validate")
MODULES = ("rawgment.batch", "rawgment_ablation")


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
            cmd = [os.path.join(env_path("RAWGMENT_APP_DIR"), program), "--help"]
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
    # Captured at gain 2: ISO 200 for a model whose gain 1 is ISO 100.
    rg.writeDng(str(tmp_path / "IMG_0001.dng"), rg.RawImage(mosaic=raw, format=sensor.rawFormat(2.0), iso=200))
    model = sensor.effectiveModel()
    model.baseIso = 100
    for name in ("camera.yml", "noise_model.yml"):
        model.save(str(tmp_path / name))
    # Dark frames of that sensor at gains 2 and 8, for the dark-frame bank's example.
    (tmp_path / "darks").mkdir()
    for gain in (2.0, 8.0):
        for t in range(3):
            dark = sensor.capture(np.zeros((96, 128), np.float32), gain, 1.0, seed=6, frameIndex=t)
            rg.writeMosaic(str(tmp_path / "darks" / ("dark_g%g_%d.png" % (gain, t))), dark,
                           rg.MosaicMetadata(format=sensor.rawFormat(gain)))
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
    source_dir, build_dir = env_path("RAWGMENT_SOURCE_DIR"), env_path("RAWGMENT_BUILD_DIR")
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


def test_the_calibration_guide_prints_what_it_shows(app_dir, tmp_path):
    # docs/calibrate_your_camera.md, section 1, showed figures that the same commands no longer printed.
    # Here its commands run as written (plus --plots=false, which changes no printed figure), every line of
    # the block it shows must be a line of the output, and the paragraph's offsets from the truth must be
    # those of the printed model (to its rounding).
    guide = os.path.join(env_path("RAWGMENT_SOURCE_DIR"), "docs", "calibrate_your_camera.md")
    text = open(guide, encoding="utf-8").read()
    section = text[text.index("## 1. Try it first on simulated files"):text.index("## 2. What to shoot")]
    commands = re.findall(r"^    build/release/bin/(rawgment_\w+ .*?)(?<!\\)$", section.replace("\\\n", " "), re.M)
    assert [c.split()[0] for c in commands] == ["rawgment_simulate", "rawgment_calibrate"], commands
    outputs = []
    for command in commands:
        args = command.split()
        if args[0] == "rawgment_calibrate":
            args.append("--plots=false")
        run = subprocess.run([os.path.join(app_dir, args[0])] + args[1:], cwd=tmp_path, capture_output=True,
                             text=True)
        assert run.returncode == 0, run.stdout + run.stderr
        outputs.append(run.stdout)
    printed = set(line.rstrip() for line in outputs[1].split("\n"))
    shown = section[section.index("It says, among its notes:"):].split("\n\n")[1]
    for line in shown.split("\n"):
        assert line[4:].rstrip() in printed, "docs/calibrate_your_camera.md shows a line the command does not " \
                                             "print:\n%s\nprinted:\n%s" % (line[4:], outputs[1])
    model = re.search(r"model: alpha (\S+) \+- (\S+)  sigma_d\^2 (\S+) \+- (\S+) \[.*?\]  sigma_r\^2 (\S+) \+- (\S+) ",
                      outputs[1])
    truth = rg.NoiseModel.load(str(tmp_path / "sim" / "truth_noise_model.yml"))
    # The truth at ISO 100; the calibration's gain 1 is ISO 200, twice the gain.
    expected = (2 * truth.alpha, 4 * truth.sigmaD2, truth.sigmaR2)
    values = [float(model.group(i)) for i in (1, 3, 5)]
    errors = [float(model.group(i)) for i in (2, 4, 6)]
    stated = re.search(r"the calibration is\s+(\S+),\s+(\S+)\s+and\s+(\S+)\s+of its standard errors off\s+"
                       r"\((\S+)%,\s+(\S+)%,\s+(\S+)%\)", section)
    assert stated, "the paragraph of offsets is missing"
    for k in range(3):
        z = (values[k] - expected[k]) / errors[k]
        percent = 100 * (values[k] / expected[k] - 1)
        assert abs(float(stated.group(1 + k)) - z) <= 0.051, (k, stated.group(1 + k), z)
        assert abs(float(stated.group(4 + k)) - percent) <= 0.0051 + 0.01 * abs(percent), (k, stated.group(4 + k), percent)
    samples = re.search(r"of (\d+) samples used", outputs[1]).group(1)
    assert "(%s samples" % format(int(samples), ",") in section, samples
    # The table of what more data buys, later in the guide, is that run's report.md.
    report = (tmp_path / "cal" / "report.md").read_text()
    plan = text[text.index("| plan | alpha | sigma_d^2 | sigma_r^2 |"):]
    for row in plan[:plan.index("\n\n")].split("\n")[2:]:
        assert row in report, "docs/calibrate_your_camera.md shows a plan row report.md does not have: " + row


def test_the_guides_colour_chart_example_prints_what_it_shows(app_dir, tmp_path):
    # The single-frame example of docs/calibrate_your_camera.md on ../shared/data/colorchart.dng: its line and
    # every row of its verdict table as the command prints them today.
    data = os.path.join(env_path("RAWGMENT_SOURCE_DIR"), "..", "shared", "data", "colorchart.dng")
    if not os.path.exists(data):
        pytest.skip("../shared/data/colorchart.dng is missing (see ../shared/data/SOURCES.md)")
    guide = open(os.path.join(env_path("RAWGMENT_SOURCE_DIR"), "docs", "calibrate_your_camera.md"),
                 encoding="utf-8").read()
    (tmp_path / "m.yml").write_text("%%YAML:1.0\ncalibration_manifest:\n  patches: detect\n  bursts:\n"
                                    "    - { files: [ '%s' ] }\n" % os.path.abspath(data))
    run = subprocess.run([os.path.join(app_dir, "rawgment_calibrate"), str(tmp_path / "m.yml"),
                          "--out=" + str(tmp_path / "out"), "--plots=false"], capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    line = re.search(r"variance = \((\S+) \+- (\S+)\) mean \+ \((\S+) \+- (\S+)\)  \(R\^2 (\S+),", run.stdout)
    shown = re.search(r"variance = \((\S+) \+- (\S+)\) mean \+ \((\S+) \+- (\S+)\) \(DN above black, \+- one\s+"
                      r"standard error, R\^2 (\S+) over", guide)
    assert line and shown, run.stdout
    for k in range(1, 6):
        digits = len(shown.group(k).split(".")[1]) if "." in shown.group(k) else 0
        assert round(float(line.group(k)), digits) == float(shown.group(k)), (k, line.group(k), shown.group(k))
    report = (tmp_path / "out" / "report.md").read_text()
    table = guide[guide.index("| check | result | measured figure and threshold |"):]
    table = table[:table.index("\n\n")]
    for row in table.split("\n")[2:]:
        assert row.replace("../shared/data/colorchart.dng", os.path.abspath(data)) in report, row


def test_the_real_cameras_report_is_what_the_command_makes_today(app_dir, tmp_path):
    # docs/real_cameras.md holds the output of rawgment_cameras --report on darktable's file, copied as it is
    # (its headings one level down, its images under images/): a run today must give it back, but for the
    # seconds the import took.
    path = rg.darktableProfilesPath()
    if not path:
        if os.environ.get("CI"):
            pytest.fail("darktable's noiseprofiles.json is missing in CI (scripts/install-deps.sh fetches it)")
        pytest.skip("darktable's noiseprofiles.json not found (run scripts/fetch-darktable-profiles.sh)")
    doc = open(os.path.join(env_path("RAWGMENT_SOURCE_DIR"), "docs", "real_cameras.md"), encoding="utf-8").read()
    start = doc.index("<!-- generated by rawgment_cameras --report")
    shown = doc[doc.index("\n", start) + 1:doc.index("<!-- end of generated report -->")].strip()
    run = subprocess.run([os.path.join(app_dir, "rawgment_cameras"), "--profiles=" + path,
                          "--report=" + str(tmp_path / "report")], capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    made = (tmp_path / "report" / "report.md").read_text()
    made = made[made.index("## The cameras"):].replace("## ", "### ").replace("](real_cameras_", "](images/real_cameras_")
    seconds = re.compile(r"read and fitted in [0-9.]+ s")
    assert seconds.sub("read and fitted in T s", shown) == seconds.sub("read and fitted in T s", made.strip())
