"""Every image and link the landing page and the documentation show is there: each relative target
of README.md (as the code host resolves it, from the repository's root) and of every Markdown page
under docs/ (as MkDocs resolves it, from the page, inside docs/ or among the pages docs/gen_pages.py
writes when the site is built) exists; and the site names no placeholder host."""

from __future__ import annotations

import re
import sys
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest

REPO = Path(__file__).resolve().parents[1]
DOCS = REPO / "docs"

# Hosts reserved for examples and tests (RFC 2606, RFC 6761): a link to one is a placeholder.
PLACEHOLDER_HOST = re.compile(r"(^|\.)(example\.(com|net|org)|example|invalid|test)$", re.I)

FENCE = re.compile(r"^ {0,3}(`{3,}|~{3,})")
INLINE_CODE = re.compile(r"(`+)(?:(?!\1).)+?\1")
# [text](target "title") and ![alt](target): the target up to a space or the closing parenthesis,
# or <target> in angle brackets; text may hold one level of brackets ([`a[0]`](x.md)).
INLINE_LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\[\]]*\])*\]\(\s*(<[^>]*>|[^\s()]*(?:\([^\s()]*\)[^\s()]*)*)"
                         r"(?:\s+(?:\"[^\"]*\"|'[^']*'|\([^)]*\)))?\s*\)")
REFERENCE_DEFINITION = re.compile(r"^ {0,3}\[[^\]]+\]:\s*(<[^>]*>|\S+)", re.M)
HTML_TARGET = re.compile(r"<(?:img|a|source)\b[^>]*?\s(?:src|href)\s*=\s*(\"[^\"]*\"|'[^']*'|[^\s>]+)", re.I)


def prose(text: str) -> str:
    """The Markdown without its code: fenced blocks and inline code spans blanked, lines kept."""
    out, fence = [], None
    for line in text.splitlines():
        m = FENCE.match(line)
        if fence is None and m:
            fence = m.group(1)[0] * len(m.group(1))
            out.append("")
            continue
        if fence is not None:
            if line.strip().startswith(fence) and set(line.strip()) <= {fence[0]}:
                fence = None
            out.append("")
            continue
        out.append(INLINE_CODE.sub(lambda c: " " * len(c.group(0)), line))
    return "\n".join(out)


def targets(text: str) -> list[tuple[int, str]]:
    """(line, target) of every link, image and HTML src/href of a Markdown text, outside code."""
    body = prose(text)
    found = []
    for pattern in (INLINE_LINK, REFERENCE_DEFINITION, HTML_TARGET):
        for m in pattern.finditer(body):
            t = m.group(1).strip()
            if t[:1] in "<\"'" and t[-1:] in ">\"'":
                t = t[1:-1].strip()
            found.append((body.count("\n", 0, m.start()) + 1, t))
    return sorted(found)


# A stand-in for mkdocs-gen-files that records the paths the script opens.
GEN_FILES_STUB = """
import atexit, io
_written = []
def open(path, mode="r", *args, **kwargs):
    _written.append(str(path))
    return io.StringIO()
atexit.register(lambda: print("\\n".join("written: " + p for p in _written)))
"""


def generated_pages(tmp: Path) -> set[str]:
    """The paths (relative to docs/) that docs/gen_pages.py writes when the site is built: the
    script run as it is, with a stand-in for mkdocs-gen-files (in `tmp`) that records what it opens."""
    import os
    import subprocess

    (tmp / "mkdocs_gen_files.py").write_text(GEN_FILES_STUB)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep))
    r = subprocess.run([sys.executable, str(DOCS / "gen_pages.py")], cwd=REPO, env=env, capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-3000:]
    return {Path(line[len("written: "):]).as_posix() for line in r.stdout.splitlines() if line.startswith("written: ")}


@pytest.fixture(scope="module")
def generated(tmp_path_factory) -> set[str]:
    pages = generated_pages(tmp_path_factory.mktemp("gen_files"))
    # what the site's nav and pages link to among them must be among them
    assert {"notebooks/index.md", "results/index.md", "api/settings-fields.md"} <= pages, sorted(pages)
    return pages


def pages() -> list[Path]:
    return [REPO / "README.md"] + sorted(DOCS.rglob("*.md"))


def broken_targets(page: Path, generated: set[str], text: str | None = None) -> list[str]:
    """'file:line: target (why)' for each relative target of `page` (its text, or `text` as if it
    were the page's) that is not there, or that points at a placeholder host."""
    in_docs = DOCS in page.parents
    problems = []
    text = page.read_text(encoding="utf-8") if text is None else text
    for line, target in targets(text):
        where = f"{page.relative_to(REPO)}:{line}: {target}"
        parts = urlsplit(target)
        if parts.scheme or target.startswith("//"):
            if parts.scheme in ("http", "https") and parts.hostname and PLACEHOLDER_HOST.search(parts.hostname):
                problems.append(f"{where} (a placeholder host)")
            continue  # http(s), mailto and other absolute targets are not files of the repository
        path = unquote(parts.path)
        if not path:
            continue  # a #anchor of the page itself
        if in_docs:
            # MkDocs: from the page's folder, or from docs/ for a leading slash; only docs/ is served
            base = DOCS if path.startswith("/") else page.parent
            resolved = (base / path.lstrip("/")).resolve()
            try:
                rel = resolved.relative_to(DOCS.resolve()).as_posix()
            except ValueError:
                problems.append(f"{where} (outside docs/: the site does not serve it)")
                continue
            if not (resolved.exists() or rel in generated or rel.rstrip("/") + "/index.md" in generated):
                problems.append(f"{where} (no docs/{rel}, and docs/gen_pages.py does not write it)")
        else:
            # the code host: from the file's folder, or from the repository's root for a leading slash
            base = REPO if path.startswith("/") else page.parent
            resolved = (base / path.lstrip("/")).resolve()
            if REPO.resolve() not in resolved.parents and resolved != REPO.resolve():
                problems.append(f"{where} (outside the repository)")
            elif not resolved.exists():
                problems.append(f"{where} (no {resolved.relative_to(REPO.resolve()).as_posix()} in the repository)")
    return problems


def test_every_image_and_link_of_the_readme_and_docs_is_there(generated):
    problems = [p for page in pages() for p in broken_targets(page, generated)]
    assert not problems, "missing link targets:\n" + "\n".join(problems)


def test_the_readme_images_are_committed_files():
    """What the landing page shows is a file of the repository, not an image a notebook or a run
    writes and nobody commits (the check above also passes on a working tree that holds one)."""
    import subprocess

    images = [t for _, t in targets((REPO / "README.md").read_text(encoding="utf-8"))
              if not urlsplit(t).scheme and re.search(r"\.(png|jpe?g|gif|svg|webp)$", urlsplit(t).path, re.I)]
    assert images, "README.md shows no image"
    try:
        tracked = subprocess.run(["git", "ls-files", "--", *images], cwd=REPO, capture_output=True, text=True,
                                 timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        pytest.skip("git is not available")
    if tracked.returncode != 0:
        pytest.skip("not a git checkout (an unpacked source distribution)")
    untracked = sorted(set(images) - set(tracked.stdout.split()))
    assert not untracked, f"README.md shows images that are not committed: {untracked}"


def test_the_site_names_no_placeholder_host():
    text = (REPO / "mkdocs.yml").read_text(encoding="utf-8")
    hosts = re.findall(r"\b[a-z][a-z0-9+.-]*://([^/\s'\"]+)", text, re.I)
    placeholders = [h for h in hosts if PLACEHOLDER_HOST.search(h.split(":")[0])]
    assert not placeholders, f"mkdocs.yml names placeholder hosts: {placeholders}"
    assert not re.search(r"example\.(invalid|com|org|net)", text, re.I)


def test_the_site_nav_names_pages_that_are_there(generated):
    """Every page of mkdocs.yml's nav is a file under docs/ or one docs/gen_pages.py writes."""
    yaml = pytest.importorskip("yaml")

    def walk(node):
        if isinstance(node, str):
            yield node
        elif isinstance(node, list):
            for item in node:
                yield from walk(item)
        elif isinstance(node, dict):
            for item in node.values():
                yield from walk(item)

    config = yaml.safe_load((REPO / "mkdocs.yml").read_text(encoding="utf-8"))
    entries = [e for e in walk(config.get("nav", [])) if not urlsplit(e).scheme]
    assert entries, "mkdocs.yml has no nav pages"
    missing = [e for e in entries if not (DOCS / e).is_file() and e not in generated]
    assert not missing, f"mkdocs.yml's nav names pages that are not there: {missing}"


@pytest.mark.parametrize("text, expected", [
    ("![a](img/x.png) and [b](page.md#part \"title\")", ["img/x.png", "page.md#part"]),
    ("[`f[0]`](api.md) <img src=\"pic.png\" alt=x> <a href='y.md'>y</a>", ["api.md", "pic.png", "y.md"]),
    ("[ref]: <other page.md>\n", ["other page.md"]),
    ("`[not](a_link.md)` and\n```\n![nor](this.png)\n```\n[yes](z.md)", ["z.md"]),
])
def test_the_link_parser(text, expected):
    assert [t for _, t in targets(text)] == expected


def test_a_missing_target_is_named_with_its_page(generated):
    text = ("![x](../images/nothing_here.png)\n[y](../../README.md) [z](https://example.invalid/ssrlab)\n"
            "[ok](../index.md) [also](../results/index.md) [page](#limits) [mail](mailto:a@b.org)")
    problems = broken_targets(DOCS / "guide" / "robustness.md", generated, text)
    assert problems == [
        "docs/guide/robustness.md:1: ../images/nothing_here.png (no docs/images/nothing_here.png, and "
        "docs/gen_pages.py does not write it)",
        "docs/guide/robustness.md:2: ../../README.md (outside docs/: the site does not serve it)",
        "docs/guide/robustness.md:2: https://example.invalid/ssrlab (a placeholder host)",
    ]
