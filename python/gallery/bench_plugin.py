"""The clothbake Mitsuba plugin against Mitsuba's native ``measured`` BSDF on the gallery's far
scene (issue 38): cost per sample and noise at equal samples, in ``llvm_ad_rgb``.

    PYTHONPATH=<staged clothbake package> DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so \\
    python3 python/gallery/bench_plugin.py --table twill.exr --rgl twill.bsdf \\
        [--width 256 --height 192 --spp 8 --rounds 6] [--profile]

``--table``: the twill baked as the gallery bakes it (``clothbake bake --weave
tables/twill.json --res 32,64,32,64 --precision f32``); ``--rgl``: that table exported as the
gallery exports it (``clothbake export --table T --rgl F --rgl-res 16,24,32``).

Three renderings of one scene (scene.py, view "far", the cloth's BSDF swapped), interleaved
round by round (plugin, measured, measured-symbolic, plugin, ...), one ``mi.render`` of
``--spp`` samples a pixel each, the seed the round's number (so the rounds are independent
renders and the run is deterministic):

* ``plugin``: the clothbake plugin (``table=``), Dr.Jit's symbolic loops and calls off (the
  plugin needs them off: evaluated wavefronts);
* ``measured``: Mitsuba's ``measured`` BSDF in the same mode (symbolic off): the same
  integrator's wavefronts, only the cloth's BSDF differs;
* ``measured-symbolic``: ``measured`` with symbolic loops and calls on (one compiled kernel a
  pass), as the gallery renders scenes without the plugin.

Each mode is rendered once before the rounds (kernel compilation, the table's first sample).
Cost: the seconds of a render over its samples (pixels x spp). Noise: per pixel, the variance
of the rounds' images (independent seeds, so the variance of one render at ``--spp``), summed
over the cloth's pixels (those whose camera ray through the pixel centre first hits the cloth)
and over the whole image, relative to the squared mean image: the relative MSE of one render.
Equal quality at equal samples means equal relative MSE; ``efficiency`` = 1 / (relMSE x
seconds). The script also prints how far the plugin's and measured's mean images are apart on
the cloth (the two are the same table, interpolated differently).

``--profile``: one plugin render with the BSDF's methods timed (their wavefronts evaluated
first, so the integrator's pending work is not counted in them) and split into the steps of
_wavefront.py, and the number of calls and lanes.
"""

import argparse
import gc
import pathlib
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))

import scene  # noqa: E402


class Settings:
    def __init__(self, width, height):
        self.width, self.height = width, height


def cloth_mask(mi, dr, sc):
    """(H, W) bool: the pixels whose centre ray first hits the cloth."""
    sensor = sc.sensors()[0]
    w, h = sensor.film().crop_size()
    idx = dr.arange(mi.UInt32, w * h)
    x = mi.Float(idx % w) + 0.5
    y = mi.Float(idx // w) + 0.5
    ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f(x / w, y / h), mi.Point2f(0.5, 0.5))
    si = sc.ray_intersect(ray)
    cloth = [s for s in sc.shapes() if s.id() == "cloth"][0]
    hit = si.is_valid() & (si.shape == mi.ShapePtr(cloth))
    return np.asarray(hit, dtype=bool).reshape(h, w)


def render(mi, dr, sc, spp, seed, symbolic):
    """The image (H, W, 3) and the seconds of the render (the scene built beforehand)."""
    if callable(sc):
        sc = sc()
    dr.set_flag(dr.JitFlag.SymbolicLoops, symbolic)
    dr.set_flag(dr.JitFlag.SymbolicCalls, symbolic)
    t = time.perf_counter()
    img = mi.render(sc, spp=spp, seed=seed)
    img = np.asarray(img, dtype=np.float64)[..., :3]
    dt = time.perf_counter() - t
    del sc
    gc.collect()
    return img, dt


def rel_mse(imgs, mask):
    """The relative MSE of one image of the stack (per-pixel variance over the stack, ddof 1),
    over the masked pixels: sum var / sum mean^2."""
    s = np.stack(imgs)[:, mask]  # (K, P, 3)
    var = s.var(axis=0, ddof=1)
    mean = s.mean(axis=0)
    return float(var.sum() / (mean ** 2).sum())


def profile(mi, dr, sc_plugin, spp):
    """Times the plugin's methods and their steps over one render."""
    import clothbake._wavefront as wf

    stats = {}

    def timed(name, fn):
        def run(*a, **k):
            t = time.perf_counter()
            r = fn(*a, **k)
            st = stats.setdefault(name, [0, 0.0, 0])
            st[0] += 1
            st[1] += time.perf_counter() - t
            return r
        return run

    # The module's helpers (each step of a call).
    saved = {n: getattr(wf, n) for n in ("_rows", "_directions", "_f", "_mask") if hasattr(wf, n)}
    for n, fn in saved.items():
        setattr(wf, n, timed(n, fn))
    bsdf = [s for s in sc_plugin.shapes() if s.id() == "cloth"][0].bsdf()
    cls = type(bsdf)
    methods = {n: getattr(cls, n) for n in ("eval", "pdf", "eval_pdf", "sample")}
    conv = {n: getattr(cls, n) for n in ("_value", "_density", "_pair") if hasattr(cls, n)}
    table = bsdf._cloth.table
    tmethods = {}

    class TimedTable:
        def __getattr__(self, n):
            fn = getattr(table, n)
            return timed("Table." + n, fn) if callable(fn) else fn

    bsdf._cloth.table = TimedTable()

    def wrap(name, fn):
        def run(self, ctx, si, *a, **k):
            t = time.perf_counter()
            dr.eval(si, *[x for x in a if not isinstance(x, (bool, float, int))])
            t1 = time.perf_counter()
            r = fn(self, ctx, si, *a, **k)
            dr.eval(r)
            t2 = time.perf_counter()
            st = stats.setdefault(name, [0, 0.0, 0])
            st[0] += 1
            st[1] += t2 - t1
            st[2] += dr.width(si.wi)
            ev = stats.setdefault("(pending Dr.Jit work evaluated on entry)", [0, 0.0, 0])
            ev[0] += 1
            ev[1] += t1 - t
            return r
        return run

    for n, fn in methods.items():
        setattr(cls, n, wrap(n, fn))
    for n, fn in conv.items():
        setattr(cls, n, timed(n, fn))
    _, total = render(mi, dr, sc_plugin, spp, 1000, False)
    for n, fn in methods.items():
        setattr(cls, n, fn)
    for n, fn in conv.items():
        setattr(cls, n, fn)
    for n, fn in saved.items():
        setattr(wf, n, fn)
    bsdf._cloth.table = table
    del tmethods
    print(f"profile: one plugin render {total:.2f} s")
    for n, (calls, secs, lanes) in sorted(stats.items(), key=lambda kv: -kv[1][1]):
        extra = f", {lanes / max(calls, 1):.0f} lanes a call" if lanes else ""
        print(f"  {n:45s} {calls:4d} calls {secs:7.3f} s ({100 * secs / total:5.1f}%){extra}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--table", required=True)
    ap.add_argument("--rgl", required=True)
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--height", type=int, default=192)
    ap.add_argument("--spp", type=int, default=8)
    ap.add_argument("--rounds", type=int, default=6)
    ap.add_argument("--cache", default=str(ROOT / "target" / "gallery"))
    ap.add_argument("--profile", action="store_true")
    ap.add_argument("--modes", default="plugin,measured,measured-symbolic")
    a = ap.parse_args(argv)

    import drjit as dr
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    import clothbake.mitsuba

    clothbake.mitsuba.register()
    cache = pathlib.Path(a.cache)
    cache.mkdir(parents=True, exist_ok=True)
    mesh = scene.cloth_mesh(cache, 257)
    settings = Settings(a.width, a.height)
    emitter = scene.environment(None)
    bsdfs = {"plugin": scene.plugin(a.table), "measured": scene.measured(a.rgl),
             "measured-symbolic": scene.measured(a.rgl)}
    modes = [m for m in a.modes.split(",") if m]
    def build(m):
        # One scene at a time: a symbolic call dispatches over every live BSDF of its
        # domain, so the plugin's scene must not be alive during a symbolic render.
        return scene.build(mi, "far", bsdfs[m], mesh, emitter, settings)

    sc = build("measured")
    mask = cloth_mask(mi, dr, sc)
    del sc
    whole = np.ones_like(mask)
    samples = a.width * a.height * a.spp
    print(f"far scene {a.width}x{a.height}, {a.spp} spp a render, {a.rounds} rounds, "
          f"cloth {mask.mean() * 100:.1f}% of the pixels; {time.strftime('%Y-%m-%d %H:%M:%S')}")
    if a.profile:
        sc = build("plugin")
        render(mi, dr, sc, a.spp, 999, False)
        profile(mi, dr, sc, a.spp)
        return 0
    for m in modes:  # warm-up: kernels compiled (and cached), the sampler's tables built
        render(mi, dr, lambda: build(m), a.spp, 999, m == "measured-symbolic")
    imgs = {m: [] for m in modes}
    secs = {m: [] for m in modes}
    for r in range(a.rounds):
        for m in modes:
            img, dt = render(mi, dr, lambda: build(m), a.spp, r, m == "measured-symbolic")
            imgs[m].append(img)
            secs[m].append(dt)
        print(f"round {r}: " + ", ".join(f"{m} {secs[m][-1]:.2f} s" for m in modes), flush=True)
    print()
    print(f"{'mode':18s} {'s/render (median)':>18s} {'ns/sample':>10s} {'relMSE cloth':>13s} "
          f"{'relMSE image':>13s} {'efficiency':>11s}")
    res = {}
    for m in modes:
        t = float(np.median(secs[m]))
        rc, ri = rel_mse(imgs[m], mask), rel_mse(imgs[m], whole)
        res[m] = (t, rc, ri)
        print(f"{m:18s} {t:18.2f} {1e9 * t / samples:10.0f} {rc:13.5f} {ri:13.5f} "
              f"{1.0 / (rc * t):11.1f}")
    if "plugin" in res:
        for m in modes:
            if m == "plugin":
                continue
            tp, rcp, rip = res["plugin"]
            tm, rcm, rim = res[m]
            print(f"plugin / {m}: time {tp / tm:.2f}x, relMSE cloth {rcp / rcm:.2f}x, "
                  f"image {rip / rim:.2f}x; time x relMSE (cloth) {tp * rcp / (tm * rcm):.2f}x")
        if "measured" in res:
            p = np.stack(imgs["plugin"]).mean(axis=0)[mask]
            q = np.stack(imgs["measured"]).mean(axis=0)[mask]
            print(f"cloth mean radiance: plugin {p.mean(axis=0).round(4)}, measured "
                  f"{q.mean(axis=0).round(4)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
