"""The gallery's cloth: a square cloth draped over a sphere resting on the floor, as a
triangle mesh (numpy, written as a binary PLY) with UVs along warp and weft.

The cloth is the square [-a, a]^2 of a flat sheet (U along +x, the weft; V along +y, the
warp), laid centred on the sphere of radius R standing on the floor z = 0. A point at arc
length r from the sheet's centre, azimuth phi, follows the sphere (polar angle r / R) up to
the contact angle; beyond, it hangs along a profile in the vertical plane at azimuth phi
whose slope relaxes toward the vertical and, near the floor, toward the floor (a smooth
skirt that settles on the floor), kept outside the ball (it rests on the ball until it hangs
free), with pleats: the hanging part stands out in FOLDS ridges around the ball (a squared sine of
irregular phase and height, ridges narrower than the valleys between them), more the lower it
hangs, up to FOLD_DEPTH at the hem. Arc length is kept along each radial line, so the UVs
(the sheet's coordinates) stay close to an isometric parameterisation and weave periods keep
their size. Not a cloth simulation: a shape that reads as a cloth over a ball.
"""

import numpy as np

SPHERE_RADIUS = 1.0
HALF_SIDE = 3.0
CONTACT = np.radians(62.0)  # polar angle where the cloth leaves the sphere
FOLDS = 9  # folds around the skirt
FOLD_DEPTH = 0.42  # how far a fold's ridge stands out at the hem
LIFT = 0.012  # the cloth's distance from the sphere and the floor


def _profile(t, fold):
    """(rho, z) after hanging arc length t (N,) beyond the contact circle, for fold
    amplitudes fold (N,): integrates the slope angle beta (downward from the horizontal)."""
    steps = 400
    tmax = float(np.max(t)) if t.size else 0.0
    dt = max(tmax, 1e-6) / steps
    ro = SPHERE_RADIUS + LIFT
    rho = ro * np.sin(CONTACT)
    z = SPHERE_RADIUS + ro * np.cos(CONTACT)
    beta = CONTACT
    ts, rhos, zs = [0.0], [rho], [z]
    for k in range(steps):
        # Toward vertical (85 degrees) high up, toward the floor's plane near it.
        near = np.clip((z - LIFT) / 0.35, 0.0, 1.0)
        target = np.radians(85.0) * near * near * (3 - 2 * near)
        beta += (target - beta) * dt / 0.25
        rho += np.cos(beta) * dt
        z = max(z - np.sin(beta) * dt, LIFT)
        # Around the ball, not through it: the cloth rests on it until it hangs free.
        dz = z - SPHERE_RADIUS
        if abs(dz) < SPHERE_RADIUS:
            rho = max(rho, np.sqrt(SPHERE_RADIUS**2 - dz * dz) + LIFT)
        ts.append((k + 1) * dt)
        rhos.append(rho)
        zs.append(z)
    rho_t = np.interp(t, ts, rhos)
    z_t = np.interp(t, ts, zs)
    return rho_t + fold, z_t


def vertices(n):
    """Positions (n*n, 3), UVs (n*n, 2) and triangles (2 (n-1)^2, 3) of the draped cloth,
    with its front (the side away from the sphere) counter-clockwise."""
    s = np.linspace(-HALF_SIDE, HALF_SIDE, n)
    x, y = np.meshgrid(s, s, indexing="xy")
    x, y = x.ravel(), y.ravel()
    r = np.hypot(x, y)
    phi = np.arctan2(y, x)
    r_c = SPHERE_RADIUS * CONTACT
    on = r <= r_c
    theta = np.minimum(r, r_c) / SPHERE_RADIUS
    ro = SPHERE_RADIUS + LIFT
    rho_on = ro * np.sin(theta)
    z_on = SPHERE_RADIUS + ro * np.cos(theta)
    t = np.maximum(r - r_c, 0.0)
    # Growing from nothing at the contact circle without a kink (a smoothstep of the hanging
    # length), so the pleats start where the cloth leaves the ball.
    d = np.clip(t / 1.1, 0.0, 1.0)
    depth = d * d * (3.0 - 2.0 * d)
    # Ridges narrower than the valleys between them (a squared sine), of irregular spacing
    # and height: the pleats of cloth hanging from a round support.
    wave = 0.5 + 0.5 * np.sin(FOLDS * phi + 0.7 * np.sin(3 * phi) + 0.4 * np.sin(5 * phi))
    height = 1.0 + 0.35 * np.sin(2 * phi + 1.3)
    fold = FOLD_DEPTH * depth * height * wave**2
    rho_off, z_off = _profile(t, fold)
    rho = np.where(on, rho_on, rho_off)
    z = np.where(on, z_on, z_off)
    pos = np.stack([rho * np.cos(phi), rho * np.sin(phi), z], axis=1)
    uv = np.stack([(x + HALF_SIDE) / (2 * HALF_SIDE), (y + HALF_SIDE) / (2 * HALF_SIDE)], axis=1)
    i, j = np.meshgrid(np.arange(n - 1), np.arange(n - 1), indexing="xy")
    a = (j * n + i).ravel()
    b, c, d = a + 1, a + n, a + n + 1
    faces = np.concatenate([np.stack([a, b, d], axis=1), np.stack([a, d, c], axis=1)])
    return pos, uv, faces


def write_ply(path, pos, uv, faces):
    """A binary little-endian PLY with x, y, z, u, v per vertex (Mitsuba's `ply` reads the
    UVs and computes smooth normals)."""
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(pos)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float u\nproperty float v\n"
        f"element face {len(faces)}\n"
        "property list uchar int vertex_indices\nend_header\n"
    )
    vtx = np.concatenate([pos, uv], axis=1).astype("<f4")
    tri = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    tri["n"] = 3
    tri["i"] = faces
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(vtx.tobytes())
        f.write(tri.tobytes())


def write(path, n=257):
    """The draped cloth as a PLY at path (n x n vertices)."""
    pos, uv, faces = vertices(n)
    write_ply(path, pos, uv, faces)
    return path
