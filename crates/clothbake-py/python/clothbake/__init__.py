"""clothbake: the BRDF of woven cloth derived from its yarn geometry (Gang Huo, 1993).

Frame: +X weft, +Y warp, +Z the cloth's normal. ``wi`` points toward the light, ``wo``
toward the eye; directions are unit vectors, arrays of shape (N, 3). f_r is in 1/sr, RGB.

* :class:`Fabric`: a fabric file (or dict) and its BRDF from the analytic model.
* :class:`Table`: a baked table with interpolated lookup and importance sampling.
* :class:`TwoFaced` (``Fabric.two_faced()``): the two-faced cloth, light through the gaps and
  the yarns: f over the whole sphere and the openness (docs/science/transmission.md).
* :func:`bake`: bake a Fabric into a Table in memory, or into a table or shard file (checkpoints, resume).
* :mod:`clothbake.mitsuba`: a Mitsuba 3 BSDF plugin (``register()``).
"""

from ._native import UNIT_TOLERANCE, Fabric, Table, TwoFaced, __version__, bake

__all__ = ["Fabric", "Table", "TwoFaced", "bake", "UNIT_TOLERANCE", "__version__"]
