"""The Python API: the example in docs/api-and-export.md runs as written (real AUTO), and its
results are the CLI's (same dataclasses, the same numbers as an independent eigenvalue
computation)."""

from __future__ import annotations

import contextlib
import io
import os
import re

import numpy as np
import pytest

from whirl_cli import api
from whirl_cli.analysis import linear
from whirl_cli.errors import WhirlError

from ..conftest import ROOT


def doc_example() -> str:
    text = (ROOT / "docs" / "api-and-export.md").read_text()
    section = text[text.index("## Python API"):]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_doc_example_runs(tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    monkeypatch.chdir(tmp_path)
    os.symlink(ROOT / "studies", tmp_path / "studies")
    printed = io.StringIO()
    namespace: dict = {}
    with contextlib.redirect_stdout(printed):
        exec(compile(doc_example(), "docs/api-and-export.md", "exec"), namespace)  # noqa: S102
    assert (tmp_path / "linear-case2.h5").is_file()
    assert (tmp_path / "linear-case2.png").read_bytes()[:4] == b"\x89PNG"
    table = namespace["table"]
    hopf = table[table["type"] == "HB"]
    assert len(hopf) == 2
    # the Hopf values AUTO found are where the linear model's eigenvalues cross Re = 0
    study = api.load(ROOT / "studies/thesis_ch3/linear_case2.yaml")
    model = study.variant()
    for k1 in hopf["K_theta [N m/rad]"]:
        around = linear.sweep(model, study.parameter_values(), "K_theta",
                              np.array([k1 - 1e-5, k1 + 1e-5]))
        leading = around.eigenvalues.real.max(axis=1)
        assert leading[0] * leading[1] < 0, (k1, leading)
    assert "Hopf points at K_theta =" in printed.getvalue()


def test_special_points_without_pandas_is_a_clear_error(monkeypatch, tmp_path):
    import builtins

    real_import = builtins.__import__

    def no_pandas(name, *args, **kwargs):
        if name == "pandas":
            raise ImportError("no pandas")
        return real_import(name, *args, **kwargs)

    result = api.run(ROOT / "studies/thesis_ch3/linear_datum_omega.yaml")
    monkeypatch.setattr(builtins, "__import__", no_pandas)
    with pytest.raises(WhirlError, match=r"pip install 'whirl\[pandas\]'"):
        api.special_points(result)


def test_run_and_save_writes_what_run_then_save_writes(tmp_path):
    """``api.run_and_save`` (what ``whirl run`` does: the plots drawn while a standby worker
    runs the cross-checks) stores the same result and the same plot files as ``api.run``
    followed by ``api.save`` (the cross-checks first, then the plots)."""
    study = api.load(ROOT / "studies/thesis_ch3/softening_case2.yaml")
    for folder in "ab":
        (tmp_path / folder).mkdir()
    together, published = api.run_and_save(study, tmp_path / "a" / "s.h5", study.plots,
                                            jobs=2)
    apart = api.run(study, jobs=2)
    api.save(apart, tmp_path / "b" / "s.h5", study.plots, state=study.plot_state, jobs=2)
    plots = sorted(p.name for p in (tmp_path / "a").glob("*.png"))
    assert len(plots) == 3 and not published.plot_error
    assert plots == sorted(p.name for p in (tmp_path / "b").glob("*.png"))
    for name in plots:
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()
    checks = [list(c.cross_checks) for c in together.continuations]
    assert checks == [list(c.cross_checks) for c in apart.continuations]  # every field equal
    assert sum(map(len, checks)) >= 2
    stored = api.read(tmp_path / "a" / "s.h5")
    assert [len(c.cross_checks) for c in stored.continuations] == list(map(len, checks))
