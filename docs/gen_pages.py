"""Pages made when the docs are built (mkdocs-gen-files), so that none can go stale by hand:

- notebooks/: every notebook under notebooks/, shown with its saved outputs (not executed);
- api/settings-fields.md: every setting, from the one declaration (cpp/render/settings_fields.def,
  read through ssrlab.settings.fields_markdown());
- results/: one page per device from the files a benchmark run wrote (run_all.json: the device,
  the date, the commit and each benchmark's command and printed tables), never copied by hand.

Building the docs opens no GL context and runs no benchmark.
"""

from __future__ import annotations

import json
from pathlib import Path

import mkdocs_gen_files

ROOT = Path(__file__).resolve().parents[1]
RESULT_FOLDERS = [ROOT / "benchmarks" / "results", ROOT / "benchmarks" / "gpu-results"]


def notebooks() -> None:
    names = sorted(p.stem for p in (ROOT / "notebooks").glob("*.ipynb"))
    for name in names:
        with mkdocs_gen_files.open(f"notebooks/{name}.ipynb", "w") as out:
            out.write((ROOT / "notebooks" / f"{name}.ipynb").read_text())
    with mkdocs_gen_files.open("notebooks/index.md", "w") as out:
        out.write("# Notebooks\n\nThe notebooks under `notebooks/`, shown with the outputs they were saved with "
                  "(the tests run each at a reduced size).\n\n")
        for name in names:
            out.write(f"- [{name}]({name}.ipynb)\n")


def results() -> None:
    pages = []
    for folder in RESULT_FOLDERS:
        for run in sorted(folder.glob("*/run_all.json")):
            data = json.loads(run.read_text())
            device = data.get("device", {})
            slug = run.parent.name
            commit = data.get("commit") or "not recorded (a run from before run_all.py recorded its commit)"
            lines = [f"# {device.get('renderer', slug)}", "",
                     "| | |", "|---|---|",
                     f"| device | {device.get('renderer', '?')} ({device.get('vendor', '?')}, OpenGL "
                     f"{device.get('gl_version', '?')}, `{device.get('device', '?')}`) |",
                     f"| date | {data.get('started', '?')[:16].replace('T', ' ')} UTC |",
                     f"| commit | {commit} |",
                     f"| command | `{data.get('command', 'python benchmarks/run_all.py')}` |",
                     f"| from | `{run.relative_to(ROOT)}` |", ""]
            if data.get("quick"):
                lines += ["!!! warning \"A --quick run\"", "    Reduced sizes: a smoke run, not figures to quote.", ""]
            for name, b in data.get("benchmarks", {}).items():
                lines += [f"## {name}", "", f"`{b.get('command', name)}` — exit {b.get('exit')}, "
                          f"{b.get('seconds', 0):.0f} s"]
                if "started" in b:  # an entry of a later `run_all.py --only` run: its own date and commit
                    lines[-1] += (f"; {b['started'][:16].replace('T', ' ')} UTC, commit {b.get('commit') or '?'}"
                                  + (", a --quick run (reduced sizes: a smoke run, not figures to quote)"
                                     if b.get("quick") else ""))
                lines += ["", "```text", str(b.get("output", "")).rstrip(), "```", ""]
            lines += records_section(run.parent)
            with mkdocs_gen_files.open(f"results/{slug}.md", "w") as out:
                out.write("\n".join(lines))
            pages.append((device.get("renderer", slug), slug, data.get("started", "?")[:10]))
            board = run.parent / "standard" / "leaderboard.md"
            if board.is_file():
                body = board.read_text()
                if body.startswith("# "):  # the page's own title stands in for the leaderboard's
                    body = body.split("\n", 1)[1].lstrip("\n")
                with mkdocs_gen_files.open(f"results/{slug}-standard.md", "w") as out:
                    out.write(f"# The standard evaluation on {device.get('renderer', slug)}\n\n"
                              f"From `{board.relative_to(ROOT)}`, written by `ssrlab bench --suite standard` with "
                              f"its records beside it (`standard.jsonl`).\n\n" + body)
                pages.append((f"{device.get('renderer', slug)}: the standard evaluation", f"{slug}-standard",
                              data.get("started", "?")[:10]))
    with mkdocs_gen_files.open("results/index.md", "w") as out:
        out.write("# Results\n\nEvery page here is made from the files `python benchmarks/run_all.py` wrote on one "
                  "device (device, date, commit and command at its head). Run it to add a device; nothing on these "
                  "pages is typed by hand.\n\n")
        for name, slug, date in pages:
            out.write(f"- [{name}]({slug}.md), {date}\n")
        if not pages:
            out.write("No benchmark run has been committed yet.\n")


def records_section(folder: Path) -> list[str]:
    """Where each benchmark's records on this device came from: their machine, commits, dates and
    command, read from the records themselves (ssrlab.lab.records)."""
    rows = []
    for path in sorted(folder.glob("*.jsonl")):
        recs = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
        if not recs:
            continue
        devices = sorted({f"{r.get('device', '?')}; {r.get('driver', '?')}" for r in recs})
        commits = sorted({str(r.get("commit", "?")) for r in recs})
        dates = sorted(str(r.get("date", "?"))[:10] for r in recs)
        quick = " (quick)" if any(r.get("quick") for r in recs) else ""
        rows.append(f"| `{path.name}` | {len(recs)}{quick} | {' / '.join(devices)} | {', '.join(commits)} | "
                    f"{dates[0]} to {dates[-1]} | `{recs[-1].get('command', '?')}` |")
    if not rows:
        return []
    return ["## Records", "", "Each file of records (`benchmarks/results/<device>/*.jsonl`, one JSON line per figure "
            "with its samples), the machine and driver its records name, their commits and dates, and the command of "
            "the last.", "", "| records | figures | machine | commits | dates | command |", "|---|---|---|---|---|---|",
            *rows, ""]


def settings_fields() -> None:
    from ssrlab.settings import fields_markdown

    with mkdocs_gen_files.open("api/settings-fields.md", "w") as out:
        out.write("# Settings, field by field\n\nEvery field of `ssrlab.Settings` as "
                  "`cpp/render/settings_fields.def` declares it (this page is made from it when the docs are "
                  "built). *read by*: `shaders` for the members of the reflection passes' uniform block, "
                  "`passes` for the settings the C++ passes read. Rules between fields: "
                  "`cpp/render/settings_rules.def` (`ssrlab.settings.CONSTRAINTS`), printed by `ssrlab settings`.\n\n")
        out.write(fields_markdown())


notebooks()
settings_fields()
results()
