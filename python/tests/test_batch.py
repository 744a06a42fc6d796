"""rawgment.batch: the same files from one process, a 2-worker Dask LocalCluster and the C++ app; a
rerun after an interrupted run finishes the job without replacing anything."""
import filecmp
import os
import pickle
import subprocess
import sys

import numpy as np
import pytest

import rawgment as rg
import rawgment.batch as batch


@pytest.fixture(scope="module")
def job(tmp_path_factory, sensor):
    """Inputs (two DNGs sharing a stem, and a PNG mosaic with its sidecar), a model and a policy."""
    from conftest import chart_mean

    root = tmp_path_factory.mktemp("batch")
    _, mean = chart_mean()
    for sub in ("a", "b"):
        (root / sub).mkdir()
    inputs = []
    for i, path in enumerate([root / "a" / "frame.dng", root / "b" / "frame.dng"]):
        raw = sensor.capture(mean, 1.0, 1.0, seed=60 + i)
        rg.writeDng(str(path), rg.RawImage(mosaic=raw, format=sensor.rawFormat(1.0)))
        inputs.append(str(path))
    png = root / "a" / "chart.png"
    rg.writeMosaic(str(png), sensor.capture(mean, 2.0, 1.0, seed=70), rg.MosaicMetadata(format=sensor.rawFormat(2.0)))
    inputs.append(str(png))
    sensor.effectiveModel().save(str(root / "model.yml"))
    rg.RandomScenePolicy(blurProbability=0.5, geometryProbability=1).save(str(root / "policy.yml"))
    return {"root": root, "inputs": inputs, "model": str(root / "model.yml"), "policy": str(root / "policy.yml")}


def app_run(app_dir, job, out, extra=()):
    cmd = [os.path.join(app_dir, "rawgment_augment"), "--model=" + job["model"], "--policy=" + job["policy"],
           "--out=" + str(out), "--variants=2", "--seed=5", *extra, *job["inputs"]]
    subprocess.run(cmd, check=True, capture_output=True)


def files_of(folder):
    return sorted(os.listdir(folder))


def assert_same_files(a, b):
    assert files_of(a) == files_of(b)
    for name in files_of(a):
        assert filecmp.cmp(os.path.join(a, name), os.path.join(b, name), shallow=False), name


def test_one_process_dask_and_the_app_make_the_same_bytes(app_dir, job):
    root = job["root"]
    app_run(app_dir, job, root / "app")
    result = batch.augmentFiles(job["inputs"], job["model"], root / "here", policy=job["policy"], variants=2, seed=5)
    assert result["written"] == 6 and result["skipped"] == 0 and len(result["outputs"]) == 6
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        assert len(client.scheduler_info()["workers"]) == 2
        on_dask = batch.augmentFiles(job["inputs"], job["model"], root / "dask", policy=job["policy"], variants=2,
                                     seed=5, client=client)
    assert on_dask["written"] == 6
    assert len(files_of(root / "app")) == 13  # 6 mosaics, each with its sidecar, and the job record
    assert_same_files(root / "app", root / "here")
    assert_same_files(root / "app", root / "dask")


def test_a_rerun_resumes_and_replaces_nothing(app_dir, job):
    root = job["root"]
    out = root / "resumed"
    options = rg._apps.AugmentOptions()
    options.inputs = list(job["inputs"])
    for flag, value in (("model", job["model"]), ("policy", job["policy"]), ("out", str(out)), ("variants", "2"),
                        ("seed", "5")):
        rg._apps.setAugmentOption(options, flag, value)
    plan = rg._apps.planAugmentJobs(options)
    assert len(plan["jobs"]) == 6 and plan["skipped"] == 0
    # Two outputs finished, then the run was killed (pid 999999) while writing a third: its temporary
    # is not an output, and the rerun removes it.
    for j in plan["jobs"][:2]:
        rg._apps.runAugmentJob(j, options)
    leftover = plan["jobs"][2]["out"] + ".tmp-999999-0"
    open(leftover, "wb").write(b"partial")
    finished = {p: os.path.getmtime(p) for p in (plan["jobs"][0]["out"], plan["jobs"][1]["out"])}
    result = batch.augmentFiles(job["inputs"], job["model"], out, policy=job["policy"], variants=2, seed=5)
    assert result["skipped"] == 2 and result["written"] == 4
    assert all(os.path.getmtime(p) == t for p, t in finished.items())
    assert not os.path.exists(leftover)
    app_run(app_dir, job, root / "app_for_resume")
    assert_same_files(root / "app_for_resume", out)
    # Another seed into the same folder is refused: its outputs would be different files of one name.
    with pytest.raises(RuntimeError, match="records another augmentation job: its seed"):
        batch.augmentFiles(job["inputs"], job["model"], out, policy=job["policy"], variants=2, seed=6)


def test_bad_options_are_errors_before_any_output(job, tmp_path):
    with pytest.raises(ValueError, match="exactly one of policy and scene"):
        batch.augmentFiles(job["inputs"], job["model"], tmp_path / "x")
    with pytest.raises(RuntimeError, match="no such file"):
        batch.augmentFiles(job["inputs"] + [str(tmp_path / "missing.dng")], job["model"], tmp_path / "y",
                           policy=job["policy"])
    assert not (tmp_path / "y").exists() or not os.listdir(tmp_path / "y")
    with pytest.raises(rg.error, match="model"):
        batch.augmentFiles(job["inputs"], job["policy"], tmp_path / "z", policy=job["policy"])


def test_unsafe_or_unbounded_requests_are_refused(app_dir, job, tmp_path):
    # One seed rule for the app and Python: -1 wrapped to 2**64 - 1 in the app and was a traceback here.
    with pytest.raises(ValueError, match="seed must be an integer from 0 to 18446744073709551615"):
        batch.augmentFiles(job["inputs"], job["model"], tmp_path / "s", policy=job["policy"], seed=-1)
    run = [sys.executable, "-m", "rawgment.batch", "--model", job["model"], "--policy", job["policy"]]
    bad = subprocess.run(run + ["--out", str(tmp_path / "s2"), "--seed", "-1", job["inputs"][0]],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and "seed must be an integer from 0 to 18446744073709551615" in bad.stderr
    app = subprocess.run([os.path.join(app_dir, "rawgment_augment"), "--model=" + job["model"],
                          "--policy=" + job["policy"], "--out=" + str(tmp_path / "s3"), "--seed=-1",
                          job["inputs"][0]], capture_output=True, text=True)
    assert app.returncode == 2 and "seed must be an integer from 0 to 18446744073709551615" in app.stderr
    # A plan is held in memory before the first job: 10^8 variants grew it to bad_alloc.
    with pytest.raises(RuntimeError, match=r"variants must lie in \[1, 100000\]"):
        batch.augmentFiles(job["inputs"], job["model"], tmp_path / "v", policy=job["policy"], variants=100000000)
    # Two names of one file are one input, not two augmentations of it.
    here = os.getcwd()
    try:
        os.chdir(job["root"])
        with pytest.raises(RuntimeError, match="is given twice"):
            batch.augmentFiles(["./a/frame.dng", "a/frame.dng"], job["model"], tmp_path / "t", policy=job["policy"])
    finally:
        os.chdir(here)


def test_a_local_cluster_listens_on_the_loopback_only(job, tmp_path, monkeypatch):
    import distributed

    seen = {}

    class Recorder:
        def __init__(self, **kwargs):
            seen.update(kwargs)
            raise RuntimeError("recorded")

    monkeypatch.setattr(distributed, "LocalCluster", Recorder)
    args = ["--model", job["model"], "--policy", job["policy"], "--out", str(tmp_path / "d"), "--workers", "1",
            job["inputs"][0]]
    assert batch.main(args) == 1
    assert seen["host"] == "127.0.0.1" and seen["dashboard_address"] == "127.0.0.1:0"
    assert batch.main(args + ["--dashboard", "127.0.0.1:8799"]) == 1
    assert seen["dashboard_address"] == "127.0.0.1:8799"


def test_command_line(job, tmp_path):
    run = [sys.executable, "-m", "rawgment.batch"]
    bad = subprocess.run(run + ["--model", job["model"], "--policy", job["policy"], "--out", str(tmp_path),
                                "--bogus", job["inputs"][0]], capture_output=True, text=True)
    assert bad.returncode == 2 and "--bogus" in bad.stderr
    ok = subprocess.run(run + ["--model", job["model"], "--policy", job["policy"], "--out", str(tmp_path / "cli"),
                               "--variants", "1", job["inputs"][2]], capture_output=True, text=True)
    assert ok.returncode == 0, ok.stderr
    assert "wrote 1 outputs" in ok.stdout
    mosaic, meta = rg.readMosaic(str(tmp_path / "cli" / "chart_v00.png"))
    assert meta.hasScene and meta.source == job["inputs"][2] and mosaic.dtype == np.uint16
    help_text = subprocess.run(run + ["--help"], capture_output=True, text=True).stdout
    assert "--scheduler" in help_text and "--workers" in help_text


def test_the_readme_commands_on_a_scheduler_and_workers(app_dir, job, tmp_path):
    """dask-scheduler and two dask-worker processes (loopback standing in for machines), then
    `python3 -m rawgment.batch --scheduler`: the app's bytes."""
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    address = "tcp://127.0.0.1:%d" % port
    env = dict(os.environ)
    logs = open(tmp_path / "dask.log", "w")
    procs = [subprocess.Popen(["dask-scheduler", "--host", "127.0.0.1", "--port", str(port),
                               "--dashboard-address", ":0"], stdout=logs, stderr=logs, env=env)]
    try:
        procs += [subprocess.Popen(["dask-worker", address, "--nthreads", "1", "--no-dashboard"], stdout=logs,
                                   stderr=logs, env=env) for _ in range(2)]
        from distributed import Client

        with Client(address, timeout=60) as client:
            client.wait_for_workers(2, timeout=60)
        cmd = [sys.executable, "-m", "rawgment.batch", "--scheduler", address, "--model", job["model"], "--policy",
               job["policy"], "--out", str(tmp_path / "cluster"), "--variants", "2", "--seed", "5", *job["inputs"]]
        run = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
        assert run.returncode == 0, run.stderr
        assert "wrote 6 outputs" in run.stdout
    finally:
        for p in procs[::-1]:
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
        logs.close()
    app_run(app_dir, job, tmp_path / "app")
    assert_same_files(tmp_path / "app", tmp_path / "cluster")


def test_a_failed_calibrations_model_is_refused_unless_accepted(job, tmp_path):
    model = rg.NoiseModel.load(job["model"])
    model.failedCalibration = "frames per burst"
    failed = str(tmp_path / "failed.yml")
    model.save(failed)
    with pytest.raises(rg.error, match=r"verdict was FAIL \(frames per burst\)"):
        rg.NoiseModel.load(failed)
    assert rg.NoiseModel.load(failed, acceptFailedCalibration=True).failedCalibration == "frames per burst"
    with pytest.raises(rg.error, match="acceptFailedCalibration=True"):
        batch.augmentFiles(job["inputs"][:1], failed, tmp_path / "refused", policy=job["policy"])
    assert not (tmp_path / "refused").exists() or not os.listdir(tmp_path / "refused")
    result = batch.augmentFiles(job["inputs"][:1], failed, tmp_path / "accepted", policy=job["policy"],
                                acceptFailedCalibration=True)
    assert result["written"] == 1
    # The same from the command line, and the mark survives pickling (Dask ships models to workers).
    run = subprocess.run([sys.executable, "-m", "rawgment.batch", "--model", failed, "--policy", job["policy"],
                          "--out", str(tmp_path / "cli"), job["inputs"][0]], capture_output=True, text=True)
    assert run.returncode == 1 and "verdict was FAIL" in run.stderr, run.stderr
    run = subprocess.run([sys.executable, "-m", "rawgment.batch", "--model", failed, "--policy", job["policy"],
                          "--accept_failed_calibration", "--out", str(tmp_path / "cli"), job["inputs"][0]],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    import pickle
    assert pickle.loads(pickle.dumps(model)).failedCalibration == "frames per burst"


def test_a_dark_frame_bank_reaches_the_app_and_the_workers_by_its_path(app_dir, job, dark_bank, tmp_path):
    # A gain ratio of 2: inputs at gains 1 and 2 go to 2 and 4, within the bank.
    policy = tmp_path / "policy.yml"
    rg.RandomScenePolicy(blurProbability=0.5, geometryProbability=1, gainDbMin=6.0206,
                         gainDbMax=6.0206).save(str(policy))
    banked = dict(job, policy=str(policy))
    app_run(app_dir, banked, tmp_path / "app", extra=["--dark_bank=" + dark_bank])
    here = batch.augmentFiles(banked["inputs"], banked["model"], tmp_path / "here", policy=str(policy), variants=2,
                              seed=5, darkBank=dark_bank)
    assert here["written"] == 6
    assert_same_files(tmp_path / "app", tmp_path / "here")
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        batch.augmentFiles(banked["inputs"], banked["model"], tmp_path / "dask", policy=str(policy), variants=2,
                           seed=5, darkBank=dark_bank, client=client)
    assert_same_files(tmp_path / "app", tmp_path / "dask")
    # The bank changes the noise: without it, other bytes.
    app_run(app_dir, banked, tmp_path / "plain")
    name = [n for n in files_of(tmp_path / "app") if n.endswith(".dng")][0]
    assert not filecmp.cmp(tmp_path / "app" / name, tmp_path / "plain" / name, shallow=False)
    # A policy file may name the bank itself, relative to its own folder.
    named = tmp_path / "named.yml"
    noise = rg.NoiseOptions(darkBank=os.path.relpath(dark_bank, tmp_path))
    rg.RandomScenePolicy(blurProbability=0.5, geometryProbability=1, gainDbMin=6.0206, gainDbMax=6.0206,
                         noise=noise).save(str(named))
    assert rg.RandomScenePolicy.load(str(named)).noise.darkBank == os.path.join(str(tmp_path), noise.darkBank)
    app_run(app_dir, dict(job, policy=str(named)), tmp_path / "named")
    # The same images; the sidecars record the bank's path as each run named it.
    for name in files_of(tmp_path / "app"):
        if not name.endswith(".yml"):
            assert filecmp.cmp(tmp_path / "app" / name, tmp_path / "named" / name, shallow=False), name
    assert "dark_bank" in (tmp_path / "named" / "chart_v00.png.yml").read_text()
    # A bank that cannot be read stops the run before its first output; a tied bank needs a bank.
    with pytest.raises(RuntimeError, match="missing.yml"):
        batch.augmentFiles(banked["inputs"], banked["model"], tmp_path / "bad", policy=str(policy),
                           darkBank=tmp_path / "missing.yml")
    with pytest.raises(RuntimeError, match="needs the bank"):
        batch.augmentFiles(banked["inputs"], banked["model"], tmp_path / "bad", policy=str(policy), darkBankTied=True)
    assert not os.path.exists(tmp_path / "bad") or not os.listdir(tmp_path / "bad")


def test_the_app_and_batch_share_one_command_line(app_dir):
    # One table of flags (pipeline/augment_command_line.hpp): every flag of it in both --help texts with the same
    # help, and one setter of values with one set of rules, so a flag added once is in both.
    flags = rg._apps.augmentFlags()
    assert [f["name"] for f in flags][:5] == ["model", "camera", "scene", "policy", "out"]
    app = subprocess.run([os.path.join(app_dir, "rawgment_augment"), "--help"], capture_output=True, text=True)
    py = subprocess.run([sys.executable, "-m", "rawgment.batch", "--help"], capture_output=True, text=True,
                        env=dict(os.environ, COLUMNS="10000"))
    assert app.returncode == 0 and py.returncode == 0
    squash = lambda text: " ".join(text.split())
    for f in flags:
        assert "--" + f["name"] in app.stdout and "--" + f["name"] in py.stdout, f["name"]
        assert squash(f["help"]) in squash(app.stdout), f["name"]
        assert squash(f["help"]) in squash(py.stdout), f["name"]
    options = rg._apps.AugmentOptions()
    for flag, value, why in (("variants", "0", "--variants must be a whole number >= 1"),
                             ("seed", "-1", "--seed must be an integer from 0 to 18446744073709551615"),
                             ("format", "jpg", "--format must be dng, npy, png or tif"),
                             ("preview", "maybe", "--preview must be true or false"),
                             ("no_such_flag", "1", "no augment flag --no_such_flag")):
        with pytest.raises(ValueError, match=why):
            rg._apps.setAugmentOption(options, flag, value)
    for flag, value in (("format", "tif"), ("seed", "18446744073709551615"), ("preview", "true"),
                        ("variants", "3"), ("dark_bank", "bank.yml")):
        rg._apps.setAugmentOption(options, flag, value)
    assert (options.extension, options.seed, options.previews, options.variants, options.darkBank) == \
        (".tif", 2**64 - 1, True, 3, "bank.yml")
    # The options travel to Dask workers pickled: every field comes back.
    back = pickle.loads(pickle.dumps(options))
    assert [getattr(back, k) for k in ("extension", "seed", "previews", "variants", "darkBank")] == \
        [".tif", 2**64 - 1, True, 3, "bank.yml"]
    # The same refusal from both front ends, by the same rule.
    for command in ([os.path.join(app_dir, "rawgment_augment"), "--model=m.yml", "--policy=p.yml", "--out=o",
                     "--variants=0", "x.dng"],
                    [sys.executable, "-m", "rawgment.batch", "--model", "m.yml", "--policy", "p.yml", "--out", "o",
                     "--variants", "0", "x.dng"]):
        run = subprocess.run(command, capture_output=True, text=True)
        assert run.returncode == 2 and "--variants must be a whole number >= 1 (got '0')" in run.stderr, run.stderr
