"""A user module of the tests (Settings.user_modules): a placed pass declared at the module's top
level. It rewrites the reflection (placed right after the resolve, which declares it), multiplying
it by its parameter `gain`."""

from pathlib import Path

import ssrlab

reflection_gain = ssrlab.UserPass(
    "reflection_gain", Path(__file__).with_name("scale.comp"), reads=("reflection",), writes=("reflection",),
    params=(ssrlab.Param("gain", "float", 1.0, 0.0, 4.0, "factor of the reflection's colour and alpha"),),
    doc="the reflection times a gain")
