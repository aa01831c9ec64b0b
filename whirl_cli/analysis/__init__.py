"""Analysis without AUTO: numpy and scipy on the symbolic model's right-hand side.

It depends only on :mod:`whirl_cli.models`, :mod:`whirl_cli.results` and
:mod:`whirl_cli.runtime` (the continuation recipes use it, never the reverse); scipy is
imported inside functions.

* :mod:`~whirl_cli.analysis.linear` -- eigenvalues of the equilibrium: damping, frequency,
  whirl direction, critical points, sweeps and grids (numpy, vectorised);
* :mod:`~whirl_cli.analysis.normal_form` -- the first Lyapunov coefficient of a Hopf point;
* :mod:`~whirl_cli.analysis.global_bifurcations` -- period blow-up at the end of a periodic
  family: homoclinic or heteroclinic approach, bracketed;
* :mod:`~whirl_cli.analysis.simulate` -- time simulation (scipy), the cross-check of what
  continuation claims;
* :mod:`~whirl_cli.analysis.lyapunov` -- the largest Lyapunov exponent of any ODE by the
  variational equations (Benettin), with its standard error;
* :mod:`~whirl_cli.analysis.motion` -- what a simulation settles to where AUTO cannot
  continue: equilibrium, periodic, quasi-periodic, chaotic or diverged, from a Poincaré
  section, the Lyapunov exponent and the spectrum;
* :mod:`~whirl_cli.analysis.boundaries` -- stability boundaries in two parameters and the
  unsafe (overhang) region.
"""
