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


def test_the_ablation_study_runs_from_the_installed_prefix(tmp_path):
    # Every module the study imports (the report, the controls, the network, the scenes) must be installed:
    # a module missing from the install list would only show here, the build tree having them all.
    build = env_path("RAWGMENT_BUILD_DIR")
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", build, "--prefix", str(prefix)], check=True, capture_output=True)
    site = prefix / "lib" / ("python%d.%d" % sys.version_info[:2]) / "dist-packages"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "LD_LIBRARY_PATH")}
    env.update(PYTHONPATH=str(site), OMP_NUM_THREADS="1")
    out = tmp_path / "study"
    run = subprocess.run([sys.executable, "-m", "rawgment_ablation", "--quick", "--per-condition", "--networks", "blind",
                          "--arms", "IGNORE_PRIOR,ACCOUNT_PRIOR,IGNORE_RESCALED,NOISY", "--seeds", "2", "--iterations",
                          "1", "--out", str(out)], env=env, cwd=str(tmp_path), capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert (out / "report.md").exists() and (out / "blind-per-condition" / "results.json").exists()
    where = subprocess.run([sys.executable, "-c", "import rawgment_ablation.controls as c; print(c.__file__)"],
                           env=env, cwd=str(tmp_path), check=True, capture_output=True, text=True)
    assert where.stdout.strip().startswith(str(site))
