"""The DNG NoiseProfile tag (51041) as an independent reader, exiftool, sees it: the values we write are
the model's, in the layout the DNG specification gives, and they come back through readRaw."""
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


def test_a_profile_dng_cannot_hold_is_refused(tmp_path):
    image = rg.RawImage(mosaic=np.full((48, 64), 600, np.uint16))
    image.noiseProfile = [(1e-4, 1e-6), (1e-4, 1e-6)]
    with pytest.raises(rg.error, match="1 or 3"):
        rg.writeDng(str(tmp_path / "two.dng"), image)
    assert not any(tmp_path.iterdir())
