"""A view-space ray march with binary-search refinement (CryENGINE 3's screen-space reflections,
Sousa, Kasyan & Schulz, SIGGRAPH 2011) as an ssrlab user trace pass: ``trace.comp`` beside this
file and this declaration. It takes the place of the screen-space trace:

    r.register_pass(view_space_march())
    frame = r.render(scene, settings=ssrlab.Settings(method="linear", user_passes=("view_space_march",)))

or, without registering it: Settings(user_modules=("examples/view_space_march/technique.py:view_space_march",), ...).
"""

from pathlib import Path

import ssrlab


def view_space_march(name: str = "view_space_march") -> ssrlab.UserPass:
    return ssrlab.UserPass(
        name, Path(__file__).with_name("trace.comp"), stage="trace",
        params=(
            ssrlab.Param("steps", "int", 32, 1, 1024, "march steps (at most Settings.max_steps)"),
            ssrlab.Param("step_scale", "float", 0.05, 1e-4, 10.0,
                         "step length as a fraction of the ray origin's view depth"),
            ssrlab.Param("refine", "int", 4, 0, 16, "binary-search halvings of the step that went behind a surface"),
            ssrlab.Param("thickness", "float", 0.05, 1e-4, 10.0, "assumed surface thickness, fraction of its depth"),
        ),
        doc="view-space march with binary refinement (Sousa, Kasyan & Schulz 2011)")
