"""The ablation study's scenes (rawgment_ablation): synthetic reflectance scenes with edges, gratings and
smooth textures, and their expected mosaic under the study's illuminant."""
import math

import numpy as np

import rawgment as _rg

__all__ = ["renderScene", "mosaicOfScene"]

# Relative illumination of the R, G, B sites: a daylight-like white balance, so the red and blue planes
# are darker (and noisier) than green, as on real sensors.
_ILLUMINANT = (0.55, 1.0, 0.75)

def _randomColour(rng):
    """Linear RGB reflectance: a log-uniform lightness from 3% to 90% with a random tint."""
    lightness = math.exp(rng.uniform(math.log(0.03), math.log(0.9)))
    return np.clip(lightness * rng.uniform(0.5, 1.5, 3), 0.02, 0.95).astype(np.float32)


def renderScene(rng, height, width):
    """A synthetic scene (H x W x 3 linear reflectance in [0.02, 0.95]): a gradient background with
    flat rectangles and discs (sharp edges), gratings of random frequency and orientation, and smooth
    random textures, drawn from the numpy Generator `rng`."""
    y, x = np.mgrid[0:height, 0:width].astype(np.float32)
    angle = rng.uniform(0.0, 2.0 * math.pi)
    t = math.cos(angle) * x + math.sin(angle) * y
    t = (t - t.min()) / max(float(t.max() - t.min()), 1.0)
    image = _randomColour(rng) * (1.0 - t)[..., None] + _randomColour(rng) * t[..., None]
    for _ in range(int(rng.integers(8, 16))):
        kind = int(rng.integers(0, 4))
        colour = _randomColour(rng)
        cx, cy = rng.uniform(0, width), rng.uniform(0, height)
        size = rng.uniform(0.08, 0.4) * min(width, height)
        if kind == 0:
            mask = (np.abs(x - cx) < size / 2) & (np.abs(y - cy) < rng.uniform(0.3, 1.0) * size / 2)
            image[mask] = colour
        elif kind == 1:
            mask = (x - cx) ** 2 + (y - cy) ** 2 < (size / 2) ** 2
            image[mask] = colour
        elif kind == 2:
            period = rng.uniform(3.0, 24.0)  # mosaic pixels: from near the planes' Nyquist to coarse
            theta = rng.uniform(0.0, math.pi)
            phase = 2.0 * math.pi * (math.cos(theta) * x + math.sin(theta) * y) / period
            wave = 0.5 + 0.5 * np.sin(phase)
            mask = (np.abs(x - cx) < size / 2) & (np.abs(y - cy) < size / 2)
            other = _randomColour(rng)
            image[mask] = (colour * wave[..., None] + other * (1.0 - wave[..., None]))[mask]
        else:
            cells = int(rng.integers(3, 9))
            coarse = rng.uniform(0.0, 1.0, (cells + 1, cells + 1)).astype(np.float32)
            gy = np.clip((y - (cy - size / 2)) / size * cells, 0, cells - 1e-3)
            gx = np.clip((x - (cx - size / 2)) / size * cells, 0, cells - 1e-3)
            iy, ix = gy.astype(int), gx.astype(int)
            fy, fx = gy - iy, gx - ix
            fy, fx = fy * fy * (3 - 2 * fy), fx * fx * (3 - 2 * fx)  # smoothstep: no creases at cells
            value = (coarse[iy, ix] * (1 - fx) * (1 - fy) + coarse[iy, ix + 1] * fx * (1 - fy) +
                     coarse[iy + 1, ix] * (1 - fx) * fy + coarse[iy + 1, ix + 1] * fx * fy)
            mask = (np.abs(x - cx) < size / 2) & (np.abs(y - cy) < size / 2)
            other = _randomColour(rng)
            image[mask] = (colour * value[..., None] + other * (1.0 - value[..., None]))[mask]
    return np.clip(image, 0.02, 0.95).astype(np.float32)


def mosaicOfScene(rgb, pattern, level):
    """The expected signal at gain 1 (DN above black, float32 H x W) of a reflectance scene under the
    study's illuminant: each CFA site sees its channel, `level` DN for reflectance 1 at white."""
    h, w, _ = rgb.shape
    mosaic = np.empty((h, w), np.float32)
    for row in (0, 1):
        for col in (0, 1):
            channel = _rg.cfaChannelAt(pattern, row, col)
            rgbIndex = {_rg.CFA_R: 0, _rg.CFA_G1: 1, _rg.CFA_G2: 1, _rg.CFA_B: 2}[channel]
            mosaic[row::2, col::2] = rgb[row::2, col::2, rgbIndex] * (_ILLUMINANT[rgbIndex] * level)
    return mosaic
