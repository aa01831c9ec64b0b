"""Shared fixtures. Tests marked ``auto`` run the real AUTO-07p (no mocks)."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
STUDIES = ROOT / "studies" / "thesis_ch3"


@pytest.fixture(autouse=True, scope="session")
def _private_cache(tmp_path_factory):
    """Compiled AUTO programs go to a per-session cache unless the caller chose one."""
    if "WHIRL_CACHE_DIR" not in os.environ:
        os.environ["WHIRL_CACHE_DIR"] = str(tmp_path_factory.mktemp("whirl-cache"))
    yield


def pytest_configure(config):
    """Python's own Ctrl-C handler, as in an interactive start: a shell without job control
    starts a background command (``make test &``, ``nohup``) with SIGINT ignored, and Python
    then keeps ignoring it, so the tests of how whirl holds and raises interrupts would see
    none."""
    if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_collection_modifyitems(items):
    for item in items:
        if "/tests/auto/" in str(item.fspath) or "/tests/regression/" in str(item.fspath):
            item.add_marker(pytest.mark.auto)
