"""The gallery (`cargo xtask gallery`): pictures of every shipped fabric as people photograph
cloth, rendered by Mitsuba 3 (``llvm_ad_rgb``), into docs/gallery/ with its README.

    python3 python/gallery/gallery.py --clothbake target/release/clothbake
        [--out docs/gallery] [--cache target/gallery] [--envmap SKY.exr] [--quick]
        [--only NAME,...]

Needs the ``clothbake`` Python package, mitsuba and numpy, and a libLLVM >= 17 in
DRJIT_LIBLLVM_PATH (`cargo xtask gallery` stages the package and finds the library).

Scene (scene.py): a square cloth draped over a ball on a floor (drape.py), lit by Mitsuba's
``sunsky`` (a physical sky with a sun) or a lat-long EXR (``--envmap``), path traced
(``path``: multiple importance sampling of the emitter and the BSDF's own sampling; shadows
and light bouncing between cloth, ball and floor), then exposure and the ACES tone curve
(tonemap.py), written as indexed-colour PNGs (png.py). Tables are baked with the
``clothbake`` binary and cached under ``--cache``, keyed by the fabric file, the bake options
and the binary, so a rerun renders only.
"""

import argparse
import hashlib
import json
import pathlib
import subprocess
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))

import png  # noqa: E402
import scene  # noqa: E402
import tonemap  # noqa: E402


class Settings:
    """Sizes and sample counts: the full gallery, or `--quick` (the CI test)."""

    def __init__(self, quick):
        self.quick = quick
        self.width, self.height = (160, 120) if quick else (1024, 768)
        # Samples a pixel: scenes with the native `measured` BSDF only, and scenes with the
        # clothbake plugin: the same count (a plugin sample costs about 1.5 times measured's,
        # docs/results/performance.md).
        self.spp = 4 if quick else 32
        self.spp_plugin = self.spp
        self.pass_spp = 4 if quick else 8
        self.res = "8,16,8,16" if quick else "32,64,32,64"
        self.spatial_res = "4,8,4,8" if quick else "16,32,16,32"
        # Baking every bounce (--bounces all) takes about 5 minutes at the default grid.
        self.all_res = "4,8,4,8" if quick else "16,32,16,32"
        self.rgl_res = "8,12,16" if quick else "16,24,32"


# The comparisons: the fabric each is shown on.
BOUNCES_FABRIC = "denim"
MODEL_FABRIC = "satin5"
MEASURED_FABRIC = "twill"


def fabrics():
    """The shipped fabrics, (name, path), in `clothbake fabrics` order of files: tables/*.json
    then tables/*.wif, each sorted by name."""
    out = []
    for ext in ("json", "wif"):
        out += [(p.stem, p) for p in sorted((ROOT / "tables").glob(f"*.{ext}"))]
    return out


class Baker:
    """Bakes and exports with the `clothbake` binary into the cache, once per key."""

    def __init__(self, exe, cache):
        self.exe = str(exe)
        self.dir = pathlib.Path(cache) / "tables"
        self.dir.mkdir(parents=True, exist_ok=True)
        h = hashlib.sha256()
        with open(self.exe, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
        self.binary = h.hexdigest()
        self.seconds = 0.0  # baking done by this run
        # How long each cached file took to make, so that the cost is known on reruns.
        self.times_path = self.dir / "times.json"
        self.times = json.loads(self.times_path.read_text()) if self.times_path.exists() else {}
        self.used = set()

    def _key(self, fabric, args):
        h = hashlib.sha256(self.binary.encode())
        h.update(pathlib.Path(fabric).read_bytes())
        h.update(json.dumps(args).encode())
        return h.hexdigest()[:16]

    def _run(self, args, out):
        self.used.add(out.name)
        if out.exists():
            return out
        t = time.time()
        tmp = out.with_name(out.stem + ".part" + out.suffix)
        subprocess.run([self.exe, *[str(a).replace("{OUT}", str(tmp)) for a in args]],
                       check=True)
        tmp.rename(out)
        dt = time.time() - t
        self.seconds += dt
        self.times[out.name] = round(dt, 1)
        self.times_path.write_text(json.dumps(self.times, indent=1))
        print(f"  baked {out.name} in {dt:.1f} s", flush=True)
        return out

    def cost(self):
        """Seconds it took to make the files this run used (cached ones included)."""
        return sum(self.times.get(n, 0.0) for n in self.used)

    def table(self, name, fabric, res, *extra):
        """The table of ``fabric`` (EXR, f32) on the grid ``res`` with extra bake options."""
        args = ["bake", "--weave", str(fabric), "--res", res, "--precision", "f32", *extra]
        out = self.dir / f"{name}-{self._key(fabric, args)}.exr"
        return self._run([*args, "-o", "{OUT}", "--quiet", "--force"], out)

    def rgl(self, name, fabric, table, rgl_res):
        """Mitsuba's `measured` file of a table (`clothbake export --rgl`)."""
        args = ["export", "--table", table.name, "--rgl-res", rgl_res]
        out = self.dir / f"{name}-{self._key(fabric, args)}.bsdf"
        return self._run(["export", "--table", str(table), "--rgl", "{OUT}", "--rgl-res", rgl_res,
                          "--quiet", "--force"], out)


class Picture:
    """One PNG: a view and one BSDF, or two shown split down the middle (left | right)."""

    def __init__(self, name, caption, view, left, right=None, labels=None):
        self.name, self.caption, self.view = name, caption, view
        self.left, self.right, self.labels = left, right, labels


def plan(settings, baker):
    """Every picture, its tables baked (cached)."""
    s = settings
    pics = []
    for name, path in fabrics():
        table = baker.table(name, path, s.res)
        rgl = baker.rgl(name, path, table, s.rgl_res)
        pics.append(Picture(
            f"{name}-far", f"`{path.name}` draped over a ball: its averaged table "
            f"({s.res} cells) through Mitsuba's native `measured` BSDF "
            "(`clothbake export --rgl`).", "far", scene.measured(rgl)))
        table = baker.table(name + "-spatial", path, s.spatial_res, "--spatial")
        pics.append(Picture(
            f"{name}-close", f"`{path.name}` up close: its spatially varying table "
            f"(`bake --spatial` on the {s.spatial_res} grid), which carries its yarns, through "
            f"the clothbake plugin with `periods` = {scene.PERIODS:g} weave periods per UV unit "
            f"(about {scene.PERIODS / (2 * scene.drape.HALF_SIDE):.0f} per unit of length, "
            "the ball's radius being 1): each sample traces the yarns at its point "
            "(docs/science/spatial.md, the point level).", "close",
            scene.plugin(table, periods=scene.PERIODS)))
    fab = dict(fabrics())
    if BOUNCES_FABRIC in fab:
        path = fab[BOUNCES_FABRIC]
        one = baker.table(BOUNCES_FABRIC + "-b1", path, s.all_res)
        every = baker.table(BOUNCES_FABRIC + "-ball", path, s.all_res, "--bounces", "all")
        pics.append(Picture(
            f"{BOUNCES_FABRIC}-direct-vs-all-bounces",
            f"`{path.name}`, left: direct reflection only (`--bounces 1`); right: every bounce "
            f"between the yarns (`--bounces all`). Both tables on the coarser {s.all_res} grid "
            "(baking every bounce takes about 5 minutes at the default grid), through the "
            "plugin.", "far", scene.plugin(one), scene.plugin(every),
            ("--bounces 1", "--bounces all")))
    if MODEL_FABRIC in fab:
        path = fab[MODEL_FABRIC]
        table = baker.table(MODEL_FABRIC, path, s.res)
        pics.append(Picture(
            f"{MODEL_FABRIC}-model-vs-table",
            f"`{path.name}`, left: the analytic model evaluated per shading point (plugin "
            f"`weave=`); right: its table ({s.res} cells, plugin `table=`).", "far",
            scene.plugin_model(path), scene.plugin(table), ("model", "table")))
    if MEASURED_FABRIC in fab:
        path = fab[MEASURED_FABRIC]
        table = baker.table(MEASURED_FABRIC, path, s.res)
        rgl = baker.rgl(MEASURED_FABRIC, path, table, s.rgl_res)
        pics.append(Picture(
            f"{MEASURED_FABRIC}-plugin-vs-measured",
            f"`{path.name}`, left: its table ({s.res} cells) through the clothbake plugin "
            "(the loader's interpolation and importance sampling); right: the same table "
            f"exported to Mitsuba's native `measured` BSDF ({s.rgl_res} RGL grid).", "far",
            scene.plugin(table), scene.measured(rgl), ("plugin", "measured")))
    return pics


def split(left, right):
    """The left half of one picture beside the right half of the other, a 2-pixel light line
    between."""
    w = left.shape[1]
    out = np.concatenate([left, right], axis=1)
    out[:, w - 1: w + 1] = 1e3
    return out


def write_png(img8, path):
    """The 8-bit sRGB picture as an indexed-colour PNG (png.py: half the size of RGB)."""
    png.write(path, np.ascontiguousarray(img8))


def write_readme(out, pics, results, settings, light, bake_seconds):
    lines = [
        "# Gallery",
        "",
        "Generated by `cargo xtask gallery` (do not edit by hand; `python/gallery/`). Every "
        "picture is rendered by Mitsuba 3.9 in `llvm_ad_rgb`: a square cloth draped over a ball "
        "(radius 1) on a grey floor, "
        f"lit by {light}, path traced (`path` integrator, multiple importance sampling of the "
        "light and of the BSDF's own sampling, shadows, light bouncing between cloth, ball and "
        f"floor), {settings.width} x {settings.height} pixels, {settings.spp} samples a pixel "
        "through `measured` and through the clothbake plugin alike (a plugin sample costs "
        "about 1.5 times `measured`'s, docs/results/performance.md). "
        f"Tone mapping: one fixed exposure per view for the sky ({scene.SKY_EXPOSURE['far']:g} "
        f"far, {scene.SKY_EXPOSURE['close']:g} close: the same for every fabric, so that "
        "fabrics compare), then the ACES filmic curve as fitted by Narkowicz (2015), "
        "`x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)`, and the sRGB transfer function "
        "(`python/gallery/tonemap.py`); the PNGs are 8-bit indexed colour, a 256-colour palette "
        "fitted to each picture (`python/gallery/png.py`: half the size of 8-bit RGB, under one "
        "level of error per channel on average). Split pictures show two renders of one scene, the left "
        "half of one and the right half of the other.",
        "",
        f"Cost: {sum(results[p.name]['seconds'] for p in pics if p.name in results) / 60:.0f} "
        f"minutes of rendering for the {len(pics)} pictures and {bake_seconds / 60:.0f} "
        "minutes of baking their tables (cached under target/gallery: a rerun only renders), "
        "on the 2-core development machine while other jobs shared it (`cargo xtask gallery "
        "--only NAME` renders some again).",
        "",
    ]
    for pic in pics:
        if pic.name not in results:
            lines += [f"## {pic.name}", "", "(not rendered yet: `cargo xtask gallery --only "
                      f"{pic.name}`)", ""]
            continue
        r = results[pic.name]
        lines += [f"## {pic.name}", "", f"![{pic.name}]({pic.name}.png)", "",
                  f"{pic.caption} Rendered in {r['seconds']:.0f} s.", ""]
    import mainstream

    name = f"{mainstream.FABRIC}-three-renderers"
    if (out / f"{name}.png").exists():
        lines += [f"## {name}", "", f"![{name}]({name}.png)", "", mainstream.CAPTION, ""]
    (out / "README.md").write_text("\n".join(lines))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clothbake", required=True, help="the clothbake binary")
    ap.add_argument("--out", default=str(ROOT / "docs" / "gallery"))
    ap.add_argument("--cache", default=str(ROOT / "target" / "gallery"))
    ap.add_argument("--envmap", help="a lat-long EXR environment instead of the sun and sky")
    ap.add_argument("--exposure", type=float, help="default: fixed for the sky, auto for --envmap")
    ap.add_argument("--quick", action="store_true", help="small and noisy: exercises the pipeline")
    ap.add_argument("--only", help="comma-separated picture names (or prefixes)")
    ap.add_argument("--bake-only", action="store_true", help="bake (or find) the tables, no render")
    a = ap.parse_args(argv)
    if a.envmap and not pathlib.Path(a.envmap).is_file():
        print(f"gallery: --envmap {a.envmap}: no such file; give a lat-long .exr", file=sys.stderr)
        return 2

    import mitsuba as mi

    try:
        mi.set_variant("llvm_ad_rgb")
    except Exception as e:  # noqa: BLE001
        print(f"gallery: Mitsuba's llvm_ad_rgb variant is not available ({e}); "
              "pip install mitsuba", file=sys.stderr)
        return 2
    import clothbake.mitsuba

    clothbake.mitsuba.register()
    settings = Settings(a.quick)
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    cache = pathlib.Path(a.cache)
    baker = Baker(a.clothbake, cache)
    only = [o for o in (a.only or "").split(",") if o]
    every = plan(settings, baker)
    pics = [p for p in every if not only or any(p.name.startswith(o) for o in only)]
    if a.bake_only:
        print(f"gallery: tables for {len(pics)} pictures in {baker.dir} ({baker.seconds:.0f} s)")
        return 0
    mesh = scene.cloth_mesh(cache, 65 if a.quick else 257)
    emitter = scene.environment(a.envmap)
    exposure = a.exposure or (None if a.envmap else scene.SKY_EXPOSURE)
    manifest = out / "gallery.json"
    results = {}
    if manifest.exists() and not a.quick:
        # Earlier runs' pictures (a run with --only renders some of them again).
        results = json.loads(manifest.read_text()).get("pictures", {})
    t_all = time.time()
    for pic in pics:
        t = time.time()
        bsdfs = [pic.left] + ([pic.right] if pic.right is not None else [])
        spp = settings.spp_plugin if any(map(scene.uses_plugin, bsdfs)) else settings.spp

        def render(b, half=None):
            sc = scene.build(mi, pic.view, b, mesh, emitter, settings, half)
            return scene.render(mi, sc, settings, spp, not scene.uses_plugin(b))

        if pic.right is None:
            img = render(pic.left)
        else:
            img = split(render(pic.left, "left"), render(pic.right, "right"))
        e = exposure[pic.view] if isinstance(exposure, dict) else exposure
        e = e or tonemap.auto_exposure(img)
        write_png(tonemap.to_8bit(img, e), out / f"{pic.name}.png")
        cloth = img.mean(axis=(0, 1))
        results[pic.name] = {"seconds": round(time.time() - t, 1),
                             "mean": [round(float(x), 5) for x in cloth],
                             "finite": bool(np.isfinite(img).all()),
                             "width": img.shape[1], "height": img.shape[0]}
        print(f"{pic.name}.png: {time.time() - t:.0f} s", flush=True)
    total = {"render": time.time() - t_all, "bake": baker.seconds}
    results = {p.name: results[p.name] for p in every if p.name in results}
    light = (f"the environment `{pathlib.Path(a.envmap).name}`" if a.envmap else
             "Mitsuba's `sunsky` (Hosek-Wilkie sky and sun, turbidity "
             f"{scene.TURBIDITY:g}, the sun {scene.SUN_ELEVATION:g} degrees above the horizon)")
    manifest.write_text(json.dumps({"pictures": results}, indent=1) + "\n")
    if not a.quick:
        write_readme(out, every, results, settings, light, baker.cost())
    print(f"gallery: {len(pics)} pictures in {out} ({total['render']:.0f} s rendering, "
          f"{total['bake']:.0f} s baking)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
