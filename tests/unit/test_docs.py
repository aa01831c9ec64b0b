"""The docs stay true to the code: each reference page names what the code declares, its
examples are the shipped files, and its links lead somewhere inside the repository."""

from __future__ import annotations

import re
from dataclasses import fields
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.glob("*.md")) + [ROOT / "README.md"]


def table_keys(text: str, heading: str) -> set[str]:
    """The backquoted names in the first column of the table under ``heading``."""
    section = text[text.index(heading):]
    rows = re.findall(r"^\| (`[^|]*`) \|", section.split("\n\n", 2)[2].split("\n\n")[0], re.M)
    return {key for row in rows for key in re.findall(r"`([^`]+)`", row)}


def test_model_file_doc_names_every_key_of_the_format():
    from whirl_cli.models.file import ModelFile
    from whirl_cli.study.reference import _fields

    declared = {path for path, _ in _fields(ModelFile, "")}
    documented = table_keys((DOCS / "model-files.md").read_text(), "## Keys")
    assert documented == declared


def test_hdf5_layout_doc_names_every_declared_field():
    from whirl_cli.output import store
    from whirl_cli.results import BranchKind

    doc = (DOCS / "hdf5-layout.md").read_text()
    words = set(re.findall(r"\w+", doc))
    tables = [getattr(store, name) for name in ("BRANCH", "ORBIT", "SPECIAL_POINT", "PARAMETER",
              "CROSS_CHECK", "SEED", "EXPLORATION", "FREEPLAY", "LINEAR_SWEEP", "LINEAR_GRID",
              "BOUNDARY", "UNSAFE_INTERVAL", "SIMULATION", "RUN", "PROVENANCE_ROOT",
              "PROVENANCE", "FIXED_PARAMETER", "SLICE_LABEL", "LAW_CURVE")]
    keys = {field.hdf5_key(kind).rsplit("/", 1)[-1] for table in tables for field in table
            for kind in (BranchKind.EQUILIBRIUM, BranchKind.PERIODIC)}
    assert keys - words == set()


def test_study_doc_gives_whirls_auto_defaults():
    from whirl_cli.continuation.numerics import Numerics
    from whirl_cli.study import AutoSettings

    doc = (DOCS / "study-yaml.md").read_text()
    rows = dict(re.findall(r"^\| `auto\.(\w+)` \| ([^|]+) \|$", doc, re.M))
    expected = {f.name: f.default for f in fields(Numerics) if f.name in AutoSettings.model_fields}
    assert {name: float(value) for name, value in rows.items()} == expected


def test_study_doc_example_is_the_shipped_study():
    doc = (DOCS / "study-yaml.md").read_text()
    name, block = re.search(r"## Example\n\n`([^`]+)`:\n\n```yaml\n(.*?)```", doc, re.S).groups()
    assert block == (ROOT / name).read_text()


def test_nothing_a_user_gets_points_outside_the_repository():
    """The package, the shipped studies, sheets and examples name no file outside the
    repository (the developers' notes in ../shared are not shipped)."""
    shipped = [p for folder in ("whirl_cli", "studies", "sheets", "examples")
               for p in sorted((ROOT / folder).rglob("*"))
               if p.suffix in (".py", ".yaml", ".ipynb") and "__pycache__" not in p.parts]
    assert shipped
    assert [str(p.relative_to(ROOT)) for p in shipped if "../shared" in p.read_text()] == []


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_links_lead_inside_the_repository(page):
    text = page.read_text()
    assert "../shared" not in text
    for target in re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", text):
        if not target.startswith(("http://", "https://")):
            assert (page.parent / target).exists(), f"{page.name}: {target}"


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_paths_named_in_backquotes_exist(page):
    """A repository path a page names (``studies/...yaml``, ``whirl_cli/...py``, ...) exists."""
    prefixes = "whirl_cli/|studies/|tests/|sheets/|benchmarks/|examples/|docs/"
    for path in re.findall(r"`((?:" + prefixes + r")[^`\s*<>{}]+)`", page.read_text()):
        assert (ROOT / path.rstrip("/.,:")).exists(), f"{page.name}: {path}"



def test_plots_doc_names_every_plot_kind():
    from whirl_cli.plots.files import PLOT_KINDS

    documented = table_keys((DOCS / "plots.md").read_text(), "## Plot kinds and their files")
    assert documented >= set(PLOT_KINDS)


def test_readme_first_study_is_the_shipped_study():
    readme = (ROOT / "README.md").read_text()
    section = readme[readme.index("## A first study"):]
    name = re.search(r"`(studies/[^`]+\.yaml)`", section).group(1)
    block = re.search(r"```yaml\n(.*?)```", section, re.S).group(1)
    assert block == (ROOT / name).read_text()


def test_readme_first_model_file_and_its_study_are_valid(tmp_path):
    from whirl_cli.study import load_study

    readme = (ROOT / "README.md").read_text()
    section = readme[readme.index("## A first model file"):]
    names = re.findall(r"`(\w+(?:\.model)?\.yaml)`", section)[:2]
    blocks = re.findall(r"```yaml\n(.*?)```", section, re.S)[:2]
    for name, block in zip(names, blocks, strict=True):
        (tmp_path / name).write_text(block)
    study = load_study(tmp_path / names[1])
    assert study.variant().family.name == "oscillator"
    assert [c.parameter for c in study.continuations] == ["mu"]


# ------------------------------------------------------------------ docs/code-layout.md
PACKAGE = ROOT / "whirl_cli"


def layout_tree() -> dict[str, list[str]]:
    """Package (dotted) -> its modules, in the order code-layout.md lists them."""
    text = (DOCS / "code-layout.md").read_text()
    block = text[text.index("```\nwhirl_cli/"):].split("```")[1]
    tree: dict[str, list[str]] = {}
    stack: list[tuple[int, str]] = []
    for line in block.splitlines():
        names = re.match(r"( *)(\S+(?: \S+)*?)(?: {2,}|$)", line)
        if not names or not names.group(2):
            continue
        indent = len(names.group(1))
        if not names.group(2).endswith(("/", ".py")) and indent > 0:
            continue  # a description's continuation line
        while stack and stack[-1][0] >= indent:
            stack.pop()
        for name in names.group(2).split():
            if name.endswith("/"):
                stack.append((indent, name[:-1]))
            elif name.endswith(".py") and stack and stack[0][1] == "whirl_cli":
                tree.setdefault(".".join(n for _, n in stack), []).append(name[:-3])
    return tree


def module_imports(path: Path) -> set[tuple[str, bool]]:
    """(whirl module imported, at import time?) for one source file; ``if TYPE_CHECKING``
    blocks are not imports."""
    import ast

    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    package = parts[:-1]
    found: set[tuple[str, bool]] = set()

    def visit(node, top: bool) -> None:
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            return
        if isinstance(node, ast.ImportFrom):
            base = package[:len(package) - node.level + 1] if node.level else []
            target = ".".join(base + ([node.module] if node.module else []))
            for alias in node.names:
                whole = f"{target}.{alias.name}"
                is_module = (ROOT / whole.replace(".", "/")).with_suffix(".py").exists() or (
                    ROOT / whole.replace(".", "/")).is_dir()
                name = whole if is_module else target
                if name.startswith("whirl_cli"):
                    found.add((name, top))
        elif isinstance(node, ast.Import):
            found.update((a.name, top) for a in node.names if a.name.startswith("whirl_cli"))
        inner = isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda)
        for child in ast.iter_child_nodes(node):
            visit(child, top and not inner)

    for statement in ast.parse(path.read_text()).body:
        visit(statement, True)
    return found


def modules() -> dict[str, Path]:
    return {".".join(p.relative_to(ROOT).with_suffix("").parts): p
            for p in PACKAGE.rglob("*.py")}


def test_code_layout_lists_every_module():
    listed = {f"{package}.{name}" for package, names in layout_tree().items() for name in names}
    sources = {m for m in modules() if m.count(".") == 1 or not m.endswith(".__init__")}
    assert sources - listed == set()
    assert listed - sources == set()


def test_code_layout_lists_each_package_lowest_first():
    for package, names in layout_tree().items():
        for k, name in enumerate(names):
            path = modules()[f"{package}.{name}"]
            later = {f"{package}.{n}" for n in names[k + 1:]}
            early = {m for m, top in module_imports(path) if top} & later
            assert not early, f"{package}.{name} imports {early}, listed below it"


def private_imports(path: Path) -> list[tuple[int, str]]:
    """(line, ``module.name``) of every private name (``_name``, not dunder) that ``path``
    imports from another whirl module, at import time or inside a function."""
    import ast

    package = list(path.relative_to(ROOT).with_suffix("").parts)[:-1]
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            base = package[:len(package) - node.level + 1] if node.level else []
            target = ".".join(base + ([node.module] if node.module else []))
            found += [(node.lineno, f"{target}.{alias.name}") for alias in node.names
                      if alias.name.startswith("_") and not alias.name.startswith("__")]
    return found


def test_no_module_imports_a_private_name_of_another():
    found = [f"{name}:{line}: {target}" for name, path in modules().items()
             for line, target in private_imports(path)]
    assert found == []


def test_code_layout_table_names_every_import_of_each_package():
    text = (DOCS / "code-layout.md").read_text()
    table = text[text.index("| package or module | imports |"):].split("\n\n")[0]
    allowed: dict[str, tuple[set[str], set[str]]] = {}
    for row in table.splitlines()[2:]:
        first, second = row.strip("|").split(" | ")
        plain = second.split("(")[0]
        eager = {n.split(".")[0] for n in re.findall(r"`([\w.]+)`", plain)}
        lazy = {n.split(".")[0] for n in re.findall(r"`([\w.]+)`", second)}
        for unit in re.findall(r"`(\w+)`", first):
            allowed[unit] = (eager, lazy)

    def unit(module: str) -> str:
        parts = module.removesuffix(".__init__").split(".")
        return parts[1] if len(parts) > 1 else "whirl_cli"

    for name, path in modules().items():
        if unit(name) == "whirl_cli":
            continue
        eager, lazy = allowed[unit(name)]
        for target, top in module_imports(path):
            if unit(target) in (unit(name), "whirl_cli"):
                continue
            assert unit(target) in (eager if top else lazy), f"{name} imports {target}"
