"""The full numerical stress run: tests/test_stress.py with every property drawing
--examples examples (the CI run draws 10-24), then prints the result.

    python benchmarks/fuzzing/stress.py --examples 500
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--examples", type=int, default=500)
    ap.add_argument("pytest_args", nargs="*")
    args = ap.parse_args()
    root = Path(__file__).resolve().parents[2]
    env = dict(os.environ, SSRLAB_STRESS_EXAMPLES=str(args.examples))
    t0 = time.perf_counter()
    rc = subprocess.call([sys.executable, "-m", "pytest", str(root / "tests" / "test_stress.py"), "-q",
                          "-p", "no:cacheprovider", *args.pytest_args], env=env, cwd=root)
    print(f"stress run: {args.examples} examples per property, {time.perf_counter() - t0:.0f} s, "
          f"{'all passed' if rc == 0 else f'FAILED (pytest exit {rc})'}")
    sys.exit(rc)


if __name__ == "__main__":
    main()
