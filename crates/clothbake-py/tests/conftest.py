"""Shared fixtures: the repository's fabric files and a small baked table."""

import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
TABLES = ROOT / "tables"


@pytest.fixture(scope="session")
def twill_path():
    return TABLES / "twill.json"


# An open plain weave (r/s = 0.25) of translucent yarns, for the two-faced cloth's tests.
OPEN_PLAIN = {
    "name": "open plain", "pattern": [[1, 0], [0, 1]],
    "warp": {"radius": 0.5, "spacing": 2,
             "material": {"albedo": 0.5, "specular": 0.1, "exponent": 8, "translucency": 0.8}},
    "weft": {"radius": 0.5, "spacing": 2,
             "material": {"albedo": 0.5, "specular": 0.1, "exponent": 8, "translucency": 0.8}},
}


@pytest.fixture(scope="session")
def figures_dir(tmp_path_factory):
    """docs/figures when CLOTHBAKE_WRITE_FIGURES=1, else a temporary folder."""
    if os.environ.get("CLOTHBAKE_WRITE_FIGURES") == "1":
        d = ROOT / "docs" / "figures"
        d.mkdir(parents=True, exist_ok=True)
        return d
    return tmp_path_factory.mktemp("figures")
