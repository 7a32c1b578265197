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
