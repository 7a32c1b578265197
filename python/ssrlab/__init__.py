"""ssrlab: screen-space reflections over deep, multi-layered G-buffers.

    import ssrlab
    renderer = ssrlab.Renderer()                        # GPU EGL device, else llvmpipe
    scene = ssrlab.scenes.spheres_and_boxes(seed=1)
    frame = renderer.render(scene, settings=ssrlab.Settings(layers=4))
    frame.color             # (H, W, 3) float32, row 0 at the top
    frame.gbuffer.depth     # (layers, H, W) view-space depth
    frame.timings           # GPU milliseconds per pass

The package has three rooms. The library, imported with the package: the renderer, settings,
scenes, io, display, sequences and animation (this folder). The truth (``ssrlab.truth``: references,
analytic answers, metrics, the Mitsuba cross-check) and the lab (``ssrlab.lab``: sweeps,
experiments, the studies of one technique, timing statistics) are imported on first use; their
modules keep their old names too (``ssrlab.metrics`` is ``ssrlab.truth.metrics``,
``ssrlab.bench`` gathers ``ssrlab.lab.plan``, ``run`` and ``report``). The lab uses the truth and
the library, the truth uses the library, never the other way round.
"""

from ._core import (Camera, DeviceError, Environment, GLError, Light, Material, OutputError, SceneError,
                    ShaderError)
from ._package import MOVED, __version__, install_moved_modules
from . import image_codec as _image_codec

_image_codec.register()  # image files through Python packages where the extension has no OpenImageIO
install_moved_modules(__name__)  # `import ssrlab.metrics` finds ssrlab.truth.metrics

from . import io, models, scenes, transforms  # noqa: E402
from .renderer import Frame, GBuffer, NoReflectionWarning, Renderer, Reprojection, devices, shader_dir  # noqa: E402
from .sequence import CameraPath  # noqa: E402
from .animation import Keyframes  # noqa: E402
from .scene import Scene, SceneWarning, directional_light, point_light, spot_light  # noqa: E402
from .settings import Settings  # noqa: E402
from .user_pass import Param, UserPass  # noqa: E402
from . import display  # noqa: E402

display.install()

_LAZY = ("cli", "lab", "progress", "truth", "viewer")


def __getattr__(name: str):
    # The truth, the lab and their old names are imported on first use: `ssrlab.metrics` works,
    # `import ssrlab` does not load it.
    if name in MOVED or name in _LAZY:
        import importlib

        return importlib.import_module(f".{name}", __name__)
    if name == "view":  # the live viewer (ssrlab.viewer.view): viser is imported on first use
        from .viewer import view

        return view
    raise AttributeError(f"module 'ssrlab' has no attribute {name!r}")


__all__ = [
    "Camera", "CameraPath", "DeviceError", "Keyframes", "Environment", "Frame", "GBuffer", "GLError", "Light", "Material",
    "NoReflectionWarning", "OutputError", "Renderer", "Reprojection", "Scene", "SceneError", "SceneWarning", "Settings", "UserPass", "Param",
    "ShaderError", "directional_light", "models", "point_light", "scenes", "spot_light",
    "shader_dir", "transforms", "display", "devices", "view", "__version__",
]
