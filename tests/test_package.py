"""The package's shape: no import circle among its modules, and `import ssrlab` loads the library
and the truth but not the lab (sweeps, experiments, the cross-check) nor their heavy dependencies."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "python" / "ssrlab"


def import_graph() -> dict[str, set[str]]:
    """Module -> the package's modules it imports, at module level or inside functions."""
    mods = {p.stem for p in PACKAGE.glob("*.py")} - {"__init__", "__main__"}
    edges: dict[str, set[str]] = {m: set() for m in mods}
    for m in mods:
        for node in ast.walk(ast.parse((PACKAGE / f"{m}.py").read_text())):
            if isinstance(node, ast.ImportFrom) and node.level == 1:
                names = [node.module.split(".")[0]] if node.module else [a.name for a in node.names]
                edges[m] |= {n for n in names if n in mods}
    return edges


def find_cycle(edges: dict[str, set[str]]) -> list[str] | None:
    state: dict[str, int] = {}
    path: list[str] = []

    def visit(u: str) -> list[str] | None:
        state[u] = 1
        path.append(u)
        for v in sorted(edges[u]):
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


def test_no_import_circle():
    edges = import_graph()
    assert len(edges) > 15
    assert find_cycle(edges) is None, " -> ".join(find_cycle(edges))


def test_a_circle_would_be_found():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]


LAB = ["ssrlab.bench", "ssrlab.experiments", "ssrlab.crosscheck", "ssrlab.glossy", "ssrlab.hybrid",
       "ssrlab.precision", "ssrlab.journal", "dask", "distributed", "matplotlib", "mitsuba", "skimage"]


def test_import_ssrlab_loads_no_lab():
    code = ("import sys, ssrlab; print(','.join(m for m in %r if m in sys.modules)); "
            "print(hasattr(ssrlab.Frame, '_repr_png_'), ssrlab.bench.__name__)" % LAB)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    loaded, last = r.stdout.splitlines()
    assert loaded == "", f"import ssrlab loaded {loaded}"
    assert last == "True ssrlab.bench"  # Jupyter reprs installed; the lab still one attribute away
