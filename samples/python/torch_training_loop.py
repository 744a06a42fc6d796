#!/usr/bin/env python3
"""Feeds augmented RAW to a small PyTorch model for a few steps.

A folder of RAW files (simulated DNGs here, yours with --folder) goes through
rawgment.torch.RawFolderDataset: every sample is a random noise-accounted scene (darker, higher gain,
blurred, shifted), packed as four CFA planes. The model learns the noise level of its input: it
predicts the capture's gain in dB, which the augmentation chose, from the packed planes alone. The
loss falls within a few dozen steps because the added noise follows the camera's model.

    /usr/bin/python3 samples/python/torch_training_loop.py [--steps 40] [--workers 2] [--folder raws/ --model m.yml]
"""
import argparse
import math
import os
import tempfile

import numpy as np
import torch

import rawgment as rg
import rawgment.torch as rgt


def simulated_folder(folder, count):
    """DNGs of a simulated sensor: gradients and patches, one exposure each."""
    sensor = rg.SensorSimulator(rg.SensorParams(), (256, 192))
    y, x = np.mgrid[0:192, 0:256].astype(np.float32)
    for i in range(count):
        scene = 300 + 1200 * ((x / 256) * (i % 3) + (y / 192) * (1 + i % 2)) / 3
        scene[40:100, 60:140] *= 0.3 + 0.2 * (i % 4)
        raw = sensor.capture(scene.astype(np.float32), 1.0, 1.0, seed=rg.deriveSeed(5, rg.SEED_DEMO, i))
        rg.writeDng(os.path.join(folder, "sim_%03d.dng" % i), rg.RawImage(mosaic=raw, format=sensor.rawFormat(1.0)))
    return sensor.effectiveModel()


class NoiseLevelNet(torch.nn.Module):
    def __init__(self):
        super().__init__()
        self.features = torch.nn.Sequential(
            torch.nn.Conv2d(4, 16, 3, padding=1), torch.nn.ReLU(),
            torch.nn.Conv2d(16, 16, 3, padding=1), torch.nn.ReLU(),
            torch.nn.AdaptiveAvgPool2d(1))
        self.head = torch.nn.Linear(16, 1)

    def forward(self, planes):
        # High-pass input: the noise, not the scene's brightness, tells the gain.
        detail = planes - torch.nn.functional.avg_pool2d(planes, 3, stride=1, padding=1)
        return self.head(self.features(detail * 100).flatten(1)).squeeze(1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], allow_abbrev=False)
    parser.add_argument("--folder", help="a folder of RAW files (default: simulated DNGs)")
    parser.add_argument("--model", help="its noise model (required with --folder)")
    parser.add_argument("--steps", type=int, default=40)
    parser.add_argument("--workers", type=int, default=2, help="DataLoader worker processes")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    torch.manual_seed(args.seed)

    with tempfile.TemporaryDirectory() as tmp:
        if args.folder:
            if not args.model:
                parser.error("--model is required with --folder")
            folder, model = args.folder, args.model
        else:
            folder, model = tmp, simulated_folder(tmp, 16)
        policy = rg.RandomScenePolicy(gainDbMin=0, gainDbMax=18, contrastMin=0.05)
        dataset = rgt.RawFolderDataset(folder, model, policy, baseSeed=args.seed, pack=True)
        loader = torch.utils.data.DataLoader(dataset, batch_size=4, shuffle=True, num_workers=args.workers)
        net = NoiseLevelNet()
        optimiser = torch.optim.Adam(net.parameters(), lr=3e-3)
        step, epoch, first, last = 0, 0, None, None
        while step < args.steps:
            dataset.set_epoch(epoch)
            for batch in loader:
                target = 20 * torch.log10(batch["gain"].float())
                loss = torch.nn.functional.mse_loss(net(batch["raw"]), target)
                optimiser.zero_grad()
                loss.backward()
                optimiser.step()
                first = loss.item() if first is None else first
                last = loss.item()
                step += 1
                if step % 10 == 0 or step == args.steps:
                    print("step %3d  loss %.3f dB^2" % (step, last))
                if step == args.steps:
                    break
            epoch += 1
        print("loss: first %.3f, last %.3f dB^2 (RMS error of the gain: %.2f dB)" % (first, last, math.sqrt(last)))


if __name__ == "__main__":
    main()
