"""The Mitsuba plugin in the llvm variants: each method takes the wavefront of lanes Mitsuba
hands it (concrete Dr.Jit arrays, symbolic loops and calls off), computes the directions in
the cloth frame in Dr.Jit (the frame, the mirroring of the back, the valid lanes: one kernel
a call), hands them to numpy as contiguous float32 (N, 3) rows and answers with one batch
call into the native module, whose results go back to Dr.Jit whole (``dr.unravel``), the
cosine and the masks applied lazily (fused into the integrator's next kernel).

The conventions are those of the scalar plugin (``clothbake.mitsuba``): the cloth frame is
(dp_du made orthogonal to the shading normal, n x s, n); seen from the back a two-sided cloth
is its front mirrored through the cloth's plane; light and eye on opposite sides give zero. With
``faces="two"`` the two-faced cloth: reflection off either face, transmission, and the null lobe
of the openness (``_two_*``).
"""

import numpy as np


def _rows(v):
    """A Dr.Jit 2- or 3-vector array as a numpy (N, k) float64 array."""
    a = np.asarray(v, dtype=np.float64)
    return a.reshape(a.shape[0], -1).T


def _unit(v):
    """Rows normalised."""
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _f(cloth, light, eye, uv, width=None):
    """f_r (N, 3) float64 of each row: with ``periods``, at the points uv of the period
    through footprints ``width`` periods wide, times their coverage (the cloth over black);
    else the averaged table or the model."""
    if cloth.periods is not None:
        w = np.zeros(len(uv)) if width is None else width
        if cloth.table is not None:
            f, c = cloth.table.eval_at(light, eye, uv * cloth.periods, w)
        else:
            s = cloth.fabric.eval(light, eye, facet=cloth.facet, uv=uv * cloth.periods,
                                  width=w, split=True)
            f, c = s["brdf"], s["coverage"]
        return np.asarray(f, dtype=np.float64) * np.asarray(c, dtype=np.float64)[:, None]
    if cloth.table is not None:
        return np.asarray(cloth.table.eval(light, eye), dtype=np.float64)
    return cloth.fabric.eval(light, eye, facet=cloth.facet)


def wavefront_class(mi, dr, Cloth):
    """The BSDF class for the current (llvm, RGB) variant; ``Cloth`` parses the parameters."""

    def check():
        if dr.flag(dr.JitFlag.SymbolicLoops) or dr.flag(dr.JitFlag.SymbolicCalls):
            raise RuntimeError(
                "clothbake BSDF: Dr.Jit's symbolic loops or calls are on; the plugin needs them "
                "off (clothbake.mitsuba.register() turns them off: call it after anything that "
                "turns them on)"
            )

    def up():
        """The normal (a fresh literal each call)."""
        return mi.Vector3f(0.0, 0.0, 1.0)

    def rows3(v):
        """A Dr.Jit 3-vector as a contiguous numpy (N, 3) float32 array."""
        return np.asarray(dr.ravel(v)).reshape(-1, 3)

    def color(rows):
        """Numpy (N, 3) rows as a Color3f (one array, unravelled)."""
        flat = np.ascontiguousarray(rows, dtype=np.float32).reshape(-1)
        return dr.unravel(mi.Color3f, mi.Float(flat))

    class ClothWavefrontBSDF(mi.BSDF):
        """Woven cloth from clothbake, a wavefront at a time (llvm variants)."""

        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self._cloth = Cloth(props)
            self.m_components = [self._cloth.flags(mi)]
            self.m_flags = self._cloth.flags(mi)

        def _frame(self, si):
            """The cloth frame in world space: s along dp_du, n the shading normal."""
            n = si.sh_frame.n
            du = si.dp_du
            s = du - n * dr.dot(n, du)
            s = dr.select(dr.squared_norm(s) < 1e-20, si.sh_frame.s, s)
            s = dr.normalize(s)
            return mi.Frame3f(s, dr.cross(n, s), n)

        def _pair(self, si, wo, active, u=None):
            """(ok, flip, frame, eye, light, light_z, u): the pair in the cloth frame, made
            valid everywhere (both above the cloth after mirroring the back; invalid lanes
            hold the normal, so that every batch call gets unit vectors). ok and flip are
            Dr.Jit masks, eye and light numpy (N, 3) float32 rows (light None without wo),
            light_z the light's cosine as a Dr.Jit Float, u the 2-vector ``u`` (the sample)
            as numpy (N, 2) float32 rows (or None). One kernel computes them all and lays
            the rows out interleaved (``dr.ravel``) for numpy."""
            check()
            frame = self._frame(si)

            def cloth(v):
                return frame.to_local(si.sh_frame.to_world(v))

            eye = cloth(si.wi)
            flip = eye.z < 0.0
            ok = mi.Bool(active)
            if not self._cloth.two_sided:
                ok &= ~flip
            sign = dr.select(flip, -1.0, 1.0)
            eye = mi.Vector3f(eye.x, eye.y, eye.z * sign)
            ok &= eye.z > 0.0
            light = None
            if wo is not None:
                light = cloth(wo)
                light = mi.Vector3f(light.x, light.y, light.z * sign)
                ok &= light.z > 0.0
            eye = dr.normalize(dr.select(ok, eye, up()))
            flat = [dr.ravel(eye)]
            if light is not None:
                light = dr.normalize(dr.select(ok, light, up()))
                flat.append(dr.ravel(light))
            if u is not None:
                flat.append(dr.ravel(u))
            lz = None if light is None else light.z
            dr.eval(ok, flip, lz, *flat)  # one kernel
            rows = [np.asarray(f).reshape(-1, k) for f, k in
                    zip(flat, [3, 3 if light is not None else 2, 2])]
            eye_rows = rows[0]
            light_rows = rows[1] if light is not None else None
            u_rows = rows[-1] if u is not None else None
            return ok, flip, frame, eye_rows, light_rows, lz, u_rows

        def _uv(self, si):
            if self._cloth.periods is None:
                return None
            return np.asarray(si.uv, dtype=np.float64).reshape(2, -1).T

        def _width(self, si, n):
            """Each lane's footprint side in periods from the ray differentials (0 without)."""
            if self._cloth.periods is None:
                return None
            def length(d):
                a = np.asarray(d, dtype=np.float64).reshape(2, -1)
                if a.shape[1] not in (1, n):
                    return np.zeros(n)  # not computed: the point
                return np.broadcast_to(np.hypot(a[0], a[1]), (n,))

            side = np.maximum(length(si.duv_dx), length(si.duv_dy))
            return np.where(np.isfinite(side), side * self._cloth.periods, 0.0)

        def _value(self, si, ok, eye, light, light_z):
            uv = self._uv(si)
            f = color(_f(self._cloth, light, eye, uv, self._width(si, len(eye))))
            return dr.select(ok, f * light_z, 0.0)

        def _density(self, ok, eye, light, light_z):
            if self._cloth.table is not None:
                pdf = mi.Float(self._cloth.table.pdf(eye, light))
            else:
                pdf = light_z / np.pi
            return dr.select(ok, pdf, 0.0)

        # -- the two-faced cloth ---------------------------------------------------------
        def _two_pair(self, si, wo, active):
            """(ok, frame, eye, eye_rows, light_rows, |light_z|): the pair in the cloth frame on
            either side, invalid lanes (at the horizon) holding the normal."""
            check()
            frame = self._frame(si)

            def cloth(v):
                return frame.to_local(si.sh_frame.to_world(v))

            eye = cloth(si.wi)
            ok = mi.Bool(active) & (dr.abs(eye.z) > 1e-9)
            light = None
            if wo is not None:
                light = cloth(wo)
                ok &= dr.abs(light.z) > 1e-9
            eye = dr.normalize(dr.select(ok, eye, up()))
            flat = [dr.ravel(eye)]
            lz = None
            if light is not None:
                light = dr.normalize(dr.select(ok, light, up()))
                flat.append(dr.ravel(light))
                lz = dr.abs(light.z)
            dr.eval(ok, eye, lz, *flat)  # one kernel
            rows = [np.asarray(f).reshape(-1, 3) for f in flat]
            return ok, frame, eye, rows[0], rows[1] if light is not None else None, lz

        def _two_value(self, ok, eye_rows, light_rows, lz):
            f = color(self._cloth.cloth.eval(light_rows, eye_rows))
            return dr.select(ok, f * lz, 0.0)

        def _two_density(self, ok, eye_rows, lz):
            o = mi.Float(np.asarray(self._cloth.cloth.openness(eye_rows), dtype=np.float32))
            return dr.select(ok, (1.0 - o) * lz / (2.0 * np.pi), 0.0)

        def _two_sample(self, si, sample1, sample2, active):
            ok, frame, eye, eye_rows, _, _ = self._two_pair(si, None, active)
            n = eye_rows.shape[0]
            o = mi.Float(np.asarray(self._cloth.cloth.openness(eye_rows), dtype=np.float32))
            null = ok & (sample1 < o)
            same = (sample1 - o) < 0.5 * (1.0 - o)
            w = mi.warp.square_to_cosine_hemisphere(sample2)
            z = dr.select(same == (eye.z > 0.0), w.z, -w.z)
            pdf = (1.0 - o) * w.z / (2.0 * np.pi)
            glossy = ok & ~null & (pdf > 0.0)
            light = dr.normalize(dr.select(glossy, mi.Vector3f(w.x, w.y, z), up()))
            dr.eval(light)
            f = color(self._cloth.cloth.eval(rows3(light), eye_rows))
            weight = dr.select(glossy, f * w.z / dr.select(glossy, pdf, 1.0), 0.0)
            weight = dr.select(null, 1.0, weight)
            bs = dr.zeros(mi.BSDFSample3f, n)
            bs.wo = dr.select(null, -si.wi, si.sh_frame.to_local(frame.to_world(light)))
            bs.pdf = dr.select(null, o, dr.select(glossy, pdf, 0.0))
            bs.eta = 1.0
            bs.sampled_type = dr.select(
                null, mi.UInt32(+mi.BSDFFlags.Null),
                dr.select(same, mi.UInt32(+mi.BSDFFlags.GlossyReflection),
                          mi.UInt32(+mi.BSDFFlags.GlossyTransmission)))
            bs.sampled_component = mi.UInt32(0)
            return bs, weight

        # -- the BSDF interface --------------------------------------------------------
        def eval(self, ctx, si, wo, active=True):
            if self._cloth.cloth is not None:
                ok, _, _, eye, light, lz = self._two_pair(si, wo, active)
                return self._two_value(ok, eye, light, lz)
            ok, _, _, eye, light, lz, _ = self._pair(si, wo, active)
            return self._value(si, ok, eye, light, lz)

        def pdf(self, ctx, si, wo, active=True):
            if self._cloth.cloth is not None:
                ok, _, _, eye, _, lz = self._two_pair(si, wo, active)
                return self._two_density(ok, eye, lz)
            ok, _, _, eye, light, lz, _ = self._pair(si, wo, active)
            return self._density(ok, eye, light, lz)

        def eval_pdf(self, ctx, si, wo, active=True):
            if self._cloth.cloth is not None:
                ok, _, _, eye, light, lz = self._two_pair(si, wo, active)
                return self._two_value(ok, eye, light, lz), self._two_density(ok, eye, lz)
            ok, _, _, eye, light, lz, _ = self._pair(si, wo, active)
            return self._value(si, ok, eye, light, lz), self._density(ok, eye, light, lz)

        def sample(self, ctx, si, sample1, sample2, active=True):
            if self._cloth.cloth is not None:
                return self._two_sample(si, sample1, sample2, active)
            table = self._cloth.table is not None
            ok, flip, frame, eye, _, _, u = self._pair(si, None, active,
                                                       sample2 if table else None)
            n = eye.shape[0]
            if table:
                if u.shape[0] != n:
                    u = np.broadcast_to(u, (n, 2))
                light, weight, pdf = self._cloth.table.sample(eye, u)
                pdf_dr = mi.Float(pdf)
                ok &= pdf_dr > 0.0
                if self._cloth.periods is not None:
                    # Sampled from the averaged table; weighted by the point's own f_r.
                    okn = np.broadcast_to(np.asarray(ok, dtype=bool).reshape(-1), (n,))
                    lu = _unit(np.where(okn[:, None], np.asarray(light, dtype=np.float64),
                                        [0.0, 0.0, 1.0]))
                    f = _f(self._cloth, lu, eye, self._uv(si), self._width(si, n))
                    pdf64 = np.asarray(pdf, dtype=np.float64)
                    weight = f * lu[:, 2:3] / np.where(okn, pdf64, 1.0)[:, None]
                wo = dr.unravel(mi.Vector3f, mi.Float(np.ascontiguousarray(light).reshape(-1)))
                weight = color(weight)
            else:
                w = mi.warp.square_to_cosine_hemisphere(sample2)
                pdf_dr = w.z / np.pi
                ok &= pdf_dr > 0.0
                lu = dr.normalize(dr.select(ok, w, up()))
                dr.eval(lu)
                weight = np.pi * color(_f(self._cloth, rows3(lu), eye, self._uv(si),
                                          self._width(si, n)))
                wo = w
            weight = dr.select(ok, weight, 0.0)
            pdf_dr = dr.select(ok, pdf_dr, 0.0)
            wo = dr.select(ok, wo, up())
            wo = mi.Vector3f(wo.x, wo.y, dr.select(flip, -wo.z, wo.z))
            bs = dr.zeros(mi.BSDFSample3f, n)
            bs.wo = si.sh_frame.to_local(frame.to_world(wo))
            bs.pdf = pdf_dr
            bs.eta = 1.0
            bs.sampled_type = mi.UInt32(+mi.BSDFFlags.GlossyReflection)
            bs.sampled_component = mi.UInt32(0)
            return bs, weight

        def traverse(self, callback):
            pass

        def to_string(self):
            c = self._cloth
            return (f"ClothBSDF[source={c.source!r}, two_sided={c.two_sided}, "
                    f"periods={c.periods}, wavefront]")

    return ClothWavefrontBSDF
