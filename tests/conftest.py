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


@pytest.fixture(autouse=True)
def _signal_handlers():
    """Each test leaves SIGINT's and SIGTERM's handlers as it found them: whirl's console
    entry (``cli.main``) ends by giving them their default action, which, left in place, would
    let a later test's own signal end the test session."""
    saved = {number: signal.getsignal(number) for number in (signal.SIGINT, signal.SIGTERM)}
    yield
    for number, handler in saved.items():
        if handler is not None:
            signal.signal(number, handler)


def pytest_collection_modifyitems(items):
    for item in items:
        if "/tests/auto/" in str(item.fspath) or "/tests/regression/" in str(item.fspath):
            item.add_marker(pytest.mark.auto)


@pytest.fixture
def extra_auto_constants(monkeypatch):
    """``add({"<glob>": {constants}})``: the AUTO runs whose name (``<continuation>.<branch>``)
    matches a glob get those constants merged in (mapping values such as ``PAR`` one level
    deep), for this test; constants no study can write, to provoke AUTO failures."""
    import fnmatch

    from whirl_cli.auto import runner

    def add(table: dict[str, dict]) -> None:
        real = runner.run

        def run(executable, constants, workdir, name, *args, **kwargs):
            for pattern, extra in table.items():
                if fnmatch.fnmatchcase(name, pattern):
                    constants = merged(constants, extra)
            return real(executable, constants, workdir, name, *args, **kwargs)

        monkeypatch.setattr(runner, "run", run)

    return add


def merged(constants: dict, extra: dict) -> dict:
    """``constants`` updated with ``extra``, mapping values one level deep."""
    result = dict(constants)
    for key, value in extra.items():
        if isinstance(value, dict) and isinstance(result.get(key), dict):
            result[key] = {**result[key], **value}
        else:
            result[key] = value
    return result
