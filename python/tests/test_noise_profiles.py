"""The noise model in the forms other tools read. The DNG NoiseProfile tag (51041) as an independent
reader, exiftool, sees it: the values we write are the model's, in the layout the DNG specification gives,
and they come back through readRaw. darktable's JSON as Python's json module parses it, and the Android
form, each back to the model."""
import json
import shutil
import subprocess

import numpy as np
import pytest

import rawgment as rg


def exiftool():
    path = shutil.which("exiftool")
    if path is None:
        pytest.fail("exiftool is missing: scripts/install-deps.sh installs it (libimage-exiftool-perl)")
    return path


@pytest.mark.parametrize("pattern", [rg.CFA_RGGB, rg.CFA_GBRG])
def test_exiftool_reads_the_models_noise_profile(tmp_path, pattern):
    model = rg.NoiseModel(alpha=0.3, sigmaD2=1.2, sigmaR2=2.5)
    fmt = rg.RawFormat(pattern=pattern, blackLevel=(100, 101, 102, 103), whiteLevel=4000, gain=4.0)
    image = rg.RawImage(mosaic=np.full((48, 64), 600, np.uint16), format=fmt)
    image.noiseProfile = rg.dngNoiseProfile(model, fmt)
    path = str(tmp_path / "profiled.dng")
    rg.writeDng(path, image)

    run = subprocess.run([exiftool(), "-n", "-s3", "-NoiseProfile", path], capture_output=True, text=True, check=True)
    values = [float(v) for v in run.stdout.split()]
    assert len(values) == 6, run.stdout
    # The DNG form: variance S x + O of x = (value - black) / (white - black), per colour plane R, G, B.
    blacks = {c: [] for c in (rg.CFA_R, rg.CFA_G1, rg.CFA_B)}
    for site in range(4):
        channel = rg.cfaChannelAt(pattern, site // 2, site % 2)
        blacks[rg.CFA_G1 if channel == rg.CFA_G2 else channel].append(fmt.blackLevel[site])
    for plane, channel in enumerate((rg.CFA_R, rg.CFA_G1, rg.CFA_B)):
        r = fmt.whiteLevel - np.mean(blacks[channel])
        # exiftool prints 15 significant digits.
        assert values[2 * plane] == pytest.approx(4.0 * model.alpha / r, rel=1e-13)
        assert values[2 * plane + 1] == pytest.approx((16.0 * model.sigmaD2 + model.sigmaR2) / r ** 2, rel=1e-13)

    valid = subprocess.run([exiftool(), "-validate", "-warning", "-s3", path], capture_output=True, text=True,
                           check=True)
    assert valid.stdout.strip() == "OK", valid.stdout

    back = rg.readRaw(path)
    assert back.noiseProfile == image.noiseProfile
    back.format.gain = 4.0
    truth = model.lineAtGain(4.0)
    for channel in (rg.CFA_R, rg.CFA_G1, rg.CFA_G2, rg.CFA_B):
        line = rg.noiseLineFromDngProfile(back.noiseProfile, back.format, channel)
        assert (line.a, line.b) == pytest.approx((truth.a, truth.b), rel=1e-13)


def test_a_monochrome_dngs_profile_is_one_pair_that_exiftool_validates(tmp_path):
    model = rg.NoiseModel(alpha=0.3, sigmaD2=1.2, sigmaR2=2.5)
    fmt = rg.RawFormat(pattern=rg.CFA_MONO, blackLevel=(100, 100, 100, 100), whiteLevel=4000, gain=4.0)
    image = rg.RawImage(mosaic=np.full((48, 64), 600, np.uint16), format=fmt)
    image.noiseProfile = rg.dngNoiseProfile(model, fmt)
    assert len(image.noiseProfile) == 1
    path = str(tmp_path / "mono.dng")
    rg.writeDng(path, image)
    run = subprocess.run([exiftool(), "-n", "-s3", "-NoiseProfile", path], capture_output=True, text=True, check=True)
    values = [float(v) for v in run.stdout.split()]
    assert values == pytest.approx([4.0 * model.alpha / 3900, (16.0 * model.sigmaD2 + model.sigmaR2) / 3900 ** 2],
                                   rel=1e-13)
    # exiftool checks the file against the DNG and TIFF rules (tag counts for one colour plane among them).
    valid = subprocess.run([exiftool(), "-validate", "-warning", "-s3", path], capture_output=True, text=True,
                           check=True)
    assert valid.stdout.strip() == "OK", valid.stdout
    back = rg.readRaw(path)
    back.format.gain = 4.0
    line, truth = rg.noiseLineFromDngProfile(back.noiseProfile, back.format, rg.CFA_W), model.lineAtGain(4.0)
    assert (line.a, line.b) == pytest.approx((truth.a, truth.b), rel=1e-13)
    with pytest.raises(rg.error, match="CFA_W is the only channel of a monochrome frame"):
        rg.noiseLineFromDngProfile(back.noiseProfile, back.format, rg.CFA_G1)
    image.noiseProfile = [(1e-4, 1e-6)] * 3
    with pytest.raises(rg.error, match="one \\(S, O\\) pair"):
        rg.writeDng(str(tmp_path / "three.dng"), image)


def test_a_profile_dng_cannot_hold_is_refused(tmp_path):
    image = rg.RawImage(mosaic=np.full((48, 64), 600, np.uint16))
    image.noiseProfile = [(1e-4, 1e-6), (1e-4, 1e-6)]
    with pytest.raises(rg.error, match="1 or 3"):
        rg.writeDng(str(tmp_path / "two.dng"), image)
    assert not any(tmp_path.iterdir())


def test_darktable_file_is_json_with_the_layout_darktable_reads(tmp_path):
    model = rg.NoiseModel(alpha=0.4, sigmaD2=1.5, sigmaR2=3.0)
    fmt = rg.RawFormat(pattern=rg.CFA_BGGR, blackLevel=(510, 512, 514, 516), whiteLevel=16383)
    text = rg.darktableNoiseProfiles(model, fmt, 100, [100, 400, 1600], "Maker", "Model")
    # Python's json module is an independent parser of what we write.
    doc = json.loads(text)
    assert doc["version"] == 0
    entry = doc["noiseprofiles"][0]
    assert entry["maker"] == "Maker" and entry["models"][0]["model"] == "Model"
    profiles = entry["models"][0]["profiles"]
    assert [p["iso"] for p in profiles] == [100, 400, 1600]
    for p in profiles:
        fmt.gain = p["iso"] / 100
        # darktable's units: c times the per-pixel variance of the DNG profile (docs/real_cameras.md).
        c = rg.DARKTABLE_HAAR_VARIANCE_RATIO
        assert list(zip(p["a"], p["b"])) == [(c * s, c * o) for s, o in rg.dngNoiseProfile(model, fmt)]
    path = tmp_path / "noiseprofiles.json"
    path.write_text(text)
    back = rg.noiseModelFromDarktableExport(str(path), fmt, 100, "Maker", "Model")
    assert (back.alpha, back.sigmaD2, back.sigmaR2) == pytest.approx((0.4, 1.5, 3.0), rel=1e-9)


def test_android_form_round_trips_and_refuses_what_the_model_cannot_hold():
    model = rg.NoiseModel(alpha=0.4, sigmaD2=1.5, sigmaR2=3.0)
    fmt = rg.RawFormat(blackLevel=(64, 64, 64, 64), whiteLevel=1023)
    profile = rg.androidNoiseProfile(model, fmt, 100)
    back = rg.noiseModelFromAndroid(profile, fmt, 100)
    assert (back.alpha, back.sigmaD2, back.sigmaR2) == pytest.approx((0.4, 1.5, 3.0), rel=1e-12)
    profile.B = (0, 1e-6, 0, 0)
    with pytest.raises(rg.error, match="site 1 has B"):
        rg.noiseModelFromAndroid(profile, fmt, 100)
