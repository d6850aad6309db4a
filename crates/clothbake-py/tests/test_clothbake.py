"""The Python API against independent references: cell-centre values of the bake, closed
relations between the split terms, a quadrature of the albedo, the ray tracer; and errors."""

import json
import math
import pathlib

import numpy as np
import pytest

import clothbake


def dirs(theta_deg, phi_deg):
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)


def hemisphere(n, rng):
    z = rng.uniform(0.0, 1.0, n)
    phi = rng.uniform(0.0, 2 * math.pi, n)
    r = np.sqrt(1 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)


def test_fabric_from_path_and_dict_agree(twill_path):
    a = clothbake.Fabric(twill_path)
    b = clothbake.Fabric(json.loads(twill_path.read_text()))
    c = clothbake.Fabric(a.to_dict())
    wi, wo = dirs([30, 50], [0, 90]), dirs([45, 20], [180, 250])
    fa = a.eval(wi, wo)
    assert fa.shape == (2, 3) and fa.dtype == np.float64
    np.testing.assert_array_equal(fa, b.eval(wi, wo))
    np.testing.assert_array_equal(fa, c.eval(wi, wo))
    assert a.name == "twill"


def test_split_terms_add_up_and_horizon_is_zero(twill_path):
    fab = clothbake.Fabric(twill_path)
    wi, wo = dirs([30, 60, 10], [0, 120, 300]), dirs([45, 30, 70], [180, 10, 90])
    s = fab.eval(wi, wo, split=True)
    np.testing.assert_allclose(s["brdf"], s["diffuse"] + s["specular"], rtol=1e-12)
    np.testing.assert_array_equal(s["secondary"], 0.0)
    s2 = fab.eval(wi, wo, bounces=2, split=True)
    np.testing.assert_allclose(s2["brdf"], s2["diffuse"] + s2["specular"] + s2["secondary"], rtol=1e-12)
    assert (s2["secondary"] > 0).all()
    # Light below the horizon: nothing.
    below = np.array([[0.6, 0.0, -0.8]])
    np.testing.assert_array_equal(fab.eval(below, wo[:1]), 0.0)


def test_every_bounce_adds_to_the_analytic_second_bounce(twill_path):
    # docs/science/transport.md: the direct term plus path-traced orders 2 to N. On the parallel surface
    # I_2 is the thesis's analytic second bounce (no perpendicular pairs), so the path-traced
    # part of orders 2 to N lies above it by the orders past the second.
    fab = clothbake.Fabric(twill_path.parent / "parallel.json")
    wi, wo = dirs([30, 50], [180, 20]), dirs([40, 35], [0, 250])
    two = fab.eval(wi, wo, bounces=2, split=True)
    three = fab.eval(wi, wo, bounces=3, split=True, samples=200_000)
    every = fab.eval(wi, wo, bounces="all", split=True, samples=200_000)
    for s in (three, every):
        np.testing.assert_allclose(s["brdf"], s["diffuse"] + s["specular"] + s["secondary"], rtol=1e-12)
        np.testing.assert_array_equal(s["diffuse"], two["diffuse"])
        assert (s["secondary"] > 0.97 * two["secondary"]).all()
    assert (every["secondary"] > three["secondary"]).all()
    np.testing.assert_array_equal(every["brdf"], fab.eval(wi, wo, bounces="all", samples=200_000))
    with pytest.raises(ValueError, match="analytic"):
        fab.eval(wi, wo, bounces="all", method="raytrace")


def test_points_of_the_period_average_to_the_period(twill_path):
    """docs/science/spatial.md: the coverage-weighted mean of the crossing cells' f_r over the period
    is the average."""
    fab = clothbake.Fabric(twill_path)
    n = 30  # 10 x 10 points in each of the twill's 3 x 3 equal cells
    u, v = np.meshgrid((np.arange(n) + 0.5) / n, (np.arange(n) + 0.5) / n)
    uv = np.stack([u.ravel(), v.ravel()], axis=-1)
    wi = np.repeat(dirs([60], [0]), len(uv), axis=0)
    wo = np.repeat(dirs([20], [180]), len(uv), axis=0)
    s = fab.eval(wi, wo, uv=uv, split=True, level="cells")
    assert "diffuse" not in s
    c = s["coverage"]
    # Light is attributed where the yarn lies, so a yarn seen over a neighbour's cell can
    # exceed 1 slightly (docs/science/spatial.md); the period mean cannot exceed 1 here.
    assert c.shape == (len(uv),) and (c > 0).all() and (c < 1.05).all() and c.mean() <= 1.0
    mean = (c[:, None] * s["brdf"]).sum(axis=0) / c.sum()
    np.testing.assert_allclose(mean, fab.eval(wi[:1], wo[:1])[0], rtol=1e-9)
    # Warp floats and weft floats differ; a whole period away is the same point.
    f = fab.eval(wi[:2], wo[:2], uv=np.array([[0.0, 0.0], [0.7, 0.05]]), level="cells")
    assert abs(f[0, 0] - f[1, 0]) > 0.1 * f[0, 0]
    np.testing.assert_array_equal(
        fab.eval(wi[0], wo[0], uv=np.array([-3.0, 2.0]), level="cells"), f[0]
    )
    with pytest.raises(ValueError, match="uv"):
        fab.eval(wi[:1], wo[:1], uv=np.array([[np.nan, 0.0]]))
    with pytest.raises(ValueError, match="uv"):
        fab.eval(wi[:1], wo[:1], uv=np.array([[0.0, 0.0]]), method="raytrace")
    with pytest.raises(ValueError, match="width"):
        fab.eval(wi[:1], wo[:1], uv=np.array([[0.0, 0.0]]), width=-1.0)
    with pytest.raises(ValueError, match="level"):
        fab.eval(wi[:1], wo[:1], uv=np.array([[0.0, 0.0]]), level="yarn")


def test_the_yarns_up_close_average_to_the_ray_tracer(twill_path):
    """docs/science/spatial.md, the point level: at a point the yarns are traced (coverage 0 in a gap,
    1 on yarn), and the coverage-weighted mean over the period is the ground truth's average
    (the ray tracer, an independent code), within its noise and the grid's."""
    fab = clothbake.Fabric(twill_path)
    n = 150
    u, v = np.meshgrid((np.arange(n) + 0.5) / n, (np.arange(n) + 0.5) / n)
    uv = np.stack([u.ravel(), v.ravel()], axis=-1)
    wi = np.repeat(dirs([50], [20]), len(uv), axis=0)
    wo = np.repeat(dirs([35], [200]), len(uv), axis=0)
    s = fab.eval(wi, wo, uv=uv, split=True)
    c = s["coverage"]
    assert set(np.unique(c)) <= {0.0, 1.0} and 0.5 < c.mean() < 1.0
    assert (s["brdf"][c == 0] == 0).all()
    mean = (c[:, None] * s["brdf"]).sum(axis=0) / c.sum()
    truth = fab.eval(wi[:1], wo[:1], method="raytrace", samples=400_000)[0]
    np.testing.assert_allclose(mean, truth, rtol=0.01)
    # A footprint of a period is the average; two cells and more, the crossing cells.
    whole = fab.eval(wi[:1], wo[:1], uv=uv[:1], width=1.0)[0]
    np.testing.assert_array_equal(whole, fab.eval(wi[:1], wo[:1])[0])
    wide = fab.eval(wi[:3], wo[:3], uv=uv[:3], width=0.7)
    np.testing.assert_array_equal(wide, fab.eval(wi[:3], wo[:3], uv=uv[:3], width=0.7, level="cells"))


def test_a_spatial_table_shows_the_model_per_cell(twill_path):
    """bake(spatial=True) and Table.eval_at: at grid nodes each crossing cell is the model's
    own f_r there (the independent path: Fabric.eval(uv=...)), and a whole period is the
    averaged table."""
    fab = clothbake.Fabric(twill_path)
    t = clothbake.bake(fab, res=(6, 12, 6, 12), spatial=True)
    # Grid nodes: theta centres (k + 0.5) * 15, phi centres (k + 0.5) * 30.
    wi = np.repeat(dirs([52.5], [15.0]), 9, axis=0)
    wo = np.repeat(dirs([22.5], [195.0]), 9, axis=0)
    uv = np.array([[(i + 0.5) / 3, (j + 0.5) / 3] for j in range(3) for i in range(3)])
    # The table carries the twill's yarns: up close it traces them, as the model does.
    assert t.has_point_level
    f_pt, c_pt = t.eval_at(wi, wo, uv)
    s_pt = fab.eval(wi, wo, uv=uv, split=True)
    np.testing.assert_allclose(f_pt, s_pt["brdf"], rtol=1e-4, atol=1e-6)
    np.testing.assert_array_equal(c_pt, s_pt["coverage"])
    # Its crossing cells alone are the model's cells.
    cells = t.without_point_level()
    assert not cells.has_point_level
    f, c = cells.eval_at(wi, wo, uv)
    s = fab.eval(wi, wo, uv=uv, split=True, level="cells")
    np.testing.assert_allclose(f, s["brdf"], rtol=1e-5)
    np.testing.assert_allclose(c, s["coverage"], rtol=1e-5)
    assert f[:, 0].max() > 1.1 * f[:, 0].min()
    # Widths one a row: from two cells wide the cells answer, at a period the average.
    w = np.array([0.7] * 8 + [1.0])
    fw, _ = t.eval_at(wi, wo, uv, width=w)
    np.testing.assert_array_equal(fw[:8], cells.eval_at(wi[:8], wo[:8], uv[:8], width=0.7)[0])
    np.testing.assert_array_equal(fw[8], t.eval(wi[8:], wo[8:])[0])
    whole, _ = t.eval_at(wi, wo, uv, width=1.0)
    np.testing.assert_array_equal(whole, t.eval(wi, wo))
    with pytest.raises(ValueError, match="uv"):
        t.eval_at(wi[:1], wo[:1], np.array([[np.inf, 0.0]]))
    with pytest.raises(ValueError, match="width"):
        t.eval_at(wi[:1], wo[:1], uv[:1], width=-1.0)


def test_a_spatial_table_with_the_second_bounce_shows_the_model_per_cell(twill_path):
    """bake(spatial=True, bounces=2): each crossing cell of a twill whose warps and wefts are
    each of their own colour is the model's f_r there with its I_2 (Fabric.eval(uv=...,
    bounces=2)), the neighbours' colours included."""
    d = json.loads(twill_path.read_text())
    d["warp"]["thread_albedo"] = [[0.8, 0.1, 0.1], [0.1, 0.7, 0.2], [0.2, 0.1, 0.9]]
    d["weft"]["thread_albedo"] = [[0.9, 0.9, 0.9], [0.5, 0.4, 0.1], [0.1, 0.7, 0.2]]
    fab = clothbake.Fabric(d)
    t = clothbake.bake(fab, res=(6, 12, 6, 12), bounces=2, spatial=True)
    wi = np.repeat(dirs([52.5], [15.0]), 9, axis=0)
    wo = np.repeat(dirs([22.5], [195.0]), 9, axis=0)
    uv = np.array([[(i + 0.5) / 3, (j + 0.5) / 3] for j in range(3) for i in range(3)])
    f, _ = t.eval_at(wi, wo, uv)
    np.testing.assert_allclose(f, fab.eval(wi, wo, uv=uv, bounces=2), rtol=1e-5)
    # The second bounce is in it: the direct reflection alone is lower.
    assert (fab.eval(wi, wo, uv=uv, level="cells") < f - 1e-4).any()


def test_brdf_is_linear_in_the_albedo(twill_path):
    """With Lewis facets and no specular part f_r is linear in each channel's albedo:
    f(rho) = rho f(1), channel by channel."""
    d = json.loads(twill_path.read_text())
    for g in ("warp", "weft"):
        d[g]["material"] = {"albedo": [1.0, 0.5, 0.25], "specular": 0.0, "exponent": 10}
    fab = clothbake.Fabric(d)
    f = fab.eval(dirs([40], [30]), dirs([20], [200]), facet="lewis")
    np.testing.assert_allclose(f[0, 1] / f[0, 0], 0.5, rtol=1e-12)
    np.testing.assert_allclose(f[0, 2] / f[0, 0], 0.25, rtol=1e-12)


def test_analytic_against_ray_traced_ground_truth(twill_path):
    fab = clothbake.Fabric(twill_path)
    wi, wo = dirs([30, 50], [0, 90]), dirs([45, 20], [180, 250])
    a = fab.eval(wi, wo)
    rt = fab.eval(wi, wo, method="raytrace", samples=40000, seed=7)
    # docs/results/validation.md: the twill's worst error is 4.1%; 40 000 rays add about 1%.
    np.testing.assert_allclose(a, rt, rtol=0.08)


def test_bake_matches_the_model_at_cell_centres(twill_path):
    fab = clothbake.Fabric(twill_path)
    t = clothbake.bake(fab, res=(4, 8, 4, 8))
    assert t.grid == {"n_theta_i": 4, "n_phi_i": 8, "n_theta_o": 4, "n_phi_o": 8}
    assert t.metadata["units"] == "1/sr" and t.metadata["fabric"]["name"] == "twill"
    v = t.to_numpy()
    assert v.shape == (4, 8, 4, 8, 3) and v.dtype == np.float32
    ti, pi, to, po = np.meshgrid(np.arange(4), np.arange(8), np.arange(4), np.arange(8), indexing="ij")
    th = lambda k, n: (k + 0.5) * 90.0 / n
    ph = lambda k, n: (k + 0.5) * 360.0 / n
    wi = dirs(th(ti, 4), ph(pi, 8)).reshape(-1, 3)
    wo = dirs(th(to, 4), ph(po, 8)).reshape(-1, 3)
    model = fab.eval(wi, wo).reshape(v.shape)
    np.testing.assert_allclose(v, model, rtol=1e-6, atol=1e-9)
    # At a cell centre the lookup returns the node (interpolation weight 1).
    np.testing.assert_allclose(t.eval(wi, wo).reshape(v.shape), v, rtol=2e-5, atol=1e-7)


def test_save_open_round_trip(tmp_path, twill_path):
    t = clothbake.bake(clothbake.Fabric(twill_path), res=(4, 8, 4, 8))
    for name, prec in (("t.exr", "f32"), ("t.bin", "f32")):
        t.save(tmp_path / name, precision=prec)
        back = clothbake.Table.open(tmp_path / name)
        np.testing.assert_array_equal(back.to_numpy(), t.to_numpy())
    with pytest.raises(FileExistsError, match="already exists"):
        t.save(tmp_path / "t.bin")
    t.save(tmp_path / "h.exr")
    assert clothbake.Table.open(tmp_path / "h.exr").precision == "f16"


def test_sampling_estimates_the_albedo(twill_path):
    t = clothbake.bake(clothbake.Fabric(twill_path), res=(16, 32, 16, 32))
    rng = np.random.default_rng(3)
    wo = np.tile(dirs([35.0], [60.0]), (200000, 1))
    wi, weight, pdf = t.sample(wo, rng.uniform(0, 1, (len(wo), 2)))
    assert (pdf > 0).all()
    np.testing.assert_allclose(t.pdf(wo[:1000], wi[:1000]), pdf[:1000], rtol=1e-5)
    # Independent: midpoint quadrature of f_r cos(theta_i) over the hemisphere.
    n = 400
    tq, pq = np.meshgrid((np.arange(n) + 0.5) * 90.0 / n, (np.arange(2 * n) + 0.5) * 180.0 / n, indexing="ij")
    w = dirs(tq, pq).reshape(-1, 3)
    f = t.eval(w, np.tile(wo[:1], (len(w), 1))).astype(np.float64)
    dw = (math.pi / 2 / n) * (math.pi / n) * np.sin(np.radians(tq)).reshape(-1)
    albedo = (f * (w[:, 2] * dw)[:, None]).sum(axis=0)
    np.testing.assert_allclose(weight.mean(axis=0), albedo, rtol=0.01)


@pytest.mark.parametrize(
    "wi, exc, words",
    [
        (np.zeros((2, 3), dtype=np.int64), TypeError, "dtype"),
        (np.zeros((2, 2)), ValueError, "shape"),
        (np.array([[0.0, 0.0, 2.0], [0.0, 0.0, 1.0]]), ValueError, "wi[0]"),
        (np.array([[0.0, 0.0, 1.0], [np.nan, 0.0, 1.0]]), ValueError, "wi[1]"),
        (np.array([[0.0, 0.0, 1.0]]), ValueError, "same number of rows"),
        ("not a vector", ValueError, "wi: shape"),
    ],
)
def test_bad_vectors_raise(twill_path, wi, exc, words):
    fab = clothbake.Fabric(twill_path)
    t = clothbake.bake(fab, res=(2, 4, 2, 4))
    wo = dirs([10, 20], [0, 0])
    with pytest.raises(exc, match=__import__("re").escape(words)):
        fab.eval(wi, wo)
    with pytest.raises(exc, match=__import__("re").escape(words)):
        t.eval(wi, wo)


def test_bad_fabric_names_the_field(twill_path):
    d = json.loads(twill_path.read_text())
    d["warp"]["radius"] = -1.0
    with pytest.raises(ValueError, match=r"<dict>: field `warp\.radius"):
        clothbake.Fabric(d)
    d = json.loads(twill_path.read_text())
    d["pattern"] = [[1, 2]]
    with pytest.raises(ValueError, match=r"pattern\[0\]\[1\]"):
        clothbake.Fabric(d)
    with pytest.raises(ValueError, match="cannot read the fabric file"):
        clothbake.Fabric("/nonexistent/fabric.json")
    fab = clothbake.Fabric(twill_path)
    with pytest.raises(ValueError, match="facet"):
        fab.eval(dirs([10], [0]), dirs([10], [0]), facet="phong")
    for bad in (0, 65, "most", 2.5):
        with pytest.raises(ValueError, match="bounces"):
            fab.eval(dirs([10], [0]), dirs([10], [0]), bounces=bad)
    with pytest.raises(ValueError, match="res"):
        clothbake.bake(fab, res=(0, 4, 4, 4))


def test_bad_tables_raise(tmp_path, twill_path):
    with pytest.raises(FileNotFoundError, match="missing.exr"):
        clothbake.Table.open(tmp_path / "missing.exr")
    junk = tmp_path / "junk.exr"
    junk.write_bytes(b"\x00" * 100)
    with pytest.raises(ValueError, match="junk.exr"):
        clothbake.Table.open(junk)
    t = clothbake.bake(clothbake.Fabric(twill_path), res=(4, 8, 4, 8))
    t.save(tmp_path / "ok.bin")
    data = bytearray((tmp_path / "ok.bin").read_bytes())
    data[len(data) // 2] ^= 0xFF
    (tmp_path / "bad.bin").write_bytes(bytes(data))
    with pytest.raises(ValueError, match="bad.bin"):
        clothbake.Table.open(tmp_path / "bad.bin")
    with pytest.raises(ValueError, match="not in"):
        t.sample(dirs([10], [0]), np.array([[0.5, 1.5]]))


def test_sharded_bake_merged_equals_the_whole_bake(tmp_path, twill_path):
    """Three shards baked from Python, merged by the `clothbake` binary (an independent
    assembly path from the in-memory bake), give the whole bake bit for bit."""
    import os
    import subprocess

    exe = os.environ.get("CLOTHBAKE_BIN")
    if not exe:
        pytest.skip("CLOTHBAKE_BIN (the clothbake binary) is not set: tests/tests/python.rs sets it")
    fab = clothbake.Fabric(twill_path)
    res = (4, 8, 4, 8)
    whole = clothbake.bake(fab, res=res, output=tmp_path / "whole.bin")
    shards = []
    for k in range(3):
        s = tmp_path / f"twill-{k}-of-3.shard"
        assert clothbake.bake(fab, res=res, output=s, shard=f"{k}/3") is None
        shards.append(str(s))
    merged = tmp_path / "merged.bin"
    subprocess.run([exe, "merge", "-q", "-o", str(merged), *shards], check=True)
    assert merged.read_bytes() == (tmp_path / "whole.bin").read_bytes()
    memory = clothbake.bake(fab, res=res)
    np.testing.assert_array_equal(clothbake.Table.open(merged).to_numpy(), memory.to_numpy())
    np.testing.assert_array_equal(whole.to_numpy(), memory.to_numpy())
    # The output exists: refused without overwrite, replaced with it.
    with pytest.raises(FileExistsError, match="whole.bin"):
        clothbake.bake(fab, res=res, output=tmp_path / "whole.bin")
    clothbake.bake(fab, res=res, output=tmp_path / "whole.bin", overwrite=True)


def test_bake_never_replaces_its_fabric_a_folder_or_a_device(tmp_path, twill_path):
    """The output check of every command (`output::preflight`, through `job::run`): an input,
    a folder or a special file is refused even with overwrite=True, and nothing changes."""
    src = tmp_path / "twill.json"
    src.write_bytes(twill_path.read_bytes())
    fab = clothbake.Fabric(src)
    res = (2, 4, 2, 4)
    with pytest.raises(Exception, match="an input of this command"):
        clothbake.bake(fab, res=res, output=src, overwrite=True)
    assert src.read_bytes() == twill_path.read_bytes()
    (tmp_path / "folder.exr").mkdir()
    with pytest.raises(Exception, match="it is a folder"):
        clothbake.bake(fab, res=res, output=tmp_path / "folder.exr", overwrite=True)
    if pathlib.Path("/dev/null").is_char_device():
        with pytest.raises(Exception, match="character device"):
            clothbake.bake(fab, res=res, output="/dev/null", overwrite=True)
        assert pathlib.Path("/dev/null").is_char_device()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder.exr", "twill.json"]


def test_resumed_bake_equals_an_uninterrupted_one(tmp_path, twill_path):
    """A bake stopped half way (its progress callback returns False) leaves a checkpoint;
    resuming from it gives the uninterrupted bake's table bit for bit, and removes it."""
    fab = clothbake.Fabric(twill_path)
    res, out = (8, 16, 8, 16), tmp_path / "twill.bin"
    checkpoint = tmp_path / "twill.bin.checkpoint"

    def stop_half_way(done, total):
        return done < total // 2

    with pytest.raises(KeyboardInterrupt, match="resume=True"):
        clothbake.bake(fab, res=res, output=out, progress=stop_half_way, bounces=2, orders="fast")
    assert checkpoint.exists() and not out.exists()
    with pytest.raises(ValueError, match="checkpoint of an interrupted bake"):
        clothbake.bake(fab, res=res, output=out, bounces=2, orders="fast")
    # Another bake's checkpoint is refused.
    with pytest.raises(ValueError, match="other options"):
        clothbake.bake(fab, res=res, output=out, resume=True, bounces=2)
    seen = []
    resumed = clothbake.bake(fab, res=res, output=out, resume=True, bounces=2, orders="fast",
                             progress=lambda d, t: seen.append((d, t)))
    assert not checkpoint.exists()
    assert seen[0][0] > 0, "the resumed bake starts from the checkpoint's rows"
    whole = clothbake.bake(fab, res=res, bounces=2, orders="fast")
    np.testing.assert_array_equal(resumed.to_numpy(), whole.to_numpy())
    np.testing.assert_array_equal(clothbake.Table.open(out).to_numpy(), whole.to_numpy())


def test_bake_options_reach_the_table(twill_path):
    fab = clothbake.Fabric(twill_path)
    t = clothbake.bake(fab, res=(2, 4, 2, 4), method="raytrace", samples=50, seed=7, caps="shaded")
    opts = json.loads(t.metadata["options_json"])
    assert (opts["method"], opts["samples"], opts["seed"], opts["caps"]) == ("raytrace", 50, 7, "shaded")
    t = clothbake.bake(fab, res=(2, 4, 2, 4), variant="thesis", bounces=2, secondary="raytrace",
                       sampling="8,0.3,1.5,area", kernel="thesis")
    opts = json.loads(t.metadata["options_json"])
    assert opts["variant"] == "thesis"
    assert opts["secondary"]["method"] == "sampling" and opts["secondary"]["kernel"] == "thesis"


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(method="raytrac"), "method: \"raytrac\""),
        (dict(samples=10), "samples=, seed= and caps= apply only to the ray tracer"),
        (dict(variant="best"), "variant: \"best\""),
        (dict(method="raytrace", variant="thesis"), "variant= applies only"),
        (dict(method="raytrace", bounces=2), "bounces=2 needs the analytic model"),
        (dict(orders="fast"), "orders= and sampling= apply only to the secondary"),
        (dict(bounces=2, orders="1,2"), "orders: expected"),
        (dict(bounces=2, secondary="raytrace", orders="fast"), "orders= sets the analytic"),
        (dict(bounces=2, sampling="8,0.3,1.5,area"), "sampling= sets the two-level"),
        (dict(kernel="pi"), "kernel: \"pi\""),
        (dict(shard="0/2"), "shard: a shard is written to a file"),
        (dict(shard="2/2", output="x.shard"), "shard: shard index 2"),
        (dict(resume=True), "resume: applies to a bake into a file"),
        (dict(precision="f32", output="t.bin"), "precision: applies only to EXR"),
        (dict(format="bin", output="t.exr"), "format: \"bin\" but the output t.exr"),
        (dict(checkpoint_every=0.0, output="t.exr"), "checkpoint_every: 0"),
        (dict(method="raytrace", samples=2**25), "samples=33554432 is out of range; give a whole number from 1 to 16777216"),
    ],
)
def test_bad_bake_options_name_the_option(twill_path, kwargs, words):
    with pytest.raises(ValueError, match=__import__("re").escape(words)):
        clothbake.bake(clothbake.Fabric(twill_path), res=(2, 4, 2, 4), **kwargs)


def test_a_period_too_large_for_sliced3d_is_refused(twill_path):
    """docs/reference/limits.md: sliced3d takes periods of at most 16 384 cells; bake and two_faced refuse
    a larger one before any work, naming the variant and the fix; sliced takes it."""
    d = json.loads(twill_path.read_text())
    n = 129
    d["pattern"] = [[1 if (i * 7 + j * 3) % 5 < 2 else 0 for i in range(n)] for j in range(n)]
    fab = clothbake.Fabric(d)
    with pytest.raises(ValueError, match=r"variant: the variant sliced3d takes a period of at most 16384 cells.*129 x 129.*sliced or refined"):
        clothbake.bake(fab, res=(2, 4, 2, 4), variant="sliced3d")
    with pytest.raises(ValueError, match=r"variant: the variant sliced3d takes a period of at most 16384 cells"):
        fab.two_faced(variant="sliced3d", nodes=(1, 1), paths=1)
    assert clothbake.bake(fab, res=(1, 2, 1, 2), variant="sliced") is not None


def test_an_unknown_variant_is_refused_alike_by_bake_and_two_faced(twill_path):
    """bake and two_faced take the same variant names and refuse another with the same line."""
    fab = clothbake.Fabric(twill_path)
    needle = r'^variant: "best" is not one of "refined", "thesis", "sliced", "sliced3d"; give one of them$'
    with pytest.raises(ValueError, match=needle):
        clothbake.bake(fab, res=(1, 2, 1, 2), variant="best")
    with pytest.raises(ValueError, match=needle):
        fab.two_faced(variant="best", nodes=(1, 1), paths=1)


def test_version_is_the_crates_version():
    """Independent: the workspace's Cargo.toml, read as text."""
    import pathlib
    import re

    cargo = (pathlib.Path(__file__).resolve().parents[3] / "Cargo.toml").read_text()
    workspace = cargo[cargo.index("[workspace.package]"):]
    expected = re.search(r'^version\s*=\s*"([^"]+)"', workspace, re.M).group(1)
    assert clothbake.__version__ == expected
    assert "__version__" in clothbake.__all__


def test_messages_name_python_arguments_not_flags(tmp_path, twill_path):
    """What a Python user is told to do is spelled as a Python argument, never a CLI flag."""
    fab = clothbake.Fabric(twill_path)
    res = (4, 8, 4, 8)
    t = clothbake.bake(fab, res=res)
    t.save(tmp_path / "t.exr")
    with pytest.raises(FileExistsError) as e:
        t.save(tmp_path / "t.exr")
    assert "overwrite=True" in str(e.value) and "--" not in str(e.value), e.value
    t.save(tmp_path / "t.exr", overwrite=True)
    with pytest.raises(FileExistsError) as e:
        clothbake.bake(fab, res=res, output=tmp_path / "t.exr")
    assert "overwrite=True" in str(e.value) and "--" not in str(e.value), e.value

    out = tmp_path / "stop.bin"
    with pytest.raises(KeyboardInterrupt) as e:
        clothbake.bake(fab, res=(8, 16, 8, 16), output=out, progress=lambda d, n: d < n // 2,
                       bounces=2, orders="fast")
    assert "call bake() again with resume=True" in str(e.value), e.value
    assert "--" not in str(e.value), e.value
    with pytest.raises(ValueError) as e:
        clothbake.bake(fab, res=(8, 16, 8, 16), output=out, bounces=2, orders="fast")
    assert "resume=True" in str(e.value) and "--" not in str(e.value), e.value

    with pytest.raises(ValueError) as e:
        clothbake.bake(fab, res=res, output=tmp_path / "x.shard", shard="4")
    assert 'shard="0/4"' in str(e.value) and "--" not in str(e.value), e.value


def test_table_eval_reads_any_layout_alike(twill_path):
    """Table.eval's fast path (contiguous float32/float64 read in place) and its general path
    (views, lists) give the same lookups."""
    t = clothbake.bake(clothbake.Fabric(twill_path), res=(4, 8, 4, 8))
    rng = np.random.default_rng(5)
    wi, wo = hemisphere(64, rng), hemisphere(64, rng)
    f = t.eval(wi, wo)
    # A strided view (every other row of a bigger array) and Python lists.
    big = np.repeat(wi, 2, axis=0)[::2]
    assert not big.flags["C_CONTIGUOUS"]
    np.testing.assert_array_equal(t.eval(big, wo), f)
    np.testing.assert_array_equal(t.eval(wi.tolist(), wo.tolist()), f)
    # float32 input: the same directions rounded, as the lookup takes them anyway.
    np.testing.assert_array_equal(t.eval(wi.astype(np.float32), wo.astype(np.float32)), f)
    assert t.eval(wi[0], wo[0]).shape == (3,)


def test_progress_into_a_log_has_no_carriage_returns(twill_path, capfd):
    """progress=True with stderr not a terminal (captured into a file here): plain lines,
    one per 10% at most, ending at 100%."""
    clothbake.bake(clothbake.Fabric(twill_path), res=(4, 8, 4, 8), progress=True)
    err = capfd.readouterr().err
    assert "\r" not in err
    lines = [l for l in err.splitlines() if l.startswith("baking ")]
    assert 1 <= len(lines) <= 11, err
    assert lines[-1].endswith("100%"), err


def test_eval_samples_are_bounded(twill_path):
    fab = clothbake.Fabric(twill_path)
    wi, wo = dirs([30], [0]), dirs([45], [180])
    with pytest.raises(ValueError, match="from 1 to 16777216"):
        fab.eval(wi, wo, method="raytrace", samples=2**25)


def test_the_two_faced_cloth_transmits_and_passes_light_through_its_gaps():
    # An open plain weave (r/s = 0.25) of translucent yarns (docs/science/transmission.md).
    from conftest import OPEN_PLAIN

    fab = clothbake.Fabric(OPEN_PLAIN)
    cloth = fab.two_faced(facet="lewis")
    assert "open plain" in repr(cloth)
    down = np.array([0.0, 0.0, -1.0])
    up = np.array([0.0, 0.0, 1.0])
    # Straight through: the geometric open area (1 - d/s)^2, from either side.
    assert cloth.openness1(up) == pytest.approx(0.25, abs=1e-12)
    assert float(cloth.openness(down)) == pytest.approx(0.25, abs=1e-12)
    # Batches answer as single pairs; transmission and reflection on both sides are positive.
    wi = np.concatenate([dirs([30, 50], [0, 90]), -dirs([20, 40], [45, 200])])
    wo = np.concatenate([-dirs([35, 10], [180, 30]), dirs([60, 25], [90, 300])])
    f = cloth.eval(wi, wo)
    assert f.shape == (4, 3)
    for k in range(4):
        np.testing.assert_array_equal(f[k], cloth.eval1(wi[k], wo[k]))
    assert (f > 0).all()
    # Energy: what is reflected, transmitted and passed through from overhead is at most what
    # arrives (a cosine-weighted estimate of each hemisphere's integral of f cos).
    rng = np.random.default_rng(1)
    n = 4000
    r = np.sqrt(rng.uniform(0, 1, n))
    phi = rng.uniform(0, 2 * math.pi, n)
    w = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - r * r)], axis=-1)
    light = np.tile(up, (n, 1))
    refl = math.pi * cloth.eval(light, w)[:, 0].mean()
    trans = math.pi * cloth.eval(light, w * [1, 1, -1])[:, 0].mean()
    assert 0.1 < trans and 0.1 < refl
    assert refl + trans + 0.25 <= 1.0
    with pytest.raises(ValueError, match="variant"):
        fab.two_faced(variant="no such")


def test_a_two_faced_table_holds_its_cloth_over_the_sphere(tmp_path):
    # Baked from the model of the same fabric (the same rays a node), looked up through the
    # loader: at cell centres the table returns the model's values. (A symmetric weave's bake
    # evaluates one cell of each mirror orbit and copies it; with the light at the first
    # azimuth, 22.5 degrees, every cell is its orbit's own.)
    from conftest import OPEN_PLAIN

    fab = clothbake.Fabric(OPEN_PLAIN)
    path = tmp_path / "open.exr"
    baked = clothbake.bake(fab, res=(4, 8, 4, 8), facet="lewis", faces="two", paths=256,
                           output=str(path), precision="f32")
    assert isinstance(baked, clothbake.TwoFaced)
    table = clothbake.TwoFaced.open(str(path))
    assert "open plain" in repr(table)
    model = fab.two_faced(facet="lewis", paths=256)
    # Cell centres: polar (k + 0.5) * 180 / 8 over the sphere, azimuths (k + 0.5) * 45.
    theta = np.radians([11.25, 33.75, 146.25, 168.75])
    phi = np.radians([22.5, 112.5, 202.5, 337.5])
    w = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)],
                 axis=-1)
    first = np.radians(22.5)
    light = np.stack([np.sin(theta) * np.cos(first), np.sin(theta) * np.sin(first),
                      np.cos(theta)], axis=-1)
    wi, wo = np.repeat(light, 4, axis=0), np.tile(w, (4, 1))
    want = model.eval(wi, wo)
    np.testing.assert_allclose(table.eval(wi, wo), want, rtol=1e-5)
    np.testing.assert_allclose(baked.eval(wi, wo), want, rtol=1e-5)
    # The openness at the incident cells' centres: the closed form's.
    np.testing.assert_allclose(table.openness(w), model.openness(w), atol=1e-6)
    # The other kinds refuse each other's files, naming the door.
    with pytest.raises(ValueError, match="TwoFaced.open"):
        clothbake.Table.open(str(path))
    one = tmp_path / "one.exr"
    clothbake.bake(fab, res=(2, 4, 2, 4), output=str(one))
    with pytest.raises(ValueError, match="one-faced"):
        clothbake.TwoFaced.open(str(one))
    with pytest.raises(ValueError, match="faces"):
        clothbake.bake(fab, res=(2, 4, 2, 4), faces="three")
    with pytest.raises(ValueError, match="paths=0 is out of range"):
        clothbake.bake(fab, res=(2, 4, 2, 4), faces="two", paths=0)


def test_two_faced_arguments_are_named_and_bounded(twill_path):
    """Out-of-range nodes and paths are refused naming the argument (they gave conversion
    errors), with the command line's limit on paths (2^24)."""
    fab = clothbake.Fabric(twill_path)
    with pytest.raises(ValueError, match=r"^nodes: \(-1, 8\)"):
        fab.two_faced(nodes=(-1, 8), paths=1)
    with pytest.raises(ValueError, match=r"^paths: -5; .*16777216"):
        fab.two_faced(nodes=(1, 1), paths=-5)
    with pytest.raises(ValueError, match=r"^paths: 16777217"):
        fab.two_faced(nodes=(1, 1), paths=2**24 + 1)


def _run_python(code):
    import subprocess
    import sys
    return subprocess.Popen(
        [sys.executable, "-c", code],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )


def test_a_two_faced_grid_beyond_the_memory_limit_is_refused_before_it_is_allocated(twill_path):
    """nodes=(64, 128) holds 8.6 GB of nodes: under a 6 GB address-space limit it was allocated
    at once and aborted the interpreter; it is refused with what to do, nothing allocated."""
    code = f"""
import resource, clothbake
resource.setrlimit(resource.RLIMIT_AS, (6 << 30, resource.RLIM_INFINITY))
fab = clothbake.Fabric({str(twill_path)!r})
try:
    fab.two_faced(nodes=(64, 128), paths=1)
except ValueError as e:
    print("refused:", e)
"""
    p = _run_python(code)
    out, err = p.communicate(timeout=120)
    assert p.returncode == 0, err
    assert out.startswith("refused: nodes: (64, 128) holds 8.6 GB"), out + err
    assert "give fewer" in out, out


def test_ctrl_c_stops_the_two_faced_path_tracing(twill_path):
    """A grid of hours of path tracing stops on SIGINT with KeyboardInterrupt, in seconds (it
    ran on, ignoring Ctrl-C)."""
    import signal
    import time
    # The default handler set again: a child of a process started in the background (`cmd &`
    # in a script) inherits SIGINT ignored, and Python keeps it so.
    code = f"""
import clothbake, signal, sys
signal.signal(signal.SIGINT, signal.default_int_handler)
fab = clothbake.Fabric({str(twill_path)!r})
print("start", flush=True)
try:
    fab.two_faced(nodes=(32, 64), paths=64)
except KeyboardInterrupt:
    print("interrupted", flush=True)
    sys.exit(3)
print("finished", flush=True)
"""
    p = _run_python(code)
    assert p.stdout.readline().strip() == "start"
    time.sleep(2.0)
    p.send_signal(signal.SIGINT)
    t0 = time.monotonic()
    out, err = p.communicate(timeout=60)
    assert p.returncode == 3, (out, err)
    assert "interrupted" in out
    assert time.monotonic() - t0 < 30


def test_negative_counts_are_refused_naming_the_argument(twill_path):
    fab = clothbake.Fabric(twill_path)
    for name in ["paths", "samples"]:
        with pytest.raises(ValueError, match=rf"^{name}: -5 is negative"):
            clothbake.bake(fab, res=(1, 1, 1, 1), **{name: -5})
