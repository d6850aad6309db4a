"""Type stubs of the native module. Frame: +X weft, +Y warp, +Z normal; wi toward the light,
wo toward the eye; f_r in 1/sr, RGB."""

import os
from typing import Any, Callable, Dict, Optional, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str
"""The package's version (the Rust crates' version, e.g. "0.1.0")."""

UNIT_TOLERANCE: float
"""How far from 1 a direction's length may be before it is rejected."""

Vec3 = Tuple[float, float, float]

class Fabric:
    """A woven fabric, validated: from a fabric file path or a dict of the same schema.
    Raises ValueError naming the file (or ``<dict>``) and the field."""

    def __init__(self, source: Union[str, "os.PathLike[str]", Dict[str, Any]]) -> None: ...
    @property
    def name(self) -> str: ...
    def to_dict(self) -> Dict[str, Any]:
        """The fabric as a fabric-file dict, every field explicit."""
    @overload
    def eval(self, wi: npt.ArrayLike, wo: npt.ArrayLike, method: str = ..., bounces: int = ...,
             facet: str = ..., split: bool = False, samples: int = ..., seed: int = ...
             ) -> npt.NDArray[np.float64]: ...
    @overload
    def eval(self, wi: npt.ArrayLike, wo: npt.ArrayLike, method: str = ..., bounces: int = ...,
             facet: str = ..., split: bool = True, samples: int = ..., seed: int = ...
             ) -> Dict[str, npt.NDArray[np.float64]]: ...
    def eval(self, wi: npt.ArrayLike, wo: npt.ArrayLike, method: str = "analytic",
             bounces: int = 1, facet: str = "huo", split: bool = False,
             samples: int = 100000, seed: int = 1, uv: Optional[npt.ArrayLike] = None,
             width: Union[float, npt.ArrayLike, None] = None, level: str = "auto") -> Any:
        """f_r(wi, wo) in 1/sr, (N, 3) float64, for unit vectors (N, 3) or (3,).
        method "analytic" | "raytrace"; bounces 1 | 2; facet "huo" | "lewis"; split=True
        returns {"brdf", "diffuse", "specular", "secondary"}. With uv (N, 2): through a
        footprint of `width` periods at each point (level "auto": the yarns traced up close;
        "cells": the crossing cells); split=True then returns {"brdf", "coverage"} (and
        "secondary" with bounces=2)."""
    def eval1(self, wi: Vec3, wo: Vec3, facet: str = "huo") -> Vec3:
        """f_r of one pair (analytic, direct reflection), 1/sr."""
    def two_faced(self, facet: str = "huo", variant: str = "refined",
                  nodes: Tuple[int, int] = (5, 8), paths: int = 8192) -> "TwoFaced":
        """The two-faced cloth (docs/science/transmission.md); its coarse grid path-traced now."""
    def eval1_at(self, wi: Vec3, wo: Vec3, u: float, v: float, width: float = 0.0,
                 facet: str = "huo") -> Tuple[Vec3, float]:
        """(f_r, coverage) of one pair through a footprint at (u, v), every level of detail."""

class TwoFaced:
    """The two-faced cloth: f over the whole sphere and the openness (docs/science/transmission.md)."""
    @staticmethod
    def open(path: Union[str, "os.PathLike[str]"], reciprocal: bool = False) -> "TwoFaced":
        """Opens a two-faced table (baked with --faces two); ValueError for a one-faced one."""
    def eval(self, wi: npt.ArrayLike, wo: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def openness(self, w: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def eval1(self, wi: Vec3, wo: Vec3) -> Vec3: ...
    def openness1(self, w: Vec3) -> float: ...

class Table:
    """A baked f_r table (1/sr, RGB) with interpolated lookup and importance sampling."""

    @staticmethod
    def open(path: Union[str, "os.PathLike[str]"], reciprocal: bool = False,
             point_level: bool = True) -> "Table":
        """Opens an .exr or binary table; FileNotFoundError / ValueError on failure."""
    @property
    def has_point_level(self) -> bool: ...
    def without_point_level(self) -> "Table": ...
    @property
    def grid(self) -> Dict[str, int]: ...
    @property
    def metadata(self) -> Dict[str, Any]: ...
    @property
    def precision(self) -> str: ...
    def to_numpy(self) -> npt.NDArray[np.float32]:
        """(n_theta_i, n_phi_i, n_theta_o, n_phi_o, 3) float32, f_r at cell centres."""
    def eval(self, wi: npt.ArrayLike, wo: npt.ArrayLike) -> npt.NDArray[np.float32]:
        """Interpolated f_r (N, 3) float32 for unit vectors (N, 3)."""
    def sample(self, wo: npt.ArrayLike, u: npt.ArrayLike
               ) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.float32], npt.NDArray[np.float32]]:
        """(wi (N, 3), weight = f_r cos(theta_i) / pdf (N, 3), pdf (N,) per sr) for u (N, 2)."""
    def pdf(self, wo: npt.ArrayLike, wi: npt.ArrayLike) -> npt.NDArray[np.float32]:
        """Density (per sr) of sample() drawing wi for wo, (N,)."""
    def eval1(self, wi: Vec3, wo: Vec3) -> Vec3: ...
    def eval_at(self, wi: npt.ArrayLike, wo: npt.ArrayLike, uv: npt.ArrayLike,
                width: Union[float, npt.ArrayLike, None] = None
                ) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]: ...
    def eval1_at(self, wi: Vec3, wo: Vec3, u: float, v: float, width: float) -> Vec3: ...
    def eval1_local(self, wi: Vec3, wo: Vec3, u: float, v: float,
                    width: float) -> Tuple[Vec3, float]: ...
    def sample1(self, wo: Vec3, u1: float, u2: float) -> Tuple[Vec3, Vec3, float]: ...
    def pdf1(self, wo: Vec3, wi: Vec3) -> float: ...
    def save(self, path: Union[str, "os.PathLike[str]"], precision: str = "f16",
             overwrite: bool = False) -> None:
        """Writes atomically: .exr (f16 or f32) or the binary format (other extensions). An
        existing file raises FileExistsError unless ``overwrite=True``."""
    def _rust_batch_seconds(self, n: int, repeats: int = 5) -> float: ...

def bake(fabric: Fabric, res: Tuple[int, int, int, int] = (32, 64, 32, 64), bounces: int = 1,
         facet: str = "huo",
         progress: Union[None, bool, Callable[[int, int], Optional[bool]]] = None, *,
         output: Union[None, str, "os.PathLike[str]"] = None, overwrite: bool = False,
         resume: bool = False, shard: Optional[str] = None, format: Optional[str] = None,
         precision: Optional[str] = None, method: str = "analytic", variant: Optional[str] = None,
         samples: Optional[int] = None, seed: Optional[int] = None, caps: Optional[str] = None,
         secondary: Optional[str] = None, kernel: Optional[str] = None,
         orders: Optional[str] = None, sampling: Optional[str] = None,
         checkpoint_every: Optional[float] = None, spatial: bool = False) -> Optional[Table]:
    """Bakes fabric (the `clothbake bake` job): returns the Table (f32), also written to
    `output` if given (atomically, with checkpoints and resume); a shard (`shard="K/N"`) is
    written only and None returned. GIL released, deterministic."""
