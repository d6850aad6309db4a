"""The Mitsuba plugin in the llvm variant (``llvm_ad_rgb``: whole wavefronts through the batch
calls) against the scalar plugin, lane by lane, against the independent per-pixel computation
of test_mitsuba.py, and against Mitsuba's native ``measured`` BSDF.

Needs an LLVM of version 17 or later for Dr.Jit (``DRJIT_LIBLLVM_PATH``; tests/tests/python.rs
finds one and sets it).
"""

import math

import numpy as np
import pytest

mi = pytest.importorskip(
    "mitsuba", reason="mitsuba is not installed (pip install mitsuba): the rendering tests are skipped"
)

import clothbake  # noqa: E402
import clothbake.mitsuba as cbm  # noqa: E402
from test_mitsuba import RES, directional, reference, rel_rmse, render, scene  # noqa: E402

N = 2000


def use(variant):
    mi.set_variant(variant)
    cbm.register()


@pytest.fixture(scope="module")
def tables(twill_path, tmp_path_factory):
    d = tmp_path_factory.mktemp("llvm")
    twill, gingham = d / "twill.exr", d / "gingham.exr"
    clothbake.bake(clothbake.Fabric(twill_path), res=(16, 32, 16, 32)).save(twill, precision="f32")
    g = clothbake.Fabric(str(twill_path.parent / "gingham.wif"))
    clothbake.bake(g, res=(8, 16, 8, 16), spatial=True).save(gingham, precision="f32")
    return {"twill": twill, "gingham": gingham}


def lanes(seed=5):
    """N random shading situations: eye and light over the whole sphere (both sides, the
    opposite-side pairs included), a tangent dp_du off the shading plane, uv, and samples."""
    rng = np.random.default_rng(seed)

    def sphere(n):
        v = rng.normal(size=(n, 3))
        return v / np.linalg.norm(v, axis=1, keepdims=True)

    wi, wo = sphere(N), sphere(N)
    a = rng.uniform(0, 2 * math.pi, N)
    du = np.stack([np.cos(a), np.sin(a), rng.uniform(-0.5, 0.5, N)], axis=1)
    uv = rng.uniform(0, 1, (N, 2))
    u2 = rng.uniform(0, 1, (N, 2))
    return wi, wo, du, uv, u2


def scalar_answers(props, data):
    """eval, pdf, sample (wo, pdf, weight) of the scalar plugin, lane by lane."""
    use("scalar_rgb")
    bsdf = mi.load_dict(props)
    ctx = mi.BSDFContext()
    wi, wo, du, uv, u2 = data
    ev, pd, sw, sp, sv = [], [], [], [], []
    for k in range(N):
        si = mi.SurfaceInteraction3f()
        si.sh_frame = mi.Frame3f(mi.Vector3f(1, 0, 0), mi.Vector3f(0, 1, 0), mi.Vector3f(0, 0, 1))
        si.wi = mi.Vector3f(*wi[k])
        si.dp_du = mi.Vector3f(*du[k])
        si.uv = mi.Point2f(*uv[k])
        w = mi.Vector3f(*wo[k])
        ev.append(list(bsdf.eval(ctx, si, w)))
        pd.append(float(bsdf.pdf(ctx, si, w)))
        bs, weight = bsdf.sample(ctx, si, 0.5, mi.Point2f(*u2[k]))
        sw.append(list(bs.wo))
        sp.append(float(bs.pdf))
        sv.append(list(weight))
    return [np.array(x, dtype=np.float64) for x in (ev, pd, sw, sp, sv)]


def llvm_answers(props, data):
    use("llvm_ad_rgb")
    bsdf = mi.load_dict(props)
    ctx = mi.BSDFContext()
    wi, wo, du, uv, u2 = data
    vec = lambda a: mi.Vector3f(*(mi.Float(a[:, j].astype(np.float32)) for j in range(3)))
    si = mi.SurfaceInteraction3f()
    si.sh_frame = mi.Frame3f(vec(np.tile([1.0, 0, 0], (N, 1))), vec(np.tile([0, 1.0, 0], (N, 1))),
                             vec(np.tile([0, 0, 1.0], (N, 1))))
    si.wi = vec(wi)
    si.dp_du = vec(du)
    si.uv = mi.Point2f(mi.Float(uv[:, 0].astype(np.float32)), mi.Float(uv[:, 1].astype(np.float32)))
    w = vec(wo)
    ev = np.asarray(bsdf.eval(ctx, si, w)).reshape(3, -1).T
    pd = np.asarray(bsdf.pdf(ctx, si, w)).reshape(-1)
    u = mi.Point2f(mi.Float(u2[:, 0].astype(np.float32)), mi.Float(u2[:, 1].astype(np.float32)))
    bs, weight = bsdf.sample(ctx, si, mi.Float(np.full(N, 0.5, dtype=np.float32)), u)
    sw = np.asarray(bs.wo).reshape(3, -1).T
    return [np.asarray(x, dtype=np.float64) for x in
            (ev, pd, sw, np.asarray(bs.pdf).reshape(-1), np.asarray(weight).reshape(3, -1).T)]


def close(a, b, rtol=2e-3, atol=1e-5, share=0.0):
    """The share of lanes where a and b differ beyond the tolerance is at most ``share``."""
    bad = ~np.isclose(a, b, rtol=rtol, atol=atol)
    if bad.ndim > 1:
        bad = bad.any(axis=1)
    return bad.mean() <= share, f"{bad.sum()} of {len(bad)} lanes differ"


@pytest.mark.parametrize("kind", ["table", "weave", "periods", "yarns"])
def test_wavefront_matches_scalar_lane_by_lane(kind, twill_path, tables):
    """The same N lanes through the scalar plugin (one native call per lookup) and the llvm
    plugin (one batch call per method): eval, pdf and sample agree lane by lane."""
    props = {
        "table": {"type": "clothbake", "table": str(tables["twill"])},
        "weave": {"type": "clothbake", "weave": str(twill_path)},
        "periods": {"type": "clothbake", "table": str(tables["gingham"]), "periods": 3.0},
        "yarns": {"type": "clothbake", "weave": str(twill_path), "periods": 3.0},
    }[kind]
    data = lanes()
    s = scalar_answers(props, data)
    v = llvm_answers(props, data)
    names = ["eval", "pdf", "sample.wo", "sample.pdf", "sample.weight"]
    lit = (s[0].max(axis=1) > 0).mean()
    print(f"{kind}: {lit:.2f} of the lanes lit; largest eval {s[0].max():.3f}")
    assert 0.15 < lit < 0.6  # the opposite-side and one-sided cases are exercised
    for name, a, b in zip(names, s, v):
        # Sampling the table inverts a CDF: where float32 rounding of the frame moves a lane
        # across a cell boundary its sample differs; allow that for a few lanes.
        share = 0.01 if name.startswith("sample") and kind != "weave" else 0.0
        # The yarns traced: where float32 rounding moves a lane's eye ray across a yarn's
        # edge or a shadow's, it meets another point; allow that for a few lanes.
        if kind in ("yarns", "periods"):
            share = max(share, 0.02)
        ok, why = close(b, a, share=share)
        assert ok, f"{kind} {name}: {why}"


def test_llvm_render_matches_independent_computation(twill_path, tables, positions_llvm):
    """test_mitsuba.py's sphere, rendered in llvm_ad_rgb through the plugin (weave= and
    table=), against the independent per-pixel E f_r cos(theta_i)."""
    fabric = clothbake.Fabric(twill_path)
    ref, mask = reference(fabric, positions_llvm)
    use("llvm_ad_rgb")
    direct = {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0}
    img_w = render(scene({"type": "clothbake", "weave": str(twill_path)}, direct, directional(), 16), 16)
    e_w = rel_rmse(img_w, ref, mask)
    print(f"llvm: relative RMSE vs the independent per-pixel computation: weave= {e_w:.4f}")
    assert e_w < 0.05


@pytest.fixture(scope="module")
def positions_llvm():
    use("scalar_rgb")
    sc = scene({"type": "diffuse"}, {"type": "aov", "aovs": "pp:position"}, directional(), 64)
    img = np.array(mi.render(sc, spp=64), dtype=np.float64)
    return img[..., -3:]


def test_llvm_plugin_matches_measured_under_a_sky(tables, tmp_path):
    """Path tracing with MIS under an environment: the plugin's table (its own importance
    sampling) against Mitsuba's native `measured` BSDF of the same table (`clothbake export
    --table ... --rgl`), both in llvm_ad_rgb; the images agree to within their noise."""
    import os
    import subprocess

    exe = os.environ.get("CLOTHBAKE_BIN")
    if not exe:
        pytest.skip("CLOTHBAKE_BIN (the clothbake binary) is not set: tests/tests/python.rs sets it")
    rgl = tmp_path / "twill.bsdf"
    subprocess.run([exe, "export", "--table", str(tables["twill"]), "--rgl", str(rgl), "-q"],
                   check=True)
    use("llvm_ad_rgb")
    sky = {"type": "constant", "radiance": {"type": "rgb", "value": 1.0}}
    sun = directional()
    path = {"type": "path", "max_depth": 3}

    def shot(bsdf, seed):
        sc = mi.load_dict({
            "type": "scene", "integrator": path,
            "sensor": {
                "type": "perspective", "fov": 40,
                "to_world": mi.ScalarTransform4f().look_at(origin=[0, -3, 2.5], target=[0, 0, 0],
                                                           up=[0, 0, 1]),
                "film": {"type": "hdrfilm", "width": 24, "height": 24, "rfilter": {"type": "box"},
                         "pixel_format": "rgb"},
                "sampler": {"type": "independent"},
            },
            "cloth": {"type": "rectangle", "bsdf": bsdf},
            "sky": sky, "sun": sun,
        })
        return render(sc, 256, seed)

    plugin = shot({"type": "clothbake", "table": str(tables["twill"]), "two_sided": False}, 1)
    plugin2 = shot({"type": "clothbake", "table": str(tables["twill"]), "two_sided": False}, 2)
    measured = shot({"type": "measured", "filename": str(rgl)}, 1)
    mask = np.ones(plugin.shape[:2], dtype=bool)
    noise = rel_rmse(plugin, plugin2, mask)
    e = rel_rmse(plugin, measured, mask)
    means = plugin.mean(axis=(0, 1)) / measured.mean(axis=(0, 1)) - 1
    print(f"plugin vs measured: relative RMSE {e:.4f} (two plugin seeds: {noise:.4f}); "
          f"image means differ by {np.abs(means).max():.4f}")
    assert e < 2 * noise + 0.03
    assert np.abs(means).max() < 0.03


def test_the_two_faced_cloth_in_wavefronts(tmp_path):
    """The scalar test's backlit and sky scenes (test_mitsuba.two_faced_checks), a wavefront
    at a time."""
    from test_mitsuba import two_faced_checks

    use("llvm_ad_rgb")
    try:
        two_faced_checks(tmp_path)
        two_faced_checks(tmp_path, table=True)
    finally:
        use("scalar_rgb")
