"""How quantities are shown to people: SI values in the units a reader expects (angles in
degrees), and ``name [unit]`` labels. Shared by the plots and the text summary; no matplotlib.
"""

from __future__ import annotations

import re

import numpy as np

HZ_PER_RAD_S = 1.0 / (2.0 * np.pi)
"""Factor from an angular frequency in rad/s to a frequency in Hz."""


def display_unit(unit: str, degrees: bool = True) -> tuple[float, str]:
    """(factor, unit) to show an SI quantity: rad -> deg (and rad/s -> deg/s) if ``degrees``."""
    if degrees and re.fullmatch(r"rad(/.*)?", unit):
        return float(np.degrees(1.0)), "deg" + unit[3:]
    return 1.0, unit


def axis_label(name: str, unit: str) -> str:
    """``"name [unit]"``, with ``[-]`` for dimensionless quantities (unit "" or "1")."""
    return f"{name} [{unit if unit not in ('', '1') else '-'}]"
