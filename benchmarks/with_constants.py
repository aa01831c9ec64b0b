"""``whirl`` with extra AUTO constants for the runs whose name matches a glob:
``python benchmarks/with_constants.py '{"<glob>": {constants}}' run STUDY ...`` (mapping values
such as ``PAR`` merged one level deep), e.g. ISP=2 for the fold-of-cycles loci
(:data:`engines.LPC_ISP2`)."""

from __future__ import annotations

import fnmatch
import json
import sys


def with_constants(table: dict[str, dict]) -> None:
    """From now on the AUTO runs of this process get the constants of ``table``."""
    from whirl_cli.auto import runner

    real = runner.run

    def run(executable, constants, workdir, name, *args, **kwargs):
        for pattern, extra in table.items():
            if fnmatch.fnmatchcase(name, pattern):
                constants = {**constants, **{key: {**constants[key], **value}
                                             if isinstance(value, dict) else value
                                             for key, value in extra.items()}}
        return real(executable, constants, workdir, name, *args, **kwargs)

    runner.run = run


if __name__ == "__main__":
    with_constants(json.loads(sys.argv[1]))
    sys.argv = ["whirl", *sys.argv[2:]]
    from whirl_cli.entry import main

    main()
