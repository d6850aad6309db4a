"""Proof by rendering: the Mitsuba 3 plugin against an independent per-pixel computation of
the same scene, and a white furnace.

Scene: a unit sphere (Mitsuba's parameterisation: u along the azimuth about +z, so dp_du is
(-y, x, 0)), an orthographic camera on +y, a directional light. Each pixel is
E f_r(wi, wo) cos(theta_i) at the point seen; the reference takes the points from Mitsuba's
position AOV and computes the frame (normal p, weft along the normalised (-y, x, 0)), the
local directions and f_r through clothbake.Fabric, without the plugin or the loader.
"""

import math

import numpy as np
import pytest

mi = pytest.importorskip(
    "mitsuba", reason="mitsuba is not installed (pip install mitsuba): the rendering tests are skipped"
)

import clothbake  # noqa: E402
import clothbake.mitsuba as cbm  # noqa: E402
from conftest import OPEN_PLAIN  # noqa: E402

RES = 48
LIGHT_TO = np.array([0.45, 0.75, 0.5])  # toward the light
LIGHT_TO = LIGHT_TO / np.linalg.norm(LIGHT_TO)
E = 2.0


@pytest.fixture(scope="module", autouse=True)
def variant():
    mi.set_variant("scalar_rgb")
    cbm.register()


def scene(bsdf, integrator, emitter, spp, res=RES):
    return mi.load_dict({
        "type": "scene",
        "integrator": integrator,
        "sensor": {
            "type": "orthographic",
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 5, 0], target=[0, 0, 0], up=[0, 0, 1])
            @ mi.ScalarTransform4f().scale([1.1, 1.1, 1]),
            "film": {"type": "hdrfilm", "width": res, "height": res, "rfilter": {"type": "box"},
                     "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "shape": {"type": "sphere", "bsdf": bsdf},
        "light": emitter,
    })


def render(sc, spp, seed=0):
    return np.array(mi.render(sc, spp=spp, seed=seed), dtype=np.float64)


def directional():
    return {"type": "directional", "direction": (-LIGHT_TO).tolist(),
            "irradiance": {"type": "rgb", "value": [E, E, E]}}


def reference(fabric, positions, turned=False):
    """E f_r cos(theta_i) per pixel from the positions, and the mask of pixels well inside."""
    p = positions.reshape(-1, 3)
    r = np.linalg.norm(p, axis=1)
    n = p / np.maximum(r, 1e-12)[:, None]
    eye = np.array([0.0, 1.0, 0.0])
    inside = (np.abs(r - 1) < 1e-3) & (n @ eye > 0.25) & (np.hypot(n[:, 0], n[:, 1]) > 0.2)
    s = np.stack([-n[:, 1], n[:, 0], np.zeros(len(n))], axis=1)
    s = s / np.maximum(np.linalg.norm(s, axis=1), 1e-12)[:, None]
    t = np.cross(n, s)
    if turned:  # the cloth turned by 90 degrees: weft along v
        s, t = t, -s
    to_local = lambda w: np.stack([s @ w, t @ w, n @ w], axis=1)
    wi, wo = to_local(LIGHT_TO), to_local(eye)
    lit = inside & (wi[:, 2] > 0)
    wi_u = np.where(lit[:, None], wi, [0.0, 0.0, 1.0])
    wo_u = np.where(lit[:, None], wo, [0.0, 0.0, 1.0])
    wi_u /= np.linalg.norm(wi_u, axis=1, keepdims=True)
    wo_u /= np.linalg.norm(wo_u, axis=1, keepdims=True)
    f = fabric.eval(wi_u, wo_u)
    img = np.where(lit[:, None], E * f * wi_u[:, 2:3], 0.0)
    return img.reshape(RES, RES, 3), inside.reshape(RES, RES)


def rel_rmse(a, b, mask):
    d = (a - b)[mask]
    return math.sqrt((d ** 2).mean()) / math.sqrt((b[mask] ** 2).mean())


@pytest.fixture(scope="module")
def positions():
    sc = scene({"type": "diffuse"}, {"type": "aov", "aovs": "pp:position"}, directional(), 64)
    img = np.array(mi.render(sc, spp=64), dtype=np.float64)  # the pixel's mean position
    return img[..., -3:]


def save_png(img, path):
    bmp = mi.Bitmap(np.ascontiguousarray(img.astype(np.float32)))
    bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, srgb_gamma=True).write(str(path))


def test_plugin_matches_independent_render(twill_path, tmp_path, positions, figures_dir):
    fabric = clothbake.Fabric(twill_path)
    ref, mask = reference(fabric, positions)
    assert mask.sum() > 0.3 * RES * RES
    direct = {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0}
    # The model through the plugin (weave=): only the pixel footprint differs.
    img_w = render(scene({"type": "clothbake", "weave": str(twill_path)}, direct, directional(), 16), 16)
    # A baked table through the plugin (table=): adds the table's interpolation.
    table = tmp_path / "twill.exr"
    clothbake.bake(fabric, res=(32, 64, 32, 64)).save(table, precision="f32")
    img_t = render(scene({"type": "clothbake", "table": str(table)}, direct, directional(), 16), 16)
    e_w, e_t = rel_rmse(img_w, ref, mask), rel_rmse(img_t, ref, mask)
    print(f"relative RMSE vs the independent per-pixel computation: weave= {e_w:.4f}, table= {e_t:.4f}")
    save_png(np.concatenate([img_t, ref], axis=1), figures_dir / "mitsuba-twill-sphere.png")
    assert e_w < 0.05 and e_t < 0.05
    # The frame matters: against the cloth turned by 90 degrees the plugin's image is far
    # off, so the weft does follow dp_du.
    turned, _ = reference(fabric, positions, turned=True)
    e_turned = rel_rmse(img_t, turned, mask)
    print(f"relative RMSE vs the turned cloth: {e_turned:.4f}")
    assert e_turned > 3 * e_t


def test_white_furnace_lewis(twill_path, tmp_path, figures_dir):
    import json

    d = json.loads(twill_path.read_text())
    for g in ("warp", "weft"):
        d[g]["material"] = {"albedo": [1.0, 1.0, 1.0], "specular": 0.0, "exponent": 10}
    table = tmp_path / "white.exr"
    clothbake.bake(clothbake.Fabric(d), res=(32, 64, 32, 64), facet="lewis").save(table, precision="f32")
    sc = scene({"type": "clothbake", "table": str(table)},
               {"type": "path", "max_depth": 2, "hide_emitters": True},
               {"type": "constant", "radiance": {"type": "rgb", "value": 1.0}}, 64, res=24)
    img = render(sc, 64)
    lum = img.mean(axis=2)
    seen = lum > 0
    print(f"furnace: max {lum.max():.4f}, mean over the sphere {lum[seen].mean():.4f}")
    save_png(img, figures_dir / "mitsuba-furnace-lewis.png")
    assert seen.sum() > 0.5 * 24 * 24
    assert lum.max() <= 1.0
    assert lum[seen].mean() > 0.3


def swatch_pair(table, tmp_path, periods=None, weave=None, spp=None, aa=4):
    """The swatch scene of `test_plugin_matches_clothbake_render` through the project's own
    renderer and through the plugin, on the same table file (or, with `weave`, the same
    fabric file): (ours, plugin) linear images. With `periods`, both look f_r up at points of
    the weave period through their footprints and draw the cloth over black (`render
    --periods N --gaps` across the side 60; the plugin's `periods` per UV unit, the
    rectangle's UV spanning it)."""
    import os
    import subprocess

    exe = os.environ.get("CLOTHBAKE_BIN")
    if not exe:
        pytest.skip("CLOTHBAKE_BIN (the clothbake binary) is not set: tests/tests/python.rs sets it")
    import OpenEXR

    res, fov, eye, light = 40, 30.0, [0.0, -40.0, 40.0], [0.3, 0.6, 0.74]
    ours = tmp_path / "ours.exr"
    close = ["--periods", str(periods), "--gaps"] if periods else []
    source = ["--weave", str(weave)] if weave else ["--table", str(table)]
    subprocess.run(
        [exe, "render", *source, "--scene", "swatch", "--eye", ",".join(map(str, eye)),
         "--look-at", "0,0,0", "--light", ",".join(map(str, light)), "--fov", str(fov),
         "--res", str(res), "--aa", str(aa), "--ambient", "0", "--irradiance", str(E),
         "-o", str(tmp_path / "ours.png"), "--exr", str(ours), "-q", "--force", *close],
        check=True,
    )
    with OpenEXR.File(str(ours)) as f:
        ch = f.channels()
        if "RGB" in ch:
            img_ours = np.asarray(ch["RGB"].pixels, dtype=np.float64)
        else:
            img_ours = np.stack([np.asarray(ch[c].pixels, dtype=np.float64) for c in "RGB"], axis=-1)
    to = np.array(light) / np.linalg.norm(light)
    bsdf = {"type": "clothbake", "weave": str(weave)} if weave else {"type": "clothbake", "table": str(table)}
    if periods:
        bsdf["periods"] = float(periods)
    spp = spp or (64 if periods else 16)
    sc = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0},
        "sensor": {
            "type": "perspective", "fov": fov, "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=eye, target=[0, 0, 0], up=[0, 0, 1]),
            "film": {"type": "hdrfilm", "width": res, "height": res, "rfilter": {"type": "box"},
                     "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "shape": {"type": "rectangle", "to_world": mi.ScalarTransform4f().scale([30, 30, 1]),
                  "bsdf": bsdf},
        "light": {"type": "directional", "direction": (-to).tolist(),
                  "irradiance": {"type": "rgb", "value": [E, E, E]}},
    })
    img_mi = render(sc, spp)
    assert img_ours.shape == img_mi.shape
    return img_ours, img_mi


def test_plugin_matches_clothbake_render(twill_path, tmp_path):
    """The same swatch scene through the plugin and through the project's own renderer.

    `clothbake render --scene swatch` (side 60 on z = 0, weft +X) seen by a pinhole camera
    that the swatch fills, against a Mitsuba rectangle of the same size (its dp_du is +X) seen
    by a perspective camera with the same eye, target, +Z up and vertical field of view; the
    table is the same file for both. No ambient term: each pixel is E f_r cos(theta_i).
    """
    table = tmp_path / "twill.exr"
    clothbake.bake(clothbake.Fabric(twill_path), res=(32, 64, 32, 64)).save(table, precision="f32")
    img_ours, img_mi = swatch_pair(table, tmp_path)
    mask = np.ones(img_mi.shape[:2], dtype=bool)
    e = rel_rmse(img_mi, img_ours, mask)
    mirrored = rel_rmse(img_mi[:, ::-1], img_ours, mask)
    print(f"relative RMSE plugin vs clothbake render (swatch): {e:.4f} (mirrored image: {mirrored:.4f})")
    assert e < 0.05
    # The comparison sees the cloth's anisotropy: the mirrored image is much farther off.
    assert mirrored > 10 * e


def test_plugin_shows_the_weave_of_a_spatial_table(twill_path, tmp_path, figures_dir):
    """periods=: the plugin's close-up of a spatial gingham against `render --periods`, the
    same table, the same points of the weave period (an even number of periods: the
    rectangle's UV origin is the swatch's corner, ours its centre)."""
    table = tmp_path / "gingham.exr"
    gingham = clothbake.Fabric(str(twill_path.parent / "gingham.wif"))
    clothbake.bake(gingham, res=(8, 16, 8, 16), spatial=True).save(table, precision="f32")
    img_ours, img_mi = swatch_pair(table, tmp_path, periods=6, spp=256, aa=8)
    save_png(np.concatenate([img_mi, img_ours], axis=1), figures_dir / "mitsuba-gingham-close.png")
    mask = np.ones(img_mi.shape[:2], dtype=bool)
    e = rel_rmse(img_mi, img_ours, mask)
    # Against the averaged table (no periods) the close-up is far off: the weave is shown.
    flat, _ = swatch_pair(table, tmp_path)
    e_flat = rel_rmse(img_mi, flat, mask)
    print(f"relative RMSE plugin vs render --periods: {e:.4f} (vs the averaged picture {e_flat:.4f})")
    assert e < 0.08
    assert e_flat > 2 * e


def test_plugin_shows_the_yarns_up_close(twill_path, tmp_path, figures_dir):
    """weave= with periods=: the yarns traced up close (round, highlights along the floats,
    shadows, gaps) by the plugin against `render --weave --periods --gaps`, the same fabric
    and points of the weave period; the plugin's pixel filter averages single points, ours
    integrates each sample's footprint."""
    img_ours, img_mi = swatch_pair(None, tmp_path, periods=4, weave=twill_path, spp=1024, aa=8)
    save_png(np.concatenate([img_mi, img_ours], axis=1), figures_dir / "mitsuba-twill-yarns.png")
    mask = np.ones(img_mi.shape[:2], dtype=bool)
    e = rel_rmse(img_mi, img_ours, mask)
    # Far from the averaged model's picture: the yarns show.
    flat, _ = swatch_pair(None, tmp_path, weave=twill_path)
    e_flat = rel_rmse(img_mi, flat, mask)
    print(f"relative RMSE plugin vs render --weave --periods 4 --gaps: {e:.4f} "
          f"(vs the averaged picture {e_flat:.4f})")
    assert e < 0.02
    assert e_flat > 5 * e


def test_the_readme_snippet_renders_the_twill(tmp_path, monkeypatch):
    """The README's Python block, run as written in a folder beside tables/: it bakes the
    twill and writes a PNG in which the ball (the image's centre) is lit above the sky."""
    import pathlib

    root = pathlib.Path(__file__).resolve().parents[3]
    readme = (root / "README.md").read_text()
    code = readme.split("```python\n", 1)[1].split("```", 1)[0]
    (tmp_path / "tables").symlink_to(root / "tables")
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})
    img = np.asarray(mi.Bitmap(str(tmp_path / "twill-py.png")), dtype=np.float64)
    h, w = img.shape[:2]
    ball = img[h // 2 - 8:h // 2 + 8, w // 2 - 8:w // 2 + 8, :3].mean()
    sky = img[:8, :8, :3].mean()
    assert ball > sky + 20, (ball, sky)



def two_faced_scene(bsdf, eye_dir, emitter, integrator, spp, res=16):
    """A large flat cloth (Mitsuba's rectangle: z = 0, normal +z, dp_du along +x) seen by an
    orthographic camera along ``eye_dir`` (toward the eye), filling the frame."""
    eye_dir = np.asarray(eye_dir, dtype=np.float64)
    eye_dir = eye_dir / np.linalg.norm(eye_dir)
    up = [0, 1, 0] if abs(eye_dir[1]) < 0.9 else [1, 0, 0]
    return mi.load_dict({
        "type": "scene",
        "integrator": integrator,
        "sensor": {
            "type": "orthographic",
            "to_world": mi.ScalarTransform4f().look_at(origin=(5 * eye_dir).tolist(),
                                                       target=[0, 0, 0], up=up)
            @ mi.ScalarTransform4f().scale([0.2, 0.2, 1]),
            "film": {"type": "hdrfilm", "width": res, "height": res, "rfilter": {"type": "box"},
                     "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "shape": {"type": "rectangle", "to_world": mi.ScalarTransform4f().scale([20, 20, 1]),
                  "bsdf": bsdf},
        "light": emitter,
    })


def two_faced_checks(tmp_path, table=False):
    """Shared by the scalar and llvm tests: (1) backlit: the sun behind the cloth, the eye in
    front, each pixel E f(wi, wo) |cos theta_i| (transmission); (2) a uniform sky around the
    cloth, one bounce: each pixel the sky's radiance times what the cloth scatters toward the
    eye from the whole sphere plus its openness along the eye (the null lobe seen through),
    against a quadrature of the same cloth through clothbake.TwoFaced. The cloth is the model
    (weave=), or with ``table`` a two-faced table baked from it (table=)."""
    import json

    if table:
        path = tmp_path / "open.exr"
        clothbake.bake(clothbake.Fabric(OPEN_PLAIN), res=(8, 16, 8, 16), facet="lewis",
                       faces="two", paths=2048, output=str(path))
        cloth = clothbake.TwoFaced.open(str(path))
        bsdf = {"type": "clothbake", "table": str(path), "faces": "two"}
    else:
        weave = tmp_path / "open.json"
        weave.write_text(json.dumps(OPEN_PLAIN))
        cloth = clothbake.Fabric(OPEN_PLAIN).two_faced(facet="lewis", nodes=(3, 6), paths=2048)
        bsdf = {"type": "clothbake", "weave": str(weave), "faces": "two", "facet": "lewis",
                "nodes": "3,6", "paths": 2048}
    eye = np.array([0.3, -0.4, 0.866])
    eye = eye / np.linalg.norm(eye)
    travel = np.array([0.2, 0.3, 1.0])  # the sunlight travels up: the sun is behind the cloth
    travel = travel / np.linalg.norm(travel)
    sun = {"type": "directional", "direction": travel.tolist(),
           "irradiance": {"type": "rgb", "value": [E, E, E]}}
    sc = two_faced_scene(bsdf, eye, sun, {"type": "direct", "emitter_samples": 1,
                                           "bsdf_samples": 0}, 4)
    img = render(sc, 4)
    light = -travel
    want = E * cloth.eval1(light, eye)[0] * abs(light[2])
    got = img[..., 0].mean()
    print(f"backlit: plugin {got:.5f}, reference {want:.5f}")
    assert want > 0.01
    assert abs(got - want) < 1e-3 * want
    # The sky: one bounce (max_depth 2), every lobe and the null one sampled.
    sky = {"type": "constant", "radiance": {"type": "rgb", "value": 1.0}}
    sc = two_faced_scene(bsdf, eye, sky, {"type": "path", "max_depth": 2, "hide_emitters": False}, 256)
    got = render(sc, 256)[..., 0].mean()
    rng = np.random.default_rng(3)
    n = 20000
    r = np.sqrt(rng.uniform(0, 1, n))
    phi = rng.uniform(0, 2 * math.pi, n)
    w = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - r * r)], axis=-1)
    eyes = np.tile(eye, (n, 1))
    scattered = math.pi * (cloth.eval(w, eyes)[:, 0].mean() + cloth.eval(w * [1, 1, -1], eyes)[:, 0].mean())
    want = scattered + cloth.openness1(eye)
    print(f"sky: plugin {got:.4f}, reference {want:.4f} (openness {cloth.openness1(eye):.4f})")
    assert abs(got - want) < 0.03 * want


def test_the_two_faced_cloth_transmits_and_shows_the_sky_through_its_gaps(tmp_path):
    two_faced_checks(tmp_path)


def test_a_two_faced_table_draws_as_its_cloth(tmp_path):
    two_faced_checks(tmp_path, table=True)
