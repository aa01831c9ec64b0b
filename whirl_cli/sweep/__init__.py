"""Many studies at once: plan which to (re)run, run them in parallel, store in the parent.

``whirl sweep PATHS...`` (:func:`whirl_cli.sweep.run.run_sweep`) is built from three pieces:

* :func:`~whirl_cli.sweep.plan.plan` (pure, no AUTO): validate the study files and decide per
  study: ``run``, ``skip`` (up to date), ``plot`` (up to date, plots missing) or ``invalid``;
* :func:`~whirl_cli.sweep.execute.compute`, the task a worker process runs:
  :func:`whirl_cli.pipeline.run_study` in its own temporary directory, returning the result;
* :func:`~whirl_cli.sweep.execute.execute`: submits the planned studies to any
  ``concurrent.futures.Executor`` (a local process pool, or Dask's ``Client.get_executor()``)
  and, as each finishes, writes its HDF5 file and plots as one unit
  (:func:`whirl_cli.publish.publish_study`) **in the parent process only**.

Interrupting (Ctrl-C) cancels the studies not started yet, interrupts the running ones (their
AUTO processes are killed and their working directories removed) and keeps every output
already written; a study's outputs are never half a set (see
:mod:`whirl_cli.publish`).

Modules, lowest first:

* :mod:`~whirl_cli.sweep.plan` -- what to do with each study file;
* :mod:`~whirl_cli.sweep.execute` -- the worker task and the parent loop;
* :mod:`~whirl_cli.sweep.executors` -- a local interruptible process pool, or Dask;
* :mod:`~whirl_cli.sweep.report` -- progress lines, progress bar and summary;
* :mod:`~whirl_cli.sweep.run` -- the whole sweep, as ``whirl sweep`` runs it.
"""
