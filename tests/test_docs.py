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
        assert entry["exit"] == 0 and entry["command"].startswith(f"python benchmarks/{name}.py"), entry["command"]
        assert run["device"]["renderer"] and (entry.get("started") or run["started"])
        assert entry.get("commit") or run.get("commit")
