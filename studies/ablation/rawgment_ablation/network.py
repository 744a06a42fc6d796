"""The ablation study's network and measures (rawgment_ablation): a compact U-Net denoiser on packed CFA
planes, told the noise or blind, and PSNR and SSIM."""
import math

import torch
import torch.nn.functional as F

from rawgment_ablation.common import BLIND_STEP

__all__ = ["Denoiser", "psnr", "ssim"]


class Denoiser(torch.nn.Module):
    """A compact two-level U-Net on the packed R, G1, G2, B planes. Told the noise (noiseMaps, the
    default) it also takes each plane's noise-level map and predicts the residual in units of the noise:
    input 8 x H x W (the planes, then each plane's noise standard deviation; H, W even). Blind
    (noiseMaps=False) it takes the 4 planes alone and predicts the residual in units of a fixed step
    `blindScale`, the same for every input (so it carries no noise information): it must infer the noise
    level from the image. Output: the 4 denoised planes."""

    #: The blind network's default fixed residual unit (BLIND_STEP).
    blindScale = BLIND_STEP

    def __init__(self, width=16, noiseMaps=True, blindScale=None):
        super().__init__()
        self.noiseMaps = bool(noiseMaps)
        if blindScale is not None:
            self.blindScale = float(blindScale)
        conv = torch.nn.Conv2d
        self.encode = torch.nn.Sequential(conv(8 if self.noiseMaps else 4, width, 3, padding=1), torch.nn.ReLU(),
                                          conv(width, width, 3, padding=1), torch.nn.ReLU())
        self.down = torch.nn.Sequential(conv(width, 2 * width, 3, stride=2, padding=1), torch.nn.ReLU(),
                                        conv(2 * width, 2 * width, 3, padding=1), torch.nn.ReLU(),
                                        conv(2 * width, 2 * width, 3, padding=1), torch.nn.ReLU())
        self.up = torch.nn.ConvTranspose2d(2 * width, width, 2, stride=2)
        self.decode = torch.nn.Sequential(conv(2 * width, width, 3, padding=1), torch.nn.ReLU(),
                                          conv(width, 4, 3, padding=1))
        # The residual starts at zero, so an untrained network passes its input through instead of
        # adding noise of its own; training then departs from the noisy input, the study's floor.
        torch.nn.init.zeros_(self.decode[-1].weight)
        torch.nn.init.zeros_(self.decode[-1].bias)

    def forward(self, x):
        skip = self.encode(x)
        residual = self.decode(torch.cat([skip, self.up(self.down(skip))], dim=1))
        if not self.noiseMaps:
            return x + self.blindScale * residual
        # The correction is predicted in units of the noise standard deviation: the same network then
        # serves a 40 dB and an 18 dB input equally well, which a plain residual does not learn in a
        # short budget (its corrections for the darkest inputs spoil the brightest).
        return x[:, :4] + x[:, 4:] * residual


def psnr(output, clean):
    """PSNR in dB of images in [0, 1] (peak 1): 10 log10(1 / MSE); inf for identical images."""
    mse = float(torch.mean((output.double() - clean.double()) ** 2))
    return math.inf if mse == 0 else 10.0 * math.log10(1.0 / mse)


def ssim(output, clean):
    """Mean SSIM of C x H x W images in [0, 1] (data range 1), per channel with the usual 11-tap
    Gaussian window of sigma 1.5 and constants (0.01)^2, (0.03)^2, over the valid region."""
    c = output.shape[0]
    taps = torch.arange(11, dtype=torch.float64) - 5
    g = torch.exp(-taps ** 2 / (2 * 1.5 ** 2))
    g = g / g.sum()
    x, y = output.double(), clean.double()
    # The window is separable: a column then a row pass, on the five planes at once, is 22 taps a pixel
    # instead of 121 (the 2-D convolution was most of a quick study's evaluation time).
    planes = torch.cat([x, y, x * x, y * y, x * y])[None]
    blurred = F.conv2d(F.conv2d(planes, g.view(1, 1, 11, 1).expand(5 * c, 1, 11, 1), groups=5 * c),
                       g.view(1, 1, 1, 11).expand(5 * c, 1, 1, 11), groups=5 * c)
    mx, my, xx, yy, xy = blurred[0].split(c)
    vx, vy, cxy = xx - mx * mx, yy - my * my, xy - mx * my
    c1, c2 = 0.01 ** 2, 0.03 ** 2
    value = ((2 * mx * my + c1) * (2 * cxy + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2))
    return float(value.mean())
