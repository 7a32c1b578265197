"""Where the glTF sample models live: inside the package (ssrlab/sample_models, with their
licences and attribution in its README.md).

Search order: the folders in $SSRLAB_MODELS (os.pathsep-separated), the package's own
sample_models, then ``shared/models`` and ``../shared/models`` beside the current folder and
beside the source checkout.
"""

from __future__ import annotations

import os
from pathlib import Path

_FILES = {
    "Suzanne": "Suzanne/Suzanne.gltf",
    "2CylinderEngine": "2CylinderEngine/2CylinderEngine.glb",
}

PACKAGED = Path(__file__).resolve().parent / "sample_models"


def search_path() -> list[Path]:
    paths = [Path(p) for p in os.environ.get("SSRLAB_MODELS", "").split(os.pathsep) if p]
    paths.append(PACKAGED)
    here = Path(__file__).resolve()
    for base in [Path.cwd(), *here.parents]:
        paths += [base / "shared" / "models", base.parent / "shared" / "models"]
    return paths


def find(name: str) -> Path:
    """The path of a sample model by name ('Suzanne', '2CylinderEngine') or relative file."""
    rel = _FILES.get(name, name)
    for folder in search_path():
        candidate = folder / rel
        if candidate.is_file():
            return candidate
    raise FileNotFoundError(
        f"model {name!r} ({rel}) not found; set SSRLAB_MODELS to the folder holding the glTF sample models "
        f"(looked in: {', '.join(str(p) for p in search_path()[:4])}, ...)")
