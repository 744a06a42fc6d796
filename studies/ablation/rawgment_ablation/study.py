"""The ablation study of the paper's claim, on your sensor: a small RAW denoiser trained on darkened
captures made with each noise alignment, tested on captures simulated directly in the dark.

Run it as ``python3 -m rawgment_ablation [--model camera.yml] [--quick] [--out DIR]``; ``--help`` lists
every option and docs/ablation.md explains the design and how to read the report.

Arms (each trains the same network with the same budget, seed and data order; only the training
inputs differ):

* ``NONE``, ``IGNORE_PRIOR``, ``ACCOUNT_PRIOR``: a bright capture of the training scene (its own
  noise), darkened by the library (motionBlur for the blur condition, then colorJitter) with that
  NoiseAlignment;
* ``ORACLE``: a capture simulated directly at the target exposure and gain (the upper bound);
* ``NOISY``: no network, the test input itself (the lower bound);
* ``DARK_BANK``, ``DARK_BANK_IGNORE``: as ACCOUNT_PRIOR and IGNORE_PRIOR, with the read part drawn from a tied
  bank of the sensor's own dark captures (docs/dark_frame_bank.md), best run with ``--departing-sensor``.

Test inputs are always captures simulated at the target (exact Poisson), never the augmentation.
Every random number derives from ``--seed`` through study_seed(study_seed(seed, role), item) (common.py: the
library's deriveSeed under the purpose 24 it reserves for this study), so the same seeds give the same numbers.
"""
import argparse
import atexit
import dataclasses
import math
import os
import shutil
import sys
import tempfile
import time

import numpy as np
import torch

import rawgment as _rg
from rawgment_ablation.common import (ARMS, BANK_ARMS, BLIND_STEP, CONTROL_ARMS, DEFAULT_ARMS, DESIGNS,
                                       TRAINED_ARMS, _ROLE_BANK, _ROLE_BATCH, _ROLE_NETWORK, _ROLE_SAMPLE,
                                       _ROLE_TEST_CAPTURE, _ROLE_TEST_SCENES, _ROLE_TRAIN_SCENES, _seed, study_seed)
from rawgment_ablation.report import (NETWORKS, SIGNIFICANCE, _plotPng, _plotScript, contrastPairs, contrastRows,
                                      correctFamily, holmAdjusted, pairedSignificance, seedsForFamily, seedsToConfirm,
                                      mergeReplicates, studyName, summarize, writeCombinedReport, writeOutputs,
                                      writeStudiesOutputs)
from rawgment_ablation.config import (AblationConfig, Condition, defaultConditions, departingSensorParams,
                                       quickConditions)
from rawgment_ablation.controls import BANK_CONTRASTS, CONTROL_CONTRASTS, PREDICTIONS
from rawgment_ablation.network import Denoiser, psnr, ssim
from rawgment_ablation.scenes import mosaicOfScene, renderScene
from rawgment.torch import packCfaPlanes

__all__ = ["Condition", "AblationConfig", "ARMS", "TRAINED_ARMS", "DEFAULT_ARMS", "CONTROL_ARMS", "BANK_ARMS", "DESIGNS",
           "defaultConditions", "quickConditions", "renderScene", "mosaicOfScene", "Denoiser", "psnr", "ssim",
           "runAblation", "pairedSignificance", "summarize", "writeOutputs", "NETWORKS", "BLIND_STEP", "SIGNIFICANCE",
           "writeStudiesOutputs", "writeCombinedReport", "mergeReplicates", "studyName", "seedsNeeded", "holmAdjusted", "seedsForFamily",
           "seedsToConfirm", "contrastRows", "correctFamily", "PREDICTIONS", "CONTROL_CONTRASTS", "BANK_CONTRASTS",
           "departingSensorParams",
           "main"]

ALIGNMENTS = {"NONE": _rg.NoiseAlignment.NONE, "IGNORE_PRIOR": _rg.NoiseAlignment.IGNORE_PRIOR,
              "ACCOUNT_PRIOR": _rg.NoiseAlignment.ACCOUNT_PRIOR}

# The brightest expected signal of a bright training capture, as a fraction of white - black: headroom
# so that the bright captures (and the test's clean references) are not clipped.
_FILL = 0.8
# The reflectance at which the report states each condition's prior share (mid-grey).
_MID_GREY = 0.18


class _Study:
    """The sensor, the scenes and the test set of one run (shared by every arm and replicate)."""

    def __init__(self, config):
        self.config = config
        self.params = config.sensorParams(16)
        probe = _rg.SensorSimulator(self.params, (16, 16))
        # The augmentation's model: the probe's effective model (quantisation included) with the sensor's
        # whole shading maps, read at each crop's place (its top-left corner, as the simulators).
        self.model = probe.effectiveModel()
        if config.model is not None and config.model.hasDarkShading():
            self.model.darkShadingPerGain = config.model.darkShadingPerGain
            self.model.darkShadingOffset = config.model.darkShadingOffset
        self.format = probe.rawFormat(config.baseGain)
        self.range = self.format.whiteLevel - self.format.blackLevel[0]
        # DN at gain 1 for reflectance 1 under the brightest channel: the bright captures fill _FILL of
        # the range at the base gain.
        self.level = _FILL * self.range / config.baseGain
        self.simulators = {}
        self.kernels = {}
        self.bank = None

    def simulator(self, size):
        if size not in self.simulators:
            self.simulators[size] = _rg.SensorSimulator(self.config.sensorParams(size), (size, size))
        return self.simulators[size]

    def kernel(self, condition):
        key = (condition.blurLength, condition.blurAngle)
        if key not in self.kernels:
            self.kernels[key] = _rg.linearMotionKernel(condition.blurLength, condition.blurAngle)
        return self.kernels[key]

    def scenes(self, role, count, size):
        return [mosaicOfScene(renderScene(np.random.default_rng(_seed(self.config.seed, role, i)), size, size),
                              self.params.pattern, self.level) for i in range(count)]

    def brightSignal(self, mean, condition):
        """The bright capture's expected signal (DN above black, float32), blurred as the target is."""
        signal = (mean * self.config.baseGain).astype(np.float32)
        if condition.blurLength > 0:
            fmt = self.format
            withBlack = signal + np.float32(fmt.blackLevel[0])
            blurred, _ = _rg.motionBlur(withBlack, fmt, self.model, self.kernel(condition),
                                        _rg.NoiseOptions(_rg.NoiseAlignment.NONE), seed=0)
            signal = blurred - np.float32(fmt.blackLevel[0])
        return signal

    def cleanPlanes(self, mean, condition):
        """The clean reference: the expected bright capture (blurred as the target is), black-subtracted,
        normalised by white - black and packed."""
        return packCfaPlanes(self.brightSignal(mean, condition) / np.float32(self.range), self.format)

    def targetCapture(self, mean, condition, seed):
        """A capture simulated directly at the target exposure and gain (exact Poisson)."""
        sim = self.simulator(mean.shape[0])
        gain = self.config.baseGain * condition.gainRatio
        if condition.blurLength > 0:
            return sim.captureBlurred(mean, self.kernel(condition), gain, condition.photonRatio, seed)
        return sim.capture(mean, gain, condition.photonRatio, seed)

    def brightCapture(self, mean, seed):
        """The bright capture of a training crop (its own noise): the input of every augmented arm."""
        return self.simulator(mean.shape[0]).capture(mean, self.config.baseGain, 1.0, seed)

    def bankPath(self):
        """The bank arms' dark-frame bank, made on first use: config.bankFrames dark captures of the training
        crops' sensor (the simulator of the crop size, whose fixed pattern the crops share) at every gain of
        the run, tied to the crops. Written to a temporary folder removed when the process ends."""
        if self.bank is None:
            folder = tempfile.mkdtemp(prefix="rawgment_ablation_bank_")
            atexit.register(shutil.rmtree, folder, True)
            size = int(self.config.patch)
            sim = self.simulator(size)
            gains = sorted({self.config.baseGain} | {self.config.baseGain * c.gainRatio for c in self.config.conditions})
            files = []
            for gi, gain in enumerate(gains):
                for t in range(int(self.config.bankFrames)):
                    dark = sim.capture(np.zeros((size, size), np.float32), gain, 1.0,
                                       _seed(self.config.seed, _ROLE_BANK, gi), frameIndex=t)
                    files.append(os.path.join(folder, "dark_%d_%03d.png" % (gi, t)))
                    _rg.writeMosaic(files[-1], dark, _rg.MosaicMetadata(format=sim.rawFormat(gain)))
            bank = _rg.DarkFrameBank.create(files, _rg.NoiseModel())
            self.bank = os.path.join(folder, "bank.yml")
            bank.save(self.bank)
        return self.bank

    def augmented(self, bright, condition, alignment, seed, shotSampling=None, bank=False):
        """The bright capture darkened (and blurred) by the library with an alignment (a name of
        ALIGNMENTS); the shot part drawn as the run's --shot-sampling, or as `shotSampling` if given; with
        `bank`, the read part from the tied bank (bankPath())."""
        options = _rg.NoiseOptions(ALIGNMENTS[alignment])
        options.shotSampling = getattr(_rg.ShotNoiseSampling, shotSampling or self.config.shotSampling)
        options.priorMean = getattr(_rg.PriorMeanEstimate, self.config.priorMean)
        if bank:
            options.darkBank = self.bankPath()
            options.darkBankTied = True
        stepSeeds = [study_seed(seed, step) for step in (1, 2)]
        if condition.blurLength > 0:
            bright, _ = _rg.motionBlur(bright, self.format, self.model, self.kernel(condition), options,
                                       seed=stepSeeds[0])
        change = _rg.ColorJitter.exposureChange(condition.photonRatio, condition.gainRatio)
        dark, _, _ = _rg.colorJitter(bright, self.format, self.model, change, options, seed=stepSeeds[1])
        return dark

    def expectedTarget(self, mean, condition):
        """The target capture's expected signal (DN above black, float64)."""
        return self.brightSignal(mean, condition).astype(np.float64) * (condition.photonRatio * condition.gainRatio)

    def priorAndTargetVariance(self, mean, condition):
        """Per pixel, the model's variance (DN^2 at the target) of the darkened prior noise and of the
        target capture: what IGNORE_PRIOR adds twice over and what a capture carries."""
        g0, p, g = self.config.baseGain, condition.photonRatio, condition.gainRatio
        expected = self.expectedTarget(mean, condition)
        bright = self.model.variance(np.clip(expected / (p * g), 0.0, None), g0)
        if condition.blurLength > 0:
            bright = bright * float(np.sum(self.kernel(condition).astype(np.float64) ** 2))
        return (p * g) ** 2 * bright, self.model.variance(np.clip(expected, 0.0, None), g0 * g), expected

    def rescaledToTarget(self, raw, mean, condition):
        """IGNORE_RESCALED: IGNORE_PRIOR's input with its noise (the input minus the expected target)
        scaled pixel by pixel by sqrt(var_target / (var_prior + var_target)), so that it carries the
        target's variance while keeping IGNORE_PRIOR's make-up (the prior's own noise plus the whole target
        variance added from the noisy value)."""
        prior, target, expected = self.priorAndTargetVariance(mean, condition)
        black = float(self.format.blackLevel[0])
        noise = raw.astype(np.float64) - black - expected
        return self.asCapture(black + expected + noise * np.sqrt(target / (prior + target)))

    def withPriorShare(self, raw, mean, condition, seed):
        """ORACLE_PLUS_SHARE: a capture at the target plus Gaussian noise of the darkened prior's
        variance, so that it carries what IGNORE_PRIOR carries in excess of the target, on real noise."""
        prior, _, _ = self.priorAndTargetVariance(mean, condition)
        draw = np.random.default_rng(study_seed(seed, 4)).standard_normal(raw.shape)
        return self.asCapture(raw.astype(np.float64) + np.sqrt(prior) * draw)

    def asCapture(self, values):
        """Values in DN rounded and clipped to the sensor's range, in the captures' type: the control arms'
        inputs are on the same integer grid as every other arm's (a network could tell a continuous input
        from a quantised one, which is not the change a control is about)."""
        return np.clip(np.rint(values), 0, self.format.whiteLevel).astype(np.uint16)

    def inputPlanes(self, raw, condition):
        """A dark mosaic as the network sees it: black-subtracted, normalised, packed and brightened by
        the inverse of the exposure change, so every condition has the bright captures' scale; then the
        noise-level map the model predicts for it at the target gain (from the noisy value itself, as
        a camera pipeline would), on the same scale."""
        gain = self.config.baseGain * condition.gainRatio
        fmt = self.simulator(raw.shape[0]).rawFormat(gain)
        scale = self.range * condition.photonRatio * condition.gainRatio
        signal = _rg.subtractBlackLevel(raw, fmt, normalize=True)
        planes = packCfaPlanes(signal / np.float32(condition.photonRatio * condition.gainRatio), fmt)
        if not self.config.noiseMaps:
            return planes
        meanDn = planes.clamp(min=0.0).double() * scale
        # The model's own variance of each mean (NoiseModel.variance on the float64 array).
        flat = meanDn.reshape(meanDn.shape[0] * meanDn.shape[1], -1).numpy()
        variance = torch.from_numpy(self.model.variance(flat, gain)).reshape(meanDn.shape)
        sigma = torch.sqrt(variance) / scale
        return torch.cat([planes, sigma.float()])

    def trainingInputs(self, mean, condition, arms, seed):
        """Each trained arm's input for one crop: the augmented arms share one bright capture (so they
        differ only in their alignment), the oracle gets a capture simulated at the target; the control
        arms derive theirs from IGNORE_PRIOR's and the oracle's (the same draws: the control differs in
        its one change alone)."""
        raws = {}

        def raw(arm):
            if arm not in raws:
                if arm == "ORACLE":
                    raws[arm] = self.targetCapture(mean, condition, study_seed(seed, 3))
                elif arm == "IGNORE_RESCALED":
                    raws[arm] = self.rescaledToTarget(raw("IGNORE_PRIOR"), mean, condition)
                elif arm == "ORACLE_PLUS_SHARE":
                    raws[arm] = self.withPriorShare(raw("ORACLE"), mean, condition, seed)
                else:
                    if "bright" not in raws:
                        raws["bright"] = self.brightCapture(mean, seed)
                    alignment = {"ACCOUNT_POISSON": "ACCOUNT_PRIOR", "DARK_BANK": "ACCOUNT_PRIOR",
                                 "DARK_BANK_IGNORE": "IGNORE_PRIOR"}.get(arm, arm)
                    raws[arm] = self.augmented(raws["bright"], condition, alignment, seed,
                                               "POISSON" if arm == "ACCOUNT_POISSON" else None, arm in BANK_ARMS)
            return raws[arm]

        return {arm: self.inputPlanes(raw(arm), condition) for arm in arms}

    def targetVariance(self, condition):
        """The target capture's noise variance at mid-grey green on the network's scale (normalised and
        brightened back): the training loss divides each crop's squared error by it, so that every
        condition weighs the same in the pooled training instead of the darkest dominating by 1/ratio."""
        gain = self.config.baseGain * condition.gainRatio
        p, g = condition.photonRatio, condition.gainRatio
        meanDn = _MID_GREY * self.level * self.config.baseGain * p * g
        scale = self.range * p * g
        return self.model.variance(meanDn, gain) / (scale * scale)

    def priorShare(self, condition):
        """The share of the target's noise variance already present in the darkened prior (mid-grey
        green, model variance): IGNORE_PRIOR's inputs carry (1 + share) times the target variance."""
        g0 = self.config.baseGain
        mean = _MID_GREY * self.level * g0  # DN above black of the bright capture
        brightVar = self.model.variance(mean, g0)
        if condition.blurLength > 0:
            brightVar *= float(np.sum(self.kernel(condition).astype(np.float64) ** 2))
        p, g = condition.photonRatio, condition.gainRatio
        targetVar = self.model.variance(p * g * mean, g0 * g)
        return (p * g) ** 2 * brightVar / targetVar


def _train(study, arms, replicate, trainMeans, conditions, log=None):
    """Trains one network per arm, in lockstep, on `conditions` (each crop draws one of them; all of the
    run's in the pooled design: the network one would deploy for all of the camera's exposures; one in the
    per-condition design, whose networks see that condition's inputs alone). The crops, their conditions,
    the noise seeds and the initialisation depend on the replicate only, so every arm sees the same scenes
    in the same order from the same starting weights; the augmented arms even start from the same bright
    captures."""
    config = study.config
    nets, optimisers, schedules = {}, {}, {}
    for arm in arms:
        torch.manual_seed(_seed(config.seed, _ROLE_NETWORK, replicate) & 0x7FFFFFFFFFFFFFFF)
        nets[arm] = Denoiser(config.width, config.noiseMaps, config.blindStep)
        optimisers[arm] = torch.optim.Adam(nets[arm].parameters(), lr=config.learningRate)
        schedules[arm] = torch.optim.lr_scheduler.CosineAnnealingLR(optimisers[arm], config.iterations)
    limit = (config.trainSceneSize - config.patch) // 2 + 1
    for it in range(config.iterations):
        rng = np.random.default_rng(_seed(config.seed, _ROLE_BATCH, (replicate << 24) | it))
        inputs, targets, weights = {arm: [] for arm in arms}, [], []
        for b in range(config.batch):
            condition = conditions[int(rng.integers(0, len(conditions)))]
            scene = int(rng.integers(0, len(trainMeans)))
            y0, x0 = 2 * int(rng.integers(0, limit)), 2 * int(rng.integers(0, limit))
            mean = np.ascontiguousarray(trainMeans[scene][y0:y0 + config.patch, x0:x0 + config.patch])
            sampleSeed = _seed(config.seed, _ROLE_SAMPLE, (replicate << 40) | (it << 8) | b)
            for arm, planes in study.trainingInputs(mean, condition, arms, sampleSeed).items():
                inputs[arm].append(planes)
            targets.append(study.cleanPlanes(mean, condition))
            weights.append(1.0 / study.targetVariance(condition))
        y = torch.stack(targets)
        w = torch.tensor(weights, dtype=torch.float32).view(-1, 1, 1, 1)
        for arm in arms:
            optimisers[arm].zero_grad()
            loss = torch.mean(w * (nets[arm](torch.stack(inputs[arm])) - y) ** 2)
            loss.backward()
            optimisers[arm].step()
            schedules[arm].step()
        if log is not None and (it + 1) % max(1, config.iterations // 10) == 0:
            log("  seed %d: iteration %d/%d" % (replicate, it + 1, config.iterations))
    return {arm: net.eval() for arm, net in nets.items()}


def _evaluate(net, testSet):
    """Mean PSNR and SSIM over the test set (network output clipped to [0, 1]; net None: the input), and
    the network's implicit noise estimate: the mean square of what it removed (input minus output) over
    that of the true noise (input minus clean), over the whole test set. 1 removes as much as the noise
    holds; below 1 the network takes the noise for less than it is, above 1 for more (or removes signal);
    about 0 for the input itself (only the clip to [0, 1] removes anything)."""
    psnrs, ssims, removed, noise = [], [], 0.0, 0.0
    with torch.no_grad():
        for noisy, clean in testSet:
            out = noisy[:4] if net is None else net(noisy[None])[0]
            out = out.clamp(0.0, 1.0)
            psnrs.append(psnr(out, clean))
            ssims.append(ssim(out, clean))
            removed += float(torch.sum((noisy[:4].double() - out.double()) ** 2))
            noise += float(torch.sum((noisy[:4].double() - clean.double()) ** 2))
    return float(np.mean(psnrs)), float(np.mean(ssims)), removed / noise


def _defaultThreads():
    """OMP_NUM_THREADS where it is a positive integer (the test suite sets 1, so that a study beside other
    tests does not fight them for the cores), else every core (torch's own default can be fewer: 1 of 2 on
    a 2-core virtual machine)."""
    try:
        value = int(os.environ.get("OMP_NUM_THREADS", ""))
    except ValueError:
        value = 0
    return value if value > 0 else (os.cpu_count() or 1)


def seedsNeeded(config, studies=1):
    """The fewest replicates whose exact sign-flip tests can reach SIGNIFICANCE after Holm's correction
    over the tests of `studies` studies of this configuration (each makes contrastPairs() in every
    condition): seedsForFamily() of their number; 6 when they make no test."""
    return seedsForFamily(len(contrastPairs(config.arms)) * len(config.conditions) * studies)


def runAblation(config, log=None):
    """Runs the study and returns its results as a dict (see results.json): for every condition and
    arm, the PSNR and SSIM of each replicate. `log` (a function of one string) receives progress.
    config.seeds 0 runs seedsNeeded(config)."""
    config.validate()
    if not config.seeds:
        config = dataclasses.replace(config, seeds=seedsNeeded(config))
    threads = int(config.threads) if config.threads else _defaultThreads()
    torch.set_num_threads(threads)
    torch.use_deterministic_algorithms(True)
    started = time.monotonic()
    study = _Study(config)
    trainMeans = study.scenes(_ROLE_TRAIN_SCENES, config.trainScenes, config.trainSceneSize)
    testMeans = study.scenes(_ROLE_TEST_SCENES, config.testScenes, config.testSceneSize)
    testSets = []
    for ci, condition in enumerate(config.conditions):
        testSet = []
        for i, mean in enumerate(testMeans):
            raw = study.targetCapture(mean, condition, _seed(config.seed, _ROLE_TEST_CAPTURE, (ci << 16) | i))
            testSet.append((study.inputPlanes(raw, condition), study.cleanPlanes(mean, condition)))
        testSets.append(testSet)
    scores = {arm: [{"psnr": [], "ssim": [], "removedNoiseRatio": []} for _ in config.conditions]
              for arm in config.arms}
    trained = [a for a in config.arms if a in TRAINED_ARMS]
    # The pooled design trains one set of networks per replicate on every condition; the per-condition
    # design one set per replicate and condition, each tested on its own condition only.
    groups = [list(range(len(config.conditions)))] if config.design == "pooled" else \
        [[ci] for ci in range(len(config.conditions))]
    replicates = range(config.firstReplicate, config.firstReplicate + config.seeds)
    for done, replicate in enumerate(replicates):
        for group in groups:
            if trained and len(groups) > 1 and log is not None:
                log("  seed %d: networks for %s" % (replicate, config.conditions[group[0]].name))
            nets = _train(study, trained, replicate, trainMeans, [config.conditions[ci] for ci in group], log) \
                if trained else {}
            for arm in config.arms:
                for ci in group:
                    value = _evaluate(nets.get(arm), testSets[ci])
                    for key, v in zip(("psnr", "ssim", "removedNoiseRatio"), value):
                        scores[arm][ci][key].append(v)
        if log is not None:
            for arm in config.arms:
                log("  seed %d %-17s PSNR %s dB" % (replicate, arm,
                                                    " ".join("%.2f" % s["psnr"][-1] for s in scores[arm])))
            elapsed = time.monotonic() - started
            log("[%d/%d seeds] %.0f s, about %.0f s left" % (done + 1, config.seeds, elapsed,
                                                           elapsed / (done + 1) * (config.seeds - done - 1)))
    conditions = [{"condition": dataclasses.asdict(c), "priorShare": study.priorShare(c),
                   "arms": {arm: scores[arm][ci] for arm in config.arms}} for ci, c in enumerate(config.conditions)]
    configDict = {k: v for k, v in dataclasses.asdict(config).items() if k not in ("model", "conditions")}
    m = study.model
    configDict["model"] = {"alpha": m.alpha, "sigmaD2": m.sigmaD2, "sigmaR2": m.sigmaR2}
    if m.rowSigmaD2 > 0 or m.rowSigmaR2 > 0:
        configDict["model"].update({"rowSigmaD2": m.rowSigmaD2, "rowSigmaR2": m.rowSigmaR2})
    if m.tukeyRead:
        configDict["model"]["tukeyLambda"] = m.tukeyLambda
    if m.hasDarkShading():
        configDict["model"]["darkShading"] = list(m.darkShadingPerGain.shape)
    configDict["camera"] = config.camera
    configDict["arms"] = list(config.arms)
    configDict["threads"] = threads
    return {"config": configDict, "conditions": conditions, "seconds": time.monotonic() - started,
            "torch": torch.__version__, "cpuPath": _rg.cpuPathName(_rg.activeCpuPath())}


def _parser():
    parser = argparse.ArgumentParser(
        prog="python3 -m rawgment_ablation",
        description="Trains a small RAW denoiser on darkened captures made with each noise alignment (NONE, "
                    "IGNORE_PRIOR, ACCOUNT_PRIOR), an oracle trained on captures simulated at the target, and "
                    "the noisy input as the floor; tests all on captures simulated at the target; writes "
                    "report.md, results.json, results.csv and psnr.png.",
        epilog="The default run (9 conditions x 3 trained arms, told and blind networks, 12 seeds: the fewest "
               "whose 54 tests can reach a verdict after Holm's correction) takes about 40 minutes on 2 cores; "
               "--per-condition trains as many more networks per study as there are conditions; --quick, a "
               "smoke test that learns almost nothing, about 30 s. See docs/ablation.md.")
    parser.add_argument("--model", help="the sensor's noise model: rawgment_calibrate's model.yml (with its "
                                        "dark-frame components, if any), an Android profile YAML, or darktable's "
                                        "noiseprofiles.json with --camera; default: the simulator's default "
                                        "sensor")
    parser.add_argument("--camera", help="with a darktable profile file: the camera (rawgment_cameras lists them)")
    parser.add_argument("--bit-depth", type=int, default=12, help="ADC bits of the sensor (default 12)")
    parser.add_argument("--black-level", type=float, default=256.0, help="black level in DN (default 256)")
    parser.add_argument("--base-gain-db", type=float, default=12.0,
                        help="gain of the bright captures in dB (default 12)")
    parser.add_argument("--out", default="ablation", help="output folder (default ./ablation)")
    parser.add_argument("--quick", action="store_true",
                        help="2 conditions, 2 seeds, 100 iterations of 8 crops, 4 test scenes: a check that it "
                             "all runs")
    parser.add_argument("--seeds", type=int,
                        help="training replicates (default: the fewest whose sign-flip tests can reach p <= 0.05 "
                             "after Holm's correction over the run's tests, 12 for the default run; --quick 2)")
    parser.add_argument("--seed", type=int, default=0, help="base seed of everything (default 0)")
    parser.add_argument("--first-replicate", type=int, default=0,
                        help="index of the first replicate (default 0): --first-replicate 12 --seeds 12 trains "
                             "replicates 12 to 23 of the same base seed, which --combine merges with a run of "
                             "replicates 0 to 11 into one study")
    parser.add_argument("--iterations", type=int, help="training iterations per network (default 800)")
    parser.add_argument("--arms", help="comma-separated subset of %s (default %s)"
                                       % (",".join(ARMS), ",".join(DEFAULT_ARMS)))
    parser.add_argument("--conditions",
                        help="comma-separated subset of the conditions, by name (%s); one condition alone "
                             "trains a network for that condition only" % ",".join(c.name for c in defaultConditions()))
    parser.add_argument("--threads", type=int, default=0,
                        help="torch threads (default: OMP_NUM_THREADS if set, else all cores)")
    parser.add_argument("--networks", default="told,blind",
                        help="which networks to train, comma-separated: told (a noise-level map per plane "
                             "beside the image) and blind (the image only, as the paper's detectors); "
                             "default both, each in its own subfolder with a report.md beside them that "
                             "sets them side by side; one alone writes its report into --out itself")
    parser.add_argument("--blind", action="store_true", help="the same as --networks blind")
    parser.add_argument("--designs", default="pooled",
                        help="the training designs, comma-separated: pooled (one network per arm on all the "
                             "conditions, each crop drawing its condition; default) and per-condition (one network "
                             "per arm and condition, trained on that condition alone); each study is a network and "
                             "a design, written into its own subfolder when there are several")
    parser.add_argument("--combine", nargs="+", metavar="STUDY",
                        help="train nothing: write --out/report.md setting side by side the studies of earlier runs "
                             "(their folders, each with its results.json), Holm-corrected over all their tests "
                             "together")
    parser.add_argument("--per-condition", action="store_true",
                        help="the same as --designs pooled,per-condition: per-condition networks beside the pooled "
                             "ones, the report setting both side by side")
    parser.add_argument("--shot-sampling", default="GAUSSIAN", type=str.upper,
                        help="the augmented arms' shot noise: GAUSSIAN (the paper's, default) or POISSON")
    parser.add_argument("--prior-mean", default="PIXEL_VALUE", type=str.upper,
                        help="the augmented arms' estimate of the prior's level: PIXEL_VALUE (the paper's, "
                             "default) or LOCAL_MEAN")
    parser.add_argument("--departing-sensor", action="store_true",
                        help="simulate a sensor that departs from the model's components (hot, noisy pixels, "
                             "column banding, DSNU; row noise and heavy tails where the model has none): what the "
                             "arms DARK_BANK and DARK_BANK_IGNORE are about")
    parser.add_argument("--blind-step", type=float, default=BLIND_STEP,
                        help="the blind network's residual unit, a fraction of white - black (default 0.02)")
    return parser


#: What writeOutputs() writes into its folder.
OUTPUT_FILES = ("results.json", "results.csv", "psnr.png", "report.md")


def _outputConflicts(outDir, studies):
    """Why the outputs could not be written into outDir (None when they can), checked before any training:
    the files are never replaced, so a previous run's would make the whole run fail at its end. `studies`:
    the studies' folder names (studyName())."""
    if os.path.lexists(outDir) and not os.path.isdir(outDir):
        return "--out '%s' exists and is not a folder" % outDir
    folders = [outDir] if len(studies) == 1 else [os.path.join(outDir, n) for n in studies]
    paths = [os.path.join(f, name) for f in folders for name in OUTPUT_FILES]
    if len(studies) > 1:
        paths += [os.path.join(outDir, "report.md")]
        paths = [p for p in paths if not os.path.isdir(p)]
        for f in folders:
            if os.path.lexists(f) and not os.path.isdir(f):
                return "'%s' exists and is not a folder" % f
    existing = [p for p in paths if os.path.lexists(p)]
    if existing:
        return ("--out '%s' holds a previous run's %s; outputs are never replaced: choose another --out or "
                "remove them" % (outDir, ", ".join("'%s'" % p for p in existing)))
    parent = os.path.dirname(os.path.abspath(outDir))
    while not os.path.exists(parent):
        parent = os.path.dirname(parent)
    if not os.path.isdir(parent) or not os.access(parent, os.W_OK | os.X_OK):
        return "--out '%s' cannot be created: '%s' is not a writable folder" % (outDir, parent)
    return None


def _argumentErrors(args):
    """The numeric options' errors, each naming its option (argparse checks only that they are numbers)."""
    errors = []
    if not 0 <= args.seed < 2 ** 64:
        errors.append("--seed must be in [0, 2^64), got %d" % args.seed)
    if not 0 <= args.first_replicate < 1 << 16:
        errors.append("--first-replicate must be in [0, 65536), got %d" % args.first_replicate)
    if args.threads < 0:
        errors.append("--threads must be >= 0 (0: all cores), got %d" % args.threads)
    if not math.isfinite(args.base_gain_db):
        errors.append("--base-gain-db must be finite, got %r" % args.base_gain_db)
    if not 1 <= args.bit_depth <= 16:
        errors.append("--bit-depth must be in [1, 16], got %d" % args.bit_depth)
    if not math.isfinite(args.black_level) or args.black_level < 0:
        errors.append("--black-level must be finite and >= 0, got %r" % args.black_level)
    if not math.isfinite(args.blind_step):
        errors.append("--blind-step must be finite, got %r" % args.blind_step)
    for name in ("seeds", "iterations"):  # argparse's None: the default
        value = getattr(args, name)
        if value is not None and value < 1:
            errors.append("--%s must be >= 1, got %d" % (name, value))
    return errors


def main(argv=None):
    parser = _parser()
    args = parser.parse_args(argv)
    errors = _argumentErrors(args)
    if errors:
        for e in errors:
            print("rawgment_ablation: %s" % e, file=sys.stderr)
        return 2
    if args.combine:
        unused = ["--" + a.dest.replace("_", "-") for a in parser._actions
                  if a.dest not in ("help", "combine", "out") and getattr(args, a.dest) != a.default]
        if unused:
            print("rawgment_ablation: --combine trains nothing, so %s would be ignored" % ", ".join(unused),
                  file=sys.stderr)
            return 2
        try:
            print(writeCombinedReport(args.combine, args.out))
        except ValueError as e:
            print("rawgment_ablation: %s" % e, file=sys.stderr)
            return 2
        return 0
    config = AblationConfig()
    if args.quick:
        config.conditions = quickConditions()
        config.seeds, config.iterations, config.batch, config.testScenes, config.trainScenes = 2, 100, 8, 4, 12
    config.bitDepth, config.blackLevel = args.bit_depth, args.black_level
    if args.model is not None:
        if not os.path.isfile(args.model):
            print("rawgment_ablation: --model '%s' is not a file" % args.model, file=sys.stderr)
            return 2
        # A darktable camera's and an Android profile's model is made at the study's levels.
        fmt = _rg.RawFormat(blackLevel=(float(args.black_level),) * 4, whiteLevel=2 ** int(args.bit_depth) - 1)
        try:
            config.model = _rg.loadAnyNoiseModel(args.model, args.camera or "", fmt)
        except _rg.error as e:
            print("rawgment_ablation: %s" % e, file=sys.stderr)
            return 2
        config.camera = args.camera or ""
    elif args.camera is not None:
        print("rawgment_ablation: --camera needs --model (a darktable profile file)", file=sys.stderr)
        return 2
    config.baseGain = _rg.dbToLinearGain(args.base_gain_db)
    config.seed, config.threads, config.firstReplicate = args.seed, args.threads, args.first_replicate
    networks = ["blind"] if args.blind else [n.strip() for n in args.networks.split(",") if n.strip()]
    if not networks or any(n not in NETWORKS for n in networks) or len(set(networks)) != len(networks):
        print("rawgment_ablation: --networks must be told, blind or told,blind, got '%s'" % args.networks,
              file=sys.stderr)
        return 2
    designs = ["pooled", "per-condition"] if args.per_condition else \
        [d.strip() for d in args.designs.split(",") if d.strip()]
    if not designs or any(d not in DESIGNS for d in designs) or len(set(designs)) != len(designs):
        print("rawgment_ablation: --designs must be pooled, per-condition or pooled,per-condition, got '%s'"
              % args.designs, file=sys.stderr)
        return 2
    config.blindStep = args.blind_step
    config.departingSensor = args.departing_sensor
    config.shotSampling, config.priorMean = args.shot_sampling, args.prior_mean
    if args.seeds is not None:
        config.seeds = args.seeds
    if args.iterations is not None:
        config.iterations = args.iterations
    if args.arms is not None:
        config.arms = tuple(a.strip() for a in args.arms.split(",") if a.strip())
    if args.conditions is not None:
        known = {c.name: c for c in defaultConditions()}
        names = [n.strip() for n in args.conditions.split(",") if n.strip()]
        unknown = [n for n in names if n not in known]
        if unknown:
            print("rawgment_ablation: unknown condition(s) %s; the conditions are %s"
                  % (", ".join(unknown), ", ".join(known)), file=sys.stderr)
            return 2
        config.conditions = [known[n] for n in names]
    try:
        config.validate()
    except (ValueError, _rg.error) as e:
        print("rawgment_ablation: %s" % e, file=sys.stderr)
        return 2
    studies = [(n, d) for n in networks for d in designs]
    if not config.seeds:
        config.seeds = seedsNeeded(config, len(studies))
    conflict = _outputConflicts(args.out, [studyName(n, d) for n, d in studies])
    if conflict is not None:
        print("rawgment_ablation: %s" % conflict, file=sys.stderr)
        return 2

    def log(line):
        print(line, file=sys.stderr, flush=True)

    byStudy = {}
    for network, design in studies:
        if len(studies) > 1:
            log("rawgment_ablation: %s networks, %s design" % (network, design))
        byStudy[studyName(network, design)] = runAblation(
            dataclasses.replace(config, noiseMaps=network == "told", design=design), log)
    if len(studies) == 1:
        written, notes = writeOutputs(next(iter(byStudy.values())), args.out)
    else:
        written, notes = writeStudiesOutputs(byStudy, args.out)
    for note in notes:
        log("rawgment_ablation: " + note)
    for path in written:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
