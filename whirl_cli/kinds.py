"""whirl's vocabulary of kinds that several stages name, each declared once here (no imports):
the study schema, the command line and the drawing code read them from this module."""

from __future__ import annotations

#: The plot kinds of a study's figures (``plots:`` in a study, ``whirl plot --kind``), in the
#: order a result's figures are drawn.
PLOT_KINDS = ("bifurcation", "linear", "root_locus", "damping_multiples", "projections",
              "period", "phase", "boundary", "amplitude", "time_history", "hub_path", "law",
              "poincare", "spectrum", "orbit_diagram")

#: The plot kinds drawn from a continuation's ``explore:`` classifications.
MOTION_KINDS = ("poincare", "spectrum", "orbit_diagram")

#: The kinds of locus (a two-parameter continuation's ``loci``) that bound the unsafe region
#: by folds: of equilibria and of cycles.
FOLD_LOCI = ("fold", "fold_of_cycles")
