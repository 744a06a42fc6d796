"""Every public name is documented with the C++ documentation, the stub covers the module, and heavy
calls release the GIL (so Python threads run them in parallel)."""
import ast
import os
import subprocess
import sys
import threading

import numpy as np

import rawgment as rg


def public_names():
    return [n for n in rg.__all__ if not n.startswith("_")]


def test_every_public_name_has_the_cxx_documentation():
    missing = []
    for name in public_names():
        obj = getattr(rg, name)
        if isinstance(obj, (int, float)):
            continue  # constants (CV_16U, MAX_MOTION_LENGTH): their docstring would be int's or float's
        if not (obj.__doc__ or "").strip():
            missing.append(name)
    assert not missing, "undocumented: %s" % missing
    # The text is the C++ documentation (converted from Doxygen), not a summary written again.
    assert "paper Eq. 11 and 13" in rg.colorJitter.__doc__
    assert "C++: colorJitter(InputArray src" in rg.colorJitter.__doc__
    assert "AS R94" in rg.shapiroWilk.__doc__
    assert "black-subtracted" in rg.NoiseModel.variance.__doc__
    assert "shot-noise slope" in rg.NoiseModel.alpha.__doc__


def test_the_stub_covers_the_module_and_parses():
    stub_path = os.path.join(os.path.dirname(rg.__file__), "_rawgment.pyi")
    tree = ast.parse(open(stub_path, encoding="utf-8").read())
    defined = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            defined.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            defined.add(node.target.id)
    missing = set(public_names()) - defined
    assert not missing, "not in the stub: %s" % sorted(missing)
    text = open(stub_path, encoding="utf-8").read()
    assert "def colorJitter(src: object, format: RawFormat, model: NoiseModel" in text


def test_heavy_calls_run_without_the_gil(sensor, capture):
    fmt, model = sensor.rawFormat(2.0), sensor.effectiveModel()
    rg.colorJitter(capture, fmt, model, rg.ColorJitter.exposureChange(0.5, 1.0), seed=1)
    rg.motionBlur(capture, fmt, model, rg.linearMotionKernel(5, 0), seed=1)
    rg.scaleMosaic(capture, fmt, model, 1.02, seed=1)
    rg.applyScene(capture, fmt, model, rg.Scene(scale=1.01), seed=1)
    rg.RandomScenePolicy().draw(capture, fmt, 1)
    rg.renderSimpleIsp(capture, fmt)
    stats = rg.BurstStatistics(fmt)
    stats.add(capture)
    rg.shapiroWilkBatch(np.random.default_rng(1).normal(size=(20, 30)))
    rg.fillStandardNormal((16, 16), 1)
    sensor.capture(np.zeros((96, 128), np.float32), 1, 1, seed=1)
    # The binding records a call only when PyGILState_Check() said the GIL was not held inside it.
    calls = rg._testing.callsWithoutGil()
    for name in ("colorJitter", "motionBlur", "scaleMosaic", "applyScene", "RandomScenePolicy.draw",
                 "renderSimpleIsp", "BurstStatistics.add", "shapiroWilkBatch", "fillStandardNormal",
                 "SensorSimulator.capture"):
        assert name in calls, name


def test_threads_get_the_results_of_sequential_calls(sensor, capture):
    fmt, model = sensor.rawFormat(2.0), sensor.effectiveModel()
    seeds = list(range(8))
    expected = [rg.colorJitter(capture, fmt, model, rg.ColorJitter.exposureChange(0.2, 2), seed=s)[0] for s in seeds]
    got = [None] * len(seeds)

    def work(i):
        got[i] = rg.colorJitter(capture, fmt, model, rg.ColorJitter.exposureChange(0.2, 2), seed=seeds[i])[0]

    threads = [threading.Thread(target=work, args=(i,)) for i in range(len(seeds))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(np.array_equal(a, b) for a, b in zip(expected, got))


def test_importing_rawgment_does_not_import_torch_or_dask():
    code = "import sys, rawgment, rawgment.batch; print(sorted(m for m in ('torch', 'dask', 'distributed') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout
    assert out.strip() == "[]"
