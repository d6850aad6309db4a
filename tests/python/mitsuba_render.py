#!/usr/bin/env python3
"""Render a flat rectangle with an RGL .bsdf in Mitsuba 3 (scalar_rgb), and say what each pixel sees.

Usage:
  python3 tests/python/mitsuba_render.py render FILE.bsdf OUTDIR [--res N] [--spp N] [--variant V]
  python3 tests/python/mitsuba_render.py png OUTDIR FIGDIR [PREFIX]

render: the scene is Mitsuba's `rectangle` ([-1, 1]^2 in the z = 0 plane, normal +z) with the
`measured` BSDF reading FILE.bsdf, lit by a `directional` emitter of irradiance E = 3 travelling
along -LIGHT (LIGHT = the unit vector toward the light, printed), seen by a perspective camera
from (0, -2.2, 2.4) looking at the origin, N x N pixels, box filter, `direct` integrator with
emitter sampling only. --variant: scalar_rgb (default; the RGB file) or scalar_spectral (the
spectral file; the film then integrates the sampled wavelengths against the CIE 1931 curves and
converts XYZ to linear sRGB, and the light's RGB irradiance becomes E times Mitsuba's normalised
D65). Writes into OUTDIR:
  render.f32   the image, N*N*3 float32 little-endian, row-major from the top-left pixel, RGB
  pairs.f64    per pixel: the direction toward the light and toward the eye in the surface's local
               shading frame (Mitsuba's si.to_local, the frame the BSDF sees), 6 float64 each, taken
               from the ray through the pixel's centre
  mask.u8      per pixel 1 where that ray hits the rectangle, else 0
  scene.json   the numbers above (irradiance, light direction, resolution, spp, Mitsuba version)

png: reads OUTDIR/render.f32 and OUTDIR/reference.f32 (the same layout, written by the Rust test
tests/tests/export_mitsuba.rs) and writes FIGDIR/PREFIX_mitsuba.png and FIGDIR/PREFIX_reference.png
(PREFIX: rgl unless given), both with the same exposure (the reference's 99th percentile maps to 0.9) and the sRGB curve.

Needs: pip install mitsuba numpy
"""

import json
import os
import sys

import numpy as np

IRRADIANCE = 3.0
LIGHT = np.array([0.35, 0.45, 0.82])
LIGHT = LIGHT / np.linalg.norm(LIGHT)
ORIGIN = [0.0, -2.2, 2.4]


def render(bsdf_path, out, res, spp, variant):
    import mitsuba as mi

    mi.set_variant(variant)
    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0},
            "sensor": {
                "type": "perspective",
                "fov": 35,
                "to_world": mi.ScalarTransform4f().look_at(
                    origin=ORIGIN, target=[0, 0, 0], up=[0, 0, 1]
                ),
                "film": {
                    "type": "hdrfilm",
                    "width": res,
                    "height": res,
                    "rfilter": {"type": "box"},
                    "pixel_format": "rgb",
                },
                "sampler": {"type": "independent", "sample_count": spp},
            },
            "plane": {
                "type": "rectangle",
                "bsdf": {"type": "measured", "filename": bsdf_path},
            },
            "light": {
                "type": "directional",
                "direction": (-LIGHT).tolist(),
                "irradiance": {"type": "rgb", "value": IRRADIANCE},
            },
        }
    )
    img = np.array(mi.render(scene, seed=1), dtype=np.float32)
    assert img.shape == (res, res, 3), img.shape
    sensor = scene.sensors()[0]
    pairs = np.zeros((res, res, 6), dtype=np.float64)
    mask = np.zeros((res, res), dtype=np.uint8)
    light = mi.Vector3f(*LIGHT.tolist())
    for y in range(res):
        for x in range(res):
            ray, _ = sensor.sample_ray(
                0.0, 0.5, mi.Point2f((x + 0.5) / res, (y + 0.5) / res), mi.Point2f(0.5, 0.5)
            )
            si = scene.ray_intersect(ray)
            if not si.is_valid():
                continue
            wl = si.to_local(light)
            we = si.to_local(-ray.d)
            pairs[y, x] = [wl[0], wl[1], wl[2], we[0], we[1], we[2]]
            mask[y, x] = 1
    os.makedirs(out, exist_ok=True)
    img.astype("<f4").tofile(os.path.join(out, "render.f32"))
    pairs.astype("<f8").tofile(os.path.join(out, "pairs.f64"))
    mask.tofile(os.path.join(out, "mask.u8"))
    with open(os.path.join(out, "scene.json"), "w") as f:
        json.dump(
            {
                "irradiance": IRRADIANCE,
                "light": LIGHT.tolist(),
                "origin": ORIGIN,
                "res": res,
                "spp": spp,
                "variant": variant,
                "mitsuba": mi.__version__,
            },
            f,
        )


def png(out, figdir, prefix):
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    res = json.load(open(os.path.join(out, "scene.json")))["res"]
    imgs = {
        name: np.fromfile(os.path.join(out, name + ".f32"), dtype="<f4").reshape(res, res, 3)
        for name in ["render", "reference"]
    }
    scale = 0.9 / max(float(np.percentile(imgs["reference"], 99)), 1e-12)
    os.makedirs(figdir, exist_ok=True)
    for name, file in [("render", prefix + "_mitsuba.png"), ("reference", prefix + "_reference.png")]:
        bmp = mi.Bitmap(np.clip(imgs[name] * scale, 0, 1).astype(np.float32))
        bmp = bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, True)
        bmp.write(os.path.join(figdir, file))


def main(argv):
    if len(argv) >= 3 and argv[0] == "render":
        res, spp, variant = 48, 16, "scalar_rgb"
        rest = argv[3:]
        while rest:
            if rest[0] == "--res":
                res = int(rest[1])
            elif rest[0] == "--spp":
                spp = int(rest[1])
            elif rest[0] == "--variant":
                variant = rest[1]
            else:
                raise SystemExit(f"unknown option {rest[0]}; see --help")
            rest = rest[2:]
        render(argv[1], argv[2], res, spp, variant)
    elif len(argv) in (3, 4) and argv[0] == "png":
        png(argv[1], argv[2], argv[3] if len(argv) == 4 else "rgl")
    else:
        raise SystemExit(__doc__)


if __name__ == "__main__":
    main(sys.argv[1:])
