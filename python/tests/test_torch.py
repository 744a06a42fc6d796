"""rawgment.torch: the transform on tensors and arrays (boxes follow), and a DataLoader over a folder
that gives the same samples with 0 and 2 workers."""
import os
import subprocess

import numpy as np
import pytest
import torch

import rawgment as rg
import rawgment.torch as rgt
from conftest import env_path


@pytest.fixture(scope="module")
def folder(tmp_path_factory, sensor):
    """Six small DNGs of the simulated chart, as a camera would give them."""
    from conftest import chart_mean

    path = tmp_path_factory.mktemp("raws")
    _, mean = chart_mean()
    for i in range(6):
        raw = sensor.capture(mean, 1.0, 1.0 + 0.2 * i, seed=40 + i)
        rg.writeDng(str(path / ("frame_%02d.dng" % i)), rg.RawImage(mosaic=raw, format=sensor.rawFormat(1.0)))
    (path / "notes.txt").write_text("not a raw file")
    return path


def test_seeds_depend_on_base_epoch_and_index_only():
    assert rgt.sampleSeed(7, 2, 5) == rgt.sampleSeed(7, 2, 5)
    seeds = {rgt.sampleSeed(7, e, i) for e in range(3) for i in range(100)}
    assert len(seeds) == 300
    assert rgt.sampleSeed(7, 0, 0) != rgt.sampleSeed(8, 0, 0)
    with pytest.raises(ValueError):
        rgt.sampleSeed(7, -1, 0)


def test_transform_gives_the_cxx_result_on_tensors_and_arrays(sensor, capture):
    fmt, model = sensor.rawFormat(2.0), sensor.effectiveModel()
    transform = rgt.RandomNoiseScene(model, rg.RandomScenePolicy(geometryProbability=1), baseSeed=3)
    boxes = [(10, 12, 30, 20)]
    result = transform(capture, fmt, boxes, index=4, epoch=1)
    seed = rgt.sampleSeed(3, 1, 4)
    scene = rg.RandomScenePolicy(geometryProbability=1).draw(capture, fmt, seed)
    expected, expectedFormat, _, expectedBoxes = rg.applyScene(capture, fmt, model, scene, seed=seed, boxes=boxes)
    assert np.array_equal(result.raw, expected) and result.format == expectedFormat
    assert result.boxes == expectedBoxes and result.scene == scene
    # A float32 tensor in, a tensor out; tensor boxes come back as a tensor of their dtype.
    tensor = torch.from_numpy(capture.astype(np.float32))
    tboxes = torch.tensor(boxes, dtype=torch.float32)
    out = transform(tensor, fmt, tboxes, index=4, epoch=1)
    assert isinstance(out.raw, torch.Tensor) and out.raw.dtype == torch.float32
    assert isinstance(out.boxes, torch.Tensor) and out.boxes.dtype == torch.float32
    assert out.boxes.tolist() == [list(map(float, b)) for b in expectedBoxes]
    with pytest.raises(TypeError, match="torch.float32"):
        transform(torch.zeros((8, 8), dtype=torch.int32), fmt, index=0)
    with pytest.raises(TypeError, match="model"):
        rgt.RandomNoiseScene(3.0)


def batches(loader):
    return [(b["index"].tolist(), b["raw"].clone(), b["gain"].tolist()) for b in loader]


def test_dataloader_gives_the_same_samples_with_0_and_2_workers(folder, sensor):
    model = sensor.effectiveModel()
    dataset = rgt.RawFolderDataset(folder, model, baseSeed=11, pack=True)
    assert len(dataset) == 6 and all(f.endswith(".dng") for f in dataset.files)
    item = dataset[2]
    assert item["raw"].shape == (4, 48, 64) and item["raw"].dtype == torch.float32
    results = {}
    for workers in (0, 2):
        loader = torch.utils.data.DataLoader(dataset, batch_size=2, num_workers=workers, shuffle=False)
        results[workers] = batches(loader)
    assert len(results[0]) == 3
    for (i0, r0, g0), (i2, r2, g2) in zip(results[0], results[2]):
        assert i0 == i2 and g0 == g2 and torch.equal(r0, r2)
    # Another epoch, other samples; the same epoch again, the same samples.
    dataset.set_epoch(1)
    other = batches(torch.utils.data.DataLoader(dataset, batch_size=2, num_workers=2))
    assert not all(torch.equal(a[1], b[1]) for a, b in zip(results[0], other))
    dataset.set_epoch(0)
    again = batches(torch.utils.data.DataLoader(dataset, batch_size=2, num_workers=2))
    assert all(torch.equal(a[1], b[1]) for a, b in zip(results[0], again))
    # The epoch is a 64-bit signed tensor: beyond it, an error that says the range (once "Overflow when
    # unpacking long").
    for bad in (2 ** 63, -1):
        with pytest.raises(ValueError, match=r"epoch must be in \[0, 2\^63\)"):
            dataset.set_epoch(bad)


def test_dataloader_workers_take_the_dark_frame_bank_by_its_path(folder, sensor, dark_bank):
    # A gain ratio of 2 takes the gain-1 DNGs to gain 2, within the bank.
    policy = rg.RandomScenePolicy(gainDbMin=6.0206, gainDbMax=6.0206, noise=rg.NoiseOptions(darkBank=dark_bank))
    dataset = rgt.RawFolderDataset(folder, sensor.effectiveModel(), policy=policy, baseSeed=11)
    here = batches(torch.utils.data.DataLoader(dataset, batch_size=2, num_workers=0))
    there = batches(torch.utils.data.DataLoader(dataset, batch_size=2, num_workers=2))
    assert all(a[0] == b[0] and torch.equal(a[1], b[1]) for a, b in zip(here, there))
    plain = rgt.RawFolderDataset(folder, sensor.effectiveModel(), policy=rg.RandomScenePolicy(
        gainDbMin=6.0206, gainDbMax=6.0206), baseSeed=11)
    assert not torch.equal(plain[0]["raw"], dataset[0]["raw"])


def test_persistent_workers_see_every_epoch(folder, sensor):
    # Persistent workers keep their copy of the dataset: set_epoch() must still reach them (they used to
    # repeat epoch 0's augmentations).
    dataset = rgt.RawFolderDataset(folder, sensor.effectiveModel(), baseSeed=5)
    persistent = torch.utils.data.DataLoader(dataset, batch_size=2, num_workers=2, persistent_workers=True)
    seen = []
    for epoch in range(3):
        dataset.set_epoch(epoch)
        seen.append(batches(persistent))
        fresh = batches(torch.utils.data.DataLoader(dataset, batch_size=2, num_workers=0))
        assert all(torch.equal(a[1], b[1]) for a, b in zip(seen[-1], fresh)), epoch
    assert not all(torch.equal(a[1], b[1]) for a, b in zip(seen[0], seen[1]))


def test_dataset_options_and_errors(folder, tmp_path, sensor):
    plain = rgt.RawFolderDataset(folder, sensor.effectiveModel(), augment=False, normalize=False)
    raw = plain[0]["raw"]
    mosaic, fmt, _ = rgt.loadMosaic(plain.files[0])
    assert torch.equal(raw[0], torch.from_numpy(rg.subtractBlackLevel(mosaic, fmt)))
    with pytest.raises(IndexError):
        plain[6]
    with pytest.raises(FileNotFoundError, match="no RAW file"):
        rgt.RawFolderDataset(tmp_path, sensor.effectiveModel())
    with pytest.raises(FileNotFoundError, match="not a folder"):
        rgt.RawFolderDataset(tmp_path / "missing", sensor.effectiveModel())


def test_a_crop_is_augmented_with_its_own_pixels_dark_shading(folder, sensor):
    # A model with dark-shading maps worked only on whole frames. The dataset's crops carry their place on
    # the sensor (RawFormat.sensorOrigin) and are augmented with the shading of their own pixels: each item
    # is exactly what the transform makes of that crop with that format, and a pattern read at the origin
    # instead would differ.
    mosaic, fmt, _ = rgt.loadMosaic(str(folder / "frame_00.dng"))
    model = sensor.effectiveModel()
    rng = np.random.default_rng(5)
    model.darkShadingPerGain = rng.uniform(0, 4, mosaic.shape).astype(np.float32)
    model.darkShadingOffset = rng.uniform(0, 8, mosaic.shape).astype(np.float32)
    data = rgt.RawFolderDataset(folder, model, baseSeed=9, normalize=False, crop=(32, 48))
    seen = set()
    for index in range(len(data)):
        item = data[index]
        assert tuple(item["raw"].shape) == (1, 32, 48)
        full, full_fmt, _ = rgt.loadMosaic(data.files[index])
        crop, crop_fmt = data._cropped(full, full_fmt, index)
        x, y = crop_fmt.sensorOrigin
        seen.add((x, y))
        assert np.array_equal(crop, full[y:y + 32, x:x + 48]) and x % 2 == 0 and y % 2 == 0
        expected = data.transform(crop, crop_fmt, index=index, epoch=0)
        assert torch.equal(item["raw"][0], torch.from_numpy(rg.subtractBlackLevel(expected.raw, expected.format)))
    assert len(seen) > 1, "crops are drawn per sample"
    # The same crop read as if it were at the sensor's corner gets another pattern: a shift of the crop by
    # (2, 2) must keep its own pixels' shading (a noiseless check, as in the C++ test).
    flat = np.full((64, 96), 600.0, np.float32) + model.darkShadingAt(fmt.gain)[:64, :96]
    crop_fmt = rg.RawFormat(pattern=fmt.pattern, blackLevel=fmt.blackLevel, whiteLevel=fmt.whiteLevel,
                            gain=fmt.gain).cropped(8, 10)
    scene = rg.Scene(shift=(2, 2))
    out = rg.applyScene(flat[8:40, 10:58], crop_fmt, model, scene, seed=1)[0]
    assert np.abs(out - flat[8:40, 10:58]).max() < 1e-3
    with pytest.raises(ValueError, match="smaller than the crop"):
        rgt.RawFolderDataset(folder, model, crop=(2000, 48))[0]
    with pytest.raises(ValueError, match="both even"):
        rgt.RawFolderDataset(folder, model, crop=(31, 48))
    # Through a file: a crop written with writeMosaic keeps its origin in its sidecar.
    first_crop, first_fmt = data._cropped(*rgt.loadMosaic(data.files[0])[:2], 0)
    path = folder.parent / "crop_origin.png"
    rg.writeMosaic(str(path), np.ascontiguousarray(first_crop), rg.MosaicMetadata(format=first_fmt))
    assert rgt.loadMosaic(str(path))[1].sensorOrigin == first_fmt.sensorOrigin


def test_packed_tensors_are_written_in_one_pass_into_their_own_memory(folder, sensor):
    """packCfaPlanes(out=tensor.numpy()) is black subtraction, normalisation and the CFA split of
    rawgment.torch.packCfaPlanes, to the bit, in the tensor's memory; the dataset's packed items too."""
    from conftest import chart_mean

    _, mean = chart_mean()
    raw = sensor.capture(mean, 1.0, 1.0, seed=3)
    fmt = sensor.rawFormat(1.0)
    for normalize in (False, True):
        expected = rgt.packCfaPlanes(rg.subtractBlackLevel(raw, fmt, normalize=normalize), fmt)
        tensor = torch.full(expected.shape, -1.0)
        result = rg.packCfaPlanes(raw, fmt, normalize=normalize, out=tensor.numpy())
        assert torch.equal(tensor, expected)
        assert np.shares_memory(result, tensor.numpy())
        assert np.array_equal(rg.packCfaPlanes(raw, fmt, normalize=normalize), expected.numpy())
    with pytest.raises(ValueError, match=r"shape \(4, "):
        rg.packCfaPlanes(raw, fmt, out=np.zeros((4, 2, 2), np.float32))
    with pytest.raises(TypeError, match="float32"):
        rg.packCfaPlanes(raw, fmt, out=np.zeros(expected.shape, np.float64))
    dataset = rgt.RawFolderDataset(folder, rg.NoiseModel(0.25, 1.5, 0.8), baseSeed=5, pack=True, augment=False)
    item = dataset[2]
    mosaic, itemFmt, _ = rgt.loadMosaic(dataset.files[2])
    assert torch.equal(item["raw"], rgt.packCfaPlanes(rg.subtractBlackLevel(mosaic, itemFmt, normalize=True), itemFmt))


def test_npy_mosaics_are_numpys_own_files_and_the_dataset_reads_them(folder, tmp_path, sensor):
    """.npy mosaics: np.load (and its memory map) reads what writeMosaic wrote, readMosaic reads what np.save
    wrote beside a sidecar, and a dataset of conversions gives the samples of the camera files."""
    from conftest import chart_mean

    _, mean = chart_mean()
    raw = sensor.capture(mean, 1.0, 1.0, seed=4)
    meta = rg.MosaicMetadata(format=sensor.rawFormat(1.0))
    rg.writeMosaic(str(tmp_path / "a.npy"), raw, meta)
    assert np.array_equal(np.load(tmp_path / "a.npy"), raw)
    assert np.array_equal(np.load(tmp_path / "a.npy", mmap_mode="r"), raw)
    floats = raw.astype(np.float32) * 0.5 - 3
    np.save(tmp_path / "b.npy", floats)
    # The sidecar of the same array written by writeMosaic, put beside numpy's file.
    rg.writeMosaic(str(tmp_path / "c.npy"), floats, meta)
    os.replace(tmp_path / "c.npy.yml", tmp_path / "b.npy.yml")
    back, _ = rg.readMosaic(str(tmp_path / "b.npy"))
    assert back.dtype == np.float32 and np.array_equal(back, floats)
    # Conversions of the folder's camera files, as rawgment_convert writes them: the same samples.
    converted = tmp_path / "converted"
    run = subprocess.run([os.path.join(env_path("RAWGMENT_APP_DIR"), "rawgment_convert"), "--out=%s" % converted]
                         + [str(folder / name) for name in sorted(os.listdir(folder)) if name.endswith(".dng")],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    model = rg.NoiseModel(0.25, 1.5, 0.8)
    fromDng = rgt.RawFolderDataset(folder, model, baseSeed=9, pack=True)
    fromNpy = rgt.RawFolderDataset(converted, model, baseSeed=9, pack=True)
    assert [os.path.splitext(os.path.basename(f))[0] for f in fromNpy.files] == \
        [os.path.splitext(os.path.basename(f))[0] for f in fromDng.files]
    for index in range(len(fromDng)):
        assert torch.equal(fromDng[index]["raw"], fromNpy[index]["raw"])


def test_a_dataset_records_where_each_items_time_went(folder):
    dataset = rgt.RawFolderDataset(folder, rg.NoiseModel(0.25, 1.5, 0.8), baseSeed=2, pack=True, timings=True)
    plain = rgt.RawFolderDataset(folder, rg.NoiseModel(0.25, 1.5, 0.8), baseSeed=2, pack=True)
    assert plain.timings is None
    for index in range(3):
        assert torch.equal(dataset[index]["raw"], plain[index]["raw"]), "recording changes no sample"
    assert len(dataset.timings) == 3
    for t in dataset.timings:
        steps = {k: v for k, v in t.items() if k not in ("read", "tensor", "other", "total")}
        assert set(steps) <= {"shift", "scale", "colorJitter", "motionBlur"}
        assert all(v >= 0 for v in t.values())
        assert abs(t["read"] + t["tensor"] + t["other"] + sum(steps.values()) - t["total"]) < 1e-9
