"""rawgment_augment on camera RAW files: the augmented DNGs stay the camera's. Make, model, colour matrix and
white balance are kept; the ISO follows the gain ratio, the exposure time the photon ratio; the NoiseProfile is
the model's at the output's gain. Checked with exiftool and with LibRaw (readRaw)."""
import os
import shutil
import subprocess

import pytest

import rawgment as rg
from conftest import env_path

PHOTON_RATIO, GAIN_RATIO = 0.125, 4.0


def exiftool_values(path, *tags):
    exiftool = shutil.which("exiftool")
    if exiftool is None:
        pytest.fail("exiftool is missing: scripts/install-deps.sh installs it (libimage-exiftool-perl)")
    run = subprocess.run([exiftool, "-n", "-s", *("-" + t for t in tags), path], capture_output=True,
                         text=True, check=True)
    values = {}
    for line in run.stdout.splitlines():
        key, _, value = line.partition(":")
        values[key.strip()] = value.strip()
    return values


def white_xy(tags):
    """The as-shot white point a DNG reader derives from one ColorMatrix (DNG 1.6 chapter 6, one
    calibration illuminant): XYZ = inverse(AnalogBalance x CameraCalibration1 x ColorMatrix1) x AsShotNeutral."""
    import numpy as np

    cm = np.array([float(v) for v in tags["ColorMatrix1"].split()]).reshape(3, 3)
    ab = np.diag([float(v) for v in tags.get("AnalogBalance", "1 1 1").split()])
    cc = np.array([float(v) for v in tags["CameraCalibration1"].split()]).reshape(3, 3) \
        if "CameraCalibration1" in tags else np.eye(3)
    neutral = np.array([float(v) for v in tags["AsShotNeutral"].split()])
    xyz = np.linalg.solve(ab @ cc @ cm, neutral)
    return tuple(xyz[:2] / xyz.sum())


def camera_file(name):
    path = os.path.join(os.environ.get("RAWGMENT_SHARED_DATA_DIR", ""), name)
    if not os.path.isfile(path):
        pytest.skip("%s is missing (see ../shared/data/SOURCES.md)" % name)
    return path


@pytest.mark.parametrize("name", ["RAW_NIKON_D1.NEF", "colorchart.dng"])
def test_augmented_dng_keeps_the_camera_and_states_the_simulated_capture(tmp_path, name):
    source = camera_file(name)
    # Gain 1 at the file's own ISO (a file that states an ISO needs a model with a base ISO).
    model = rg.NoiseModel(alpha=0.8, sigmaD2=2.0, sigmaR2=6.0)
    model.baseIso = rg.readRaw(source).iso
    model.save(str(tmp_path / "model.yml"))
    contrast = PHOTON_RATIO * GAIN_RATIO
    (tmp_path / "scene.yml").write_text("%%YAML:1.0\nscene: {contrast: [%g, %g, %g, %g], brightness: 0, "
                                        "gain_ratio: %g}\n" % (contrast, contrast, contrast, contrast, GAIN_RATIO))
    app = os.path.join(env_path("RAWGMENT_APP_DIR"), "rawgment_augment")
    subprocess.run([app, "--model=%s" % (tmp_path / "model.yml"), "--scene=%s" % (tmp_path / "scene.yml"),
                    "--out=%s" % (tmp_path / "out"), "--preview", source], check=True, capture_output=True)
    stem = os.path.splitext(name)[0]
    out = str(tmp_path / "out" / (stem + "_v00.dng"))

    before, after = rg.readRaw(source), rg.readRaw(out)
    assert (after.make, after.model) == (before.make, before.model)
    assert after.iso == pytest.approx(before.iso * GAIN_RATIO)
    # The darkening is the scene's light, so the exposure stays the input's (a scene states another as
    # exposure_time); the DNG stores it as a rational: exact to a part in 1e6 at these values.
    assert after.exposureTime == pytest.approx(before.exposureTime, rel=1e-6)
    assert after.format.exposureTime == after.exposureTime
    # White balance and colour matrix go through DNG rationals and LibRaw's own normalisation.
    assert after.whiteBalance == pytest.approx(before.whiteBalance, rel=1e-5)
    for row_after, row_before in zip(after.cameraToSrgb, before.cameraToSrgb):
        assert row_after == pytest.approx(row_before, abs=1e-4)
    after_format = rg.RawFormat(pattern=after.format.pattern, blackLevel=after.format.blackLevel,
                                whiteLevel=after.format.whiteLevel, gain=GAIN_RATIO)
    assert after.noiseProfile == [tuple(so) for so in rg.dngNoiseProfile(model, after_format)]

    tags = exiftool_values(out, "Make", "Model", "ISO", "ExposureTime", "NoiseProfile", "UniqueCameraModel")
    assert tags["Make"] == before.make
    assert tags["Model"] == before.model
    assert "cv::rawgment" not in tags["UniqueCameraModel"]
    if before.iso > 0:
        assert float(tags["ISO"]) == before.iso * GAIN_RATIO
    else:
        assert "ISO" not in tags  # unknown stays unknown
    profile = [float(v) for v in tags["NoiseProfile"].split()]
    assert profile == pytest.approx([v for so in after.noiseProfile for v in so], rel=1e-13)

    # The colour tags as the source states them: a DNG's verbatim (colorchart.dng has no
    # CalibrationIlluminant1, and none may appear), another RAW's from LibRaw's XYZ matrix unscaled.
    colour = ["ColorMatrix1", "ColorMatrix2", "CalibrationIlluminant1", "CalibrationIlluminant2",
              "AsShotNeutral", "AsShotWhiteXY", "AnalogBalance", "CameraCalibration1", "ForwardMatrix1"]
    tags_out = exiftool_values(out, *colour)
    if name.endswith(".dng"):
        tags_in = exiftool_values(source, *colour)
        assert tags_out == tags_in
        assert "CalibrationIlluminant1" not in tags_out
    else:
        cm = [v for t in before.colorTags if t.tag == 50721 for v in t.values]
        assert [float(v) for v in tags_out["ColorMatrix1"].split()] == pytest.approx(
            [cm[k] / cm[k + 1] for k in range(0, 18, 2)], abs=1e-12)
        assert tags_out["CalibrationIlluminant1"] == "21"
    xy_in, xy_out = white_xy(exiftool_values(source if name.endswith(".dng") else out, *colour)), white_xy(tags_out)
    assert xy_out == pytest.approx(xy_in, abs=1e-9)
    if name == "colorchart.dng":
        # The white point a DNG reader derives, as an independent computation gave it for the input.
        assert xy_out == pytest.approx((0.338, 0.369), abs=1e-3)

    # The preview's brightness is checked in test/test_app_augment.cpp (OpenCV reads PNG there).
    assert os.path.getsize(str(tmp_path / "out" / (stem + "_v00_preview.png"))) > 0


def test_an_iso_1600_file_is_at_gain_16_through_the_app_the_library_and_the_dataset(tmp_path, app_dir):
    """Issue #60 items 3 and 4: only the app turned ISO into gain; the dataset read an ISO-1600 file at gain 1
    and readRaw + applyScene (as the docs showed) too. At base ISO 100 every way gives gain 16, never 1 and
    never 256, through formatAtIso; a model without a base ISO is refused for a file that states an ISO."""
    import numpy as np
    import torch  # noqa: F401 (rawgment.torch needs it)
    import rawgment.torch as rgt

    folder = tmp_path / "raws"
    folder.mkdir()
    mosaic = np.full((64, 64), 1000, np.uint16)
    fmt = rg.RawFormat(blackLevel=(64, 64, 64, 64), whiteLevel=4095)
    rg.writeDng(str(folder / "iso1600.dng"), rg.RawImage(mosaic=mosaic, format=fmt, iso=1600))
    model = rg.NoiseModel(alpha=0.05, sigmaD2=1.25, sigmaR2=0.5)
    model.baseIso = 100
    gain16 = rg.RawFormat(blackLevel=(64, 64, 64, 64), whiteLevel=4095, gain=16)

    # The library, as the docs show: the file's format for the model.
    image = rg.readRaw(str(folder / "iso1600.dng"))
    assert image.format.gain == 1 and image.formatFor(model).gain == 16
    _, outFormat, _, _ = rg.applyScene(image.mosaic, image.formatFor(model), model, rg.Scene(), seed=1)
    assert outFormat.gain == 16
    # A DNG's own profile is read at its own gain: the measured line at ISO 1600 is the one applied.
    profiled = rg.withDngNoiseProfileLine(model, rg.RawImage(mosaic=mosaic, format=fmt, iso=1600,
                                                             noiseProfile=[(2e-4, 4e-6)]))
    line = profiled.lineAtGain(image.formatFor(profiled).gain)
    assert (line.a, line.b) == pytest.approx((2e-4 * 4031, 4e-6 * 4031 ** 2), rel=1e-12)

    # The app: the output DNG's NoiseProfile is the model's at the file's gain 16 (the scene keeps the gain).
    model.save(str(tmp_path / "model.yml"))
    (tmp_path / "scene.yml").write_text("%YAML:1.0\nscene: {contrast: [0.5, 0.5, 0.5, 0.5], brightness: 0, gain_ratio: 1}\n")
    app = os.path.join(app_dir, "rawgment_augment")
    subprocess.run([app, "--model=%s" % (tmp_path / "model.yml"), "--scene=%s" % (tmp_path / "scene.yml"),
                    "--out=%s" % (tmp_path / "out"), str(folder / "iso1600.dng")], check=True, capture_output=True)
    out = rg.readRaw(str(tmp_path / "out" / "iso1600_v00.dng"))
    assert out.noiseProfile == [tuple(so) for so in rg.dngNoiseProfile(model, gain16)]

    # The dataset, from the camera file and from its conversion (whose sidecar says gain_from_iso).
    policy = rg.RandomScenePolicy()
    policy.gainDbMin = policy.gainDbMax = 0
    policy.blurProbability = policy.geometryProbability = 0
    converted = tmp_path / "converted"
    subprocess.run([os.path.join(app_dir, "rawgment_convert"), "--out=%s" % converted, str(folder / "iso1600.dng")],
                   check=True, capture_output=True)
    for source in (folder, converted):
        data = rgt.RawFolderDataset(source, model, policy=policy)
        assert data[0]["gain"] == pytest.approx(16, rel=1e-12), source
        # #79 item 29: without augmentation the item's gain is still the file's, never the format's 1.
        plain = rgt.RawFolderDataset(source, model, augment=False)
        assert plain[0]["gain"] == pytest.approx(16, rel=1e-12), source
        assert rgt.loadMosaic(data.files[0])[2] == 1600

    # A model without a base ISO cannot say which gain ISO 1600 is: refused everywhere, never gain 1.
    noBase = rg.NoiseModel(alpha=0.05, sigmaD2=1.25, sigmaR2=0.5)
    with pytest.raises(rg.error, match="no base ISO"):
        image.formatFor(noBase)
    with pytest.raises(rg.error, match="no base ISO"):
        rgt.RawFolderDataset(folder, noBase, policy=policy)[0]
    noBase.save(str(tmp_path / "nobase.yml"))
    run = subprocess.run([app, "--model=%s" % (tmp_path / "nobase.yml"), "--scene=%s" % (tmp_path / "scene.yml"),
                          "--out=%s" % (tmp_path / "out2"), str(folder / "iso1600.dng")], capture_output=True, text=True)
    assert run.returncode != 0 and "no base ISO" in run.stderr, run.stderr
    # A file that states no ISO stays at its format's gain.
    rg.writeDng(str(tmp_path / "noiso.dng"), rg.RawImage(mosaic=mosaic, format=fmt))
    assert rg.readRaw(str(tmp_path / "noiso.dng")).formatFor(noBase).gain == 1


def test_a_monochrome_dng_stays_monochrome_through_the_app_and_the_dataset(tmp_path, app_dir):
    """A monochrome sensor's frame (CFA_MONO) is a LinearRaw DNG with one sample per pixel, which exiftool and
    LibRaw read; the app and the dataset augment it with one contrast and write it back the same way, its
    NoiseProfile one (S, O) pair."""
    import numpy as np
    import torch  # noqa: F401 (rawgment.torch needs it)
    import rawgment.torch as rgt

    folder = tmp_path / "raws"
    folder.mkdir()
    rng = np.random.default_rng(3)
    mosaic = (rng.poisson(900, size=(64, 96)) + 100).astype(np.uint16)
    fmt = rg.RawFormat(pattern=rg.CFA_MONO, blackLevel=(100, 100, 100, 100), whiteLevel=4095)
    model = rg.NoiseModel(alpha=0.3, sigmaD2=1.5, sigmaR2=4.0)
    model.baseIso = 100
    rg.writeDng(str(folder / "mono.dng"), rg.RawImage(mosaic=mosaic, format=fmt, iso=100, make="Basler",
                                                      noiseProfile=rg.dngNoiseProfile(model, fmt)))
    tags = exiftool_values(str(folder / "mono.dng"), "PhotometricInterpretation", "SamplesPerPixel", "BlackLevel",
                           "WhiteLevel", "CFAPattern2", "NoiseProfile")
    assert tags["PhotometricInterpretation"] == "34892" and tags["SamplesPerPixel"] == "1"
    assert tags["BlackLevel"] == "100" and tags["WhiteLevel"] == "4095" and "CFAPattern2" not in tags
    assert len(tags["NoiseProfile"].split()) == 2
    image = rg.readRaw(str(folder / "mono.dng"))
    assert image.format.pattern == rg.CFA_MONO and np.array_equal(image.mosaic, mosaic)
    assert rg.withDngNoiseProfileLine(model, image).lineAtGain(1).a == pytest.approx(model.alpha, rel=1e-12)

    model.save(str(tmp_path / "model.yml"))
    policy = rg.RandomScenePolicy(hueProbability=1, blurProbability=1, geometryProbability=1)
    policy.save(str(tmp_path / "policy.yml"))
    subprocess.run([os.path.join(app_dir, "rawgment_augment"), "--model=%s" % (tmp_path / "model.yml"),
                    "--policy=%s" % (tmp_path / "policy.yml"), "--out=%s" % (tmp_path / "out"), "--variants=2",
                    "--preview", str(folder / "mono.dng")], check=True, capture_output=True)
    for v in range(2):
        out = str(tmp_path / "out" / ("mono_v%02d.dng" % v))
        tags = exiftool_values(out, "PhotometricInterpretation", "SamplesPerPixel", "NoiseProfile", "ISO")
        assert tags["PhotometricInterpretation"] == "34892" and tags["SamplesPerPixel"] == "1"
        after = rg.readRaw(out)
        assert after.format.pattern == rg.CFA_MONO
        meta = rg.readMosaic(out)[1]
        assert len(set(meta.scene.jitter.contrast)) == 1
        # The DNG's ISO is rounded to an integer; the sidecar keeps the exact gain.
        assert after.iso == round(100 * meta.format.gain)
        assert after.noiseProfile == [tuple(so) for so in rg.dngNoiseProfile(model, meta.format)]

    for pack, shape in ((False, (1, 64, 96)), (True, (4, 32, 48))):
        sample = rgt.RawFolderDataset(folder, model, policy=policy, pack=pack)[0]
        assert tuple(sample["raw"].shape) == shape and sample["gain"] >= 1
    # The site order of packCfaPlanes, in rawgment.torch's own packing too.
    signal = rg.subtractBlackLevel(mosaic, fmt)
    assert np.array_equal(rgt.packCfaPlanes(signal, fmt).numpy(),
                          np.stack([signal[0::2, 0::2], signal[0::2, 1::2], signal[1::2, 0::2], signal[1::2, 1::2]]))
