"""An edge-aware spatial filter of the reflection (FidelityFX SSSR's spatial denoiser, as AMD
describes it) as an ssrlab user pass: ``filter.comp`` beside this file and this declaration.

    import ssrlab
    from examples.bilateral_filter.technique import bilateral_filter
    r = ssrlab.Renderer()
    r.register_pass(bilateral_filter())
    frame = r.render(scene, settings=ssrlab.Settings(user_passes=("bilateral_filter",),
                                                     user_params={"bilateral_filter.radius": 3}))

or, without registering it, in settings any process (a sweep's workers) can use:

    ssrlab.Settings(user_modules=("examples/bilateral_filter/technique.py:bilateral_filter",),
                    user_passes=("bilateral_filter",))
"""

from pathlib import Path

import ssrlab


def bilateral_filter(name: str = "bilateral_filter") -> ssrlab.UserPass:
    return ssrlab.UserPass(
        name, Path(__file__).with_name("filter.comp"), stage="reflection_filter",
        reads=("reflection", "linear_depth", "gbuffer.normal"),
        params=(
            ssrlab.Param("radius", "int", 3, 0, 8, "largest filter radius in pixels, reached at roughness 1"),
            ssrlab.Param("sigma_depth", "float", 0.02, 1e-4, 1.0,
                         "relative view-depth difference over which a tap's weight falls by e"),
            ssrlab.Param("normal_power", "float", 32.0, 0.0, 512.0, "taps weigh max(0, n_p . n_q)^power"),
            ssrlab.Param("min_roughness", "float", 0.05, 0.0, 1.0, "pixels smoother than this keep their rays' result"),
        ),
        doc="edge-aware spatial filter of the reflection, radius growing with roughness (FidelityFX SSSR's "
            "spatial denoiser as AMD describes it)")
