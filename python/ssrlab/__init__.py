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
from . import image_codec as _image_codec

_image_codec.register()  # image files through Python packages where the extension has no OpenImageIO
from . import bench, display, experiments, io, metrics, models, reference, scenes, transforms
from .renderer import Frame, GBuffer, NoReflectionWarning, Renderer, Reprojection, devices, shader_dir
from .sequence import CameraPath
from .scene import Scene, SceneWarning, directional_light, point_light, spot_light
from .settings import Settings


def _package_version() -> str:
    # pyproject.toml is the one place the version is written; the installed metadata carries it.
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("ssrlab")
    except PackageNotFoundError:  # imported from a source tree that was never installed
        return "0+unknown"


__version__ = _package_version()

__all__ = [
    "Camera", "CameraPath", "DeviceError", "Environment", "Frame", "GBuffer", "GLError", "Light", "Material",
    "NoReflectionWarning", "OutputError", "Renderer", "Reprojection", "Scene", "SceneError", "SceneWarning", "Settings",
    "ShaderError", "directional_light", "models", "point_light", "scenes", "spot_light",
    "shader_dir", "transforms", "display", "devices", "__version__",
]
