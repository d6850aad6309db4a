"""The gallery's scene in Mitsuba 3: the draped cloth (drape.py) over a ball on a floor, the
sky, the two views, and the BSDFs (Mitsuba's native ``measured``, the clothbake plugin)."""

import hashlib
import math
import pathlib

import numpy as np

import drape

# Weave periods per UV unit in the close-ups: the cloth's side (UV 0 to 1) is 4.8 ball radii.
PERIODS = 120.0
TURBIDITY = 3.0
SUN_ELEVATION = 35.0  # degrees above the horizon
SUN_AZIMUTH = 245.0  # degrees from +x toward +y: the sun to the left of the camera
# The exposures of the sky's pictures, per view: a sunlit white cloth near the curve's
# shoulder (the close view sees only sunlit cloth, the far view mostly the floor).
SKY_EXPOSURE = {"far": 3.0, "close": 1.6}


def measured(path):
    return {"type": "measured", "filename": str(path)}


def plugin(table, periods=None):
    b = {"type": "clothbake", "table": str(table)}
    if periods:
        b["periods"] = float(periods)
    return b


def plugin_model(fabric):
    return {"type": "clothbake", "weave": str(fabric)}


def cloth_mesh(cache, n):
    """The draped cloth as a PLY in the cache (written once per resolution and drape.py)."""
    key = hashlib.sha256(pathlib.Path(drape.__file__).read_bytes()).hexdigest()[:12]
    path = cache / f"drape-{n}-{key}.ply"
    if not path.exists():
        drape.write(path, n)
    return path


def sun_direction():
    e, a = math.radians(SUN_ELEVATION), math.radians(SUN_AZIMUTH)
    return [math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)]


def environment(envmap):
    """Mitsuba's sunsky, or the lat-long EXR turned so that its up (+Y) is the scene's +Z."""
    import mitsuba as mi

    up = mi.ScalarTransform4f().rotate([1, 0, 0], 90)
    if envmap:
        return {"type": "envmap", "filename": str(envmap), "to_world": up}
    # sunsky's zenith is +Z and its sun direction is in world space.
    return {"type": "sunsky", "sun_direction": sun_direction(), "turbidity": TURBIDITY}


VIEWS = {
    # origin, target, horizontal field of view (degrees)
    "far": ([4.6, -6.4, 3.3], [0.0, 0.0, 0.75], 44.0),
    # The sunlit shoulder of the ball, seen close.
    "close": ([-1.9, -2.5, 2.25], [-0.3, -0.45, 1.75], 22.0),
}


def build(mi, view, cloth_bsdf, mesh, emitter, settings, half=None, extra=None):
    """The scene for one view and one cloth BSDF; ``half`` "left" or "right" renders only
    that half of the picture (a crop of the same camera); ``extra``: more scene objects (by
    name), e.g. a second emitter."""
    origin, target, fov = VIEWS[view]
    film = {"type": "hdrfilm", "width": settings.width, "height": settings.height,
            "pixel_format": "rgb"}
    if half:
        w = settings.width // 2
        film.update({"crop_offset_x": 0 if half == "left" else w, "crop_offset_y": 0,
                     "crop_width": w if half == "left" else settings.width - w,
                     "crop_height": settings.height})
    return mi.load_dict({
        **(extra or {}),
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 5},
        "sensor": {
            "type": "perspective", "fov": fov, "fov_axis": "x",
            "to_world": mi.ScalarTransform4f().look_at(origin=origin, target=target, up=[0, 0, 1]),
            "film": film,
            "sampler": {"type": "independent"},
        },
        "cloth": {"type": "ply", "filename": str(mesh), "bsdf": cloth_bsdf},
        "ball": {"type": "sphere", "center": [0, 0, drape.SPHERE_RADIUS],
                 "radius": drape.SPHERE_RADIUS * 0.995,
                 "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": 0.3}}},
        "floor": {"type": "rectangle", "to_world": mi.ScalarTransform4f().scale(400),
                  "bsdf": {"type": "diffuse",
                           "reflectance": {"type": "rgb", "value": [0.2, 0.19, 0.18]}}},
        "sky": emitter,
    })


def uses_plugin(bsdf):
    return bsdf["type"] == "clothbake"


def render(mi, sc, settings, spp, symbolic):
    """The linear image (H, W, 3) float64: the mean of passes of a few samples a pixel each
    (the wavefront of a pass stays small), seeds 0, 1, ... ``symbolic``: Dr.Jit's symbolic
    loops and calls (one compiled kernel per pass, about 3 times faster), possible only when
    no clothbake plugin is in the scene (the plugin needs them off)."""
    import drjit as dr

    dr.set_flag(dr.JitFlag.SymbolicLoops, symbolic)
    dr.set_flag(dr.JitFlag.SymbolicCalls, symbolic)
    passes = max(1, spp // settings.pass_spp)
    acc = None
    for k in range(passes):
        img = np.asarray(mi.render(sc, spp=settings.pass_spp, seed=k), dtype=np.float64)[..., :3]
        acc = img if acc is None else acc + img
    return acc / passes
