"""Figures of study results (matplotlib, Agg): bifurcation diagrams, state projections, period
plots, phase planes of stored orbits, linear sweeps, two-parameter stability maps with the
unsafe (overhang) region and the bifurcation diagrams of their slices, time histories and hub
paths of simulations, Poincaré sections and orbit diagrams of explored values.

The only package that imports matplotlib, and only inside functions (the CLI starts without
it). Figures are built with the object-oriented API on an Agg canvas, never through pyplot, so
they need no display, are not kept alive by pyplot's figure registry and are freed once
unreferenced. It depends on :mod:`whirl_cli.results` and :mod:`whirl_cli.units` (and
:mod:`whirl_cli.output.atomic` to publish the files; :mod:`~whirl_cli.plots.captions` on
:mod:`whirl_cli.study` to read the stored study).

Units: data arrive in SI (angles in rad, rates in rad/s, eigenvalues in 1/s). Bifurcation
diagrams show angle states in degrees by default ("rad" -> "deg", "rad/s" -> "deg/s");
parameters are always shown in their own (SI) units; periods in s. Linear sweeps show frequency
in rad/s (Hz on request) and the damping ratio (dimensionless). The study's figures are titled
by the study and the parameters it fixes, its slices by their labels
(:mod:`~whirl_cli.plots.captions`).

Modules, lowest first:

* :mod:`~whirl_cli.plots.key` -- the plot key (thesis Table 2.1) and the stability-map key,
  stability segments, units, axis labels, new figures;
* :mod:`~whirl_cli.plots.captions` -- titles and slice labels from the stored study;
* :mod:`~whirl_cli.plots.diagrams` -- bifurcation diagrams, projections, period plots, phase
  planes;
* :mod:`~whirl_cli.plots.linear` -- linear sweeps;
* :mod:`~whirl_cli.plots.maps` -- stability maps in two parameters and overhang diagrams;
* :mod:`~whirl_cli.plots.simulations` -- time histories and hub paths of simulations;
* :mod:`~whirl_cli.plots.motion` -- Poincaré sections, frequencies and orbit diagrams of the
  motion classified by simulation at a continuation's ``explore:`` values;
* :mod:`~whirl_cli.plots.files` -- a study's figures as named PNG files (axis limits, Hz, the
  kinds a result has the data for);
* :mod:`~whirl_cli.plots.panels` -- any kind drawn onto a given Axes, overlays;
* :mod:`~whirl_cli.plots.kinds` -- the registry of plot kinds (what each needs, the files it
  writes, its panel), read by all of the above and by the command line and study schema.
"""

#: The modules drawing imports (matplotlib's Figure and Agg canvas, about 0.7 s): what a caller
#: that will draw can :func:`~whirl_cli.runtime.preload` while AUTO runs.
MODULES = ("matplotlib.figure", "matplotlib.backends.backend_agg")
