"""The package's shape: three rooms (the library at the top, ssrlab.truth, ssrlab.lab) whose
imports go one way only (lab -> truth -> library), no import circle, `import ssrlab` loads the
library but neither the truth nor the lab (nor their heavy dependencies), and the old module
names (ssrlab.metrics, ssrlab.bench, ...) still reach the moved modules."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "python" / "ssrlab"

# Each room may import its own modules and those of the rooms below it. The command line is the
# front door: it may use every room.
RANK = {"library": 0, "truth": 1, "lab": 2, "door": 3}
# The one import against the direction: Frame.reference() runs the reference tracer of the native
# renderer on the frame's own resources and returns the truth's result types (imported when called).
UPWARD = {("frame", "truth.reference")}


def module_names() -> dict[str, Path]:
    """Dotted name inside the package (``renderer``, ``truth.reference``; a subpackage's
    __init__ is the subpackage's name) -> file."""
    out = {}
    for path in PACKAGE.rglob("*.py"):
        parts = list(path.relative_to(PACKAGE).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if parts and parts != ["__main__"]:
            out[".".join(parts)] = path
    out["_core"] = PACKAGE / "_core.pyi"  # the native module, as its stubs describe it
    return out


def room(name: str) -> str:
    head = name.split(".")[0]
    if head in ("truth", "lab"):
        return head
    # The live viewer is a front door too: an application over the library, the truth (its error
    # figures) and the lab alike.
    return "door" if head in ("cli", "__main__", "viewer") else "library"


def resolve(importer: str, is_package: bool, node: ast.ImportFrom, names: set[str]) -> set[str]:
    """The package's modules a relative `from ... import ...` names."""
    base = importer.split(".") if is_package else importer.split(".")[:-1]
    if node.level > 1:
        base = base[:len(base) - (node.level - 1)]
    prefix = ".".join([*base, *(node.module.split(".") if node.module else [])])
    out = set()
    for alias in node.names:  # `from . import metrics`: the name is a module; else one of prefix's names
        sub = f"{prefix}.{alias.name}" if prefix else alias.name
        out.add(sub if sub in names else prefix or "<package>")
    return out


def import_graph() -> dict[str, set[str]]:
    """Module -> the package's modules it imports (relative imports), at module level or inside
    functions. A name that is no module of the package (say an old, moved name) is kept as it is."""
    names = module_names()
    edges: dict[str, set[str]] = {m: set() for m in names}
    for m, path in names.items():
        if path.suffix == ".pyi":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level >= 1:
                edges[m] |= resolve(m, path.name == "__init__.py", node, set(names)) - {m}
    return edges


def find_cycle(edges: dict[str, set[str]]) -> list[str] | None:
    state: dict[str, int] = {}
    path: list[str] = []

    def visit(u: str) -> list[str] | None:
        state[u] = 1
        path.append(u)
        for v in sorted(edges.get(u, ())):
            if state.get(v) == 1:
                return path[path.index(v):] + [v]
            if v not in state and (c := visit(v)):
                return c
        state[u] = 2
        path.pop()
        return None

    for u in sorted(edges):
        if u not in state and (c := visit(u)):
            return c
    return None


def test_the_graph_sees_the_rooms_and_their_imports():
    edges = import_graph()
    assert {"renderer", "truth.reference", "truth.metrics", "lab.plan", "lab.run", "lab.report", "lab.timing"} <= set(edges)
    assert "truth.metrics" in edges["lab.run"] and "settings" in edges["truth.reference"]
    assert "lab.plan" in edges["lab.run"] and "lab.timing" in edges["lab.report"]


def test_no_import_circle():
    edges = import_graph()
    assert find_cycle(edges) is None, " -> ".join(find_cycle(edges))


def test_a_circle_would_be_found():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]


def test_imports_go_from_the_lab_to_the_truth_to_the_library_only():
    edges = import_graph()
    names = set(edges)
    unknown = sorted(f"{u} -> {v}" for u, vs in edges.items() for v in vs if v not in names)
    assert not unknown, f"imports of names that are no module of the package (an old name?): {unknown}"
    upward = {(u, v) for u, vs in edges.items() for v in vs if RANK[room(u)] < RANK[room(v)]}
    assert upward == UPWARD, f"imports against lab -> truth -> library: {sorted(upward - UPWARD)}; " \
                             f"no longer there: {sorted(UPWARD - upward)}"


def test_a_wrong_way_import_would_be_seen():
    tree = ast.parse("from ..lab.run import sweep\nfrom . import reference, views\n")
    names = {"lab.run", "truth.reference", "truth.views", "settings"}
    assert resolve("truth.metrics", False, tree.body[0], names) == {"lab.run"}
    assert resolve("truth.metrics", False, tree.body[1], names) == {"truth.reference", "truth.views"}
    assert RANK[room("truth.metrics")] < RANK[room("lab.run")]


HEAVY = ["dask", "distributed", "matplotlib", "mitsuba", "skimage", "flip_evaluator"]


def _run(code: str) -> str:
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return r.stdout


def test_import_ssrlab_loads_neither_the_truth_nor_the_lab():
    out = _run("import sys, ssrlab\n"
               "print(sorted(m for m in sys.modules if m.startswith(('ssrlab.truth', 'ssrlab.lab', 'ssrlab.cli'))))\n"
               f"print(sorted(m for m in {HEAVY!r} if m in sys.modules))\n"
               "print(hasattr(ssrlab.Frame, '_repr_png_'))\n").splitlines()
    assert out[0] == "[]", f"import ssrlab loaded {out[0]}"
    assert out[1] == "[]", f"import ssrlab loaded {out[1]}"
    assert out[2] == "True"  # the frames' Jupyter representations are installed with the library


def test_the_old_module_names_are_the_moved_modules():
    out = _run("import ssrlab, ssrlab.metrics, ssrlab.truth.metrics as m\n"
               "from ssrlab.bench import spread, sweep, pareto_front\n"
               "from ssrlab import reference, experiments\n"
               "import ssrlab.lab.run, ssrlab.lab.report, ssrlab.lab.timing, ssrlab.truth.reference as ref\n"
               "print(ssrlab.metrics is m, sweep is ssrlab.lab.run.sweep, pareto_front is ssrlab.lab.report.pareto_front,"
               " spread is ssrlab.lab.timing.spread, reference is ref, experiments is ssrlab.lab.experiments,"
               " ssrlab.journal is ssrlab.lab.journal, ssrlab.analytic.__name__)\n"
               # the references' Jupyter representations come with the truth
               "print(hasattr(ref.ConvergedReference, '_repr_png_'), hasattr(ref.PerRayReference, '_repr_html_'))\n"
               ).splitlines()
    assert out[0] == "True True True True True True True ssrlab.truth.analytic"
    assert out[1] == "True True"


def test_an_unknown_name_is_an_attribute_error():
    out = _run("import ssrlab\ntry:\n    ssrlab.nothing\nexcept AttributeError as e:\n    print(e)\n"
               "try:\n    import ssrlab.nothing\nexcept ImportError as e:\n    print(type(e).__name__)\n")
    assert out.splitlines() == ["module 'ssrlab' has no attribute 'nothing'", "ModuleNotFoundError"]


REPO = PACKAGE.parents[1]


def _private_uses(path: Path) -> list[str]:
    """ssrlab names a script uses that start with an underscore (ssrlab._core, ssrlab.x._y, x._y
    of a module imported from ssrlab), or any import from the tests."""
    tree = ast.parse(path.read_text())
    found, aliases = [], set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "ssrlab":
            parts = node.module.split(".") + [a.name for a in node.names]
            found += [f"from {node.module} import {a.name}" for a in node.names
                      if any(p.startswith("_") and p != "__version__" for p in parts[:len(node.module.split("."))] + [a.name])]
            aliases |= {a.asname or a.name for a in node.names}
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] == "ssrlab" and any(p.startswith("_") for p in a.name.split(".")):
                    found.append(f"import {a.name}")
                if a.name.split(".")[0] == "ssrlab":
                    aliases.add(a.asname or a.name.split(".")[0])
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            names = [node.module or ""] if isinstance(node, ast.ImportFrom) else [a.name for a in node.names]
            found += [f"import of the tests' {n}" for n in names if n.split(".")[0] in ("tests", "conftest", "data")]
    for node in ast.walk(tree):  # ssrlab._core, cc._mi, ssrlab.reference._x ...
        if isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__"):
            base = node.value
            while isinstance(base, ast.Attribute):
                base = base.value
            if isinstance(base, ast.Name) and base.id in aliases:
                found.append(ast.unparse(node))
    return found


def test_benchmarks_use_the_public_api_only():
    scripts = sorted(p for p in (REPO / "benchmarks").rglob("*.py") if p.name != "__init__.py")
    assert len(scripts) > 20
    bad = {p.name: u for p in scripts if (u := _private_uses(p))}
    assert not bad, bad


def test_the_public_api_check_would_see_private_names(tmp_path):
    script = tmp_path / "s.py"
    script.write_text("import ssrlab\nfrom ssrlab import _core, crosscheck as cc\nfrom ssrlab.settings import _FIELDS\n"
                      "from data.make_hostile import base\nx = cc._mi\ny = ssrlab._core\n")
    assert sorted(_private_uses(script)) == sorted(["from ssrlab import _core", "from ssrlab.settings import _FIELDS",
                                                    "import of the tests' data.make_hostile", "cc._mi",
                                                    "ssrlab._core"])


def test_tests_import_no_script_by_path():
    bad = []
    for path in sorted((REPO / "tests").glob("*.py")):
        text = path.read_text()
        for needle in ("spec_from_file_location", "runpy", "sys.path.insert", "sys.path.append"):
            if needle in text and path.name != "test_package.py":
                bad.append(f"{path.name}: {needle}")
    assert not bad, bad
