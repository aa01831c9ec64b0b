"""Continuation recipes: which AUTO runs to make, in what order, with which constants.

A recipe turns one continuation of a study into AUTO runs
(:class:`~whirl_cli.continuation.engine.RunSpec`), executes them through an
:class:`~whirl_cli.continuation.engine.Engine` (independent runs in parallel) and collects the
branches and special points into a :class:`~whirl_cli.results.ContinuationResult`. It builds on
:mod:`whirl_cli.auto` and :mod:`whirl_cli.analysis`.

Modules, lowest first (each imports only those above it):

* :mod:`~whirl_cli.continuation.branches` -- operations on branches: first rows, joined runs,
  orbit amplitude, special points;
* :mod:`~whirl_cli.continuation.numerics` -- AUTO numerics under readable names, whirl's
  defaults (imported by the study schema too);
* :mod:`~whirl_cli.continuation.engine` -- numerics, run specifications, the engine that
  makes the runs and reads their branches;
* :mod:`~whirl_cli.continuation.equilibria` -- equilibrium branches with branch switching;
* :mod:`~whirl_cli.continuation.homoclinic` -- HomCont runs locating homoclinic ends;
* :mod:`~whirl_cli.continuation.periodic` -- periodic families of the Hopf points;
* :mod:`~whirl_cli.continuation.criticality` -- super- or subcritical Hopf points;
* :mod:`~whirl_cli.continuation.one_parameter` -- the one-parameter recipe;
* :mod:`~whirl_cli.continuation.geometry` -- curve geometry of loci;
* :mod:`~whirl_cli.continuation.loci` -- the two-parameter recipe: slices and loci.
"""
