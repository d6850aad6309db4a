"""Exposure and the tone curve of the gallery's pictures, in numpy.

A linear RGB image (Mitsuba's output, scene-referred) is multiplied by the exposure, mapped
through the ACES filmic curve as fitted by Narkowicz (2015),

    f(x) = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14),  clamped to [0, 1],

per channel (highlights roll off instead of clipping; mid-tones gain a little contrast),
then encoded with the sRGB transfer function and rounded to 8 bits.
"""

import numpy as np


def aces(x):
    """Narkowicz's fit of the ACES filmic curve, per channel, clamped to [0, 1]."""
    x = np.maximum(x, 0.0)
    return np.clip(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0)


def srgb(x):
    """The sRGB transfer function (IEC 61966-2-1) of linear values in [0, 1]."""
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def auto_exposure(img, key=0.18):
    """The exposure that brings the image's log-average luminance (Rec. 709 weights) to
    ``key`` (Reinhard et al. 2002)."""
    lum = img[..., :3] @ np.array([0.2126, 0.7152, 0.0722])
    return key / float(np.exp(np.mean(np.log(1e-4 + np.maximum(lum, 0.0)))))


def to_8bit(img, exposure):
    """The displayable 8-bit sRGB image (H, W, 3) uint8 of a linear image."""
    return np.round(255.0 * srgb(aces(exposure * img[..., :3]))).astype(np.uint8)
