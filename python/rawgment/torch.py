"""PyTorch integration: random noise-accounted scenes as a transform, and a dataset of RAW files.

Seeds derive from (base seed, epoch, sample index) only, so a ``DataLoader`` gives the same samples
for any ``num_workers`` and any order in which workers take samples::

    dataset = rawgment.torch.RawFolderDataset("raws/", model="camera.yml", baseSeed=7)
    loader = torch.utils.data.DataLoader(dataset, batch_size=4, num_workers=2, persistent_workers=True)
    for epoch in range(10):
        dataset.set_epoch(epoch)   # before iterating: the epoch is shared with the loader's workers
        for batch in loader:
            ...

Importing this module needs torch; importing ``rawgment`` does not.
"""
import collections
import os
import time

import numpy as np
import torch

import rawgment as _rg
from rawgment.batch import RAW_EXTENSIONS

__all__ = ["sampleSeed", "Augmented", "RandomNoiseScene", "RawFolderDataset", "packCfaPlanes", "loadMosaic"]

#: Extensions of the mosaics readMosaic() reads beside their sidecar: the library's table (mosaicContainers()).
MOSAIC_EXTENSIONS = tuple(e for c in _rg.mosaicContainers() if c.readsMosaic and not c.cameraRaw for e in c.extensions)

Augmented = collections.namedtuple("Augmented", ["raw", "format", "boxes", "report", "scene", "camera"],
                                   defaults=(None,))
Augmented.__doc__ = """What RandomNoiseScene returns: the augmented mosaic (the input's kind: tensor or
array), its RawFormat (the new gain), the boxes (the input's kind), the AugmentReport, the Scene, and the
name of the real camera whose noise it took (None when the model is not a real camera's)."""


def sampleSeed(baseSeed, epoch, index):
    """The seed of sample `index` in `epoch`: deriveSeed(deriveSeed(baseSeed, SEED_TRAINING_EPOCH, epoch),
    SEED_TRAINING_SAMPLE, index). A pure function, the same in every process."""
    if epoch < 0 or index < 0:
        raise ValueError("epoch and index must be >= 0, got epoch=%r, index=%r" % (epoch, index))
    epochSeed = _rg.deriveSeed(int(baseSeed), _rg.SEED_TRAINING_EPOCH, int(epoch))
    return _rg.deriveSeed(epochSeed, _rg.SEED_TRAINING_SAMPLE, int(index))


def _loaded(value, cls, what, default=None):
    """`value` if it is a `cls`, else the `cls` saved at that path; None gives `default`."""
    if value is None and default is not None:
        return default
    if isinstance(value, cls):
        return value
    if isinstance(value, (str, os.PathLike)):
        return cls.load(os.fspath(value))
    raise TypeError("%s must be a rawgment.%s or the path of a saved one%s, not %s" % (
        what, cls.__name__, ", or None" if default is not None else "", type(value).__name__))


def _toArray(raw):
    """A numpy view of a mosaic given as a tensor (CPU, float32, 2-D) or an array (uint16 or float32)."""
    if isinstance(raw, torch.Tensor):
        if raw.device.type != "cpu":
            raise ValueError("argument 'raw' must be a CPU tensor, got one on %s" % raw.device)
        if raw.dtype != torch.float32:
            raise TypeError("argument 'raw' has dtype %s; a tensor mosaic must be torch.float32 (DN with "
                            "black, as stored)" % raw.dtype)
        return raw.detach().numpy(), True
    if isinstance(raw, np.ndarray):
        return raw, False
    raise TypeError("argument 'raw' must be a torch.Tensor or a numpy array, not %s" % type(raw).__name__)


class _ModelSource:
    """Where each sample's NoiseModel comes from: one model, an Android profile (per mosaic format), or
    real cameras (one drawn per sample from its seed, at the mosaic's format)."""

    def __init__(self, model, camera):
        self.model = self.android = None
        self.cameras = []
        if isinstance(model, _rg.NoiseModel):
            if camera is not None:
                raise ValueError("camera chooses among the cameras of a darktable profile file; model is a NoiseModel")
            self.model = model
            return
        if isinstance(model, (list, tuple)) and model and all(isinstance(c, _rg.CameraNoiseProfile) for c in model):
            if camera is not None:
                raise ValueError("camera is for a darktable profile file; model is already a list of cameras")
            for c in model:
                if not c.usable():
                    raise ValueError("camera '%s' is REFUSED: %s" % (c.name(), c.reason))
            self.cameras = list(model)
            return
        if not isinstance(model, (str, os.PathLike)):
            raise TypeError("model must be a rawgment.NoiseModel, a list of rawgment.CameraNoiseProfile or the path "
                            "of a model file, not %s" % type(model).__name__)
        path = os.fspath(model)
        kind = _rg.noiseModelFileKind(path)
        if kind == _rg.DARKTABLE_PROFILE_FILE:
            if camera is None:
                raise ValueError("'%s' is a darktable noise-profile file of many cameras: choose with camera= (a "
                                 "name, a list of names, 'good' or 'usable')" % path)
            catalogue = _rg.readCameraProfiles(path)
            # Each name of a list on its own: a camera's name may hold a comma.
            selections = [camera] if isinstance(camera, str) else list(camera)
            if not selections:
                raise ValueError("camera= is an empty list: name at least one camera, 'good' or 'usable'")
            self.cameras = [c for one in selections for c in _rg.selectCameraProfiles(catalogue, one)]
        elif camera is not None:
            raise ValueError("camera chooses among the cameras of a darktable profile file, and '%s' is not one" % path)
        elif kind == _rg.ANDROID_PROFILE_FILE:
            # An Android profile's model depends on each mosaic's levels: it is made per format (and checked
            # now, at a format of full range).
            _rg.noiseModelFromAndroidFile(path, _rg.RawFormat())
            self.android = path
        else:
            self.model = _rg.NoiseModel.load(path)

    def at(self, format, seed):
        """The model of one sample, and its camera's name (None for a model that is not a camera's)."""
        if self.model is not None:
            return self.model, None
        if self.android is not None:
            return _rg.noiseModelFromAndroidFile(self.android, format), None
        camera = self.cameras[_rg.drawCameraIndex(len(self.cameras), seed)]
        return camera.modelFor(format), camera.name()

    def __repr__(self):
        if self.model is not None:
            return repr(self.model)
        if self.android is not None:
            return repr(self.android)
        return "[%s]" % ", ".join(repr(c.name()) for c in self.cameras)


class RandomNoiseScene:
    """A transform that applies a random noise-accounted scene (RandomScenePolicy.draw, then
    applyScene) to a RAW mosaic: darker, noisier, blurred, shifted, with the noise the sensor would
    have given. Boxes follow the shift and the scale.

    Args:
        model: the camera's NoiseModel; the path of a NoiseModel file, an Android profile YAML or a darktable
            noise-profile file (``rawgment.darktableProfilesPath()``, with ``camera``); or a list of
            rawgment.CameraNoiseProfile.
        policy: a RandomScenePolicy, the path of a saved one, or None for the paper's defaults.
        baseSeed: the seed of the whole run; each sample's seed is sampleSeed(baseSeed, epoch, index).
        camera: with a darktable file, a camera name, a list of names, or "good" / "usable" (every camera of
            that verdict). With several cameras (here or in a list given as ``model``), each sample draws one
            from its seed (rawgment.drawCameraIndex), so a network sees the noise of many real sensors; the
            camera's model is scaled to each mosaic's black and white levels.
    """

    def __init__(self, model, policy=None, baseSeed=0, camera=None):
        self._models = _ModelSource(model, camera)
        self.policy = _loaded(policy, _rg.RandomScenePolicy, "policy", _rg.RandomScenePolicy())
        self.policy.validate()
        self.baseSeed = int(baseSeed)

    @property
    def model(self):
        """The one NoiseModel of every sample, or None when each sample's depends on its camera or format."""
        return self._models.model

    @property
    def cameras(self):
        """The real cameras samples draw from (empty when the model is not a real camera's)."""
        return list(self._models.cameras)

    def __call__(self, raw, format, boxes=None, *, index, epoch=0, iso=0.0):
        """Augments one mosaic.

        Args:
            raw: HxW mosaic with its black level: a float32 CPU tensor, or a uint16/float32 array.
            format: its rawgment.RawFormat.
            iso: the ISO the capture was taken at when it sets the gain (loadMosaic's third value; 0: the
                format's gain stands). The sample's format then has gain iso / baseIso of the sample's model
                (rawgment.formatAtIso), as rawgment_augment takes a camera file.
            boxes: None, a sequence of (x, y, w, h), an N x 4 array or an N x 4 tensor (mosaic pixels).
            index: the sample's index in the dataset; epoch: the epoch (both set the seed).

        Returns:
            Augmented(raw, format, boxes, report, scene), raw and boxes of the kind given.
        """
        array, isTensor = _toArray(raw)
        seed = sampleSeed(self.baseSeed, epoch, index)
        boxesIn = boxes
        if isinstance(boxes, torch.Tensor):
            boxesIn = boxes.detach().cpu().numpy().astype(np.int64).reshape(-1, 4)
        model, camera = self._models.at(format, seed)
        format = _rg.formatAtIso(format, iso, model)
        scene = self.policy.draw(array, format, seed)
        out, outFormat, report, outBoxes = _rg.applyScene(array, format, model, scene, seed=seed, boxes=boxesIn)
        if isTensor:
            out = torch.from_numpy(out)
        if isinstance(boxes, torch.Tensor):
            outBoxes = torch.tensor(outBoxes, dtype=boxes.dtype).reshape(-1, 4)
        elif isinstance(boxes, np.ndarray):
            outBoxes = np.asarray(outBoxes, dtype=boxes.dtype).reshape(-1, 4)
        elif boxes is None:
            outBoxes = None
        return Augmented(out, outFormat, outBoxes, report, scene, camera)

    def __repr__(self):
        return "RandomNoiseScene(model=%r, policy=%r, baseSeed=%d)" % (self._models, self.policy, self.baseSeed)


def packCfaPlanes(signal, format):
    """A 4 x H/2 x W/2 float32 tensor of the CFA planes of a black-subtracted mosaic, in the order
    R, G1, G2, B (whatever the pattern): the input layout of most RAW networks. A monochrome frame
    (CFA_MONO) is packed in site order, as rawgment.packCfaPlanes does."""
    planes = _rg.splitCfaPlanes(np.ascontiguousarray(signal, dtype=np.float32))
    if format.pattern == _rg.CFA_MONO:
        order = [0, 1, 2, 3]
    else:
        order = [_rg.cfaSiteOfChannel(format.pattern, c) for c in (_rg.CFA_R, _rg.CFA_G1, _rg.CFA_G2, _rg.CFA_B)]
    return torch.from_numpy(np.stack([planes[s] for s in order]))


def _tensorOf(mosaic, fmt, pack, normalize):
    """The sample's tensor in one pass over the mosaic, written into the tensor's own memory: black
    subtraction, normalisation and (with pack) the CFA planes together."""
    if pack:
        rows, cols = mosaic.shape
        if rows % 2 or cols % 2:
            raise ValueError("RawFolderDataset: pack=True needs even sides; the mosaic is %dx%d" % (cols, rows))
        planes = torch.empty((4, rows // 2, cols // 2), dtype=torch.float32)
        _rg.packCfaPlanes(mosaic, fmt, normalize=normalize, out=planes.numpy())
        return planes
    return torch.from_numpy(_rg.subtractBlackLevel(mosaic, fmt, normalize=normalize)).unsqueeze(0)


def loadMosaic(path):
    """(mosaic, format, iso) of a camera RAW file (readRaw) or of a mosaic with a sidecar (readMosaic).

    ``iso`` is the ISO that sets the capture's gain for a noise model (a camera file's, or a converted one's
    whose sidecar says gainFromIso), 0 when the format's own gain stands: give it to RandomNoiseScene, which
    turns it into the gain of each sample's model (rawgment.formatAtIso)."""
    path = os.fspath(path)
    if os.path.exists(_rg.sidecarPathOf(path)):
        mosaic, meta = _rg.readMosaic(path)
        return mosaic, meta.format, meta.camera.iso if meta.gainFromIso else 0.0
    image = _rg.readRaw(path)
    return image.mosaic, image.format, image.iso


class RawFolderDataset(torch.utils.data.Dataset):
    """The RAW files of a folder (camera RAWs that LibRaw reads, or mosaics with a .yml sidecar), each
    augmented by RandomNoiseScene.

    Each item is a dict: ``raw`` (float32 tensor: 1 x H x W of the mosaic, or 4 x H/2 x W/2 CFA planes
    with ``pack=True``; black-subtracted and divided by white - black, so 1 is saturation, unless
    ``normalize=False``, which keeps DN above black), ``gain`` (the output's linear gain, float), ``index``,
    ``path`` and ``camera`` (the real camera whose noise the sample took, "" for none).

    Args:
        folder: the folder (files sorted by name; sub-folders are not read).
        model, policy, baseSeed, camera: as RandomNoiseScene.
        pack: return the four CFA planes instead of the mosaic.
        normalize: divide by the per-site range white - black.
        augment: False returns the files as they are (for validation sets).
        crop: None, or (height, width), both even: a random crop of each file per sample (its own draw from
            the sample's seed, at even offsets), taken before the augmentation with its place on the sensor
            (RawFormat.cropped sets sensorOrigin), so that a model's dark shading is read at the crop's own
            pixels. A file smaller than the crop is an error naming it.
        timings: record where each item's time went, in this process: a dict per item appended to the list
            ``timings``, in seconds: ``read`` (reading and decoding the file), one key per augmentation step
            that ran (AugmentReport.stepSeconds: ``shift``, ``scale``, ``colorJitter``, ``motionBlur``),
            ``tensor`` (black subtraction, normalisation and packing in one pass), ``other`` (the rest: the
            scene's draw, the crop, Python) and ``total``. python/bench/pipeline.py reports them.
    """

    def __init__(self, folder, model, policy=None, baseSeed=0, pack=False, normalize=True, augment=True,
                 crop=None, camera=None, timings=False):
        if crop is not None:
            if len(crop) != 2 or any(int(v) != v or v <= 0 or int(v) % 2 for v in crop):
                raise ValueError("RawFolderDataset: crop must be (height, width), both even and > 0, not %r"
                                 % (crop,))
            crop = (int(crop[0]), int(crop[1]))
        self.crop = crop
        folder = os.fspath(folder)
        if not os.path.isdir(folder):
            raise FileNotFoundError("RawFolderDataset: '%s' is not a folder" % folder)
        files = []
        for name in sorted(os.listdir(folder)):
            path = os.path.join(folder, name)
            ext = os.path.splitext(name)[1].lower()
            if not os.path.isfile(path):
                continue
            if ext in RAW_EXTENSIONS or (ext in MOSAIC_EXTENSIONS and os.path.exists(_rg.sidecarPathOf(path))):
                files.append(path)
        if not files:
            raise FileNotFoundError("RawFolderDataset: no RAW file (%s) and no mosaic with a sidecar in '%s'" %
                                    (", ".join(RAW_EXTENSIONS[:5]) + ", ...", folder))
        self.files = files
        self.transform = RandomNoiseScene(model, policy, baseSeed, camera=camera)
        self.pack = bool(pack)
        self.normalize = bool(normalize)
        self.augment = bool(augment)
        self.timings = [] if timings else None
        # In shared memory: a DataLoader's workers hold copies of the dataset, and persistent workers keep
        # theirs across epochs; a plain attribute set after they started never reached them, and they
        # repeated epoch 0's augmentations.
        self._epoch = torch.zeros(1, dtype=torch.int64).share_memory_()

    @property
    def epoch(self):
        """The epoch whose seeds samples use (set_epoch() sets it, in every worker too)."""
        return int(self._epoch[0])

    def set_epoch(self, epoch):
        """Sets the epoch whose seeds the next iteration uses, in this process and in a DataLoader's
        workers, persistent or not (call it before iterating over the loader for that epoch)."""
        if not 0 <= int(epoch) < 2 ** 63:
            raise ValueError("epoch must be in [0, 2^63), got %r" % epoch)
        self._epoch[0] = int(epoch)

    def __len__(self):
        return len(self.files)

    def _cropped(self, mosaic, fmt, index):
        """The sample's crop of `mosaic` (a view) and its format, placed on the sensor."""
        h, w = self.crop
        rows, cols = mosaic.shape
        if h > rows or w > cols:
            raise ValueError("RawFolderDataset: '%s' is %dx%d, smaller than the crop %dx%d (width x height)" %
                             (self.files[index], cols, rows, w, h))
        seed = sampleSeed(self.transform.baseSeed, self.epoch, index)
        draw = np.random.default_rng([seed & 0xFFFFFFFF, seed >> 32, 0x63726F70])  # "crop": not the scene's
        y = 2 * int(draw.integers(0, (rows - h) // 2 + 1))
        x = 2 * int(draw.integers(0, (cols - w) // 2 + 1))
        return mosaic[y:y + h, x:x + w], fmt.cropped(y, x)

    def __getitem__(self, index):
        if not 0 <= index < len(self.files):
            raise IndexError("RawFolderDataset index %d out of range (%d files)" % (index, len(self.files)))
        if torch.utils.data.get_worker_info() is not None and _rg.getNumThreads() > 1:
            # A worker process is one of several running samples in parallel: OpenCV's own threads
            # would only oversubscribe the cores (the samples are the same on any thread count).
            _rg.setNumThreads(1)
        start = time.perf_counter()
        mosaic, fmt, iso = loadMosaic(self.files[index])
        read = time.perf_counter()
        if self.crop is not None:
            mosaic, fmt = self._cropped(mosaic, fmt, index)
        camera = ""
        steps = {}
        if self.augment:
            result = self.transform(mosaic, fmt, index=index, epoch=self.epoch, iso=iso)
            mosaic, fmt, camera = result.raw, result.format, result.camera or ""
            for name, seconds in zip(result.report.steps, result.report.stepSeconds):
                steps[name] = steps.get(name, 0.0) + seconds
        elif iso:
            # The item's gain is the file's whatever the augmentation (#79 item 29): an ISO-1600 capture is
            # at gain 16 of a base-ISO-100 model whether or not noise was added.
            model, _ = self.transform._models.at(fmt, sampleSeed(self.transform.baseSeed, self.epoch, index))
            fmt = _rg.formatAtIso(fmt, iso, model)
        beforeTensor = time.perf_counter()
        raw = _tensorOf(mosaic, fmt, self.pack, self.normalize)
        if self.timings is not None:
            end = time.perf_counter()
            record = dict(steps, read=read - start, tensor=end - beforeTensor, total=end - start)
            record["other"] = record["total"] - record["read"] - record["tensor"] - sum(steps.values())
            self.timings.append(record)
        return {"raw": raw, "gain": float(fmt.gain), "index": int(index), "path": self.files[index], "camera": camera}
