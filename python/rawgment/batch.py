"""Batch augmentation of RAW files, in this process or on a Dask cluster: the job of rawgment_augment.

The plan (output names, seeds, which outputs a previous run finished) and each output are made by the
app's own C++ code, so the files are the app's, byte for byte, whatever runs them: this process, a
``LocalCluster`` or workers on many machines. Each output's seed depends only on (seed, input name,
variant); outputs are written atomically and never replaced; a rerun skips finished outputs, so a run
that lost a worker (or was killed) resumes where it stopped.

On many machines (the inputs, the model and the output folder on a filesystem every machine mounts at
the same path; give absolute paths)::

    dask-scheduler                                  # on one machine: prints tcp://<host>:8786
    dask-worker tcp://<host>:8786 --nthreads 1      # on every machine (rawgment importable there)
    python3 -m rawgment.batch --scheduler tcp://<host>:8786 --model /data/camera.yml \\
        --policy /data/policy.yml --out /data/augmented --variants 8 /data/raws/*.dng
"""
import argparse
import os
import sys
import time

from . import _rawgment

__all__ = ["augmentFiles", "main", "RAW_EXTENSIONS"]

#: File extensions of the camera RAW formats LibRaw reads (lower case), for picking inputs from a folder: the
#: library's table of containers (mosaicContainers()).
RAW_EXTENSIONS = tuple(e for c in _rawgment.mosaicContainers() if c.cameraRaw for e in c.extensions)
#: The containers writeMosaic() writes, by name ("dng", "npy", "png", "tif"): what --format takes.
WRITTEN_CONTAINERS = tuple(c.name for c in _rawgment.mosaicContainers() if c.writes)


def _runJob(job, model, scene, policy, acceptFailedCalibration=False, camera="", darkBank="", darkBankTied=False):
    """One output (runs on a worker). Returns its path."""
    _rawgment._apps.runAugmentJob(job, model, scene, policy, acceptFailedCalibration, camera, darkBank, darkBankTied)
    return job["out"]


def augmentFiles(inputs, model, out, *, policy=None, scene=None, variants=1, seed=1, format=None,
                 previews=False, client=None, progress=None, acceptFailedCalibration=False, camera=None,
                 darkBank=None, darkBankTied=False):
    """Augments every input `variants` times, as ``rawgment_augment`` does.

    Args:
        inputs: input files (camera RAWs, or mosaics with a .yml sidecar). The paths are recorded in the
            outputs' sidecars as given: give the same strings as to the app for identical files.
        model: the noise model file: a NoiseModel, an Android profile YAML, or darktable's
            noiseprofiles.json with ``camera``. policy / scene: exactly one, a file.
        out: output folder (created). variants: outputs per input. seed: the run's seed.
        format: output container "dng", "png", "tif" or "npy" (default: dng for RAW inputs, else the input's).
        previews: also write an sRGB preview PNG per output.
        client: a ``dask.distributed.Client`` to run the jobs on; None runs them here, one by one.
        progress: a callable(done, total), or None for a line on stderr per 5% when stderr is a terminal.
        acceptFailedCalibration: also use a model whose calibration's verdict was FAIL (refused otherwise).
        camera: with a darktable file, a camera name, a comma-separated list of names, "good" or "usable";
            with several, each output draws one from its seed and records it in its sidecar.
        darkBank: a dark-frame bank file (``DarkFrameBank.save``) as every output's read noise, instead of the
            scene's or policy's own; workers read it by its path. darkBankTied: the inputs are the bank's
            sensor's (``NoiseOptions.darkBankTied``).

    Returns:
        dict with ``written``, ``skipped`` (finished by an earlier run) and ``outputs`` (every output path).

    Raises:
        RuntimeError or rawgment.error naming the file, for bad options or inputs (before any output is
        made) and for the first job that failed (the others still finish).
    """
    if (policy is None) == (scene is None):
        raise ValueError("give exactly one of policy and scene")
    if format is not None and format not in WRITTEN_CONTAINERS:
        raise ValueError("format must be %s, not %r" % (", ".join("'%s'" % n for n in WRITTEN_CONTAINERS), format))
    seed = _checkedSeed(seed)
    camera = "" if camera is None else str(camera)
    inputs = [os.fspath(p) for p in inputs]
    # Workers may run elsewhere: the files every job reads are named absolutely (they are not recorded
    # in the outputs, so this changes no byte).
    model = os.path.abspath(os.fspath(model))
    policy = os.path.abspath(os.fspath(policy)) if policy is not None else ""
    scene = os.path.abspath(os.fspath(scene)) if scene is not None else ""
    darkBank = os.path.abspath(os.fspath(darkBank)) if darkBank is not None else ""
    darkBankTied = bool(darkBankTied)
    plan = _rawgment._apps.planAugmentJobs(inputs, model, scene, policy, os.fspath(out), int(variants), int(seed),
                                           "" if format is None else "." + format, bool(previews),
                                           bool(acceptFailedCalibration), camera, darkBank, darkBankTied)
    jobs = plan["jobs"]
    total = len(jobs)
    if progress is None:
        progress = _terminalProgress(total)
    errors = []
    written = 0
    if client is None:
        for job in jobs:
            try:
                _runJob(job, model, scene, policy, bool(acceptFailedCalibration), camera, darkBank, darkBankTied)
                written += 1
            except Exception as e:  # the others still run; the first error is raised at the end
                errors.append("'%s' variant %d: %s" % (job["input"], job["variant"], e))
            progress(written + len(errors), total)
    else:
        from distributed import as_completed

        futures = client.map(_runJob, jobs, model=model, scene=scene, policy=policy,
                             acceptFailedCalibration=bool(acceptFailedCalibration), camera=camera,
                             darkBank=darkBank, darkBankTied=darkBankTied, pure=False)
        where = {f.key: job for f, job in zip(futures, jobs)}
        for future in as_completed(futures):
            job = where[future.key]
            try:
                future.result()
                written += 1
            except Exception as e:
                errors.append("'%s' variant %d: %s" % (job["input"], job["variant"], e))
            progress(written + len(errors), total)
    if errors:
        raise RuntimeError("%d of %d outputs failed; first: %s" % (len(errors), total, errors[0]))
    return {"written": written, "skipped": plan["skipped"], "outputs": list(plan["outputs"])}


def _checkedSeed(seed):
    """The rule of the apps' --seed: an integer from 0 to 2**64 - 1."""
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2 ** 64:
        raise ValueError("seed must be an integer from 0 to 18446744073709551615 (got %r)" % (seed,))
    return seed


def _terminalProgress(total):
    if not sys.stderr.isatty() or total == 0:
        return lambda done, total: None
    start = time.monotonic()
    step = max(1, total // 20)

    def show(done, total):
        if done % step == 0 or done == total:
            sys.stderr.write("\raugment %d/%d  %.1f s" % (done, total, time.monotonic() - start))
            if done == total:
                sys.stderr.write("\n")
            sys.stderr.flush()

    return show


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python3 -m rawgment.batch",
        description="Noise-accounted augmentation of RAW files (the job of rawgment_augment), in this process, "
                    "on a local Dask cluster (--workers) or on a running one (--scheduler).",
        allow_abbrev=False)
    parser.add_argument("--model", required=True,
                        help="noise model of the camera: a NoiseModel YAML/JSON, an Android profile YAML, or "
                             "darktable's noiseprofiles.json with --camera")
    parser.add_argument("--camera",
                        help="with a darktable file: a camera name, a comma-separated list, good or usable "
                             "(several: each output draws one)")
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument("--policy", help="a random policy file (map 'random_scene_policy')")
    group.add_argument("--scene", help="a scene file (map 'scene') applied to every input")
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--variants", type=int, default=1, help="variants per input (default 1)")
    parser.add_argument("--seed", type=int, default=1,
                        help="seed from 0 to 2**64 - 1: same seed, same files (default 1)")
    parser.add_argument("--format", choices=WRITTEN_CONTAINERS, help="output container")
    parser.add_argument("--preview", action="store_true", help="also write an sRGB preview PNG per output")
    parser.add_argument("--accept_failed_calibration", action="store_true",
                        help="also use a model whose calibration's verdict was FAIL")
    parser.add_argument("--dark_bank", help="a dark-frame bank file: its real dark frames are every output's read "
                                            "noise, accounted for the input's own")
    parser.add_argument("--dark_bank_tied", action="store_true",
                        help="the inputs come from the bank's own sensor: their fixed pattern is swapped for the "
                             "target's")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--scheduler", help="address of a running Dask scheduler (tcp://host:8786)")
    where.add_argument("--workers", type=int, help="start a local Dask cluster with this many worker processes")
    parser.add_argument("--dashboard", metavar="HOST:PORT",
                        help="where the local cluster's dashboard listens (default: a free port of 127.0.0.1 "
                             "only; this tool opens no port to other machines unless asked)")
    parser.add_argument("inputs", nargs="+", help="input files")
    args = parser.parse_args(argv)
    if args.variants < 1:
        parser.error("--variants must be >= 1")
    if args.workers is not None and args.workers < 1:
        parser.error("--workers must be >= 1")
    try:
        _checkedSeed(args.seed)
    except ValueError as e:
        parser.error("--" + str(e))
    if args.dashboard is not None and not args.workers:
        parser.error("--dashboard is for the local cluster of --workers")

    client = cluster = None
    try:
        if args.scheduler or args.workers:
            from distributed import Client, LocalCluster

            if args.scheduler:
                client = Client(args.scheduler)
            else:
                # Scheduler, workers and dashboard on the loopback: Dask's defaults listen on every
                # interface (its dashboard on 0.0.0.0:8787) and would serve the files' names to the network.
                cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                                       host="127.0.0.1", dashboard_address=args.dashboard or "127.0.0.1:0")
                client = Client(cluster)
        result = augmentFiles(args.inputs, args.model, args.out, policy=args.policy, scene=args.scene,
                              variants=args.variants, seed=args.seed, format=args.format, previews=args.preview,
                              client=client, acceptFailedCalibration=args.accept_failed_calibration,
                              camera=args.camera, darkBank=args.dark_bank, darkBankTied=args.dark_bank_tied)
    except (RuntimeError, ValueError, OSError) as e:
        sys.stderr.write("rawgment.batch: %s\n" % e)
        return 1
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    print("wrote %d outputs, skipped %d that already existed, in %s" % (result["written"], result["skipped"], args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
