"""Shared fixtures: the repository's fabric files and a small baked table."""

import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
TABLES = ROOT / "tables"


@pytest.fixture(scope="session")
def twill_path():
    return TABLES / "twill.json"


@pytest.fixture(scope="session")
def figures_dir(tmp_path_factory):
    """docs/figures when CLOTHBAKE_WRITE_FIGURES=1, else a temporary folder."""
    if os.environ.get("CLOTHBAKE_WRITE_FIGURES") == "1":
        d = ROOT / "docs" / "figures"
        d.mkdir(parents=True, exist_ok=True)
        return d
    return tmp_path_factory.mktemp("figures")
