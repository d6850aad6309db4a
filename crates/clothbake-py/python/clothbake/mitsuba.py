"""A Mitsuba 3 BSDF plugin for woven cloth: ``clothbake.mitsuba.register()``.

After ``register()``, scenes can use ``{"type": "clothbake", "table": "twill.exr"}`` (a
baked table: interpolated lookup and the loader's importance sampling) or
``{"type": "clothbake", "weave": "tables/twill.json"}`` (the analytic model evaluated
directly; cosine-weighted sampling). Optional parameters: ``facet`` ("huo" | "lewis", weave
only), ``two_sided`` (bool, default True), ``periods`` (float: weave periods per unit of the
surface's UV). With ``periods`` each lookup is at the point (u, v) * periods of the weave period
through its footprint, at the footprint's level of detail (docs/science/spatial.md): with ``weave=``
the yarns are traced up close (round yarns, highlights along the floats, shadows, gaps), the
crossing cells answer from two cells wide and the average from a period; a table baked with
``spatial=True`` / ``--spatial`` (one bounce) carries its yarns and answers alike, another
spatial table shows its cells. The footprint is the UV footprint of the ray differentials
where Mitsuba provides them (``si.duv_dx``, ``si.duv_dy``; its side the larger of the two
lengths, times ``periods``); where they are zero the footprint is the point, and the pixel
filter and the samples per pixel do the averaging. With ``periods`` the cloth is drawn over
black, as ``clothbake render --periods N --gaps`` draws it: each value is f_r times the
footprint's coverage, so a point that shows a gap between the yarns is black (the thesis's
floor; no light passes through the cloth).

Frame: the cloth's +X (the weft) follows the surface's ``dp_du`` (the U texture direction),
made orthogonal to the shading normal; +Y (the warp) is ``n x s``, along V on a regular
parameterisation; +Z is the shading normal. So warp and weft follow the mesh's UVs.

Two-sided: seen from the back (both directions below the shading normal), the cloth is
evaluated as its front mirrored through the cloth's plane (z negated for both directions):
the same weave, seen from the other side. With ``two_sided=False`` the back is black. Light
and eye on opposite sides give zero (no transmission).

Two faces and transmission: ``faces="two"`` with ``weave=`` (or ``table=``, a table baked with
``clothbake --faces two``) draws the two-faced cloth
(docs/science/transmission.md: no floor, light through the gaps and through translucent yarns, the back
the inverted weave): ``eval`` gives reflection off either face and transmission across, and a
null lobe passes the ray straight through with the openness O along the eye's direction (a
delta, as Mitsuba's null-scattering BSDFs do: sampled with probability O, weight 1). The
other lobes are sampled cos-weighted on either side with even odds. ``facet="lewis"`` is
worth giving (reciprocal and energy conserving; the default stays ``huo``, as everywhere);
``periods`` and ``two_sided=False`` do not apply.
Building it path-traces the model's coarse grid (about 25 s on two cores; ``nodes="P,A"`` polar
angles by azimuths a direction, default "5,8", and ``paths`` eye rays a node, default 8192).

Variants: ``scalar_rgb`` (the plugin calls the native module once per lookup, on Python
floats) and ``llvm_ad_rgb`` (whole wavefronts: each method converts the lanes Mitsuba hands
it to numpy and makes one batch call, ``Table.eval``, ``Table.eval_at``, ``Table.sample``,
``Table.pdf`` or ``Fabric.eval``). A Python BSDF can only see concrete arrays, so in an llvm
variant ``register()`` switches Dr.Jit's symbolic loops and calls off
(``dr.JitFlag.SymbolicLoops``, ``dr.JitFlag.SymbolicCalls``): the integrator then runs its
bounces as evaluated wavefronts. Turning them on again later makes the plugin raise. The llvm
variants need an LLVM of version 17 or later (``DRJIT_LIBLLVM_PATH``, e.g.
``/usr/lib/x86_64-linux-gnu/libLLVM-19.so``).
"""

import math

from . import Fabric, Table, TwoFaced

_REGISTERED = False


class Cloth:
    """The plugin's parameters, checked: ``table`` (a Table) or ``fabric`` (a Fabric) with
    ``facet``, ``two_sided``, ``periods`` (or None) and ``source`` (the file named)."""

    def __init__(self, props):
        has_table, has_weave = "table" in props, "weave" in props
        if has_table == has_weave:
            raise ValueError(
                "clothbake BSDF: give exactly one of table= (a baked .exr/.bin table) "
                "or weave= (a fabric .json file)"
            )
        faces = str(props.get("faces", "one"))
        if faces not in ("one", "two"):
            raise ValueError(
                f"clothbake BSDF: faces={faces!r}; use \"one\" (over the thesis's floor) or "
                "\"two\" (the two-faced cloth: transmission and openness)"
            )
        one_table = has_table and faces == "one"
        self.table = Table.open(str(props["table"])) if one_table else None
        self.fabric = Fabric(str(props["weave"])) if has_weave else None
        self.facet = str(props.get("facet", "huo"))
        self.two_sided = bool(props.get("two_sided", True))
        self.periods = float(props["periods"]) if "periods" in props else None
        if self.periods is not None and not (0.0 < self.periods < math.inf):
            raise ValueError(
                "clothbake BSDF: periods= is the weave periods per UV unit, a finite number > 0"
            )
        self.source = str(props["table"] if has_table else props["weave"])
        self.cloth = None
        if faces == "two":
            if self.periods is not None or not self.two_sided:
                raise ValueError(
                    "clothbake BSDF: faces=\"two\" takes no periods= or two_sided=False (the "
                    "two-faced cloth is drawn whole from either side)"
                )
            if has_table:
                self.cloth = TwoFaced.open(str(props["table"]))
            else:
                grid = str(props.get("nodes", "5,8")).split(",")
                self.cloth = self.fabric.two_faced(
                    facet=self.facet, nodes=(int(grid[0]), int(grid[1])),
                    paths=int(props.get("paths", 8192)))

    def flags(self, mi):
        """Glossy reflection, front side (and back side when two-sided); with two faces also
        glossy transmission and the null lobe of the openness."""
        if self.cloth is not None:
            return (mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.GlossyTransmission
                    | mi.BSDFFlags.Null | mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide)
        flags = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide
        if self.two_sided:
            flags = flags | mi.BSDFFlags.BackSide
        return flags


def _variant_check(mi):
    """True for a JIT (llvm) variant, False for a scalar one; raises for the others."""
    v = mi.variant()
    if v is not None and v.endswith("_rgb") and not v.endswith("polarized_rgb"):
        if v.startswith("scalar_"):
            return False
        if v.startswith("llvm_"):
            return True
    raise RuntimeError(
        f"clothbake.mitsuba: variant {v!r} is not supported; call "
        "mitsuba.set_variant('scalar_rgb') or mitsuba.set_variant('llvm_ad_rgb') before "
        "register()"
    )


def register():
    """Registers the BSDF plugin ``clothbake`` with Mitsuba 3 (for the current variant; call
    it again after switching variants). Call it after ``mitsuba.set_variant("scalar_rgb")``
    or ``mitsuba.set_variant("llvm_ad_rgb")``; in the llvm variant it turns Dr.Jit's symbolic
    loops and calls off (see the module's documentation)."""
    global _REGISTERED
    import drjit as dr
    import mitsuba as mi

    if _variant_check(mi):
        dr.set_flag(dr.JitFlag.SymbolicLoops, False)
        dr.set_flag(dr.JitFlag.SymbolicCalls, False)
        if _REGISTERED != mi.variant():
            from ._wavefront import wavefront_class

            cls = wavefront_class(mi, dr, Cloth)
            mi.register_bsdf("clothbake", lambda props: cls(props))
            _REGISTERED = mi.variant()
        return

    class ClothBSDF(mi.BSDF):
        """Woven cloth from clothbake: a baked table or the analytic model."""

        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            c = Cloth(props)
            self._table, self._fabric, self._facet = c.table, c.fabric, c.facet
            self._two_sided, self._periods, self._source = c.two_sided, c.periods, c.source
            self._cloth = c.cloth
            self.m_components = [c.flags(mi)]
            self.m_flags = c.flags(mi)

        # -- frames --------------------------------------------------------------------
        def _cloth_frame(self, si):
            """The cloth frame in world space: s along dp_du, n the shading normal."""
            n = si.sh_frame.n
            du = si.dp_du
            s = du - n * dr.dot(n, du)
            if dr.squared_norm(s) < 1e-20:
                s = si.sh_frame.s
            s = dr.normalize(s)
            return mi.Frame3f(s, dr.cross(n, s), n)

        def _to_cloth(self, si, frame, v):
            """A shading-frame vector in the cloth frame, as a tuple."""
            w = frame.to_local(si.sh_frame.to_world(v))
            return [float(w[0]), float(w[1]), float(w[2])]

        def _from_cloth(self, si, frame, v):
            return si.sh_frame.to_local(frame.to_world(mi.Vector3f(v[0], v[1], v[2])))

        def _directions(self, si, wo):
            """(light, eye, frame, flip) in the cloth frame, or None when they are on
            opposite sides or on the back of a one-sided cloth."""
            frame = self._cloth_frame(si)
            eye = self._to_cloth(si, frame, si.wi)
            light = self._to_cloth(si, frame, wo) if wo is not None else None
            flip = eye[2] < 0.0
            if flip and not self._two_sided:
                return None
            if flip:
                eye[2] = -eye[2]
                if light is not None:
                    light[2] = -light[2]
            if eye[2] <= 0.0 or (light is not None and light[2] <= 0.0):
                return None
            return light, _unit(eye), frame, flip

        def _width(self, si):
            """The footprint's side in periods from the ray differentials (0 without them)."""
            dx, dy = si.duv_dx, si.duv_dy
            side = max(math.hypot(float(dx[0]), float(dx[1])),
                       math.hypot(float(dy[0]), float(dy[1])))
            return side * self._periods if math.isfinite(side) else 0.0

        def _f(self, light, eye, si=None):
            """f_r, times the footprint's coverage with ``periods``."""
            if self._periods is not None and si is not None:
                u, v = float(si.uv[0]) * self._periods, float(si.uv[1]) * self._periods
                w = self._width(si)
                if self._table is not None:
                    f, c = self._table.eval1_local(light, eye, u, v, w)
                else:
                    f, c = self._fabric.eval1_at(light, eye, u, v, w, self._facet)
                return tuple(x * c for x in f)
            if self._table is not None:
                return self._table.eval1(light, eye)
            return self._fabric.eval1(light, eye, self._facet)

        def _pdf(self, light, eye):
            if self._table is not None:
                return self._table.pdf1(eye, light)
            return light[2] / math.pi

        # -- the two-faced cloth ---------------------------------------------------------
        def _two(self, si, wo):
            """(light, eye, frame) in the cloth frame, either side; None at the horizon."""
            frame = self._cloth_frame(si)
            eye = _unit(self._to_cloth(si, frame, si.wi))
            light = _unit(self._to_cloth(si, frame, wo)) if wo is not None else None
            if abs(eye[2]) <= 1e-9 or (light is not None and abs(light[2]) <= 1e-9):
                return None
            return light, eye, frame

        def _two_eval(self, si, wo):
            d = self._two(si, wo)
            if d is None:
                return mi.Color3f(0.0), 0.0
            light, eye, _ = d
            f = self._cloth.eval1(light, eye)
            c = abs(light[2])
            pdf = (1.0 - self._cloth.openness1(eye)) * c / (2.0 * math.pi)
            return mi.Color3f(f[0], f[1], f[2]) * c, pdf

        def _two_sample(self, si, sample1, sample2):
            bs = mi.BSDFSample3f()
            d = self._two(si, None)
            if d is None:
                return bs, mi.Color3f(0.0)
            _, eye, frame = d
            p_null = self._cloth.openness1(eye)
            bs.eta = 1.0
            bs.sampled_component = 0
            if sample1 < p_null:
                # Straight through the gaps: a delta of weight O, drawn with probability O.
                bs.wo = -si.wi
                bs.pdf = p_null
                bs.sampled_type = int(mi.BSDFFlags.Null)
                return bs, mi.Color3f(1.0)
            same = (sample1 - p_null) / (1.0 - p_null) < 0.5
            w = mi.warp.square_to_cosine_hemisphere(sample2)
            z = float(w[2]) if same == (eye[2] > 0.0) else -float(w[2])
            light = _unit([float(w[0]), float(w[1]), z])
            pdf = (1.0 - p_null) * abs(z) / (2.0 * math.pi)
            if pdf <= 0.0:
                return bs, mi.Color3f(0.0)
            f = self._cloth.eval1(light, eye)
            bs.wo = self._from_cloth(si, frame, light)
            bs.pdf = pdf
            bs.sampled_type = int(mi.BSDFFlags.GlossyReflection if same
                                  else mi.BSDFFlags.GlossyTransmission)
            k = abs(z) / pdf
            return bs, mi.Color3f(f[0] * k, f[1] * k, f[2] * k)

        # -- the BSDF interface --------------------------------------------------------
        def eval(self, ctx, si, wo, active=True):
            if self._cloth is not None:
                return self._two_eval(si, wo)[0]
            d = self._directions(si, wo)
            if d is None:
                return mi.Color3f(0.0)
            light, eye, _, _ = d
            light = _unit(light)
            f = self._f(light, eye, si)
            return mi.Color3f(f[0], f[1], f[2]) * light[2]

        def pdf(self, ctx, si, wo, active=True):
            if self._cloth is not None:
                return self._two_eval(si, wo)[1]
            d = self._directions(si, wo)
            if d is None:
                return 0.0
            light, eye, _, _ = d
            return self._pdf(_unit(light), eye)

        def eval_pdf(self, ctx, si, wo, active=True):
            return self.eval(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

        def sample(self, ctx, si, sample1, sample2, active=True):
            if self._cloth is not None:
                return self._two_sample(si, float(sample1), sample2)
            bs = mi.BSDFSample3f()
            d = self._directions(si, None)
            if d is None:
                return bs, mi.Color3f(0.0)
            _, eye, frame, flip = d
            if self._table is not None:
                light, weight, pdf = self._table.sample1(eye, sample2[0], sample2[1])
                light = list(light)
                if self._periods is not None and pdf > 0.0:
                    # Sampled from the averaged table; weighted by the point's own f_r.
                    f = self._f(_unit(light), eye, si)
                    weight = tuple(x * light[2] / pdf for x in f)
            else:
                w = mi.warp.square_to_cosine_hemisphere(sample2)
                light = [float(w[0]), float(w[1]), float(w[2])]
                pdf = light[2] / math.pi
                f = self._f(_unit(light), eye, si) if pdf > 0 else (0, 0, 0)
                weight = tuple(math.pi * x for x in f)
            if pdf <= 0.0:
                return bs, mi.Color3f(0.0)
            if flip:
                light[2] = -light[2]
            bs.wo = self._from_cloth(si, frame, light)
            bs.pdf = pdf
            bs.eta = 1.0
            bs.sampled_type = int(mi.BSDFFlags.GlossyReflection)
            bs.sampled_component = 0
            return bs, mi.Color3f(weight[0], weight[1], weight[2])

        def traverse(self, callback):
            pass

        def to_string(self):
            return (f"ClothBSDF[source={self._source!r}, two_sided={self._two_sided}, "
                    f"periods={self._periods}]")

    if _REGISTERED != mi.variant():
        mi.register_bsdf("clothbake", lambda props: ClothBSDF(props))
        _REGISTERED = mi.variant()


def _unit(v):
    """v normalised (the frame changes round-trip through float32)."""
    n = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return [v[0] / n, v[1] / n, v[2] / n]
