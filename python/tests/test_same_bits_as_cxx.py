"""Python gives the C++ API's bits: every result of tests/cxx_reference.cpp, recomputed through the
module with the same parameters and seeds, is identical (arrays bit for bit, numbers to the last digit)."""
import pickle

import numpy as np
import pytest

import rawgment as rg
from conftest import chart_mean


def numbers(folder):
    out = {}
    for line in (folder / "numbers.txt").read_text().splitlines():
        key, *values = line.split()
        out[key] = values
    return out


def same(folder, name, array):
    expected = np.load(folder / (name + ".npy"))
    assert array.dtype == expected.dtype, name
    assert array.shape == expected.shape, name
    assert np.array_equal(array, expected), "%s differs from C++ in %d elements" % (
        name, int(np.count_nonzero(array != expected)))


def test_simulator_and_noise_steps(cxx_reference, sensor, capture):
    ref = numbers(cxx_reference)
    same(cxx_reference, "capture", capture)
    fmt = sensor.rawFormat(2.0)
    model = sensor.effectiveModel()
    jitter = rg.ColorJitter.exposureChange(0.2, 2.0)
    jitter.contrast = (0.4, 0.38, 0.41, 0.5)
    jitter.brightness = -3
    out, outFormat, report, mask = rg.colorJitter(capture, fmt, model, jitter, rg.NoiseAlignment.ACCOUNT_PRIOR,
                                                  seed=5, saturatedMask=True)
    same(cxx_reference, "jitter", out)
    same(cxx_reference, "jitter_mask", mask)
    assert outFormat.gain == float(ref["jitter_gain"][0])
    assert report.brighteningPixels == int(ref["jitter_brightening"][0])

    blurred, _ = rg.motionBlur(capture, fmt, model, rg.linearMotionKernel(9, 30), rg.NoiseAlignment.ACCOUNT_PRIOR,
                               seed=6)
    same(cxx_reference, "blur", blurred)
    scaled, _ = rg.scaleMosaic(capture, fmt, model, 1.03, rg.NoiseAlignment.IGNORE_PRIOR, seed=7)
    same(cxx_reference, "scale", scaled)


def test_dark_frame_bank(cxx_reference, sensor, capture):
    ref = numbers(cxx_reference)
    fmt = sensor.rawFormat(2.0)
    model = sensor.effectiveModel()
    path = str(cxx_reference / "bank.yml")
    bank = rg.DarkFrameBank.load(path)
    assert [g.gain for g in bank.groups] == [2.0, 4.0]
    # Pickled as its path: the other process loads the same bank.
    again = pickle.loads(pickle.dumps(bank))
    assert again.path == path and again == bank
    out, outFormat, report = rg.colorJitter(capture, fmt, model, rg.ColorJitter.exposureChange(0.3, 2.0),
                                            rg.NoiseOptions(darkBank=path, darkBankTied=True), seed=8)
    same(cxx_reference, "bank_jitter", out)
    assert outFormat.gain == 4.0
    assert report.readBrighteningPixels == int(ref["bank_read_brightening"][0])
    blurred, _ = rg.motionBlur(capture, fmt, model, rg.linearMotionKernel(9, 30), rg.NoiseOptions(darkBank=path),
                               seed=9)
    same(cxx_reference, "bank_blur", blurred)


def test_a_bank_is_copied_in_memory_and_pickled_only_as_its_own_file(cxx_reference, tmp_path, monkeypatch):
    """#79 items 9 and 11: a bank loaded by a relative path loaded another bank in a worker with another
    working folder; copy.deepcopy of an edited bank reverted to the file (gain 1.5 back to 1), and of an
    unsaved bank raised TypeError."""
    import copy
    monkeypatch.chdir(cxx_reference)
    bank = rg.DarkFrameBank.load("bank.yml")
    assert bank.path == str(cxx_reference / "bank.yml")
    monkeypatch.chdir(tmp_path)
    assert pickle.loads(pickle.dumps(bank)) == bank
    assert bank.readFrame(0, 0).size > 0  # its frames were resolved against the absolute folder too
    edited = copy.deepcopy(bank)
    groups = edited.groups
    groups[0].gain = 1.5
    edited.groups = groups
    assert copy.deepcopy(edited).groups[0].gain == 1.5 and copy.copy(edited).groups[0].gain == 1.5
    with pytest.raises(TypeError, match="is not its file"):
        pickle.dumps(edited)
    # A deep copy owns its maps: writing into the copy's pattern leaves the original's as it was.
    twin = copy.deepcopy(bank)
    statistics = twin.groups[0].statistics
    pattern = statistics.pattern
    pattern[0, 0] += 1000
    statistics.pattern = pattern
    groups = twin.groups
    groups[0].statistics = statistics
    twin.groups = groups
    assert twin.groups[0].statistics.pattern[0, 0] != bank.groups[0].statistics.pattern[0, 0]
    with pytest.raises(TypeError, match="is not its file"):
        pickle.dumps(twin)
    unsaved = rg.DarkFrameBank()
    unsaved.groups = bank.groups
    unsaved.format, unsaved.size = bank.format, bank.size
    assert copy.deepcopy(unsaved) == unsaved
    with pytest.raises(TypeError, match="save"):
        pickle.dumps(unsaved)


def test_scene_policy_and_boxes(cxx_reference, sensor, capture):
    ref = numbers(cxx_reference)
    fmt = sensor.rawFormat(2.0)
    policy = rg.RandomScenePolicy(blurProbability=1, geometryProbability=1)
    seed = rg.augmentedOutputSeed(1, "frame", 2)
    scene = policy.draw(capture, fmt, seed)
    out, outFormat, _, boxes = rg.applyScene(capture, fmt, sensor.effectiveModel(), scene, seed=seed,
                                             boxes=[(10, 12, 30, 20), (100, 80, 20, 10)])
    same(cxx_reference, "scene", out)
    assert float(ref["scene_gain"][0]) == outFormat.gain
    assert boxes == [tuple(int(v) for v in ref["scene_box%d" % i]) for i in range(2)]


def test_a_monochrome_frames_scene_and_preview(cxx_reference, sensor, capture):
    ref = numbers(cxx_reference)
    fmt = rg.RawFormat(pattern=rg.CFA_MONO, blackLevel=(64, 64, 64, 64), whiteLevel=4095, gain=2.0)
    assert fmt.isMonochrome()
    policy = rg.RandomScenePolicy(blurProbability=1, geometryProbability=1, hueProbability=1)
    seed = rg.augmentedOutputSeed(1, "mono", 0)
    scene = policy.draw(capture, fmt, seed)
    assert len(set(scene.jitter.contrast)) == 1  # no hue on a monochrome frame
    same(cxx_reference, "mono_kernel", np.asarray(scene.motionKernel))
    out, outFormat, _, _ = rg.applyScene(capture, fmt, sensor.effectiveModel(), scene, seed=seed)
    same(cxx_reference, "mono_scene", out)
    assert outFormat.pattern == rg.CFA_MONO and outFormat.gain == float(ref["mono_scene_gain"][0])
    same(cxx_reference, "mono_isp", rg.renderSimpleIsp(out, outFormat))


def test_normals_shapiro_wilk_and_isp(cxx_reference, sensor, capture):
    ref = numbers(cxx_reference)
    z = rg.fillStandardNormal((33, 17), 9)
    same(cxx_reference, "normal", z)
    result = rg.shapiroWilk(z)
    assert result.W == float(ref["sw_W"][0]) and result.pValue == float(ref["sw_p"][0])
    same(cxx_reference, "isp", rg.renderSimpleIsp(capture, sensor.rawFormat(2.0)))


def test_burst_statistics_and_calibration(cxx_reference, sensor):
    ref = numbers(cxx_reference)
    chart, mean = chart_mean()
    squares = rg.cfaAlignedSquares(chart.patches, 8)
    samples = []
    for g in range(3):
        gain = rg.dbToLinearGain(6.0 * g)
        stats = rg.BurstStatistics(sensor.rawFormat(gain))
        for frame in sensor.captureBurst(mean, gain, 1.0, 16, 100 + g):
            stats.add(frame)
        if g == 0:
            same(cxx_reference, "burst_variance", stats.variance())
        samples += rg.sampleBurstPatches(stats, squares, gain)
    assert len(samples) == int(ref["calibration_samples"][0])
    report = rg.calibrateNoiseModel(samples)
    assert report.model.alpha == float(ref["calibration_alpha"][0])
    assert report.model.sigmaD2 == float(ref["calibration_sigmaD2"][0])
    assert report.model.sigmaR2 == float(ref["calibration_sigmaR2"][0])


def test_every_cpu_path_gives_the_same_bits(sensor, capture):
    fmt, model = sensor.rawFormat(2.0), sensor.effectiveModel()
    results = []
    try:
        for path in rg.availableCpuPaths():
            rg.setCpuPath(path)
            results.append(rg.colorJitter(capture, fmt, model, rg.ColorJitter.exposureChange(0.1, 4.0), seed=3)[0])
    finally:
        rg.setCpuPath(rg.CpuPath.AUTO)
    assert all(np.array_equal(results[0], r) for r in results[1:])


def dark_model(model):
    """The dark-frame components of tests/cxx_reference.cpp: maps of exact binary values."""
    dark = rg.NoiseModel(model.alpha, model.sigmaD2, model.sigmaR2)
    dark.rowSigmaD2, dark.rowSigmaR2 = 0.2, 0.4
    dark.tukeyRead, dark.tukeyLambda = True, -0.05
    r, c = np.mgrid[0:96, 0:128]
    dark.darkShadingPerGain = ((c % 7) * 0.25 - 0.5).astype(np.float32)
    dark.darkShadingOffset = ((r % 5) - 2 + (c % 3) * 0.5).astype(np.float32)
    return dark


def test_dark_frame_components(cxx_reference, sensor, capture):
    ref = numbers(cxx_reference)
    fmt = sensor.rawFormat(2.0)
    dark = dark_model(sensor.effectiveModel())
    out = rg.colorJitter(capture, fmt, dark, rg.ColorJitter.exposureChange(0.1, 4.0), rg.NoiseAlignment.ACCOUNT_PRIOR,
                         seed=8)[0]
    same(cxx_reference, "dark_jitter", out)
    blurred, _ = rg.motionBlur(capture, fmt, dark, rg.linearMotionKernel(9, 30), rg.NoiseAlignment.ACCOUNT_PRIOR,
                               seed=9)
    same(cxx_reference, "dark_blur", blurred)
    params = rg.SensorParams()
    params.blackLevel = (64, 66, 65, 63)
    params.bitDepth = 12
    noise = params.noise
    noise.rowSigmaD2, noise.rowSigmaR2 = dark.rowSigmaD2, dark.rowSigmaR2
    noise.tukeyRead, noise.tukeyLambda = True, dark.tukeyLambda
    noise.darkShadingPerGain, noise.darkShadingOffset = dark.darkShadingPerGain, dark.darkShadingOffset
    params.noise = noise
    sim = rg.SensorSimulator(params, (128, 96))
    zeros = np.zeros((96, 128), np.float32)
    bursts = [sim.captureBurst(zeros, 1.0 + 7 * g, 1.0, 4, 200 + g) for g in range(2)]
    same(cxx_reference, "dark_capture", bursts[1][0])
    calibrated = rg.calibrateDarkNoise(bursts, [1.0, 8.0], sim.rawFormat(1.0), sim.effectiveModel())
    assert repr(calibrated.model.rowSigmaD2) == repr(float(ref["dark_row_d2"][0]))
    assert repr(calibrated.model.rowSigmaR2) == repr(float(ref["dark_row_r2"][0]))
    assert repr(calibrated.model.tukeyLambda) == repr(float(ref["dark_lambda"][0]))
    same(cxx_reference, "dark_shading_per_gain", calibrated.model.darkShadingPerGain)


def test_dark_components_survive_save_and_load(tmp_path, sensor):
    dark = dark_model(sensor.effectiveModel())
    dark.save(str(tmp_path / "dark.yml"))
    back = rg.NoiseModel.load(str(tmp_path / "dark.yml"))
    assert (back.rowSigmaD2, back.rowSigmaR2, back.tukeyRead, back.tukeyLambda) == (0.2, 0.4, True, -0.05)
    assert np.array_equal(back.darkShadingOffset, dark.darkShadingOffset)
    assert np.array_equal(back.darkShadingAt(2.0), 2 * dark.darkShadingPerGain + dark.darkShadingOffset)
    plain = rg.NoiseModel(1, 1, 1)
    assert plain.darkShadingPerGain is None and not plain.hasDarkComponents()
    # Pickled with its maps, as Dask sends a model to its workers.
    assert pickle.loads(pickle.dumps(dark)) == dark and pickle.loads(pickle.dumps(plain)) == plain
