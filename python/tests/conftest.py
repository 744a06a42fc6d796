"""Shared fixtures of the Python tests: the build's apps and reference program, small simulated mosaics."""
import os
import subprocess

import numpy as np
import pytest

import rawgment as rg


# Set by scripts/test-pip.sh, which runs these tests against the package `pip install .` put in a virtual
# environment: the folder the package must come from. The build tree's apps, C++ reference program and
# CMake build are then absent, and the tests that need them skip (the script allows only those skips).
INSTALLED_PACKAGE_DIR = os.environ.get("RAWGMENT_TEST_INSTALLED_PACKAGE")


@pytest.fixture(autouse=True)
def environment_as_it_was():
    """Restores os.environ after each test. Starting a Dask LocalCluster sets MALLOC_TRIM_THRESHOLD_=65536
    (and the BLAS thread counts) in this process for good; every program a later test starts inherited it, and
    the trimming made the installed ablation study run three times as long (35 s against 11 s)."""
    saved = dict(os.environ)
    yield
    if dict(os.environ) != saved:
        os.environ.clear()
        os.environ.update(saved)


def env_path(name):
    value = os.environ.get(name)
    if not value:
        if INSTALLED_PACKAGE_DIR and name in ("RAWGMENT_BUILD_DIR", "RAWGMENT_APP_DIR", "RAWGMENT_PYTHON_REFERENCE"):
            pytest.skip("needs the build tree (%s) and runs against a pip-installed package" % name)
        pytest.fail("%s is not set: run the Python tests through ctest (python_tests)" % name)
    return value


@pytest.fixture(scope="session")
def app_dir():
    return env_path("RAWGMENT_APP_DIR")


@pytest.fixture(scope="session")
def source_dir():
    return env_path("RAWGMENT_SOURCE_DIR")


@pytest.fixture(scope="session")
def cxx_reference(tmp_path_factory):
    """The folder of the C++ reference results (tests/cxx_reference.cpp)."""
    folder = tmp_path_factory.mktemp("cxx_reference")
    subprocess.run([env_path("RAWGMENT_PYTHON_REFERENCE"), str(folder)], check=True)
    return folder


def chart_mean(width=128, height=96):
    """The colour-checker scene of the reference program, on a frame of the given size."""
    chart = rg.makeColorCheckerScene(rg.ColorCheckerOptions(patchSize=16, border=4))
    mean = np.zeros((height, width), np.float32)
    h, w = chart.meanAtUnitGain.shape
    mean[:h, :w] = chart.meanAtUnitGain
    return chart, mean


@pytest.fixture(scope="session")
def sensor():
    params = rg.SensorParams(blackLevel=(64, 66, 65, 63), bitDepth=12)
    return rg.SensorSimulator(params, (128, 96))


@pytest.fixture(scope="session")
def dark_bank(tmp_path_factory, sensor):
    """The path of a saved dark-frame bank of `sensor`: three dark frames at each of gains 1, 2 and 4."""
    folder = tmp_path_factory.mktemp("dark_bank")
    files = []
    for gain in (1.0, 2.0, 4.0):
        for t in range(3):
            path = folder / ("dark_g%g_%d.png" % (gain, t))
            dark = sensor.capture(np.zeros((96, 128), np.float32), gain, 1.0, seed=90, frameIndex=t)
            rg.writeMosaic(str(path), dark, rg.MosaicMetadata(format=sensor.rawFormat(gain)))
            files.append(str(path))
    bank = rg.DarkFrameBank.create(files, rg.NoiseModel())
    bank.save(str(folder / "bank.yml"))
    return str(folder / "bank.yml")


@pytest.fixture(scope="session")
def capture(sensor):
    _, mean = chart_mean()
    return sensor.capture(mean, 2.0, 1.0, seed=11, frameIndex=3)

