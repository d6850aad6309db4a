"""The gingham in three renderers (docs/gallery/gingham-three-renderers.png): Mitsuba 3 rendering
its spatial table through the clothbake plugin, three.js rendering the fitted glTF material, and
Blender's Cycles rendering the fitted Blender module, side by side, in one scene, far (top) and
close (bottom).

    python3 python/gallery/mainstream.py --clothbake target/release/clothbake
        [--out docs/gallery] [--cache target/gallery]

Run by `cargo xtask gallery` (full gallery only). Needs mitsuba with a libLLVM >= 17 and the
staged `clothbake` package (as gallery.py), node with tests/renderers/node_modules and
Chromium (three_scene.mjs), and bpy in the same Python (cycles_scene.py, run as a separate
process so that Blender and Mitsuba do not share one).

The scene is the gallery's (scene.py: the cloth draped over a ball on a floor, its two views), lit
the same way in all three so that they can be compared: a sun (a directional light of
irradiance SUN_IRRADIANCE from scene.sun_direction()) and a uniform sky of radiance
SKY_RADIANCE (Mitsuba `directional` + `constant`; three.js DirectionalLight + a constant
environment, prefiltered by its PMREM, as the background too; Cycles a Sun lamp + a world of
that colour). The weave tiles scene.PERIODS times across the cloth in all three. Each picture
is linear; all three get the Mitsuba picture's exposure and the gallery's tone curve.
"""

import argparse
import json
import math
import pathlib
import subprocess
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))

import drape  # noqa: E402
import gallery  # noqa: E402
import scene  # noqa: E402
import tonemap  # noqa: E402

FABRIC = "gingham"
# The picture's caption in docs/gallery/README.md (gallery.py's write_readme).
CAPTION = (
    "`gingham.wif` in three renderers, one scene (a sun and a uniform sky, the same camera, "
    "tiling and exposure), far (top) and close (bottom). Left: Mitsuba 3 rendering its "
    "spatial table through the clothbake plugin (the point level up close). Middle: three.js "
    "r187 rendering the glTF material `clothbake export --gltf` fitted to it (per crossing "
    "cell), in headless Chromium, with its shadow map and a prefiltered constant "
    "environment (no occlusion of the sky). Right: Blender 5.0.1's Cycles rendering the "
    "material the `--blender` module builds. 400 x 300 pixels each, Mitsuba 32 and Cycles "
    "32 samples a pixel, three.js 3 x 3 supersampled (`python/gallery/mainstream.py`). The "
    "fitted materials draw the checks and each cell's yarn direction but not the yarns "
    "themselves, and no gaps. Mean luminance, far: Mitsuba 0.224, three.js 0.251, Cycles "
    "0.241; close: 0.49, 0.58, 0.56. The fitted pictures are brighter because the plugin "
    "with `periods` draws the cloth over its black floor (each value times the coverage, "
    "0.83-0.93 for this cloth at these views), while a fitted material, like the table's RGL "
    "export, is the averaged BRDF, which has no gaps (docs/guide/export.md).")
WIDTH, HEIGHT = 400, 300
SUN_IRRADIANCE = 3.0
SKY_RADIANCE = 0.35
SPP = 32
MESH_N = 257
BALL = [0.3, 0.3, 0.3]
FLOOR = [0.2, 0.19, 0.18]


def config(view):
    """What the three renderers share: the camera, the lights, the mesh's tiling."""
    origin, target, fov = scene.VIEWS[view]
    return {"width": WIDTH, "height": HEIGHT, "origin": origin, "target": target,
            "hfov_deg": fov, "sun": scene.sun_direction(), "sun_irradiance": SUN_IRRADIANCE,
            "sky_radiance": SKY_RADIANCE, "periods": scene.PERIODS,
            "ball": {"center": [0, 0, drape.SPHERE_RADIUS],
                     "radius": drape.SPHERE_RADIUS * 0.995, "albedo": BALL},
            "floor": {"half_side": 400.0, "albedo": FLOOR}, "spp": SPP, "view": view}


def write_mesh(path):
    """The draped cloth as raw little-endian arrays: a JSON header line, then positions
    (f32 x 3), UVs (f32 x 2) and triangle indices (u32 x 3)."""
    pos, uv, faces = drape.vertices(MESH_N)
    head = json.dumps({"vertices": len(pos), "triangles": len(faces)}).encode() + b"\n"
    with open(path, "wb") as f:
        f.write(head)
        f.write(pos.astype("<f4").tobytes())
        f.write(uv.astype("<f4").tobytes())
        f.write(faces.astype("<u4").tobytes())


def mitsuba_picture(table, cfg, cache):
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    import clothbake.mitsuba

    clothbake.mitsuba.register()

    class S:
        width, height, pass_spp = cfg["width"], cfg["height"], 8

    mesh = scene.cloth_mesh(cache, MESH_N)
    sun = {"type": "directional", "direction": [-x for x in cfg["sun"]],
           "irradiance": {"type": "rgb", "value": cfg["sun_irradiance"]}}
    sky = {"type": "constant", "radiance": {"type": "rgb", "value": cfg["sky_radiance"]}}
    sc = scene.build(mi, cfg["view"], scene.plugin(table, cfg["periods"]), mesh, sky, S,
                     extra={"sun": sun})
    return scene.render(mi, sc, S, cfg["spp"], False)


def run(cmd, what):
    t = time.time()
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        print(f"mainstream: {what} failed:\n{r.stdout}\n{r.stderr}", file=sys.stderr)
        sys.exit(1)
    print(f"  {what}: {time.time() - t:.0f} s", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clothbake", required=True)
    ap.add_argument("--out", default=str(ROOT / "docs" / "gallery"))
    ap.add_argument("--cache", default=str(ROOT / "target" / "gallery"))
    a = ap.parse_args(argv)
    cache = pathlib.Path(a.cache)
    work = cache / "mainstream"
    work.mkdir(parents=True, exist_ok=True)
    write_mesh(work / "drape.bin")
    fabric = ROOT / "tables" / f"{FABRIC}.wif"
    baker = gallery.Baker(a.clothbake, cache)
    table = baker.table(FABRIC + "-spatial", fabric, "16,32,16,32", "--spatial")
    # The fitted materials, tiled as the plugin tiles the table.
    subprocess.run([a.clothbake, "export", "--weave", str(fabric), "--gltf",
                    str(work / "cloth.glb"), "--blender", str(work / "cloth.py"),
                    "--periods-per-uv", str(scene.PERIODS), "--force"], check=True)
    rows, means = [], {}
    for view in ("far", "close"):
        cfg = config(view)
        cj = work / f"config-{view}.json"
        cj.write_text(json.dumps(cfg))
        t = time.time()
        mitsuba = mitsuba_picture(table, cfg, cache)
        print(f"  {view}, Mitsuba 3: {time.time() - t:.0f} s", flush=True)
        run(["node", str(HERE / "three_scene.mjs"), str(work / "cloth.glb"),
             str(work / "drape.bin"), str(cj), str(work / "three.f32")], f"{view}, three.js")
        run([sys.executable, str(HERE / "cycles_scene.py"), str(work / "cloth.py"),
             str(work / "drape.bin"), str(cj), str(work / "cycles.f32")], f"{view}, Cycles")
        shape = (cfg["height"], cfg["width"], 3)
        three = np.fromfile(work / "three.f32", dtype="<f4").reshape(shape).astype(np.float64)
        cycles = np.fromfile(work / "cycles.f32", dtype="<f4").reshape(shape).astype(np.float64)
        e = tonemap.auto_exposure(mitsuba)
        gap = np.full((cfg["height"], 4, 3), 255, dtype=np.uint8)
        rows.append(np.concatenate([tonemap.to_8bit(mitsuba, e), gap, tonemap.to_8bit(three, e),
                                    gap, tonemap.to_8bit(cycles, e)], axis=1))
        means[view] = {k: [round(float(x), 4) for x in v.mean(axis=(0, 1))]
                       for k, v in (("mitsuba", mitsuba), ("three.js", three),
                                    ("cycles", cycles))}
    band = np.full((4, rows[0].shape[1], 3), 255, dtype=np.uint8)
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    gallery.write_png(np.concatenate([rows[0], band, rows[1]], axis=0),
                      out / f"{FABRIC}-three-renderers.png")
    print(f"mainstream: {FABRIC}-three-renderers.png; image means {means}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
