"""Facts about the installed package that every module may need without importing another:
its version (from the package metadata, written once in pyproject.toml) and its shader folder."""

from __future__ import annotations

from importlib import resources
from pathlib import Path


def package_version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("ssrlab")
    except PackageNotFoundError:  # imported from a source tree that was never installed
        return "0+unknown"


__version__ = package_version()


def shader_dir() -> Path:
    """The GLSL sources installed with the package."""
    return Path(str(resources.files("ssrlab") / "shaders"))


# Modules that moved into the truth and the lab, under their old names: ssrlab.<old> is the module
# ssrlab.<new> itself (one object, so that patching or pickling through either name is the same).
MOVED = {
    "reference": "truth.reference", "analytic": "truth.analytic", "metrics": "truth.metrics",
    "crosscheck": "truth.crosscheck", "bench": "lab.bench", "experiments": "lab.experiments",
    "glossy": "lab.glossy", "hybrid": "lab.hybrid", "precision": "lab.precision", "journal": "lab.journal",
}


class _MovedFinder:
    """Finds ``package.<old>`` for the MOVED names by importing ``package.<new>`` (PEP 451 finder
    and loader: create_module returns the existing module, exec_module has nothing left to do)."""

    def __init__(self, package: str):
        self.package = package

    def find_spec(self, fullname: str, path=None, target=None):
        head, _, old = fullname.rpartition(".")
        if head != self.package or old not in MOVED:
            return None
        from importlib.util import spec_from_loader

        return spec_from_loader(fullname, self)

    def create_module(self, spec):
        from importlib import import_module

        return import_module(f"{self.package}.{MOVED[spec.name.rpartition('.')[2]]}")

    def exec_module(self, module) -> None:
        pass


def install_moved_modules(package: str) -> None:
    import sys

    if not any(isinstance(f, _MovedFinder) and f.package == package for f in sys.meta_path):
        sys.meta_path.append(_MovedFinder(package))
