"""The Mitsuba plugin in the llvm variants: each method takes the wavefront of lanes Mitsuba
hands it (concrete Dr.Jit arrays, symbolic loops and calls off), converts the directions in
the cloth frame to numpy and answers with one batch call into the native module.

The conventions are those of the scalar plugin (``clothbake.mitsuba``): the cloth frame is
(dp_du made orthogonal to the shading normal, n x s, n); seen from the back a two-sided cloth
is its front mirrored through the cloth's plane; light and eye on opposite sides give zero.
"""

import numpy as np


def _rows(v):
    """A Dr.Jit 3-vector array as a numpy (N, 3) float64 array."""
    return np.asarray(v, dtype=np.float64).reshape(3, -1).T


def _mask(m, n):
    """A Dr.Jit mask (or Python bool) as a numpy (N,) bool array."""
    a = np.asarray(m, dtype=bool).reshape(-1)
    return np.broadcast_to(a, (n,)) if a.size == 1 else a


def _unit(v):
    """Rows normalised (the frame changes round-trip through float32)."""
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _directions(cloth, eye, light, active):
    """The rows where the pair is valid (both above the cloth after mirroring the back) and
    the pair made valid everywhere: (ok, eye, light), eye and light unit (N, 3). Invalid rows
    hold the normal, so that every batch call gets unit vectors."""
    flip = eye[:, 2] < 0.0
    ok = active.copy()
    if not cloth.two_sided:
        ok &= ~flip
    sign = np.where(flip, -1.0, 1.0)
    eye = eye * np.stack([np.ones_like(sign), np.ones_like(sign), sign], axis=1)
    ok &= eye[:, 2] > 0.0
    if light is not None:
        light = light * np.stack([np.ones_like(sign), np.ones_like(sign), sign], axis=1)
        ok &= light[:, 2] > 0.0
    up = np.array([0.0, 0.0, 1.0])
    eye = np.where(ok[:, None], eye, up)
    eye = _unit(eye)
    if light is not None:
        light = _unit(np.where(ok[:, None], light, up))
    return ok, eye, light, flip


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

    def to_color(rows):
        rows = np.ascontiguousarray(rows, dtype=np.float32)
        return mi.Color3f(mi.Float(rows[:, 0]), mi.Float(rows[:, 1]), mi.Float(rows[:, 2]))

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

        def _local(self, si, frame, v):
            return _rows(frame.to_local(si.sh_frame.to_world(v)))

        def _pair(self, si, wo, active):
            """(ok, eye, light, flip, frame): the numpy pair in the cloth frame."""
            check()
            frame = self._frame(si)
            eye = self._local(si, frame, si.wi)
            n = eye.shape[0]
            light = self._local(si, frame, wo) if wo is not None else None
            ok, eye, light, flip = _directions(self._cloth, eye, light, _mask(active, n))
            return ok, eye, light, flip, frame

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

        def _value(self, si, ok, eye, light):
            uv = self._uv(si)
            f = _f(self._cloth, light, eye, uv, self._width(si, len(eye))) * light[:, 2:3]
            return np.where(ok[:, None], f, 0.0)

        def _density(self, ok, eye, light):
            if self._cloth.table is not None:
                pdf = np.asarray(self._cloth.table.pdf(eye, light), dtype=np.float64)
            else:
                pdf = light[:, 2] / np.pi
            return np.where(ok, pdf, 0.0)

        def eval(self, ctx, si, wo, active=True):
            ok, eye, light, _, _ = self._pair(si, wo, active)
            return to_color(self._value(si, ok, eye, light))

        def pdf(self, ctx, si, wo, active=True):
            ok, eye, light, _, _ = self._pair(si, wo, active)
            return mi.Float(self._density(ok, eye, light).astype(np.float32))

        def eval_pdf(self, ctx, si, wo, active=True):
            ok, eye, light, _, _ = self._pair(si, wo, active)
            value = to_color(self._value(si, ok, eye, light))
            return value, mi.Float(self._density(ok, eye, light).astype(np.float32))

        def sample(self, ctx, si, sample1, sample2, active=True):
            ok, eye, _, flip, frame = self._pair(si, None, active)
            n = eye.shape[0]
            u = np.asarray(sample2, dtype=np.float64).reshape(2, -1).T
            if self._cloth.table is not None:
                light, weight, pdf = self._cloth.table.sample(eye, u)
                light = np.asarray(light, dtype=np.float64)
                weight = np.asarray(weight, dtype=np.float64)
                pdf = np.asarray(pdf, dtype=np.float64)
                ok &= pdf > 0.0
                if self._cloth.periods is not None:
                    # Sampled from the averaged table; weighted by the point's own f_r.
                    lu = _unit(np.where(ok[:, None], light, [0.0, 0.0, 1.0]))
                    f = _f(self._cloth, lu, eye, self._uv(si), self._width(si, n))
                    weight = f * lu[:, 2:3] / np.where(ok, pdf, 1.0)[:, None]
            else:
                w = _rows(mi.warp.square_to_cosine_hemisphere(sample2))
                pdf = w[:, 2] / np.pi
                ok &= pdf > 0.0
                lu = _unit(np.where(ok[:, None], w, [0.0, 0.0, 1.0]))
                weight = np.pi * _f(self._cloth, lu, eye, self._uv(si), self._width(si, n))
                light = w
            weight = np.where(ok[:, None], weight, 0.0)
            pdf = np.where(ok, pdf, 0.0)
            light = np.where(ok[:, None], light, [0.0, 0.0, 1.0])
            light[:, 2] = np.where(flip, -light[:, 2], light[:, 2])
            lf = np.ascontiguousarray(light, dtype=np.float32)
            v = mi.Vector3f(mi.Float(lf[:, 0]), mi.Float(lf[:, 1]), mi.Float(lf[:, 2]))
            bs = dr.zeros(mi.BSDFSample3f, n)
            bs.wo = si.sh_frame.to_local(frame.to_world(v))
            bs.pdf = mi.Float(pdf.astype(np.float32))
            bs.eta = 1.0
            bs.sampled_type = mi.UInt32(+mi.BSDFFlags.GlossyReflection)
            bs.sampled_component = mi.UInt32(0)
            return bs, to_color(weight)

        def traverse(self, callback):
            pass

        def to_string(self):
            c = self._cloth
            return (f"ClothBSDF[source={c.source!r}, two_sided={c.two_sided}, "
                    f"periods={c.periods}, wavefront]")

    return ClothWavefrontBSDF
