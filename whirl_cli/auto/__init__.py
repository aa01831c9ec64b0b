"""AUTO-07p: the symbolic model as AUTO's Fortran, compiled once, run, and its output read.

Modules, lowest first (each imports only those above it, and :mod:`whirl_cli.models`):

* :mod:`~whirl_cli.auto.constants` -- the PAR layout and AUTO's constants files;
* :mod:`~whirl_cli.auto.codegen` -- model -> the Fortran equations file (and its cache key);
* :mod:`~whirl_cli.auto.equation_files` -- the committed ``auto_equations/`` (``whirl
  generate``);
* :mod:`~whirl_cli.auto.toolchain` -- gfortran, the AUTO runtime, compiled executables in a
  cache;
* :mod:`~whirl_cli.auto.runner` -- one AUTO run in its own directory and its outcome; no AUTO
  process outlives an interrupt;
* :mod:`~whirl_cli.auto.parse` -- AUTO's ``b.``, ``s.`` and ``d.`` files ->
  :class:`~whirl_cli.results.Branch`.
"""
