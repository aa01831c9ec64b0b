"""Which result file a plot belongs to: the plot files a whirl result file records (its root
attribute ``plots``), and whether a plot may be written where another result's plot stands.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import OutputError
from .guard import IMAGE, RESULT, check, plot_stem, refusal

#: Root attribute of the HDF5 file: names of the plot files published with it.
PLOTS_ATTRIBUTE = "plots"


def check_plot(path: Path, output: Path, overwrite: bool) -> None:
    """Raise :class:`OutputError` unless the plot ``path`` of the result file ``output`` may
    be written: :func:`whirl_cli.output.guard.check` (a PNG image, with ``overwrite``), and
    no other whirl result file beside it records ``path`` as its plot (two results' plot
    names can meet: ``a`` with continuation ``b_c`` and ``a_b`` with ``c``)."""
    other = owner(path, output)
    if other is not None:
        raise OutputError(f"{path}: a plot of {other}, not of {output}; whirl never "
                          "replaces it")
    check(path, IMAGE, overwrite)


def owner(path: Path, output: Path) -> Path | None:
    """The whirl result file beside the existing file ``path``, other than ``output``, that
    records it as one of its plots (None if none does). Only results whose stem begins
    ``path``'s name can: few are opened."""
    if not os.path.lexists(path):
        return None
    directory = Path(path).parent
    for name in sorted(os.listdir(directory)):
        other = directory / name
        if not Path(path).name.startswith(plot_stem(other.stem) + "_") or \
                _same_file(other, output) or refusal(other, RESULT):
            continue
        if Path(path).name in recorded_plots(other):
            return other
    return None


def _same_file(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def recorded_plots(output: Path) -> tuple[str, ...]:
    """The plot file names an existing result file records (empty if it records none, is
    absent or unreadable)."""
    if not os.path.isfile(output):  # absent, or nothing to open (a FIFO would block)
        return ()
    try:
        import h5py

        with h5py.File(output, "r") as handle:
            names = handle.attrs.get(PLOTS_ATTRIBUTE, ())
            return tuple(n.decode() if isinstance(n, bytes) else str(n) for n in names)
    except (OSError, ValueError, TypeError):
        return ()
