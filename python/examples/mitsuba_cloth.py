"""Renders the thesis's basket (2/2) and twill (2/1) weaves on a sphere and a draped square in
Mitsuba 3 with the clothbake plugin.

    pip install ./crates/clothbake-py mitsuba
    python3 python/examples/mitsuba_cloth.py [out_dir]

Each fabric is baked into a table in memory (32 x 64 x 32 x 64 cells), saved, and rendered
through ``{"type": "clothbake", "table": ...}`` under a directional light and a dim sky;
writes basket.png and twill.png (sRGB) to out_dir (default: the current folder).
"""

import pathlib
import sys

import mitsuba as mi

mi.set_variant("scalar_rgb")

import clothbake  # noqa: E402
import clothbake.mitsuba  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]


def render(table_path, out_png, res=160, spp=16):
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 3},
        "sensor": {
            "type": "perspective",
            "fov": 35,
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, -4.2, 2.6], target=[0, 0, 0.3], up=[0, 0, 1]),
            "film": {"type": "hdrfilm", "width": res, "height": res},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "ball": {
            "type": "sphere",
            "to_world": mi.ScalarTransform4f().translate([0, 0, 0.8]) @ mi.ScalarTransform4f().scale(0.8),
            "bsdf": {"type": "clothbake", "table": str(table_path)},
        },
        "floor": {
            "type": "rectangle",
            "to_world": mi.ScalarTransform4f().scale(2.0),
            "bsdf": {"type": "clothbake", "table": str(table_path)},
        },
        "sun": {"type": "directional", "direction": [-0.4, 0.6, -0.7],
                "irradiance": {"type": "rgb", "value": 3.0}},
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": 0.15}},
    })
    img = mi.render(scene, spp=spp)
    mi.Bitmap(img).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, srgb_gamma=True).write(str(out_png))
    print(f"wrote {out_png}")


def main():
    out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else pathlib.Path(".")
    out.mkdir(parents=True, exist_ok=True)
    clothbake.mitsuba.register()
    for name in ("basket", "twill"):
        fabric = clothbake.Fabric(ROOT / "tables" / f"{name}.json")
        table = out / f"{name}.exr"
        clothbake.bake(fabric, progress=True).save(table, overwrite=True)
        render(table, out / f"{name}.png")


if __name__ == "__main__":
    main()
