"""The gallery's PNG files: 8-bit indexed colour with a 256-colour palette fitted to each
picture, about half the size of 8-bit RGB (path-traced noise does not compress; the palette
stores each pixel in one byte). The palette is a k-means fit (8 Lloyd iterations, from 256
pixels of a fixed random sample of 60 000, seed 0, so a picture always gets the same file);
each pixel takes its nearest palette colour. The mean error is under one 8-bit level per
channel; the render's own noise hides the quantisation steps, so no dithering.
"""

import struct
import zlib

import numpy as np


def palette(px, k=256, iters=8, seed=0):
    """k colours (k, 3) float32 fitted to the pixels px (N, 3) uint8."""
    rng = np.random.default_rng(seed)
    sample = px[rng.choice(len(px), size=min(len(px), 60000), replace=False)].astype(np.float32)
    k = min(k, len(sample))
    centers = sample[rng.choice(len(sample), size=k, replace=False)]
    for _ in range(iters):
        label = nearest(sample, centers)
        sums = np.zeros_like(centers)
        np.add.at(sums, label, sample)
        counts = np.bincount(label, minlength=k)
        used = counts > 0
        centers[used] = sums[used] / counts[used, None]
    return centers


def nearest(px, centers):
    """The index (N,) uint8 of the nearest colour of each pixel, in blocks."""
    c = centers.astype(np.float32)
    cn = (c * c).sum(axis=1)
    out = np.empty(len(px), dtype=np.uint8)
    for i in range(0, len(px), 65536):
        p = px[i:i + 65536].astype(np.float32)
        out[i:i + 65536] = (cn[None, :] - 2.0 * p @ c.T).argmin(axis=1)
    return out


def _chunk(kind, data):
    return (struct.pack(">I", len(data)) + kind + data
            + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))


def write(path, img8):
    """Writes the 8-bit RGB image (H, W, 3) uint8 as an indexed-colour PNG."""
    h, w, _ = img8.shape
    px = img8.reshape(-1, 3)
    colours = palette(px)
    index = nearest(px, colours).reshape(h, w)
    rows = b"".join(b"\x00" + index[y].tobytes() for y in range(h))
    plte = np.clip(np.round(colours), 0, 255).astype(np.uint8).tobytes()
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(_chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 3, 0, 0, 0)))
        f.write(_chunk(b"PLTE", plte))
        f.write(_chunk(b"IDAT", zlib.compress(rows, 9)))
        f.write(_chunk(b"IEND", b""))
