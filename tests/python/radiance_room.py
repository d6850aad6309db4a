#!/usr/bin/env python3
"""Radiance reads a Klems BSDF XML and lights a room through it (tests/tests/daylighting.rs).

Usage:
  python3 tests/python/radiance_room.py room SHADE.xml WORKDIR SENSORS
  python3 tests/python/radiance_room.py query SHADE.xml QUERIES
  python3 tests/python/radiance_room.py check SHADE.xml

room: a closed room, W x D x H = 4 x 5 x 3 m (Radiance's x across, y into the room, z up),
whose wall y = 0 is one window filled by a BSDF material with SHADE.xml (its surface normal
into the room, +y; up vector +z, the cloth's warp), the other walls black, under a uniform sky:
a glow of radiance 1 over the whole sphere outside. SENSORS is a JSON list of [x, y, z, nx, ny,
nz]; rtrace -I (with Radiance's binaries from the pyradiance package) gives the irradiance at
each, averaged over repeated runs with different seeds. Prints a JSON object: "irradiance"
(one number each, the mean of R, G, B, per unit sky radiance), "spread" (the standard error
of each mean, relative), "radiance" (the version line). Only what Radiance computed: the
expected values are the test's.

query: Radiance's BSDF library on the file (pyradiance.bsdf.query, which calls SDevalBSDF with
its first direction as the outgoing vector and its second as the incident one): for each
[theta_out, phi_out, theta_in, phi_in] (degrees, in Radiance's BSDF frame: z the surface normal,
y the up vector; vectors away from the surface) the CIE Y of the BSDF Radiance looks up, 1/sr.
Prints a JSON list.

check: Radiance's checkBSDF on the file; prints its report as it is.
"""

import json
import os
import subprocess
import sys


def radiance_bin():
    import pyradiance

    return os.path.join(os.path.dirname(pyradiance.__file__), "bin")


def run(cmd, **kw):
    out = subprocess.run(cmd, capture_output=True, **kw)
    if out.returncode != 0:
        sys.exit(f"{cmd[0]} failed ({out.returncode}): {out.stderr.decode(errors='replace')}")
    return out.stdout


def room(xml, work, sensors):
    bindir = radiance_bin()
    env = dict(os.environ, PATH=bindir + os.pathsep + os.environ.get("PATH", ""))
    os.makedirs(work, exist_ok=True)
    w, d, h = 4.0, 5.0, 3.0
    quad = lambda name, mat, pts: "%s polygon %s\n0\n0\n12 %s\n" % (
        mat,
        name,
        " ".join("%g %g %g" % p for p in pts),
    )
    scene = [
        "void glow skyglow\n0\n0\n4 1 1 1 0\n",
        "skyglow source sky\n0\n0\n4 0 0 1 360\n",
        "void plastic black\n0\n0\n5 0 0 0 0 0\n",
        # Radiance's BSDF material: thickness 0, the file, the up vector, no function file.
        "void BSDF shade\n6 0 %s 0 0 1 .\n0\n0\n" % os.path.abspath(xml),
        # The window: normal +y (into the room), counter-clockwise seen from inside.
        quad("window", "shade", [(0, 0, 0), (0, 0, h), (w, 0, h), (w, 0, 0)]),
        # Walls, floor and ceiling, normals inward.
        quad("back", "black", [(0, d, 0), (w, d, 0), (w, d, h), (0, d, h)]),
        quad("left", "black", [(0, 0, 0), (0, d, 0), (0, d, h), (0, 0, h)]),
        quad("right", "black", [(w, 0, 0), (w, 0, h), (w, d, h), (w, d, 0)]),
        quad("floor", "black", [(0, 0, 0), (w, 0, 0), (w, d, 0), (0, d, 0)]),
        quad("ceiling", "black", [(0, 0, h), (0, d, h), (w, d, h), (w, 0, h)]),
    ]
    rad = os.path.join(work, "room.rad")
    with open(rad, "w") as f:
        f.write("".join(scene))
    oct_path = os.path.join(work, "room.oct")
    with open(oct_path, "wb") as f:
        f.write(run(["oconv", rad], env=env, cwd=work))
    runs = 8
    rays = "".join("%g %g %g %g %g %g\n" % tuple(s) for s in sensors) * runs
    # -u+: uncorrelated sampling, so each repeat of a sensor is an independent estimate.
    out = run(
        [
            "rtrace", "-h", "-I", "-ab", "2", "-ad", "4096", "-aa", "0", "-as", "0",
            "-lw", "1e-7", "-lr", "-10", "-ss", "64", "-st", "0", "-u+", oct_path,
        ],
        input=rays.encode(),
        env=env,
        cwd=work,
    )
    values = []
    for line in out.decode().split("\n"):
        if line.strip():
            r, g, b = map(float, line.split()[:3])
            values.append((r + g + b) / 3.0)
    n = len(sensors)
    means, spreads = [], []
    for k in range(n):
        v = values[k::n]
        m = sum(v) / len(v)
        var = sum((x - m) ** 2 for x in v) / max(len(v) - 1, 1)
        means.append(m)
        spreads.append((var / len(v)) ** 0.5 / m if m > 0 else 0.0)
    version = run(["rtrace", "-version"], env=env).decode().strip()
    print(json.dumps({"irradiance": means, "spread": spreads, "radiance": version}))


def query(xml, queries):
    from pyradiance import bsdf

    sd = bsdf.load_file(xml)
    print(json.dumps([float(bsdf.query(sd, *q)[1]) for q in queries]))


if __name__ == "__main__":
    if sys.argv[1] == "room":
        room(sys.argv[2], sys.argv[3], json.loads(sys.argv[4]))
    elif sys.argv[1] == "check":
        bindir = radiance_bin()
        sys.stdout.write(run([os.path.join(bindir, "checkBSDF"), sys.argv[2]]).decode())
    elif sys.argv[1] == "query":
        query(sys.argv[2], json.loads(sys.argv[3]))
    else:
        sys.exit(__doc__)
