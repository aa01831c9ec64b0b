"""The package declares its type hints (PEP 561): a ``py.typed`` marker that wheels carry."""

from __future__ import annotations

import tomllib
from importlib import resources

from ..conftest import ROOT


def test_the_package_carries_a_py_typed_marker():
    assert resources.files("whirl_cli").joinpath("py.typed").is_file()
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert "py.typed" in project["tool"]["setuptools"]["package-data"]["whirl_cli"]
