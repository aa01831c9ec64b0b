"""One vocabulary: the words result files store are the enums of ``whirl_cli.kinds``, read
and written at the file boundary only; code compares enum members and Origin fields, never
text."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import h5py
import numpy as np
import pytest

from whirl_cli import kinds
from whirl_cli.continuation.criticality import with_criticality
from whirl_cli.errors import OutputError
from whirl_cli.output import store
from whirl_cli.plots.cuts import _cycle
from whirl_cli.results import (
    BoundaryMethod,
    Branch,
    BranchKind,
    CheckKind,
    ContinuationKind,
    ContinuationResult,
    Criticality,
    LocateStatus,
    LocusKind,
    MotionKind,
    Orbit,
    Origin,
    PointType,
    RunStatus,
    SeedKind,
    SimulationLaw,
    Spacing,
    SpecialPoint,
    StudyResult,
    UnsafeCause,
)

ROOT = Path(__file__).resolve().parents[2]
REFERENCES = sorted((ROOT / "tests/regression/references").glob("*.h5")) + [
    ROOT / "tests/data/legacy_hardening_case2.h5"]
LAYOUT = (ROOT / "docs/hdf5-layout.md").read_text()


def _text(value) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def _stored_words(path: Path) -> dict[type, set[str]]:
    """Every word of the vocabulary a result file stores, by the enum it belongs to (read
    with h5py alone, as another reader of the file would)."""
    found: dict[type, set[str]] = {}

    def add(enum, values):
        found.setdefault(enum, set()).update(_text(v) for v in np.atleast_1d(values))

    with h5py.File(path) as handle:
        for continuation in handle["continuations"].values():
            add(ContinuationKind, continuation.attrs["kind"])
            for branch in continuation["branches"].values():
                add(BranchKind, branch.attrs["kind"])
                add(RunStatus, branch.attrs["status"])
            points = continuation["special_points"]
            add(LocateStatus, points["status"][()])
            add(Criticality, points["criticality"][()])
            if "cross_checks" in continuation:
                add(CheckKind, continuation["cross_checks/kind"][()])
        for run in handle.get("runs", {}).values():
            add(RunStatus, run.attrs["status"])
    return found


@pytest.mark.parametrize("path", REFERENCES, ids=lambda p: p.name)
def test_every_word_a_reference_file_stores_is_a_value_of_its_enum(path):
    found = _stored_words(path)
    assert {BranchKind, RunStatus, ContinuationKind, LocateStatus} <= set(found)
    for enum, words in found.items():
        assert words <= {m.value for m in enum}, (enum.__name__, words)
        assert all(enum(w).value == w for w in words)


#: (enum, the line of docs/hdf5-layout.md that lists its words)
DOCUMENTED = [
    (ContinuationKind, r"kind \((one-parameter \| two-parameter)\)"),
    (LocateStatus, r"status\s+\((located \| bracketed \| rejected)\)"),
    (SeedKind, r"kind \((periodic \| equilibrium \| diverged \| unsettled)\)"),
    (MotionKind, r"kind \((equilibrium \| periodic \| quasi-periodic \| chaotic \|\s+diverged)\)"),
    (CheckKind, r"kind \((orbit \| equilibrium)\)"),
    (SimulationLaw, r"law \((smoothed \| exact)\)"),
    (RunStatus, r"status \((ok \| mx \| error \| timeout \| crashed)\)"),
    (BoundaryMethod, r"method \((loci \| slices)\)"),
    (UnsafeCause, r"cause \((flutter \|\s+divergence)\)"),
    (Spacing, r"spacing \((linear \| log)"),
    (LocusKind, r"attrs kind \((hopf \|\s+branch_point \| fold \| fold_of_cycles \| torus)\)"),
]


@pytest.mark.parametrize("enum, pattern", DOCUMENTED, ids=lambda x: getattr(x, "__name__", ""))
def test_the_words_of_each_enum_are_those_the_file_layout_documents(enum, pattern):
    found = re.search(pattern, LAYOUT)
    assert found, f"docs/hdf5-layout.md does not list the words of {enum.__name__}"
    assert re.split(r"\s*\|\s*", found[1]) == [m.value for m in enum]


def test_every_branch_kind_is_documented_as_a_branch_kind():
    listed = re.search(r"kind \((equilibrium \| periodic \| <kind>_locus)\)", LAYOUT)
    assert listed
    loci = {m.value for m in BranchKind if m.is_locus}
    assert loci == {f"{k.value}_locus" for k in kinds.LocusKind}
    assert {m.value for m in BranchKind} - loci == {"equilibrium", "periodic", "homoclinic"}


@pytest.mark.parametrize("path", REFERENCES, ids=lambda p: p.name)
def test_every_stored_origin_reads_back_as_the_same_text(path):
    with h5py.File(path) as handle:
        texts = [_text(b.attrs["origin"]) for c in handle["continuations"].values()
                 for b in c["branches"].values()]
    assert texts
    for text in texts:
        assert str(Origin.parse(text)) == text


def _hopf(branch: str, value: float, parameter: str = "K1") -> SpecialPoint:
    return SpecialPoint(branch=branch, index=2, point_type=int(PointType.HB),
                        parameter_names=(parameter,), parameters=np.array([value]),
                        state=np.zeros(4), period=1.0, stable=False)


def test_an_origin_at_a_point_has_its_fields_and_its_text():
    origin = Origin.at(_hopf("main_down", 0.1), "smoothing x 0.5")
    assert (origin.point, origin.parameter, origin.value, origin.branch) == (
        PointType.HB, "K1", 0.1, "main_down")
    assert str(origin) == "HB at K1 = 0.1 on main_down, smoothing x 0.5"
    assert Origin.parse(str(origin)) == origin
    assert Origin.parse("start at K1 = 0.5") == Origin("start at K1 = 0.5")
    assert Origin.parse("start at K1 = 0.5").point is None


def test_a_text_that_would_not_read_back_the_same_stays_a_note():
    for text in ("HB at K1 = 0.10 on main_down",  # not as whirl writes 0.1
                 "XX at K1 = 0.1 on main_down",  # no such point type
                 "equilibrium at K1 = 0.3 off every branch (a seed settled on it)"):
        assert Origin.parse(text) == Origin(text)


def _branch(name: str, kind: BranchKind, origin: Origin, k1: np.ndarray,
            eigenvalues: np.ndarray | None = None, orbits=()) -> Branch:
    n = len(k1)
    return Branch(name=name, kind=kind, origin=origin, parameter_names=("K1",),
                  parameter_units=("N m/rad",), state_names=("theta", "psi", "dtheta", "dpsi"),
                  state_units=("rad", "rad", "rad/s", "rad/s"), parameters=k1[:, None],
                  state_max=np.zeros((n, 4)), state_min=np.zeros((n, 4)), l2_norm=np.zeros(n),
                  period=np.full(n, np.nan), stable=np.zeros(n, dtype=bool),
                  point_type=np.zeros(n, dtype=np.int64), label=np.zeros(n, dtype=np.int64),
                  eigenvalues=np.full((n, 4), np.nan + 0j) if eigenvalues is None
                  else eigenvalues, orbits=orbits)


def test_a_family_labels_the_hopf_point_it_starts_at_not_one_written_alike():
    """Two Hopf points on one branch whose values agree to the 6 digits an origin's text
    keeps: the family started at the second decides the second's criticality only."""
    k1 = np.array([0.3, 0.25, 0.2, 0.15, 0.1])
    growth = -(k1 - 0.2)  # the pair grows as K1 falls: a family below is supercritical
    omega = 2 * np.pi
    values = np.column_stack([growth + 1j * omega, growth - 1j * omega,
                              np.full(5, -5.0 + 0j), np.full(5, -6.0 + 0j)])
    main = _branch("main_down", BranchKind.EQUILIBRIUM, Origin("start"), k1, values)
    first, second = (replace_criticality(_hopf("main_down", v), Criticality.SUBCRITICAL)
                     for v in (0.2, 0.2 + 1e-9))
    assert str(Origin.at(first)) == str(Origin.at(second))
    family = _branch("periodic_2", BranchKind.PERIODIC, Origin.at(second),
                     np.array([0.2, 0.19, 0.18, 0.17]))
    labelled = with_criticality([first, second], [family], [main], 0.8, np.ones(4))
    assert [p.criticality for p in labelled] == [Criticality.SUBCRITICAL,
                                                 Criticality.SUPERCRITICAL]


def replace_criticality(point: SpecialPoint, criticality: Criticality) -> SpecialPoint:
    from dataclasses import replace

    return replace(point, criticality=criticality)


def test_a_cycle_of_a_short_run_names_the_branch_it_was_born_on():
    orbit = Orbit(label=1, point_type=0, index=0, parameters=np.array([0.2]), period=1.0,
                  time=np.linspace(0, 1, 5), states=np.zeros((5, 4)))
    for origin, parent in ((Origin.at(_hopf("main_down", 0.2), "smoothing x 0.5"),
                            " of main_down"),
                           (Origin("seed 1 settled by time simulation (on it)"), "")):
        family = _branch("periodic_1", BranchKind.PERIODIC, origin, np.array([0.2]),
                         orbits=(orbit,))
        assert _cycle(family, orbit).parent == parent


def test_a_file_with_a_word_outside_the_vocabulary_is_damaged(tmp_path):
    branch = _branch("main_down", BranchKind.EQUILIBRIUM, Origin("start"), np.array([0.1, 0.2]))
    result = StudyResult("s", "classical", (ContinuationResult(
        "k1", ContinuationKind.ONE_PARAMETER, (branch,), ()),), (), ())
    path = store.write(result, tmp_path / "r.h5")
    assert store.read(path).continuations[0].branches[0].kind is BranchKind.EQUILIBRIUM
    with h5py.File(path, "r+") as handle:
        handle["continuations/k1/branches/main_down"].attrs["kind"] = "equilibria"
    with pytest.raises(OutputError, match=r"/continuations/k1/branches/main_down: attribute "
                                          r"'kind': unknown kind 'equilibria'"):
        store.read(path)


# ------------------------------------------------------------------ no text dispatch on kinds
#: Attributes holding a word of the vocabulary (or a typed relation built of them).
WORDS = {"kind", "status", "criticality", "type", "action", "law", "origin", "runs"}
#: Attributes named like one that are something else: numpy's dtype kind codes, and the
#: storage type of a mapping Field (text, int, float, ...), dispatched through its tables.
OTHER = {("dtype", "kind"), ("field", "kind")}


def _text_literal(node: ast.AST) -> bool:
    if isinstance(node, ast.Constant):
        return isinstance(node.value, str)
    return isinstance(node, ast.Tuple | ast.List | ast.Set) and any(
        _text_literal(e) for e in node.elts)


def _word_attribute(node: ast.AST) -> bool:
    if not (isinstance(node, ast.Attribute) and node.attr in WORDS):
        return False
    owner = node.value
    owner_name = owner.attr if isinstance(owner, ast.Attribute) else getattr(owner, "id", "")
    return (owner_name, node.attr) not in OTHER


def text_dispatch(source: str) -> list[tuple[int, str]]:
    """Where ``source`` compares a vocabulary attribute with text, or cuts one as text."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            if any(map(_word_attribute, sides)) and any(map(_text_literal, sides)):
                found.append((node.lineno, ast.unparse(node)))
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
              and node.func.attr in ("startswith", "endswith", "split", "rsplit", "partition",
                                     "rpartition") and _word_attribute(node.func.value)):
            found.append((node.lineno, ast.unparse(node)))
    return found


def test_the_scan_finds_text_dispatch_on_kinds():
    assert text_dispatch('if branch.kind == "periodic": pass')
    assert text_dispatch('x = [s for s in seeds if s.status in ("ok", "mx")]')
    assert text_dispatch('b.origin.endswith("main_down")')
    assert text_dispatch('runs = branch.runs.split("+")')
    assert not text_dispatch("if branch.kind == BranchKind.PERIODIC: pass")
    assert not text_dispatch('data.dtype.kind == "f"')


def test_no_module_compares_a_kind_or_status_with_text():
    offences = [f"{path.relative_to(ROOT)}:{line}: {code}"
                for path in sorted((ROOT / "whirl_cli").rglob("*.py"))
                for line, code in text_dispatch(path.read_text())]
    assert not offences, "\n".join(offences)
