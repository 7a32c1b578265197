"""The documentation: the site builds in strict mode (a broken link, a missing page or an API
reference to nothing fails), its generated chain page says what the code says, and the README
stays a landing page."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def test_docs_build_in_strict_mode(tmp_path):
    pytest.importorskip("mkdocs", reason="the docs need the 'docs' extra (pip install .[docs])")
    r = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                       cwd=REPO, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-6000:]
    site = tmp_path / "site"
    assert (site / "index.html").is_file()
    assert (site / "api" / "renderer" / "index.html").read_text().count("Renderer.chain") >= 1
    assert (site / "notebooks" / "hybrid" / "index.html").is_file()
    assert (site / "results" / "index.html").is_file()


def test_chain_page_matches_the_code():
    r = subprocess.run([sys.executable, str(REPO / "docs" / "make_chain_page.py"), "--check"], cwd=REPO,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr


def test_readme_is_a_landing_page():
    text = (REPO / "README.md").read_text()
    lines = text.splitlines()
    assert len(lines) <= 300, len(lines)
    assert "./run.sh render" in text and "./run.sh test" in text and "pip install ." in text
    assert not re.search(r"\b[Ii]ssue \d+|\bround \d+\b|\b(first|second|third|fourth|fifth|sixth) round\b", text)


CODE_ROOTS = ["cpp", "shaders", "python/ssrlab", "benchmarks", "tests"]


def test_code_comments_say_why_not_which_issue():
    offenders = []
    for root in CODE_ROOTS:
        for p in (REPO / root).rglob("*"):
            if p.suffix in (".cpp", ".h", ".glsl", ".comp", ".vert", ".frag", ".py", ".pyi") and p.is_file():
                text = p.read_text()
                # also where a line break (and a comment marker) falls between the word and the number
                for m in re.finditer(r"\b[Ii]ssues?(?:\s|//|#|\*)+\d+|\b(first|second|third|fourth|fifth|sixth)"
                                     r"\s+round\b", text):
                    i = text.count("\n", 0, m.start()) + 1
                    offenders.append(f"{p.relative_to(REPO)}:{i}: {' '.join(m.group(0).split())}")
    assert not offenders, "\n".join(offenders[:20])


def test_code_comments_keep_no_cut_out_figure():
    """A figure cut out of a comment leaves a stub: "slow:)" where "slow (3 ms against 1 ms):"
    stood, or empty parentheses. A comment says why in words, or names the command that prints the
    figure."""
    stubs = re.compile(r"(//|#).*?(\w:\)|\s\(\s*\)|\(\s*%\s*\)|\bwas\s+\d+(\.\d+)?\s*-\s*\d+\s*%)")
    offenders = []
    for root in CODE_ROOTS:
        for p in (REPO / root).rglob("*"):
            if p.suffix in (".cpp", ".h", ".glsl", ".comp", ".vert", ".frag", ".py") and p.is_file():
                for i, line in enumerate(p.read_text().splitlines(), 1):
                    if stubs.search(line):
                        offenders.append(f"{p.relative_to(REPO)}:{i}: {line.strip()}")
    assert not offenders, "\n".join(offenders[:20])


def test_docs_figures_link_a_recorded_benchmark_run():
    """A page that discusses a benchmark's figures links its section of a results page, which
    gen_pages.py makes from a committed run_all.json: the run must be there, have succeeded and
    name its device, date, commit and command."""
    import json

    runs = {run.parent.name: json.loads(run.read_text())
            for folder in ("results", "gpu-results") for run in (REPO / "benchmarks" / folder).glob("*/run_all.json")}
    links = {m for page in (REPO / "docs").rglob("*.md")
             for m in re.findall(r"results/([\w.-]+)\.md#(\w+)", page.read_text())}
    assert {"occlusion", "deep_gbuffer", "metric_cost", "reference_speed"} <= {name for _, name in links}
    for slug, name in sorted(links):
        assert slug in runs, f"docs link results/{slug}.md, but no benchmarks/*/{slug}/run_all.json"
        run = runs[slug]
        assert name in run["benchmarks"], f"results/{slug}.md has no {name} section"
        entry = run["benchmarks"][name]
        # the script's path as it was run: a genre folder's, or benchmarks/ itself for runs made before
        # the scripts were sorted into genres (a committed run keeps the command it ran)
        assert entry["exit"] == 0 and re.match(rf"python benchmarks/(\w+/)?{name}\.py\b", entry["command"]), \
            entry["command"]
        assert run["device"]["renderer"] and (entry.get("started") or run["started"])
        assert entry.get("commit") or run.get("commit")


# The genre folders of benchmarks/ (benchmarks/README.md): a newcomer finds the kind of
# measurement first, then the script. Only the runner and the shared helpers stay at the top.
BENCHMARK_GENRES = ("timing", "accuracy", "studies", "tools", "fuzzing", "packaging")
BENCHMARK_TOP = {"__init__.py", "common.py", "run_all.py"}
# Scripts the docs and tests name as examples, which are not meant to exist.
EXAMPLE_SCRIPTS = {"my_bench.py", "fake.py"}


def test_every_benchmark_script_sits_in_a_genre_folder():
    bench = REPO / "benchmarks"
    loose = sorted(p.name for p in bench.glob("*.py") if p.name not in BENCHMARK_TOP)
    assert not loose, f"scripts outside a genre folder: {loose}"
    scripts = [p for p in bench.glob("*/*.py") if p.name != "__init__.py"]
    assert {p.parent.name for p in scripts} == set(BENCHMARK_GENRES)
    assert not list(bench.glob("*/*/*.py")), "a genre folder holds scripts, not folders of them"
    # a benchmark is named by its script (its records' benchmark name): one script of each name
    names = [p.stem for p in scripts]
    assert len(names) == len(set(names)), sorted(n for n in names if names.count(n) > 1)
    readme = (bench / "README.md").read_text()
    assert all(f"{genre}/" in readme for genre in BENCHMARK_GENRES)


def test_every_cited_benchmark_script_exists():
    """Each benchmarks/...py path the README, the docs, the notebooks, the sweep files, the tests,
    the package, the C++ and shader comments and the scripts themselves cite is a file of this
    checkout."""
    cited = re.compile(r"benchmarks/(?:\w+/)*\w+\.py\b")
    sources = [REPO / "README.md", REPO / "benchmarks" / "README.md", *(REPO / "docs").rglob("*.md"),
               *(REPO / "notebooks").glob("*.ipynb"), *(REPO / "benchmarks" / "sweeps").glob("*.toml"),
               *(REPO / "tests").glob("*.py"), *(REPO / "benchmarks").rglob("*.py"),
               *(REPO / "python" / "ssrlab").rglob("*.py"),
               *(p for p in (REPO / "cpp").rglob("*") if p.suffix in {".h", ".cpp", ".def"}),
               *(p for p in (REPO / "shaders").rglob("*") if p.is_file())]
    missing = []
    for path in sources:
        for i, line in enumerate(path.read_text().splitlines(), 1):
            for m in cited.finditer(line):
                if m.group(0).rsplit("/", 1)[1] not in EXAMPLE_SCRIPTS and not (REPO / m.group(0)).is_file():
                    missing.append(f"{path.relative_to(REPO)}:{i}: {m.group(0)}")
    assert not missing, "\n".join(missing)
