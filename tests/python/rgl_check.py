#!/usr/bin/env python3
"""Check a spectral RGL .bsdf against pbrt-v4's reader, with a reader of our own (numpy only).

Usage:
  python3 tests/python/rgl_check.py pbrt FILE_spec.bsdf
  python3 tests/python/rgl_check.py project FILE_spec.bsdf FILE_rgb.bsdf

pbrt: parses the tensor file from its bytes (not with clothbake's or Mitsuba's code) and checks
every condition pbrt-v4's MeasuredBxDFData::Create (src/pbrt/bxdfs.cpp) and its Tensor reader
place on a file, as read from pbrt-v4's public source (commit 5f7a606 of mmp/pbrt-v4): magic and
version 1.0; the fields theta_i, phi_i, ndf, sigma, vndf, spectra, luminance, wavelengths,
description, jacobian, with their ranks, types and matching extents; an azimuth range of 2 pi
(pbrt refuses a symmetry reduction); plus what its interpolants assume: increasing nodes, slices
of at least 2 x 2, luminance and vndf non-negative with a positive sum per slice (it builds CDFs
from them), and wavelengths covering 360-830 nm (Lambda_min, Lambda_max, the range pbrt samples;
beyond the nodes it would hold the end values). Prints a JSON summary; exits 1 listing every
failed condition. This is NOT pbrt reading the file.

project: projects every spectrum of the spectral file to linear sRGB with Mitsuba 3's own CIE
1931 curves and D65 (mitsuba.cie1931_xyz, mitsuba.cie_d65, mitsuba.xyz_to_srgb), reading the
spectrum as both readers do (linear between nodes), and compares with the RGB file's rgb field.
Prints a JSON summary (the largest error relative to the largest rgb value); checks nothing.
"""

import json
import math
import struct
import sys

import numpy as np

TYPES = {1: ("u1", 1), 2: ("i1", 1), 3: ("<u2", 2), 4: ("<i2", 2), 5: ("<u4", 4), 6: ("<i4", 4),
         7: ("<u8", 8), 8: ("<i8", 8), 9: ("<f2", 2), 10: ("<f4", 4), 11: ("<f8", 8)}
UINT8, FLOAT32 = 1, 10


def read_tensor_file(path):
    """{name: (type code, shape tuple, numpy array)} from the bytes of a tensor file."""
    b = open(path, "rb").read()
    if len(b) < 18 or b[:12] != b"tensor_file\0":
        raise SystemExit(f"{path}: not a tensor file (bad magic)")
    if b[12:14] != bytes([1, 0]):
        raise SystemExit(f"{path}: version {b[12]}.{b[13]}, pbrt-v4 reads only 1.0")
    (n,) = struct.unpack_from("<I", b, 14)
    at, fields = 18, {}
    for _ in range(n):
        (ln,) = struct.unpack_from("<H", b, at)
        name = b[at + 2:at + 2 + ln].decode()
        at += 2 + ln
        rank, code, offset = struct.unpack_from("<HBQ", b, at)
        at += 11
        shape = struct.unpack_from("<" + "Q" * rank, b, at)
        at += 8 * rank
        if code not in TYPES:
            raise SystemExit(f"{path}: field {name}: unknown type code {code}")
        dt, size = TYPES[code]
        count = math.prod(shape)
        if offset + count * size > len(b):
            raise SystemExit(f"{path}: field {name}: data beyond the end of the file")
        arr = np.frombuffer(b, dtype=dt, count=count, offset=offset).reshape(shape)
        fields[name] = (code, tuple(shape), arr)
    return fields


def pbrt(path):
    f = read_tensor_file(path)
    fails = []

    def need(cond, what):
        if not cond:
            fails.append(what)

    names = ["theta_i", "phi_i", "ndf", "sigma", "vndf", "spectra", "luminance", "wavelengths",
             "description", "jacobian"]
    missing = [n for n in names if n not in f]
    if missing:
        print(json.dumps({"ok": False, "failed": [f"missing field {m}" for m in missing]}))
        sys.exit(1)
    code = {k: v[0] for k, v in f.items()}
    shape = {k: v[1] for k, v in f.items()}
    data = {k: v[2] for k, v in f.items()}
    rank1 = {"description": UINT8, "theta_i": FLOAT32, "phi_i": FLOAT32, "wavelengths": FLOAT32}
    for n, t in rank1.items():
        need(len(shape[n]) == 1 and code[n] == t, f"{n}: rank 1 of type {t}")
    for n in ["ndf", "sigma"]:
        need(len(shape[n]) == 2 and code[n] == FLOAT32, f"{n}: rank 2 float32")
    n_phi, n_theta, n_wl = shape["phi_i"][0], shape["theta_i"][0], shape["wavelengths"][0]
    need(len(shape["vndf"]) == 4 and code["vndf"] == FLOAT32
         and shape["vndf"][:2] == (n_phi, n_theta), "vndf: float32 [phi_i, theta_i, a, b]")
    lum = shape["luminance"]
    need(len(lum) == 4 and code["luminance"] == FLOAT32 and lum[:2] == (n_phi, n_theta)
         and lum[2] == lum[3], "luminance: float32 [phi_i, theta_i, n, n]")
    sp = shape["spectra"]
    need(len(sp) == 5 and code["spectra"] == FLOAT32 and sp[:3] == (n_phi, n_theta, n_wl)
         and sp[3] == sp[4], "spectra: float32 [phi_i, theta_i, wavelengths, n, n]")
    need(len(lum) == 4 and len(sp) == 5 and lum[2:] == sp[3:], "luminance and spectra: same n")
    need(shape["jacobian"] == (1,) and code["jacobian"] == UINT8, "jacobian: uint8 [1]")
    phi, theta, wl = (data[n].astype(np.float64) for n in ["phi_i", "theta_i", "wavelengths"])
    isotropic = n_phi <= 2
    if not isotropic:
        reduction = round(2 * math.pi / (phi[-1] - phi[0]))
        need(reduction == 1, f"phi_i spans 2 pi (reduction {reduction}; pbrt accepts only 1)")
    for n, v in [("theta_i", theta), ("phi_i", phi), ("wavelengths", wl)]:
        need(len(v) == 1 or bool(np.all(np.diff(v) > 0)), f"{n}: increasing")
    need(theta[0] >= 0 and theta[-1] < math.pi / 2, "theta_i in [0, pi/2) (radians)")
    need(phi[0] >= -math.pi - 1e-6 and phi[-1] <= math.pi + 1e-6, "phi_i in [-pi, pi] (radians)")
    need(wl[0] <= 360 and wl[-1] >= 830, "wavelengths cover 360-830 nm (what pbrt samples)")
    for n in ["ndf", "sigma", "vndf", "luminance"]:
        need(min(shape[n][-2:]) >= 2, f"{n}: slices of at least 2 x 2")
    for n in ["vndf", "luminance"]:
        d = data[n].reshape(-1, shape[n][-2] * shape[n][-1]).astype(np.float64)
        need(bool(np.all(d >= 0) and np.all(d.sum(1) > 0)), f"{n}: non-negative, positive per slice")
    need(bool(np.all(data["sigma"] > 0)), "sigma: positive (pbrt divides by it)")
    spectra = data["spectra"]
    need(bool(np.all(np.isfinite(spectra))), "spectra: finite")
    summary = {
        "ok": not fails,
        "failed": fails,
        "shape": list(sp),
        "wavelengths": [float(wl[0]), float(wl[-1]), int(n_wl)],
        "spectra_min": float(spectra.min()),
        "spectra_max": float(spectra.max()),
        "negative_fraction": float((spectra < 0).mean()),
        "description": bytes(data["description"]).decode(errors="replace")[:200],
    }
    print(json.dumps(summary))
    if fails:
        sys.exit(1)


def project(spec_path, rgb_path):
    import mitsuba as mi

    mi.set_variant("scalar_spectral")
    s, r = read_tensor_file(spec_path), read_tensor_file(rgb_path)
    wl = s["wavelengths"][2].astype(np.float64)
    spectra = s["spectra"][2].astype(np.float64)
    rgb = r["rgb"][2].astype(np.float64)
    lam = np.arange(360.0, 830.0 + 1e-9, 0.25)
    cmf = np.array([list(mi.cie1931_xyz(float(x))) for x in lam])
    d65 = np.array([float(mi.cie_d65(float(x))) for x in lam])
    # The hat function of each node (linear interpolation, ends held), times x, y, z and D65.
    hats = np.stack([np.interp(lam, wl, np.eye(len(wl))[k]) for k in range(len(wl))], 1)
    trap = np.full(len(lam), lam[1] - lam[0])
    trap[[0, -1]] *= 0.5
    weights = (hats * (trap * d65)[:, None]).T @ cmf  # [node, xyz]
    weights /= np.sum(trap * d65 * cmf[:, 1])
    m = np.array(mi.xyz_to_srgb(mi.Color3f(1, 0, 0))), np.array(mi.xyz_to_srgb(mi.Color3f(0, 1, 0))), \
        np.array(mi.xyz_to_srgb(mi.Color3f(0, 0, 1)))
    to_srgb = np.stack(m, 1)  # columns: images of X, Y, Z
    xyz = np.einsum("ptwyx,wc->ptcyx", spectra, weights)
    back = np.einsum("rc,ptcyx->ptryx", to_srgb, xyz)
    err = np.abs(back - rgb)
    print(json.dumps({
        "max_abs_error": float(err.max()),
        "rgb_max": float(rgb.max()),
        "max_error_rel_to_max": float(err.max() / rgb.max()),
        "rel_rmse": float(np.sqrt((err ** 2).sum() / (rgb ** 2).sum())),
        "mitsuba": mi.__version__,
    }))


def main(argv):
    if len(argv) == 2 and argv[0] == "pbrt":
        pbrt(argv[1])
    elif len(argv) == 3 and argv[0] == "project":
        project(argv[1], argv[2])
    else:
        raise SystemExit(__doc__)


if __name__ == "__main__":
    main(sys.argv[1:])
