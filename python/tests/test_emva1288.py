"""The EMVA 1288 topic from Python: set 001's figures under the names the issue gives, a series written
with numpy, and the descriptor's errors as rawgment.error."""
import os

import numpy as np
import pytest

import rawgment as rg

SET_001 = "emva1288/EMVA1288_ReferenceSet_001_CCD_12Bit/EMVA1288_Data.txt"

# The reference implementation's figures on set 001 (../shared/data/emva1288/README.md), in its units.
REFERENCE = {"K": 0.28006, "sigmaYDark": 3.0731, "sigmaD": 10.924, "muPSat": 30957, "muESat": 14008,
             "eta": 45.25, "snrMax": 118.35, "muPMin": 25.35, "dsnu1288": 0.553, "prnu1288": 0.433,
             "linearityErrorMin": -0.616, "linearityErrorMax": 0.480}
REFERENCE_DB = {"snrMaxDb": 41.46, "dynamicRangeDb": 61.73}


def test_set_001_gives_the_reference_implementations_figures():
    path = os.path.join(os.environ.get("RAWGMENT_SHARED_DATA_DIR", ""), SET_001)
    if not os.path.isfile(path):
        pytest.skip("%s is missing (see ../shared/data/SOURCES.md)" % SET_001)
    results = rg.emva1288Results(rg.readEmva1288(path))
    # The tolerances: 0.5% of each figure (percentages: 0.5% of their value), 0.04 dB.
    for name, value in REFERENCE.items():
        assert getattr(results, name) == pytest.approx(value, rel=0.005), name
    for name, value in REFERENCE_DB.items():
        assert getattr(results, name) == pytest.approx(value, abs=0.04), name


def write_series(folder, gain_k=0.25, dark_sigma=3.0, steps=8, seed=1):
    """A 64x48 12-bit series with Poisson electrons and Gaussian dark noise, as the standard's frames."""
    import cv2  # Debian's python3-opencv writes the 16-bit PNGs

    rng = np.random.default_rng(seed)
    lines = ["v 4.0", "n 12 64 48"]
    for s in range(steps):
        photons = 400.0 * (s + 1)
        for kind in ("b", "d"):
            lines.append("b %g %g" % (1000 * (s + 1), photons) if kind == "b" else "d %g" % (1000 * (s + 1)))
            for frame in range(2):
                electrons = rng.poisson(0.5 * photons, (48, 64)) if kind == "b" else np.zeros((48, 64))
                dn = 100 + gain_k * electrons + rng.normal(0, dark_sigma, (48, 64))
                name = "%s%d_%d.png" % (kind, s, frame)
                assert cv2.imwrite(str(folder / name), np.clip(np.rint(dn), 0, 4095).astype(np.uint16))
                lines.append("i " + name)
    (folder / "EMVA1288_Data.txt").write_text("\n".join(lines) + "\n")
    return str(folder / "EMVA1288_Data.txt")


def test_a_series_written_with_numpy_gives_its_gain(tmp_path):
    pytest.importorskip("cv2")
    series = rg.readEmva1288(write_series(tmp_path))
    assert series.bits == 12 and (series.width, series.height) == (64, 48)
    assert len(series.temporal) == 16 and not series.spatial
    results = rg.emva1288Results(series)
    # 8 steps of 3072 pixel pairs: K's standard error is about 1.5% here; 6% is four of them.
    assert results.K == pytest.approx(0.25, rel=0.06)
    assert results.eta == pytest.approx(50, rel=0.06)
    assert len(results.mean) == 8 and np.all(np.diff(results.mean) > 0)
    image = rg.readEmva1288Image(series, series.temporal[0].images[0], series.temporal[0].line)
    assert image.dtype == np.uint16 and image.shape == (48, 64)


def test_a_bad_descriptor_is_an_error_naming_the_line(tmp_path):
    path = tmp_path / "EMVA1288_Data.txt"
    path.write_text("v 4.0\nn 16 100000 100000\n")
    with pytest.raises(rg.error, match="line 2: 100000 x 100000 pixels"):
        rg.readEmva1288(str(path))
