"""AUTO numerics under readable names, and whirl's defaults for them (no heavy imports: the
study schema checks a study's ``auto`` settings against these defaults)."""

from __future__ import annotations

from dataclasses import dataclass, fields, replace


@dataclass(frozen=True)
class Numerics:
    """Resolved AUTO numerics under readable names (study ``auto:`` keys override them).

    Step sizes are fractions of the width of the continuation range, so one set of defaults
    serves every parameter (the model's time and states are non-dimensional, see
    :mod:`whirl_cli.models.variant`).
    """

    max_steps: int = 2000  # NMX
    step_initial: float = 0.002  # |DS| / range width
    step_min: float = 1e-7  # DSMIN / range width
    step_max: float = 0.005  # DSMAX / range width
    mesh_intervals: int = 40  # NTST
    collocation_points: int = 4  # NCOL
    newton_max_iterations: int = 7  # ITNW
    tolerance: float = 1e-8  # EPSL = EPSU
    timeout: float = 120.0  # s per AUTO run
    max_amplitude: float = 1.5  # branches stop when a dof exceeds it (typical amplitudes)
    orbits_at: tuple[float, ...] = ()  # parameter values with a labelled solution (UZR)

    @classmethod
    def from_settings(cls, settings: object | None) -> Numerics:
        """Defaults overridden by the non-None attributes of a study's ``auto`` settings."""
        if settings is None:
            return cls()
        chosen = {f.name: getattr(settings, f.name) for f in fields(cls)
                  if getattr(settings, f.name, None) is not None}
        return replace(cls(), **chosen)
