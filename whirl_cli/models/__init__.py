"""Models: each defined once, as data, from which everything downstream is generated.

Modules, lowest first:

* :mod:`~whirl_cli.models.declaration` -- what a model family declares: degrees of freedom,
  parameters with bounds, its equations (M q'' = G - S); no sympy;
* :mod:`~whirl_cli.models.laws` -- structural stiffness laws on a dof (polynomial);
* :mod:`~whirl_cli.models.expressions`, :mod:`~whirl_cli.models.file` -- model files: a
  family as YAML data, its expressions read through a whitelist; the built-in families
  (classical, gimballed (provisional), oscillators) are such files, ``builtin/*.model.yaml``;
* :mod:`~whirl_cli.models.variant` -- a family with a law on each dof, as whirl runs it
  (names, scales, numeric functions);
* :mod:`~whirl_cli.models.symbolic` -- a variant's sympy equations (code generation only);
* :mod:`~whirl_cli.models.numeric` -- the numeric module generated from them, cached.

:func:`get_model` builds variants (cheap: no sympy); :data:`SHIPPED` lists the variants the
shipped studies use, whose AUTO files are committed under ``auto_equations/``.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from functools import cache
from pathlib import Path

from .declaration import Bounds, Constraint, Dof, Family, ModeGroup, Parameter, State
from .laws import LAWS
from .variant import Model

__all__ = ["Bounds", "Constraint", "Dof", "Family", "ModeGroup", "Model", "Parameter", "State",
           "BUILTIN", "FAMILIES", "LAWS", "MODEL_SUFFIX", "SHIPPED", "get_model", "all_variants",
           "family_of", "file_key", "is_model_file", "load_model_file", "register_model_text"]

#: The folder of the built-in model files, ``<name>.model.yaml``.
BUILTIN = Path(__file__).resolve().parent / "builtin"
MODEL_SUFFIX = ".model.yaml"


class _BuiltIns(Mapping):
    """The built-in families by name: known from the file names, each file read and checked
    when first asked for (a command that needs no model reads none)."""

    def __init__(self, folder: Path) -> None:
        self._paths = {p.name[:-len(MODEL_SUFFIX)]: p
                       for p in sorted(folder.glob(f"*{MODEL_SUFFIX}"))}
        self._read: dict[str, Family] = {}

    def __getitem__(self, name: str) -> Family:
        if name not in self._read:
            from .file import read_builtin

            self._read[name] = read_builtin(self._paths[name])
        return self._read[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._paths)

    def __len__(self) -> int:
        return len(self._paths)

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and name in self._paths


#: Model families by the name a study gives as ``model``.
FAMILIES: Mapping[str, Family] = _BuiltIns(BUILTIN)

#: The variants the shipped studies use: (family, law per dof).
SHIPPED: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("classical", ("polynomial", "polynomial")),
    ("classical", ("freeplay", "polynomial")),  # studies/freeplay
    ("classical", ("polynomial", "freeplay")),
    ("gimballed", ("polynomial",) * 4),
)


#: Model files read in this process, by the reference a study holds (the file's absolute path).
_FILES: dict[str, Family] = {}


def is_model_file(reference: object) -> bool:
    """True if a study's ``model`` names a model file (``*.yaml``/``*.yml``), not a built-in."""
    return isinstance(reference, str) and reference.lower().endswith((".yaml", ".yml"))


def family_of(reference: str) -> Family:
    """The family a study's ``model`` names: a built-in by name, or a model file by its
    absolute path (read once per process, :func:`load_model_file`). KeyError otherwise."""
    if reference in FAMILIES:
        return FAMILIES[reference]
    if reference not in _FILES and is_model_file(reference) and Path(reference).is_absolute() \
            and Path(reference).is_file():  # e.g. in a worker process of another machine
        load_model_file(Path(reference))
    return _FILES[reference]


def file_key(reference: str) -> str:
    """The content key of the model file a study's ``model`` names; "" for a built-in (a
    built-in is named, and its equations are whirl's version's)."""
    return family_of(reference).key if is_model_file(reference) else ""


def is_known(reference: object) -> bool:
    return isinstance(reference, str) and (reference in FAMILIES or reference in _FILES)


def load_model_file(path: Path, label: str | None = None) -> str:
    """Read and check the model file at ``path`` (StudyError listing every problem) and
    return the reference a study holds for it: its absolute path."""
    from .file import read_model_file

    reference = str(Path(path).absolute())
    _FILES[reference] = read_model_file(Path(path), label)
    return reference


def register_model_text(reference: str, text: str, label: str) -> str:
    """Hold the model file ``text`` (e.g. as stored with a result) under ``reference``."""
    from .file import model_from_text

    _FILES[reference] = model_from_text(text, label)
    return reference


def get_model(family: str | Family, laws: tuple[str, ...] | None = None) -> Model:
    """The variant of ``family`` (a family, or a study's ``model`` reference) with ``laws[i]``
    on its i-th dof (default: the polynomial law on every dof, which with zero coefficients is
    the linear model)."""
    declared = family_of(family) if isinstance(family, str) else family
    return _variant(declared, tuple(laws) if laws else ("polynomial",) * len(declared.dofs))


@cache
def _variant(family: Family, laws: tuple[str, ...]) -> Model:
    return Model(family, laws)


def all_variants() -> list[Model]:
    """The shipped variants, in a fixed order (the contents of ``auto_equations/``)."""
    return [get_model(family, laws) for family, laws in SHIPPED]
