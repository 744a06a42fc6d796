"""The ablation study's configuration: its test conditions, its settings and the sensor it simulates
(rawgment_ablation.study re-exports every name; import them from there)."""
import copy
import dataclasses

import rawgment as _rg
from rawgment_ablation.common import ARMS, BLIND_STEP, DEFAULT_ARMS, DESIGNS


@dataclasses.dataclass(frozen=True)
class Condition:
    """One test condition: the photon ratio of the target to the bright capture, its gain ratio, and
    an optional linear motion blur (length in CFA-plane pixels, angle in degrees; 0 = no blur)."""
    name: str
    photonRatio: float
    gainRatio: float = 1.0
    blurLength: float = 0.0
    blurAngle: float = 0.0


def defaultConditions():
    """Photon ratios 0.5, 0.2, 0.05, 0.01 at the bright gain and with the gain raised to keep the
    brightness (by 1/ratio, at most 4x = +12 dB), and a motion blur of 9 plane pixels at 30 degrees at
    ratio 0.2."""
    conditions = []
    for ratio in (0.5, 0.2, 0.05, 0.01):
        conditions.append(Condition("x%g" % ratio, ratio))
        conditions.append(Condition("x%g +%gdB" % (ratio, round(_rg.linearGainToDb(min(4.0, 1.0 / ratio)))),
                                    ratio, min(4.0, 1.0 / ratio)))
    conditions.append(Condition("x0.2 blur9", 0.2, 1.0, 9.0, 30.0))
    return conditions


def quickConditions():
    """The --quick run's two conditions: a moderate darkening and a very dark one with a gain change."""
    return [Condition("x0.2", 0.2), Condition("x0.01 +12dB", 0.01, 4.0)]


def departingSensorParams(params):
    """The sensor with what the parametric components do not describe, as the dark-frame bank's study has it
    (docs/dark_frame_bank.md): 0.2% hot and 1% noisy pixels (100 DN^2 more), column banding of 2 DN^2, a
    dark-signal non-uniformity of 2 DN; and, where the model has none, row noise (0.1 DN^2 before the gain,
    0.5 after) and Tukey lambda -0.1 tails, which the model given to the augmentation then holds."""
    noise = copy.deepcopy(params.noise)
    if not noise.hasRowNoise():
        noise.rowSigmaD2, noise.rowSigmaR2 = 0.1, 0.5
    if not noise.tukeyRead:
        noise.tukeyRead, noise.tukeyLambda = True, -0.1
    params.noise = noise
    params.hotPixelFraction, params.noisyPixelFraction, params.noisyPixelVariance = 0.002, 0.01, 100.0
    params.columnNoiseVariance, params.dsnu = 2.0, 2.0
    return params


@dataclasses.dataclass
class AblationConfig:
    """Everything that sets the numbers of a run (all of it is written to results.json)."""
    model: object = None            # rawgment.NoiseModel of the sensor (effective: quantisation included)
    bitDepth: int = 12
    blackLevel: float = 256.0
    # Linear gain of the bright captures: +12 dB. At unit gain the default sensor's bright captures are
    # so clean that the mildest darkening still leaves a 46 dB input, where no arm differs; at +12 dB the
    # bright captures' own noise is a visible share of the target's, which is what the arms disagree on.
    baseGain: float = 10.0 ** (12.0 / 20.0)
    conditions: list = dataclasses.field(default_factory=defaultConditions)
    arms: tuple = DEFAULT_ARMS
    # Training replicates (network initialisation and data order); 0: the fewest whose tests can reach a
    # verdict after Holm's correction over the study's tests (seedsNeeded()).
    seeds: int = 0
    # The index of the first replicate: a run with firstReplicate = n trains replicates n, n+1, ... of the
    # same base seed (the same scenes and test captures), so that a study can be extended with more seeds
    # and the runs merged (--combine).
    firstReplicate: int = 0
    seed: int = 0                   # the base seed of everything
    iterations: int = 800
    batch: int = 16
    patch: int = 64                 # training crop, mosaic pixels (even)
    trainScenes: int = 24
    trainSceneSize: int = 192
    testScenes: int = 8
    testSceneSize: int = 256
    width: int = 16                 # channels of the network's first level
    # Whether the network is told the noise level (a noise map per plane, as the default denoiser) or is
    # blind, seeing only the image, as the paper's detectors do (--blind).
    noiseMaps: bool = True
    # The training design (DESIGNS): "pooled", one network per arm on all conditions, or "per-condition",
    # one per arm and condition (--per-condition runs both).
    design: str = "pooled"
    # The blind network's residual unit (Denoiser.blindScale): a design choice, so a run can vary it to
    # see whether a verdict depends on it.
    blindStep: float = BLIND_STEP
    # How the augmented arms draw their added noise (NoiseOptions): the library's defaults, or the exact
    # Poisson shape of the shot part and the local mean as the prior's level, to see what a result owes
    # to either.
    shotSampling: str = "GAUSSIAN"
    priorMean: str = "PIXEL_VALUE"
    learningRate: float = 2e-3
    threads: int = 0                # torch threads (0: OMP_NUM_THREADS if set, else every core)
    camera: str = ""                # the real camera of a darktable profile file the model came from
    # A sensor that departs from the model's parametric components (departingSensorParams()): what the
    # dark-frame bank's arms are about.
    departingSensor: bool = False
    # Dark captures per gain in the bank arms' bank (a group needs two; docs/dark_frame_bank.md: 25).
    bankFrames: int = 25

    def sensorParams(self, size=None):
        """The simulator's parameters: the model without the rounding's 1/12 DN^2, which the simulator
        adds back by quantising (so effectiveModel() is the model given), with every dark-frame component
        of the model (row noise, heavy-tailed read noise, dark shading). The shading maps are the sensor's:
        a simulator of `size` (height and width, the study's square crops) takes their top-left corner,
        where the augmentation reads them too (sensorOrigin 0); without `size`, the whole maps."""
        if self.model is None:
            params = _rg.SensorParams(bitDepth=int(self.bitDepth), blackLevel=(float(self.blackLevel),) * 4,
                                      quantize=True)
            return departingSensorParams(params) if self.departingSensor else params
        noise = copy.deepcopy(self.model)
        noise.sigmaR2 = max(self.model.sigmaR2 - 1.0 / 12.0, 0.0)
        if size is not None and noise.hasDarkShading():
            rows, cols = noise.darkShadingPerGain.shape
            if size > rows or size > cols:
                raise ValueError("the model's dark shading is %dx%d, smaller than the study's %dx%d captures"
                                 % (cols, rows, size, size))
            noise.darkShadingPerGain = noise.darkShadingPerGain[:size, :size]
            noise.darkShadingOffset = noise.darkShadingOffset[:size, :size]
        params = _rg.SensorParams(noise=noise, bitDepth=int(self.bitDepth),
                                  blackLevel=(float(self.blackLevel),) * 4, quantize=True)
        return departingSensorParams(params) if self.departingSensor else params

    def validate(self):
        if not self.conditions:
            raise ValueError("no condition to run")
        for c in self.conditions:
            if not (0.0 < c.photonRatio <= 1.0) or not (c.gainRatio >= 1.0) or c.blurLength < 0:
                raise ValueError("condition %r: photonRatio must be in (0, 1], gainRatio >= 1, blurLength >= 0"
                                 % (c,))
        unknown = [a for a in self.arms if a not in ARMS]
        if unknown or not self.arms:
            raise ValueError("unknown arm(s) %s; the arms are %s" % (", ".join(unknown), ", ".join(ARMS)))
        if not 0 <= int(self.firstReplicate) < 1 << 16:
            raise ValueError("firstReplicate must be in [0, 65536), got %r" % self.firstReplicate)
        if int(self.bankFrames) < 2:
            raise ValueError("bankFrames must be >= 2 (a bank's group needs two frames), got %r" % self.bankFrames)
        if int(self.seeds) < 0:
            raise ValueError("seeds must be >= 1 (or 0: as many as the study's tests need), got %r" % self.seeds)
        for name in ("iterations", "batch", "trainScenes", "testScenes", "width"):
            if int(getattr(self, name)) < 1:
                raise ValueError("%s must be >= 1, got %r" % (name, getattr(self, name)))
        for name in ("patch", "trainSceneSize", "testSceneSize"):
            value = int(getattr(self, name))
            # Even for the CFA, and a multiple of 4 so the network's half-resolution level fits.
            if value < 16 or value % 4:
                raise ValueError("%s must be a multiple of 4 and >= 16, got %r" % (name, value))
        if self.patch > self.trainSceneSize:
            raise ValueError("patch (%d) is larger than trainSceneSize (%d)" % (self.patch, self.trainSceneSize))
        if self.baseGain <= 0 or not (self.learningRate > 0) or not (0 < self.blindStep <= 1):
            raise ValueError("baseGain and learningRate must be > 0, blindStep in (0, 1]")
        if self.design not in DESIGNS:
            raise ValueError("design must be one of %s, got %r" % (", ".join(DESIGNS), self.design))
        if self.shotSampling not in ("GAUSSIAN", "POISSON") or self.priorMean not in ("PIXEL_VALUE", "LOCAL_MEAN"):
            raise ValueError("shotSampling must be GAUSSIAN or POISSON and priorMean PIXEL_VALUE or LOCAL_MEAN, "
                             "got %r and %r" % (self.shotSampling, self.priorMean))
        for size in (16, self.patch, self.trainSceneSize, self.testSceneSize):
            self.sensorParams(int(size)).validate()
