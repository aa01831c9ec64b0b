"""whirl's vocabulary of kinds that several stages name, each declared once here (no imports);
plot kinds are registered in :mod:`whirl_cli.plots.kinds`."""

from __future__ import annotations

#: The kinds of locus (a two-parameter continuation's ``loci``) that bound the unsafe region
#: by folds: of equilibria and of cycles.
FOLD_LOCI = ("fold", "fold_of_cycles")
