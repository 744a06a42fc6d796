"""cv2.rawgment, the binding OpenCV's generator makes when rawgment is built inside OpenCV, gives the C++
library's bits: every result of python/tests/cxx_reference.cpp (the standalone library, in its own
process) is recomputed through cv2.rawgment from the same inputs and seeds and compared bit for bit.

Run by scripts/build-in-opencv.sh with that build's cv2 first on PYTHONPATH. This folder has no
conftest of the pybind module: loading both libraries (and two builds of OpenCV) into one process
would let one library's symbols stand in for the other's, and the comparison would prove nothing.
"""
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

cv2 = pytest.importorskip("cv2")
if not hasattr(cv2, "rawgment"):
    pytest.skip("this cv2 (%s) has no rawgment module: run scripts/build-in-opencv.sh" % cv2.__file__,
                allow_module_level=True)
rg = cv2.rawgment


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The C++ reference folder: arrays as .npy, numbers in numbers.txt."""
    program = os.environ.get("RAWGMENT_PYTHON_REFERENCE")
    if not program:
        pytest.fail("RAWGMENT_PYTHON_REFERENCE names no program (scripts/build-in-opencv.sh sets it)")
    folder = tmp_path_factory.mktemp("cxx_reference")
    subprocess.run([program, str(folder)], check=True)
    numbers = {}
    for line in (folder / "numbers.txt").read_text().splitlines():
        key, *values = line.split()
        numbers.setdefault(key, []).append(values)
    return folder, numbers


def number(numbers, key, index=0):
    return float(numbers[key][0][index])


def same(folder, name, array):
    expected = np.load(folder / (name + ".npy"))
    assert array.dtype == expected.dtype and array.shape == expected.shape, name
    assert np.array_equal(array, expected), "%s differs from C++ in %d elements" % (
        name, int(np.count_nonzero(array != expected)))


def inputs(numbers):
    fmt = rg.RawFormat()
    fmt.blackLevel = tuple(float(v) for v in numbers["format_black"][0])
    fmt.whiteLevel = number(numbers, "format_white")
    fmt.gain = number(numbers, "format_gain")
    model = rg.NoiseModel()
    model.alpha = number(numbers, "model_alpha")
    model.sigmaD2 = number(numbers, "model_sigmaD2")
    model.sigmaR2 = number(numbers, "model_sigmaR2")
    model.validate()
    return fmt, model


def test_this_is_the_built_cv2():
    prefix = os.environ.get("RAWGMENT_OPENCV_PREFIX")
    if prefix:
        assert pathlib.Path(cv2.__file__).resolve().is_relative_to(pathlib.Path(prefix).resolve()), cv2.__file__
    assert cv2.__version__.startswith("4.6")


def test_noise_model(reference, tmp_path):
    _, numbers = reference
    _, model = inputs(numbers)
    assert model.variance(100, 3) == number(numbers, "model_variance_100_3")
    means = np.array([[0, 100], [2000, -5]], np.float64)
    assert np.array_equal(model.variance(means, 3), [[model.variance(float(m), 3) for m in row] for row in means])
    path = str(tmp_path / "model.yml")
    model.save(path)
    back = rg.NoiseModel_load(path)
    assert (back.alpha, back.sigmaD2, back.sigmaR2) == (model.alpha, model.sigmaD2, model.sigmaR2)
    model.sigmaD2 = -1
    with pytest.raises(cv2.error, match="NoiseModel.sigmaD2"):
        model.validate()
    with pytest.raises(cv2.error, match="NoiseModel.sigmaD2"):
        model.variance(100, 3)


def test_noise_steps(reference):
    folder, numbers = reference
    fmt, model = inputs(numbers)
    capture = np.load(folder / "capture.npy")
    jitter = rg.ColorJitter_exposureChange(0.2, 2.0)
    jitter.contrast = (0.4, 0.38, 0.41, 0.5)
    jitter.brightness = -3
    noise = rg.NoiseOptions(rg.NoiseAlignment_ACCOUNT_PRIOR)
    out, outFormat, report, mask = rg.colorJitter(capture, fmt, model, jitter, noise, 5)
    same(folder, "jitter", out)
    same(folder, "jitter_mask", mask)
    assert outFormat.gain == number(numbers, "jitter_gain")
    assert report.brighteningPixels == int(numbers["jitter_brightening"][0][0])
    assert report.steps == ("colorJitter",)

    blurred, _ = rg.motionBlur(capture, fmt, model, rg.linearMotionKernel(9, 30), noise, 6)
    same(folder, "blur", blurred)
    scaled, _ = rg.scaleMosaic(capture, fmt, model, 1.03, rg.NoiseOptions(rg.NoiseAlignment_IGNORE_PRIOR), 7)
    same(folder, "scale", scaled)


def test_scene_policy_and_boxes(reference):
    folder, numbers = reference
    fmt, model = inputs(numbers)
    capture = np.load(folder / "capture.npy")
    policy = rg.RandomScenePolicy()
    policy.blurProbability = 1
    policy.geometryProbability = 1
    seed = rg.augmentedOutputSeed(1, "frame", 2)
    scene = policy.draw(capture, fmt, seed)
    out, outFormat, report, boxes = rg.applyScene(capture, fmt, model, scene, seed, boxes=[(10, 12, 30, 20),
                                                                                         (100, 80, 20, 10)])
    same(folder, "scene", out)
    assert outFormat.gain == number(numbers, "scene_gain")
    assert [tuple(int(v) for v in box) for box in boxes] == [
        tuple(int(v) for v in numbers["scene_box%d" % i][0]) for i in range(2)]
    assert report.steps and len(report.stepSeconds) == len(report.steps)


def test_a_monochrome_frames_scene_and_preview(reference):
    folder, numbers = reference
    fmt, model = inputs(numbers)
    fmt.pattern = rg.CFA_MONO
    fmt.blackLevel = (64, 64, 64, 64)
    assert fmt.isMonochrome()
    capture = np.load(folder / "capture.npy")
    policy = rg.RandomScenePolicy()
    policy.blurProbability = 1
    policy.geometryProbability = 1
    policy.hueProbability = 1
    seed = rg.augmentedOutputSeed(1, "mono", 0)
    scene = policy.draw(capture, fmt, seed)
    same(folder, "mono_kernel", scene.motionKernel)
    out, outFormat, _, _ = rg.applyScene(capture, fmt, model, scene, seed, boxes=[])
    same(folder, "mono_scene", out)
    assert outFormat.pattern == rg.CFA_MONO and outFormat.gain == number(numbers, "mono_scene_gain")
    assert rg.cfaChannelAt(rg.CFA_MONO, 1, 1) == rg.CFA_W


def test_shapiro_wilk(reference):
    folder, numbers = reference
    normals = np.load(folder / "normal.npy")
    result = rg.shapiroWilk(normals)
    assert result.W == number(numbers, "sw_W") and result.pValue == number(numbers, "sw_p")
    # The batch gives the single test's bits for every column.
    batch = rg.shapiroWilkBatch(normals, layout=rg.SW_SERIES_IN_COLUMNS)
    single = [rg.shapiroWilk(np.ascontiguousarray(normals[:, c])) for c in range(normals.shape[1])]
    assert [(r.W, r.pValue) for r in batch] == [(r.W, r.pValue) for r in single]


def test_burst_statistics_and_calibration(reference):
    folder, numbers = reference
    fmt, _ = inputs(numbers)
    patches = [tuple(int(v) for v in p) for p in numbers["patch"]]
    squares = rg.cfaAlignedSquares(patches, 8)
    samples = []
    for g in range(3):
        gain = rg.dbToLinearGain(6.0 * g)
        frames = np.load(folder / ("burst_g%d.npy" % g)).reshape(16, 96, 128)
        burstFormat = rg.RawFormat()
        burstFormat.blackLevel, burstFormat.whiteLevel, burstFormat.gain = fmt.blackLevel, fmt.whiteLevel, gain
        stats = rg.BurstStatistics_create(burstFormat)
        for frame in frames:
            stats.add(frame)
        assert stats.frames() == 16 and stats.format().gain == gain
        if g == 0:
            same(folder, "burst_variance", stats.variance())
        samples += rg.sampleBurstPatches(stats, squares, gain)
    assert len(samples) == int(numbers["calibration_samples"][0][0])
    report = rg.calibrateNoiseModel(samples)
    assert report.model.alpha == number(numbers, "calibration_alpha")
    assert report.model.sigmaD2 == number(numbers, "calibration_sigmaD2")
    assert report.model.sigmaR2 == number(numbers, "calibration_sigmaR2")


def test_raw_files(reference, tmp_path):
    folder, numbers = reference
    fmt, _ = inputs(numbers)
    fmt.gain = 1
    image = rg.RawImage()
    image.mosaic = np.load(folder / "capture.npy")
    image.format = fmt
    image.iso = 200
    path = tmp_path / "capture.dng"
    rg.writeDng(str(path), image)
    # The same image written by the C++ library and by cv2.rawgment: the same file.
    assert path.read_bytes() == (folder / "capture.dng").read_bytes()
    back = rg.readRaw(str(path))
    assert np.array_equal(back.mosaic, image.mosaic) and back.iso == 200
    assert back.format.blackLevel == fmt.blackLevel
    with pytest.raises(cv2.error, match="missing.dng"):
        rg.readRaw(str(tmp_path / "missing.dng"))


def test_camera_catalogue(reference):
    _, numbers = reference
    path = rg.darktableProfilesPath()
    if "cameras" not in numbers or not path:
        pytest.skip("darktable's noiseprofiles.json is not installed (scripts/install-deps.sh fetches it)")
    cameras = rg.readCameraProfiles(path)
    assert len(cameras) == int(numbers["cameras"][0][0])
    d3 = rg.findCameraProfile(cameras, "Nikon D3")
    verdict, alpha, variance = numbers["camera_d3"][0]
    fmt, _ = inputs(numbers)
    d3Model = d3.modelFor(fmt)
    assert (d3.verdict, d3Model.alpha, d3Model.variance(100, 3)) == (int(verdict), float(alpha), float(variance))
    assert d3.name() == "Nikon D3" and d3.usable()


def test_arrays_the_binding_would_misread_are_cv2_errors(reference):
    """Issue #60's cv2 round: the generated binding hands an N-D array to C++ as an N-D Mat, a (3, 3, 3)
    kernel as three channels, and its constructors report errors as SystemError. The checks are in the C++
    entry points every binding calls, and BurstStatistics is made by a function that can raise cv2.error."""
    folder, numbers = reference
    fmt, model = inputs(numbers)
    capture = np.load(folder / "capture.npy")
    four_d = capture.reshape(1, 1, *capture.shape)
    noise = rg.NoiseOptions(rg.NoiseAlignment_ACCOUNT_PRIOR)
    stats = rg.BurstStatistics_create(fmt)
    with pytest.raises(cv2.error, match="4 dimensions"):
        stats.add(four_d)
    with pytest.raises(cv2.error, match="4 dimensions"):
        model.variance(np.ones((1, 1, 2, 2), np.float64), 1.0)
    with pytest.raises(cv2.error, match="4 dimensions"):
        rg.colorJitter(four_d, fmt, model, rg.ColorJitter(), noise, 1)
    kernel = np.ones((3, 3, 3), np.float64)
    with pytest.raises(cv2.error, match="3 channels"):
        rg.motionBlur(capture, fmt, model, kernel, noise, 1)
    with pytest.raises(cv2.error, match="groupFrames"):
        rg.BurstStatistics_create(fmt, 0)
    bad = rg.RawFormat()
    bad.gain = float("nan")
    with pytest.raises(cv2.error):
        rg.BurstStatistics_create(bad)


def test_integer_samples_beyond_32_bits_are_taken_exactly():
    """cv2 casts int64 arrays to int32: [1, 2, 3, 2**40] wrapped and Shapiro-Wilk gave W 0.9929 instead of
    0.6298 (the value R's shapiro.test and the pybind module give)."""
    samples = np.array([1, 2, 3, 2 ** 40], np.int64)
    exact = rg.shapiroWilk(samples.astype(np.float64))
    assert abs(exact.W - 0.6298) < 5e-5
    for dtype in (np.int64, np.uint64):
        result = rg.shapiroWilk(samples.astype(dtype))
        assert (result.W, result.pValue) == (exact.W, exact.pValue)
    batch = rg.shapiroWilkBatch(np.stack([samples, samples], axis=1), layout=rg.SW_SERIES_IN_COLUMNS)
    assert [r.W for r in batch] == [exact.W, exact.W]
    with pytest.raises(ValueError, match="beyond 2\\*\\*53"):
        rg.shapiroWilk(np.array([1, 2, 3, 2 ** 60], np.int64))
    # Small integers keep their own depths.
    assert rg.shapiroWilk(np.array([1, 2, 4, 9], np.int32)).W == rg.shapiroWilk(np.array([1., 2., 4., 9.])).W


def test_emva1288_series_figures_and_calibration(tmp_path):
    """The EMVA 1288 topic through cv2.rawgment: a series written with cv2, its figures and the model, the
    same numbers as the C++ library's (pairs measured from the same frames), and set 001's figures against
    the reference implementation's when ../shared/data holds it."""
    rng = np.random.default_rng(1288)
    lines = ["v 4.0", "n 12 64 48"]
    frames = {}
    for s in range(8):
        for kind in ("b", "d"):
            lines.append("b %d %d" % (s + 1, 400 * (s + 1)) if kind == "b" else "d %d" % (s + 1))
            for f in range(2):
                electrons = rng.poisson(200.0 * (s + 1), (48, 64)) if kind == "b" else np.zeros((48, 64))
                dn = np.clip(np.rint(100 + 0.25 * electrons + rng.normal(0, 3, (48, 64))), 0, 4095)
                name = "%s%d_%d.png" % (kind, s, f)
                frames[name] = dn.astype(np.uint16)
                assert cv2.imwrite(str(tmp_path / name), frames[name])
                lines.append("i " + name)
    (tmp_path / "EMVA1288_Data.txt").write_text("\n".join(lines) + "\n")
    series = rg.readEmva1288(str(tmp_path / "EMVA1288_Data.txt"))
    assert (series.bits, series.width, series.height) == (12, 64, 48)
    results = rg.emva1288Results(series)
    pair = rg.measureEmva1288Pair(frames["b0_0.png"], frames["b0_1.png"], 1, 400, False)
    assert pair.mean == results.mean[0] and pair.variance == results.variance[0]
    assert abs(results.K / 0.25 - 1) < 0.06  # 8 steps of 3072 pixels: K to about 1.5%
    report = rg.calibrateEmva1288([results], [1.0], rg.Emva1288CalibrationParams())
    assert abs(report.model.alpha / 0.25 - 1) < 0.06
    with pytest.raises(cv2.error, match="line 2: 100000 x 100000 pixels"):
        (tmp_path / "huge.txt").write_text("v 4.0\nn 16 100000 100000\n")
        rg.readEmva1288(str(tmp_path / "huge.txt"))
    data = os.environ.get("RAWGMENT_SHARED_DATA_DIR", "")
    set001 = pathlib.Path(data) / "emva1288/EMVA1288_ReferenceSet_001_CCD_12Bit/EMVA1288_Data.txt"
    if set001.is_file():
        figures = rg.emva1288Results(rg.readEmva1288(str(set001)))
        assert abs(figures.K / 0.28006 - 1) < 0.005
        assert abs(figures.sigmaYDark / 3.0731 - 1) < 0.005
        assert abs(figures.dynamicRangeDb - 61.73) < 0.04


CONSTRUCT_AND_CALL_EACH = r"""
import sys
import cv2
cls = getattr(cv2.rawgment, sys.argv[1])
obj = cls()
for name in sorted(n for n in dir(obj) if not n.startswith("__")):
    try:
        member = getattr(obj, name)
        if callable(member):
            member()
    except (cv2.error, TypeError, ValueError):
        pass
"""


def test_every_class_constructs_a_valid_object_and_no_method_crashes():
    """#79 item 30: cv2.rawgment.BurstStatistics() made an object holding no C++ object, and add() on it
    died with SIGSEGV. Each class is constructed and each method called once, with no arguments, in a
    process of its own so that a crash is a failure naming the class, not the end of the run."""
    classes = sorted(n for n in dir(rg) if isinstance(getattr(rg, n), type))
    assert "BurstStatistics" in classes and "DarkFrameBank" in classes
    crashed = {}
    for name in classes:
        run = subprocess.run([sys.executable, "-c", CONSTRUCT_AND_CALL_EACH, name], capture_output=True, text=True,
                             env=dict(os.environ), timeout=120)
        if run.returncode != 0:
            crashed[name] = (run.returncode, run.stderr[-400:])
    assert not crashed, crashed


def test_a_burst_made_without_a_format_is_refused_naming_the_factory():
    stats = rg.BurstStatistics()
    with pytest.raises(cv2.error, match="BurstStatistics_create"):
        stats.add(np.zeros((4, 4), np.uint16))
    # Arguments are refused, never ignored; OpenCV 4.6's generated constructor reports the refusal as
    # SystemError (the reason the factory exists).
    with pytest.raises((TypeError, SystemError)):
        rg.BurstStatistics(rg.RawFormat())
    fmt = rg.RawFormat()
    fmt.whiteLevel = 4095
    stats.reset(fmt)
    stats.add(np.full((4, 4), 700, np.uint16))
    stats.add(np.full((4, 4), 702, np.uint16))
    assert stats.frames() == 2 and np.all(stats.variance() == 2.0)
