"""ssrlab: screen-space reflections over deep, multi-layered G-buffers.

    import ssrlab
    renderer = ssrlab.Renderer()                        # GPU EGL device, else llvmpipe
    scene = ssrlab.scenes.spheres_and_boxes(seed=1)
    frame = renderer.render(scene, settings=ssrlab.Settings(layers=4))
    frame.color             # (H, W, 3) float32, row 0 at the top
    frame.gbuffer.depth     # (layers, H, W) view-space depth
    frame.timings           # GPU milliseconds per pass
"""

from ._core import (Camera, DeviceError, Environment, GLError, Light, Material, OutputError, SceneError,
                    ShaderError)
from ._package import __version__
from . import image_codec as _image_codec

_image_codec.register()  # image files through Python packages where the extension has no OpenImageIO

# The library (rendering) and the truth (references, metrics) are imported with the package; the
# view (display) gives their results a Jupyter representation. The lab (sweeps, experiments, the
# cross-check) is imported on first use: `ssrlab.bench` works, `import ssrlab` does not load it.
from . import io, metrics, models, reference, scenes, transforms  # noqa: E402
from .renderer import Frame, GBuffer, NoReflectionWarning, Renderer, Reprojection, devices, shader_dir  # noqa: E402
from .sequence import CameraPath  # noqa: E402
from .scene import Scene, SceneWarning, directional_light, point_light, spot_light  # noqa: E402
from .settings import Settings  # noqa: E402
from .user_pass import Param, UserPass  # noqa: E402
from . import display  # noqa: E402

display.install()

_LAB = ("analytic", "bench", "cli", "crosscheck", "experiments", "glossy", "hybrid", "journal", "precision",
        "progress")


def __getattr__(name: str):
    if name in _LAB:
        import importlib

        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module 'ssrlab' has no attribute {name!r}")


__all__ = [
    "Camera", "CameraPath", "DeviceError", "Environment", "Frame", "GBuffer", "GLError", "Light", "Material",
    "NoReflectionWarning", "OutputError", "Renderer", "Reprojection", "Scene", "SceneError", "SceneWarning", "Settings", "UserPass", "Param",
    "ShaderError", "directional_light", "models", "point_light", "scenes", "spot_light",
    "shader_dir", "transforms", "display", "devices", "__version__",
]
