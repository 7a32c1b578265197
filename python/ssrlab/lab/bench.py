"""The sweeps' public names in one namespace, as ``ssrlab.bench`` has always offered them.

A sweep is planned (ssrlab.lab.plan: the grid, the scene and view specs, sweep files), run
(ssrlab.lab.run: the workers, the reference store, the rows' columns) and reported
(ssrlab.lab.report: Pareto fronts, CSV and JSON, plots); its timing statistics are
ssrlab.lab.timing. New code may import those modules; this one gathers them so that code and
notebooks written against ``ssrlab.bench`` keep working.
"""

from .plan import *  # noqa: F401,F403
from .plan import __all__ as _plan
from .report import *  # noqa: F401,F403
from .report import __all__ as _report
from .run import *  # noqa: F401,F403
from .run import __all__ as _run
from .timing import SPREAD_SUFFIXES, median_range, spread, verdict  # noqa: F401

__all__ = [*_plan, *_run, *_report, "SPREAD_SUFFIXES", "spread", "median_range", "verdict"]
