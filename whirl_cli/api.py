"""whirl from Python (a notebook, a script): the functions the command line is built on.

Load a study, run it, get the same result dataclasses the CLI stores
(:class:`~whirl_cli.results.StudyResult`), save and read HDF5 files, get the special points as
a table (a pandas DataFrame with the optional extra ``whirl[pandas]``) and draw any plot kind
onto a matplotlib Axes::

    from whirl_cli import api
    study = api.load("studies/thesis_ch3/linear_case2.yaml")
    result = api.run(study)
    api.save(result, "linear-case2.h5", plots=["bifurcation"])
    table = api.special_points(api.read("linear-case2.h5"))
    api.draw(result, "bifurcation", ax)

A model, built-in or a model file, as numbers (its right-hand side, Jacobian, eigenvalues)::

    model = api.load_model("studies/nacelle_on_wing/nacelle_on_wing.model.yaml")
    model.jacobian_numpy(np.zeros(model.n_states), model.parameter_vector({"V": 7.0}))

Nothing here prints; progress of the AUTO runs goes to ``on_run`` (and ``on_slow``) if given.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .errors import WhirlError
from .jobs import jobs_or_default
from .results import StudyResult
from .study import Study, load_study

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from .models import Model
    from .publish import Published

__all__ = ["draw", "export", "load", "load_model", "read", "run", "run_and_save", "save",
           "special_points"]


def load(path: str | os.PathLike[str]) -> Study:
    """The validated study at ``path`` (a StudyError lists every problem)."""
    return load_study(path)


def load_model(model: str | os.PathLike[str], laws: Sequence[str] | None = None) -> Model:
    """A model: a built-in by name (``"classical"``) or a model file by path (checked; a
    StudyError lists every problem), with the stiffness law ``laws[i]`` on its i-th dof
    (default: the polynomial law on every dof, linear at its datum). What a study's
    ``model:`` names, as :class:`~whirl_cli.models.Model`: names, units, datum values and
    the generated numeric functions (``rhs_numpy``, ``jacobian_numpy``, ...)."""
    from .models import FAMILIES, get_model, is_model_file, load_model_file

    reference = os.fspath(model)
    if reference not in FAMILIES and is_model_file(reference):
        reference = load_model_file(Path(reference))
    elif reference not in FAMILIES:
        raise WhirlError(f"unknown model {reference!r} (built-in: {', '.join(FAMILIES)}; or "
                         "a model file path ending in .yaml)")
    return get_model(reference, tuple(laws) if laws else None)


def run(study: Study | str | os.PathLike[str], jobs: int | None = None,
        on_run: Callable[[Any], None] | None = None,
        keep_runs: str | os.PathLike[str] | None = None,
        preload: tuple[str, ...] = (),
        on_slow: Callable[[str, float], None] | None = None,
        on_plan: Callable[[int], None] | None = None) -> StudyResult:
    """Run every continuation, linear analysis and cross-check of ``study`` (a Study or a
    path); ``jobs`` AUTO runs at once (None: as ``whirl run``, one per CPU); ``on_run`` is
    called with each AUTO run's outcome as it ends, ``on_slow`` with a run's name and seconds
    when it still runs after 10 s, 20 s, ..., ``on_plan`` with the number of AUTO runs
    about to start whenever more are (the runs planned so far).
    AUTO works in a temporary directory, removed afterwards, or kept under ``keep_runs``.
    ``preload``: modules needed afterwards, imported while AUTO runs (e.g.
    :data:`whirl_cli.plots.MODULES` before :func:`save` draws plots)."""
    from .pipeline import run_study

    study = study if isinstance(study, Study) else load_study(study)
    with _workroot(study, keep_runs) as workroot:
        return run_study(study, workroot, jobs=jobs_or_default(jobs), on_run=on_run,
                         preload=preload, on_slow=on_slow, on_plan=on_plan)


def save(result: StudyResult, path: str | os.PathLike[str], plots: Sequence[str] = (),
         overwrite: bool = False, state: str | None = None, jobs: int | None = None
         ) -> Published:
    """Write ``result`` to the HDF5 file ``path`` and its ``plots`` (kinds of
    :data:`whirl_cli.plots.files.PLOT_KINDS`, drawn in ``jobs`` processes, None: one per CPU)
    next to it, as one unit (all or nothing)."""
    from .publish import publish_study

    return publish_study(result, Path(path), tuple(plots), overwrite, state=state,
                         jobs=jobs_or_default(jobs))


def run_and_save(study: Study | str | os.PathLike[str], path: str | os.PathLike[str],
                 plots: Sequence[str] = (), overwrite: bool = False, jobs: int | None = None,
                 on_run: Callable[[Any], None] | None = None,
                 keep_runs: str | os.PathLike[str] | None = None,
                 preload: tuple[str, ...] = (),
                 on_slow: Callable[[str, float], None] | None = None,
                 on_plan: Callable[[int], None] | None = None
                 ) -> tuple[StudyResult, Published]:
    """:func:`run`, then :func:`save` with the study's ``plot_state``: the same files, but
    the plots drawn while the cross-checks run (:func:`whirl_cli.pipeline.run_and_draw`):
    what ``whirl run`` does."""
    from .output.guard import ready
    from .pipeline import run_and_draw
    from .publish import drawn_plots, publish_study

    study = study if isinstance(study, Study) else load_study(study)
    path, kinds, jobs = Path(path), tuple(plots), jobs_or_default(jobs)
    ready(path, overwrite, study.path, plots=bool(kinds))  # refused before any work
    draw = partial(drawn_plots, kinds=kinds, stem=path.stem, state=study.plot_state,
                   jobs=jobs)
    with _workroot(study, keep_runs) as workroot:
        result, drawn = run_and_draw(study, workroot, draw if kinds else None, jobs=jobs,
                                     on_run=on_run, preload=preload, on_slow=on_slow,
                                     on_plan=on_plan)
    return result, publish_study(result, path, kinds, overwrite, state=study.plot_state,
                                 jobs=jobs, drawn=drawn)


@contextmanager
def _workroot(study: Study, keep_runs: str | os.PathLike[str] | None) -> Iterator[Path]:
    """AUTO's working directory for ``study``: a new temporary one, removed afterwards (also
    when an interrupt held while it is made is raised), or one kept under ``keep_runs``.
    Nothing is made for an unknown AUTO engine."""
    from .auto.toolchain import engine_name
    from .runtime import held_signals

    engine_name()  # WHIRL_AUTO_ENGINE checked first
    workroot = None
    try:
        with held_signals():  # the work directory is made and removed whole
            if keep_runs:
                Path(keep_runs).mkdir(parents=True, exist_ok=True)
                workroot = Path(tempfile.mkdtemp(prefix=f"{study.name}-", dir=keep_runs))
            else:
                workroot = Path(tempfile.mkdtemp(prefix="whirl-"))
        yield workroot
    finally:
        with held_signals():
            if workroot is not None and not keep_runs:
                shutil.rmtree(workroot, ignore_errors=True)


def read(path: str | os.PathLike[str]) -> StudyResult:
    """The result stored in the HDF5 file ``path`` (schema 1 or 2)."""
    from .output import store

    return store.read(Path(path))


def export(result: StudyResult, path: str | os.PathLike[str], branches: bool = False,
           overwrite: bool = False) -> tuple[Path, ...]:
    """Write ``result`` for other tools, the format chosen by ``path``'s suffix: ``.mat``
    (MATLAB/Octave), ``.nc`` (NetCDF-4, needs ``whirl[export]``) or ``.csv`` (the special
    points; with ``branches`` also one file per branch beside it). Returns the paths
    written (:func:`whirl_cli.export.export`)."""
    from .export import export as write

    return write(result, path, branches=branches, overwrite=overwrite)


def special_points(result: StudyResult, dofs: Sequence[str] | None = None):
    """The special points of every continuation as a pandas DataFrame, one row per point, the
    columns of ``whirl summary --format csv`` (parameters and amplitudes with their units in
    the column names; amplitudes of ``dofs``, None: every dof). Needs pandas
    (``pip install 'whirl[pandas]'``)."""
    try:
        import pandas
    except ImportError:
        raise WhirlError("special_points needs pandas: pip install 'whirl[pandas]'") from None
    from .output.summary import columns, records, summary_rows

    rows = summary_rows(result, dofs)
    return pandas.DataFrame.from_records(records(rows), columns=columns(rows))


def draw(result: StudyResult, kind: str, ax: Axes, **choice) -> list[Axes]:
    """Draw ``result``'s figure of ``kind`` onto ``ax`` (any kind of
    :data:`whirl_cli.plots.panels.PANEL_KINDS`); ``choice``: the fields of
    :class:`~whirl_cli.plots.panels.PanelChoice` (``continuation``, ``state``, ``sweep``,
    ``slice``, ...). Returns the axes drawn on."""
    from .plots.panels import PanelChoice
    from .plots.panels import draw as draw_panel

    return draw_panel(result, kind, ax, PanelChoice(**choice))
