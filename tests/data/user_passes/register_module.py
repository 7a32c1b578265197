"""A user module of the tests (Settings.user_modules) whose register(registry) function declares
its passes: a second pass over the rays after the trace (keeps or drops every hit) and a glossy
filter on the pre-convolved mips."""

from pathlib import Path

import ssrlab

HERE = Path(__file__).parent


def register(registry):
    registry.register_pass(ssrlab.UserPass(
        "drop_hits", HERE / "drop_hits.comp", reads=("rays.hit",), writes=("rays.hit",), dispatch="ray",
        params=(ssrlab.Param("keep", "bool", True, doc="keep the trace's hits (True) or drop them all"),)))
    registry.register_pass(ssrlab.UserPass(
        "preconvolved_level", HERE / "preconvolved_level.comp", reads=("lit_preconvolved",),
        writes=("reflection",), params=(ssrlab.Param("level", "int", 1, 0, 8, "the mip level read"),)))
