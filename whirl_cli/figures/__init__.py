"""Figures made of several results: sheets, drawn after the studies they need have run.

``whirl figures SHEETS...`` (``make figures``) reads the sheet files (one YAML file per
figure: which study results, which plot kind, single panels, overlays or a grid), runs the
studies they name as one sweep (reusing up-to-date results), draws each sheet to
``fig<n>.png`` and writes ``index.html``.

Modules, lowest first:

* :mod:`~whirl_cli.figures.index` -- the index page (pure text);
* :mod:`~whirl_cli.figures.numbers` -- the thesis's numbers beside whirl's, for the index;
* :mod:`~whirl_cli.figures.sheet` -- sheet files, read and checked like studies;
* :mod:`~whirl_cli.figures.draw` -- one sheet as one matplotlib Figure
  (:mod:`whirl_cli.plots.panels` draws each panel);
* :mod:`~whirl_cli.figures.build` -- run, draw, publish and index.
"""
