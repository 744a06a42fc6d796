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
import operator
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


def _runJob(job, options):
    """One output (runs on a worker). Returns its path."""
    _rawgment._apps.runAugmentJob(job, options)
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
        format: output container, a name of WRITTEN_CONTAINERS (default: dng for RAW inputs, else the input's).
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
        ValueError for a value no flag of rawgment_augment takes; RuntimeError or rawgment.error naming the
        file, for bad options or inputs (before any output is made) and for the first job that failed (the
        others still finish).
    """
    if (policy is None) == (scene is None):
        raise ValueError("give exactly one of policy and scene")
    options = _rawgment._apps.AugmentOptions()
    options.inputs = [os.fspath(p) for p in inputs]
    # The app's rules for every value (augmentFlags(), setAugmentOption()): one command line, two front ends.
    # Whole numbers as the app reads them: an int or numpy integer, never a bool or a float.
    numbers = {"variants": variants, "seed": seed}
    for flag, value in numbers.items():
        if isinstance(value, bool) or not hasattr(value, "__index__"):
            raise ValueError("%s must be an integer%s (got %r)" % (
                flag, " from 0 to 18446744073709551615" if flag == "seed" else "", value))
        _rawgment._apps.setAugmentOption(options, flag, str(operator.index(value)))
    texts = {"model": model, "out": out, "policy": policy, "scene": scene, "format": format,
             "camera": None if camera is None else str(camera), "dark_bank": darkBank}
    switches = {"preview": previews, "accept_failed_calibration": acceptFailedCalibration,
                "dark_bank_tied": darkBankTied}
    for flag, value in texts.items():
        if value is not None:
            _rawgment._apps.setAugmentOption(options, flag, os.fspath(value))
    for flag, value in switches.items():
        _rawgment._apps.setAugmentOption(options, flag, "true" if value else "false")
    return _augment(options, client, progress)


def _augment(options, client, progress):
    # Workers may run elsewhere: the files every job reads are named absolutely (they are not recorded
    # in the outputs, so this changes no byte).
    for field in ("model", "scene", "policy", "darkBank"):
        if getattr(options, field):
            setattr(options, field, os.path.abspath(getattr(options, field)))
    plan = _rawgment._apps.planAugmentJobs(options)
    jobs = plan["jobs"]
    total = len(jobs)
    if progress is None:
        progress = _terminalProgress(total)
    errors = []
    written = 0
    if client is None:
        for job in jobs:
            try:
                _runJob(job, options)
                written += 1
            except Exception as e:  # the others still run; the first error is raised at the end
                errors.append("'%s' variant %d: %s" % (job["input"], job["variant"], e))
            progress(written + len(errors), total)
    else:
        from distributed import as_completed

        futures = client.map(_runJob, jobs, options=options, pure=False)
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
    # rawgment_augment's flags, from its own table: the same names, help and rules.
    flags = _rawgment._apps.augmentFlags()
    groups = {}
    for f in flags:
        names = ["--" + f["name"]] + (["-" + f["shortName"]] if f["shortName"] else [])
        where = parser
        if f["oneOf"]:
            if f["oneOf"] not in groups:
                groups[f["oneOf"]] = parser.add_mutually_exclusive_group(required=True)
            where = groups[f["oneOf"]]
        helpText = f["help"] + (" (default %s)" % f["defaultValue"] if f["defaultValue"] and not f["isSwitch"] else "")
        helpText = helpText.replace("%", "%%")  # argparse formats help with %
        if f["isSwitch"]:
            where.add_argument(*names, action="store_true", help=helpText)
        else:
            where.add_argument(*names, required=f["required"], help=helpText)
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--scheduler", help="address of a running Dask scheduler (tcp://host:8786)")
    where.add_argument("--workers", type=int, help="start a local Dask cluster with this many worker processes")
    parser.add_argument("--dashboard", metavar="HOST:PORT",
                        help="where the local cluster's dashboard listens (default: a free port of 127.0.0.1 "
                             "only; this tool opens no port to other machines unless asked)")
    parser.add_argument("inputs", nargs="+", help="input files")
    args = parser.parse_args(argv)
    options = _rawgment._apps.AugmentOptions()
    options.inputs = list(args.inputs)
    try:
        for f in flags:
            value = getattr(args, f["name"])
            if f["isSwitch"]:
                value = "true" if value else "false"
            if value is not None:
                _rawgment._apps.setAugmentOption(options, f["name"], value)
    except ValueError as e:
        parser.error(str(e))
    if args.workers is not None and args.workers < 1:
        parser.error("--workers must be >= 1")
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
        result = _augment(options, client, None)
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
