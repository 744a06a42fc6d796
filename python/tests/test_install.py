"""`cmake --install` puts an importable package into the interpreter's folder under the prefix, with
its stub, and the extension finds the installed library (no build tree on the path)."""
import os
import subprocess
import sys

import numpy as np

import rawgment as rg
from conftest import env_path


def test_the_package_under_test_is_the_one_meant():
    # Under ctest the build tree's package, under scripts/test-pip.sh the one pip installed in the venv: a
    # stray PYTHONPATH or an older install must not stand in for either.
    from conftest import INSTALLED_PACKAGE_DIR
    expected = INSTALLED_PACKAGE_DIR or os.path.join(env_path("RAWGMENT_BUILD_DIR"), "python")
    for module in (rg, rg._rawgment):
        assert os.path.realpath(module.__file__).startswith(os.path.realpath(expected) + os.sep), module.__file__


def test_installed_package_imports_and_runs(tmp_path):
    build = env_path("RAWGMENT_BUILD_DIR")
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", build, "--prefix", str(prefix)], check=True, capture_output=True)
    site = prefix / "lib" / ("python%d.%d" % sys.version_info[:2]) / "dist-packages"
    assert (site / "rawgment" / "_rawgment.pyi").exists() and (site / "rawgment" / "py.typed").exists()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "LD_LIBRARY_PATH")}
    env["PYTHONPATH"] = str(site)
    code = ("import rawgment, numpy; print(rawgment.__file__); "
            "print(rawgment.colorJitter(numpy.full((8, 8), 100, numpy.uint16), rawgment.RawFormat(), "
            "rawgment.NoiseModel(1, 1, 1), rawgment.ColorJitter.exposureChange(0.5, 1), seed=1)[0].sum())")
    # From another folder: the build tree's package must not be found through the working directory.
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=str(tmp_path), check=True, capture_output=True,
                         text=True)
    lines = out.stdout.split()
    assert lines[0].startswith(str(site))
    expected = rg.colorJitter(np.full((8, 8), 100, np.uint16), rg.RawFormat(), rg.NoiseModel(1, 1, 1),
                              rg.ColorJitter.exposureChange(0.5, 1), seed=1)[0].sum()
    assert int(lines[1]) == int(expected)


def test_the_install_holds_no_study(tmp_path):
    # Users install the library, the apps, the samples' documentation and the rawgment package: the studies
    # (studies/: the ablation, the calibration and dark-bank studies) run from the build tree. The trade-off
    # report is an app, shipped with its measuring code.
    build = env_path("RAWGMENT_BUILD_DIR")
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", build, "--prefix", str(prefix)], check=True, capture_output=True)
    installed = [p.relative_to(prefix).as_posix() for p in prefix.rglob("*") if p.is_file()]
    assert installed, "cmake --install installed nothing"
    studies = [p for p in installed if "ablation" in p or "/study_" in p or "studies" in p]
    assert not studies, studies
    assert "bin/rawgment_tradeoffs" in installed
    assert any(p.endswith("/rawgment/__init__.py") for p in installed)
    # The study is still there to run, from the build tree.
    assert os.path.exists(os.path.join(build, "python", "rawgment_ablation", "__main__.py"))
