"""Result files: HDF5 written and read, published atomically, compared, with their provenance.

It depends on :mod:`whirl_cli.results`, never on :mod:`whirl_cli.plots` (a study's HDF5 file
and plots as one unit: :mod:`whirl_cli.publish`, a stage above both). Modules, lowest first:

* :mod:`~whirl_cli.output.atomic` -- a file appears complete or not at all (``publish``);
* :mod:`~whirl_cli.output.mapping` -- dataclass fields to HDF5 attributes, datasets and tables;
* :mod:`~whirl_cli.output.owners` -- which result file a plot belongs to;
* :mod:`~whirl_cli.output.store` -- the one writer and reader of result files (HDF5; older
  files upgraded on reading);
* :mod:`~whirl_cli.output.compare` -- two result files compared on what is physical;
* :mod:`~whirl_cli.output.provenance` -- versions, code fingerprint and study text of a result.
"""
