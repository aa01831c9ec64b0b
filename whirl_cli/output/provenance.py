"""Provenance of a result: which whirl, which AUTO, which study text made it.

:func:`code_sha256` fingerprints whirl's own source code, so that a result counts as up to
date (``whirl sweep``) only while the code that produced it is unchanged: the version number
alone stays the same through commits that change results.
"""

from __future__ import annotations

import hashlib
import subprocess
from datetime import UTC, datetime
from functools import cache
from pathlib import Path

from .. import __version__
from ..models import file_key

PACKAGE = Path(__file__).resolve().parent.parent


@cache
def code_sha256() -> str:
    """sha256 over the package's Python sources (path and text of every ``*.py`` file under
    ``whirl_cli/``, in sorted order)."""
    digest = hashlib.sha256()
    for path in sorted(PACKAGE.rglob("*.py")):
        digest.update(path.relative_to(PACKAGE).as_posix().encode() + b"\0")
        digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()


def provenance(study) -> dict[str, str]:
    """Root attributes of a result file: versions, the code fingerprint, the study text and
    its hash, the time of creation (UTC) and ``git describe`` where available."""
    from ..auto.toolchain import auto_version

    attributes = {
        "whirl_version": __version__,
        "whirl_code_sha256": code_sha256(),
        "auto_version": auto_version(),
        "study_yaml": study.source,
        "study_sha256": study.sha256,
        "created": datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
    }
    family = study.variant().family
    if file_key(study.model):  # a model file: the equations that made the result, their hash
        attributes["model_file"] = study.model
        attributes["model_file_yaml"] = family.source
        attributes["model_file_sha256"] = hashlib.sha256(family.source.encode()).hexdigest()
        attributes["model_key"] = family.key
    if family.first_order:  # which states are not a dof or its rate
        attributes["first_order_states"] = ",".join(x.name for x in family.first_order)
    try:
        described = subprocess.run(["git", "describe", "--always", "--dirty"], cwd=PACKAGE,
                                   capture_output=True, text=True, timeout=5, check=False)
        if described.returncode == 0 and described.stdout.strip():
            attributes["git_describe"] = described.stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        pass
    return attributes
