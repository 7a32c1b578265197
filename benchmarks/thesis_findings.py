"""Runs the three paper-reproduction notebooks and prints every finding beside ours.

    python benchmarks/thesis_findings.py [--scale full|small] [--taa thesis|off] [--figures docs/images]
                                         [--executed results/notebooks]

Each notebook (notebooks/*.ipynb) runs its experiment from ssrlab.experiments at the given
scale (full: 640x360, median of 5 runs after 2 warm-ups, 256-ray converged references; about
ten minutes on llvmpipe), saves its figures into --figures, and ends with a table of the
paper's findings and ours; this script prints those tables together with the device they were
measured on. Executed copies of the notebooks go to --executed.

--taa: the thesis's two experiments run with its temporal anti-aliasing (seed 000, 2.5), as
the thesis measured them ("thesis", the default: sequences of the static camera, see
ssrlab.experiments), or on single frames without it ("off"); hiz_vs_linear always runs single
frames. The TAA cost lines the notebooks print (the reproject and taa passes' share of the
frame) are printed too.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import nbclient
import nbformat

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ["thesis_layers", "thesis_downscale_rays_stride", "hiz_vs_linear"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scale", default="full", choices=("full", "small"))
    ap.add_argument("--taa", default="thesis", choices=("thesis", "off"),
                    help="TAA of the thesis's experiments (default: the thesis's, as it measured them)")
    ap.add_argument("--figures", default=str(ROOT / "docs" / "images"))
    ap.add_argument("--executed", default=str(ROOT / "results" / "notebooks"))
    ap.add_argument("--only", nargs="+", choices=NOTEBOOKS, default=NOTEBOOKS, help="run only these notebooks")
    args = ap.parse_args()
    os.environ["SSRLAB_NOTEBOOK_SCALE"] = args.scale
    os.environ["SSRLAB_NOTEBOOK_OUT"] = args.figures
    os.environ["SSRLAB_NOTEBOOK_TAA"] = args.taa
    os.environ.setdefault("MPLBACKEND", "Agg")
    Path(args.executed).mkdir(parents=True, exist_ok=True)
    for name in args.only:
        start = time.time()
        nb = nbformat.read(ROOT / "notebooks" / f"{name}.ipynb", as_version=4)
        nbclient.NotebookClient(nb, timeout=3600, kernel_name="python3",
                                resources={"metadata": {"path": str(ROOT)}}).execute()
        nbformat.write(nb, Path(args.executed) / f"{name}.ipynb")
        outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
        stdout = [line for o in outputs if o.get("name") == "stdout" for line in o.get("text", "").splitlines()]
        device = next((line for line in stdout if line.startswith("device:")), "")
        table = next(o["data"]["text/markdown"] for o in outputs if "text/markdown" in o.get("data", {}))
        print(f"## {name} ({args.scale} scale, {time.time() - start:.0f} s)")
        print(device)
        for line in stdout:
            if line.startswith("TAA cost"):
                print(line)
        print(table)
        print()


if __name__ == "__main__":
    main()
