"""How the module takes and gives arrays, and every bad-argument path: a wrong dtype is a TypeError, a
wrong shape or layout a ValueError, each naming the argument; a C++ error is rawgment.error with the C++
message; option structs take keywords and refuse unknown ones."""
import pickle

import numpy as np
import pytest

import rawgment as rg
from conftest import chart_mean


def test_inputs_are_read_without_a_copy_including_padded_rows(sensor, capture):
    fmt, model = sensor.rawFormat(2.0), sensor.effectiveModel()
    jitter = rg.ColorJitter.exposureChange(0.3, 1.0)
    expected = rg.colorJitter(capture, fmt, model, jitter, seed=1)[0]
    # A crop of a wider array has padded rows: wrapped as it is (OpenCV's step), same result.
    wide = np.zeros((96, 160), np.uint16)
    wide[:, :128] = capture
    crop = wide[:, :128]
    assert not crop.flags.c_contiguous
    assert np.array_equal(rg.colorJitter(crop, fmt, model, jitter, seed=1)[0], expected)
    # The statistics read the caller's buffer: what the call sees is the array now, not a stale copy.
    samples = np.arange(10, dtype=np.float64)
    before = rg.shapiroWilk(samples).W
    samples[3] = 7.5
    assert rg.shapiroWilk(samples).W != before


def test_outputs_own_their_memory_and_never_alias_an_input(sensor, capture):
    fmt, model = sensor.rawFormat(2.0), sensor.effectiveModel()
    out = rg.colorJitter(capture, fmt, model, rg.ColorJitter.exposureChange(0.5, 1.0), seed=1)[0]
    assert out.flags.writeable and out.flags.c_contiguous and out.base is not None  # OpenCV's buffer, shared
    # An identity step returns the input's data in C++; Python gets a copy, never a view of the input.
    identity = rg.colorJitter(capture, fmt, model, rg.ColorJitter(), seed=1)[0]
    assert np.array_equal(identity, capture) and not np.shares_memory(identity, capture)
    scene_out = rg.applyScene(capture, fmt, model, rg.Scene(), seed=1)[0]
    assert not np.shares_memory(scene_out, capture)


def test_dst_is_written_in_place_and_gives_the_same_bits(sensor, capture):
    fmt, model = sensor.rawFormat(2.0), sensor.effectiveModel()
    jitter = rg.ColorJitter.exposureChange(0.3, 2.0)
    expected = rg.colorJitter(capture, fmt, model, jitter, seed=4)[0]
    buffer = np.full_like(capture, 7)
    result = rg.colorJitter(capture, fmt, model, jitter, seed=4, dst=buffer)
    assert result[0] is buffer and np.array_equal(buffer, expected)
    assert result[1].gain == rg.colorJitter(capture, fmt, model, jitter, seed=4)[1].gain
    # Reused: the next seed overwrites every pixel.
    rg.colorJitter(capture, fmt, model, jitter, seed=5, dst=buffer)
    assert np.array_equal(buffer, rg.colorJitter(capture, fmt, model, jitter, seed=5)[0])
    # A crop of a wider array (padded rows): only the crop is written.
    wide = np.zeros((capture.shape[0], capture.shape[1] + 2), np.uint16)
    rg.colorJitter(capture, fmt, model, jitter, seed=4, dst=wide[:, 1:-1])
    assert np.array_equal(wide[:, 1:-1], expected) and not wide[:, 0].any() and not wide[:, -1].any()
    # In place over the input, and an identity step: the result still lands in dst.
    same = capture.copy()
    assert rg.colorJitter(same, fmt, model, jitter, seed=4, dst=same)[0] is same
    assert np.array_equal(same, expected)
    identity = np.zeros_like(capture)
    rg.colorJitter(capture, fmt, model, rg.ColorJitter(), seed=4, dst=identity)
    assert np.array_equal(identity, capture)
    # motionBlur takes dst too.
    kernel = rg.linearMotionKernel(5, 30)
    blurred = np.zeros_like(capture)
    assert rg.motionBlur(capture, fmt, model, kernel, seed=2, dst=blurred)[0] is blurred
    assert np.array_equal(blurred, rg.motionBlur(capture, fmt, model, kernel, seed=2)[0])


@pytest.mark.parametrize("dst, error, words", [
    ([[0]], TypeError, ["'dst'", "numpy array", "list"]),
    (np.zeros((96, 128), np.float32), TypeError, ["'dst'", "float32", "uint16"]),
    (np.zeros((96, 100), np.uint16), ValueError, ["'dst'", "(96, 100)", "96 x 128, the shape of src"]),
    (np.zeros((96, 256), np.uint16)[:, ::2], ValueError, ["'dst'", "not contiguous"]),
])
def test_bad_dst_names_the_argument(sensor, capture, dst, error, words):
    assert capture.shape == (96, 128)
    with pytest.raises(error) as info:
        rg.colorJitter(capture, sensor.rawFormat(1.0), sensor.effectiveModel(),
                       rg.ColorJitter.exposureChange(0.5, 1.0), seed=1, dst=dst)
    for w in words:
        assert w in str(info.value)


def test_read_only_dst_is_refused(sensor, capture):
    frozen = np.zeros_like(capture)
    frozen.flags.writeable = False
    with pytest.raises(ValueError, match="'dst' is read-only"):
        rg.colorJitter(capture, sensor.rawFormat(1.0), sensor.effectiveModel(),
                       rg.ColorJitter.exposureChange(0.5, 1.0), seed=1, dst=frozen)
    assert not frozen.any()


@pytest.mark.parametrize("bad, error, words", [
    ([[1, 2], [3, 4]], TypeError, ["'src'", "numpy array", "list"]),
    (np.zeros((8, 8), np.int32), TypeError, ["'src'", "int32", "uint16 or float32"]),
    (np.zeros((8, 8), np.float64), TypeError, ["'src'", "float64"]),
    (np.zeros((8, 8), np.dtype(">u2")), TypeError, ["'src'", "byte order"]),
    (np.zeros(64, np.uint16), ValueError, ["'src'", "2-D", "(64,)"]),
    (np.zeros((2, 8, 8), np.uint16), ValueError, ["'src'", "2-D", "(2, 8, 8)"]),
    (np.zeros((8, 16), np.uint16)[:, ::2], ValueError, ["'src'", "not contiguous", "ascontiguousarray"]),
    (np.zeros((16, 8), np.uint16).T, ValueError, ["'src'", "not contiguous"]),
])
def test_bad_arrays_name_the_argument(sensor, bad, error, words):
    with pytest.raises(error) as info:
        rg.colorJitter(bad, sensor.rawFormat(1.0), sensor.effectiveModel(), rg.ColorJitter(), seed=1)
    for w in words:
        assert w in str(info.value)


def test_bad_arrays_of_other_arguments():
    with pytest.raises(TypeError, match="'kernel'"):
        rg.motionBlur(np.zeros((8, 8), np.uint16), rg.RawFormat(), rg.NoiseModel(1, 1, 1), [[1.0]], seed=1)
    with pytest.raises(TypeError, match=r"'frames\[1\]'"):
        rg.shapiroWilkBurst([np.zeros((4, 4), np.uint16), "x", np.zeros((4, 4), np.uint16)])
    with pytest.raises(ValueError, match="'samples'.*C-contiguous"):
        rg.shapiroWilk(np.zeros((10, 10))[:, ::2])
    with pytest.raises(TypeError, match="'meanAtUnitGain'"):
        rg.SensorSimulator(rg.SensorParams(), (8, 8)).capture(np.zeros((8, 8), np.float64), 1, 1, 1)
    with pytest.raises(ValueError, match="'boxes'"):
        rg.applyScene(np.zeros((8, 8), np.uint16), rg.RawFormat(), rg.NoiseModel(1, 1, 1), rg.Scene(), seed=1,
                      boxes=np.zeros((2, 3)))


def test_arguments_that_do_not_convert_are_named(sensor):
    # pybind11's own message named no argument and printed the whole call.
    capture = np.zeros((8, 8), np.uint16)
    fmt, model = sensor.rawFormat(1.0), sensor.effectiveModel()
    with pytest.raises(TypeError, match=r"colorJitter\(\): argument 'model' must be a rawgment.NoiseModel, not NoneType"):
        rg.colorJitter(capture, fmt, None, rg.ColorJitter(), seed=1)
    with pytest.raises(TypeError, match=r"argument 'seed' must be a seed, an integer from 0 to 18446744073709551615 \(got -1\)"):
        rg.colorJitter(capture, fmt, model, rg.ColorJitter(), seed=-1)
    with pytest.raises(TypeError, match="unknown keyword argument 'sed'"):
        rg.applyScene(capture, fmt, model, rg.Scene(), sed=1)
    # An array without elements is empty, whatever numpy's strides: no advice to copy it.
    with pytest.raises(rg.error, match="src is empty"):
        rg.colorJitter(np.zeros((0, 4), np.uint16), fmt, model, rg.ColorJitter(), seed=1)
    with pytest.raises(rg.error, match="src is empty"):  # the empty input is the error, not dst's dtype
        rg.colorJitter(np.zeros((0, 4), np.uint16), fmt, model, rg.ColorJitter(), seed=1,
                       dst=np.zeros((2, 2), np.float32))


@pytest.mark.parametrize("boxes, words", [
    (np.array([[0, 0, 2 ** 32 + 5, 4]]), "row 0 column 2 is 4294967301"),
    (np.array([[0.0, np.nan, 4.0, 4.0]]), "row 0 column 1 is nan"),
    (np.array([[0.5, 0.0, 4.0, 4.0]]), "row 0 column 0 is 0.5"),
])
def test_array_boxes_are_never_wrapped_or_zeroed(boxes, words):
    with pytest.raises(ValueError, match="'boxes' " + words):
        rg.applyScene(np.zeros((8, 8), np.uint16), rg.RawFormat(), rg.NoiseModel(1, 1, 1), rg.Scene(), seed=1,
                      boxes=boxes)


def test_devices_and_fifos_are_refused_not_read(tmp_path):
    import os

    with pytest.raises(rg.error, match="'/dev/zero': it is a device"):
        rg.NoiseModel.load("/dev/zero")
    fifo = str(tmp_path / "model.yml")
    os.mkfifo(fifo)
    with pytest.raises(rg.error, match="it is a FIFO"):
        rg.NoiseModel.load(fifo)


def test_a_nul_in_a_path_is_a_value_error_and_writes_nothing(tmp_path, dark_bank):
    # bank.save("other.yml\0.json") wrote the maps and the bank over each other into other.yml.
    import os

    bank = rg.DarkFrameBank.load(dark_bank)
    target = str(tmp_path / "other.yml")
    with pytest.raises(ValueError, match="a path holds a NUL character"):
        bank.save(target + "\0.json")
    with pytest.raises(ValueError, match="a path holds a NUL character"):
        rg.NoiseModel().save(target + "\0.json")
    with pytest.raises(ValueError, match="a path holds a NUL character"):
        rg.NoiseModel.load(dark_bank + "\0.yml")
    with pytest.raises(ValueError, match="a path holds a NUL character"):
        rg.readRaw(target + "\0.dng")
    assert os.listdir(str(tmp_path)) == []


def test_cxx_errors_are_rawgment_error_with_the_cxx_message(sensor, tmp_path):
    with pytest.raises(rg.error) as info:
        rg.NoiseModel(-1, 0, 0)
    assert isinstance(info.value, RuntimeError)
    assert "alpha must be finite and >= 0" in str(info.value) and info.value.err == str(info.value)
    assert info.value.code == -5 and info.value.func  # StsBadArg, and the C++ function
    with pytest.raises(rg.error, match="must be even"):
        rg.splitCfaPlanes(np.zeros((5, 4), np.uint16))
    with pytest.raises(rg.error, match="n < 3|3 <= n|between 3"):
        rg.shapiroWilk([1.0, 2.0])
    with pytest.raises(rg.error, match=str(tmp_path / "missing.yml")):
        rg.NoiseModel.load(str(tmp_path / "missing.yml"))
    with pytest.raises(rg.error, match="seed|gain|> 0"):
        rg.colorJitter(np.zeros((8, 8), np.uint16), rg.RawFormat(), rg.NoiseModel(1, 1, 1),
                       rg.ColorJitter(gainRatio=-1), seed=1)


def test_option_structs_take_keywords_and_refuse_unknown_ones():
    policy = rg.RandomScenePolicy(contrastMin=0.05, gainDbMax=6, noise=rg.NoiseOptions(
        alignment=rg.NoiseAlignment.IGNORE_PRIOR, shotSampling=rg.ShotNoiseSampling.POISSON))
    assert policy.contrastMin == 0.05 and policy.gainDbMax == 6 and policy.blurLengthMax == 13
    assert policy.noise.shotSampling == rg.ShotNoiseSampling.POISSON
    with pytest.raises(TypeError, match="unexpected keyword argument 'contrst_min'"):
        rg.RandomScenePolicy(contrst_min=0.1)
    with pytest.raises(rg.error, match="contrast"):
        rg.RandomScenePolicy(contrastMin=2, contrastMax=1)  # validated where it is made
    with pytest.raises(TypeError):
        rg.RawFormat(blackLevel=(1, 2, 3))  # four sites
    # A NoiseAlignment is accepted where NoiseOptions are, as in C++.
    scene = rg.Scene(noise=rg.NoiseAlignment.NONE, shift=(2, 4))
    assert scene.noise.alignment == rg.NoiseAlignment.NONE and scene.shift == (2, 4)
    kernel = rg.linearMotionKernel(7, 0)
    scene.motionKernel = kernel
    assert np.array_equal(scene.motionKernel, kernel)
    with pytest.raises(TypeError, match="'motionKernel'"):
        scene.motionKernel = kernel.astype(np.float16)


def test_values_print_compare_and_pickle(tmp_path):
    for value in (rg.RawFormat(pattern=rg.CFA_GBRG, blackLevel=(1, 2, 3, 4)), rg.NoiseModel(0.5, 2, 1),
                  rg.RandomScenePolicy(hueMin=0.7), rg.Scene(scale=1.02, motionKernel=rg.linearMotionKernel(5, 45)),
                  rg.IspParams(colorMatrix=np.eye(3) * 2), rg.Scene(), rg.RawImage(), rg.MosaicMetadata(),
                  rg.CalibrationReport(perGain=[rg.NoiseLineFit(gain=2)])):
        assert pickle.loads(pickle.dumps(value)) == value
        assert type(value).__name__ + "(" in repr(value)
    model = rg.NoiseModel(0.5, 2, 1)
    model.save(str(tmp_path / "m.yml"))
    assert rg.NoiseModel.load(str(tmp_path / "m.yml")) == model
    model.baseIso = 160.0
    model.save(str(tmp_path / "iso.yml"))
    assert rg.NoiseModel.load(str(tmp_path / "iso.yml")) == model
    assert "baseIso=160" in repr(model)
    policy = rg.RandomScenePolicy(maxScale=0.01)
    policy.save(str(tmp_path / "p.json"))
    assert rg.RandomScenePolicy.load(str(tmp_path / "p.json")) == policy


def test_files_round_trip(tmp_path, capture, sensor):
    meta = rg.MosaicMetadata(format=sensor.rawFormat(2.0), source="test")
    rg.writeMosaic(str(tmp_path / "a.png"), capture, meta)
    mosaic, back = rg.readMosaic(str(tmp_path / "a.png"))
    assert np.array_equal(mosaic, capture) and back.format == meta.format and back.size == (128, 96)
    # The same job's files again are its output; another mosaic at the path is never written.
    rg.writeMosaic(str(tmp_path / "a.png"), capture, meta)
    with pytest.raises(rg.error, match="never overwritten"):
        rg.writeMosaic(str(tmp_path / "a.png"), capture + 1, meta)
    image = rg.RawImage(mosaic=capture, format=sensor.rawFormat(1.0), make="Sim", model="S1", iso=200)
    rg.writeDng(str(tmp_path / "a.dng"), image)
    read = rg.readRaw(str(tmp_path / "a.dng"))
    assert np.array_equal(read.mosaic, capture) and read.make == "Sim" and read.iso == 200
    rg.writeFileAtomically(str(tmp_path / "t.txt"), b"abc")
    assert (tmp_path / "t.txt").read_bytes() == b"abc"


def test_results_of_the_statistics(sensor):
    _, mean = chart_mean()
    burst = sensor.captureBurst(mean, 1.0, 1.0, 8, 1)
    series = np.stack([f.reshape(-1)[:200] for f in burst]).astype(np.float32)
    batch = rg.shapiroWilkBatch(series)
    assert len(batch) == 200 and all(b == rg.shapiroWilk(np.ascontiguousarray(series[:, i])) for i, b in
                                     enumerate(batch))
    normality = rg.shapiroWilkBurst(burst, [(3, 4), (40, 30)])
    assert normality.positions == [(3, 4), (40, 30)] and len(normality.results) == 2
    assert len(rg.summarizeNormality(normality, 4)) == 4
    planes = rg.splitCfaPlanes(burst[0])
    assert len(planes) == 4 and np.array_equal(rg.mergeCfaPlanes(planes), burst[0])
    signal = rg.subtractBlackLevel(burst[0], sensor.rawFormat(1.0), normalize=True)
    back = rg.addBlackLevel(signal, sensor.rawFormat(1.0), rg.CV_16U, normalized=True)
    assert np.array_equal(back, burst[0])


def test_fits_reports_and_tone_curves(sensor, capture, tmp_path):
    chart, _ = chart_mean()
    squares = rg.cfaAlignedSquares(chart.patches, 8)
    fmt = sensor.rawFormat(2.0)
    samples = rg.sampleSingleFramePatches(capture, fmt, squares, 2.0)
    assert samples and all(s.gain == 2.0 for s in samples)
    fit = rg.fitNoiseLine(samples, rg.LineFitParams(robust=False))
    assert fit.samples == len(samples) and fit.line.a > 0
    report = rg.CalibrationReport(model=rg.NoiseModel(0.3, 1, 1), separable=True, perGain=[fit], notes=["n"])
    report.save(str(tmp_path / "r.yml"))
    back = rg.CalibrationReport.load(str(tmp_path / "r.yml"))
    assert back.model == report.model and back.notes == ["n"] and back.perGain[0].line.a == fit.line.a
    with pytest.raises(rg.error, match="2 samples|fewer"):
        rg.fitNoiseLine(samples[:1])
    curve = rg.ToneCurve.srgb()
    linear = np.linspace(0, 1, 12, dtype=np.float32).reshape(3, 4)
    toned = rg.applyToneCurve(linear, curve)
    assert toned.dtype == np.float32 and abs(float(toned[2, 3]) - 1.0) < 1e-6 and abs(curve(0.5) - 0.7353569) < 1e-6
    rgb = rg.applyToneCurve(np.dstack([linear] * 3), curve, rg.CV_8U)
    assert rgb.shape == (3, 4, 3) and rgb.dtype == np.uint8


def test_calibration_errors_intervals_and_projections(sensor, tmp_path):
    """Each parameter's standard error, interval and covariance from Python, the same as C++ writes them,
    and what more data would buy."""
    _, mean = chart_mean()
    samples = []
    # One object for both bursts, reset between them (as a calibration over many bursts reuses its memory):
    # the same statistics as a new object's, bit for bit.
    stats = rg.BurstStatistics(sensor.rawFormat(1.0))
    for gain in (1.0, 4.0):
        stats.reset(sensor.rawFormat(gain))
        fresh = rg.BurstStatistics(sensor.rawFormat(gain))
        for frame in sensor.captureBurst(mean, gain, 1.0 / gain, 16, 5):
            stats.add(frame)
            fresh.add(frame)
        assert stats.frames() == 16 and stats.format().gain == gain
        assert (stats.variance() == fresh.variance()).all() and (stats.mean() == fresh.mean()).all()
        samples += rg.sampleStaticScene(stats, gain)
    assert all(s.pixel >= 0 for s in samples)
    report = rg.calibrateNoiseModel(samples, rg.CalibrationParams(bootstrapReplicates=50))
    u = report.uncertainty
    assert report.separable and u.source in (rg.UNCERTAINTY_COVARIANCE, rg.UNCERTAINTY_BOOTSTRAP)
    assert u.bootstrapReplicates == 50 and u.covariance.shape == (3, 3)
    assert all(e > 0 for e in u.stdError) and all(e > 0 for e in u.fitStdError)
    low, high = report.interval(rg.NOISE_PARAM_ALPHA)
    assert low < report.model.alpha < high
    assert abs((high - low) / 2 - 1.959963984540054 * u.stdError[0]) < 1e-12
    assert -1 <= u.correlation(rg.NOISE_PARAM_SIGMA_D2, rg.NOISE_PARAM_SIGMA_R2) <= 1
    assert all(f.slopeStdError > 0 and f.offsetStdError > 0 for f in report.perGain)
    report.save(str(tmp_path / "errors.yml"))
    back = rg.CalibrationReport.load(str(tmp_path / "errors.yml"))
    assert back.uncertainty.stdError == u.stdError and (back.uncertainty.covariance == u.covariance).all()
    quarter = rg.projectedStdError(samples, report, rg.CalibrationPlan(pixelFactor=4))
    assert all(abs(q - e / 2) <= 1e-9 * e for q, e in zip(quarter, u.stdError))
    with pytest.raises(rg.error, match="level"):
        report.interval(rg.NOISE_PARAM_ALPHA, 1.5)
    with pytest.raises(rg.error, match="frameFactor"):
        rg.projectedStdError(samples, report, rg.CalibrationPlan(frameFactor=-1))


def test_an_exposure_time_travels_through_files_and_chooses_the_banks_group(tmp_path):
    # #79 item 10: the format states the exposure; a bank's group is the input's exposure's, the target's the
    # jitter's when it states one, and an exposure the bank has no frames of is refused naming those it has.
    fmt = rg.RawFormat(blackLevel=(64, 64, 64, 64), whiteLevel=4095, exposureTime=1.0)
    assert pickle.loads(pickle.dumps(fmt)).exposureTime == 1.0
    rng = np.random.default_rng(5)
    files = []
    for exposure, sigma in ((0.001, 2.0), (1.0, 6.0)):
        for i in range(4):
            frame = np.round(64 + sigma * rng.standard_normal((48, 64))).astype(np.uint16)
            path = str(tmp_path / ("dark_%g_%d.npy" % (exposure, i)))
            rg.writeMosaic(path, frame, rg.MosaicMetadata(format=rg.RawFormat(
                blackLevel=(64, 64, 64, 64), whiteLevel=4095, exposureTime=exposure)))
            files.append(path)
    _, meta = rg.readMosaic(files[-1])
    assert meta.format.exposureTime == 1.0
    bank = rg.DarkFrameBank.create(files, rg.NoiseModel())
    assert [g.exposureTime for g in bank.groups] == [0.001, 1.0]
    assert bank.nearestGroup(1.0, 1.1) == 1
    bank.save(str(tmp_path / "bank.yml"))
    options = rg.NoiseOptions(alignment=rg.NoiseAlignment.IGNORE_PRIOR, darkBank=str(tmp_path / "bank.yml"))
    flat = np.full((48, 64), 64, np.uint16)
    out, out_format, _ = rg.colorJitter(flat, fmt, rg.NoiseModel(0, 0, 1), rg.ColorJitter(contrast=(0.5,) * 4),
                                        options, seed=1)
    assert out_format.exposureTime == 1.0
    assert 0.75 * 36 < np.var(out.astype(np.float64)) < 1.35 * 36, "the 1 s frames vary as 36 DN^2, 1 ms as 4"
    with pytest.raises(rg.error, match=r"no frames within a third of a stop of exposure 0.1 s at gain 1; "
                                       r"it has 0.001 s, 1 s there"):
        rg.colorJitter(flat, fmt, rg.NoiseModel(0, 0, 1), rg.ColorJitter(contrast=(0.5,) * 4, exposureTime=0.1),
                       options, seed=1)
