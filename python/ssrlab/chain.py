"""A chain of passes as Renderer.chain lists it, and the raster floors under the deep G-buffer
(Renderer.raster_floor)."""

from __future__ import annotations

import dataclasses

import numpy as np


@dataclasses.dataclass(frozen=True)
class ChainPass:
    """One pass of a chain: its name and the textures it reads and writes; `history`: what it
    reads from the previous frame of a sequence when there is one; `scratch`: those of its outputs
    that are per-renderer scratch (one copy shared by every frame; read them right after the
    render); `buffer_inputs` and `buffer_outputs`: the GPU buffers it reads and writes for later
    passes of the same frame (work lists and their indirect dispatch arguments, such as
    classify's ``ray_list``), owned by the pass that writes them."""

    name: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    history: tuple[str, ...] = ()
    scratch: tuple[str, ...] = ()
    buffer_inputs: tuple[str, ...] = ()
    buffer_outputs: tuple[str, ...] = ()


@dataclasses.dataclass(frozen=True)
class RasterFloor:
    """What Renderer.raster_floor measured: `ms` the GPU milliseconds of every repeat of each
    floor, `counts` what it counted (see Renderer.raster_floor), at width x height."""

    width: int
    height: int
    ms: dict[str, list[float]]
    counts: dict[str, int]

    def median(self, name: str) -> float:
        """The median milliseconds of floor `name` (KeyError naming the floors measured)."""
        if name not in self.ms:
            raise KeyError(f"RasterFloor: no floor {name!r}; measured: {sorted(self.ms)}")
        return float(np.median(self.ms[name]))


class Chain(list):
    """Renderer.chain's result: the ordered passes (ChainPass), printable as a table."""

    @property
    def names(self) -> list[str]:
        return [p.name for p in self]

    def __str__(self) -> str:
        lines = []
        for i, p in enumerate(self):
            lines.append(f"{i + 1:>2}. {p.name}")
            lines.append(f"      reads:  {', '.join(p.inputs) or '-'}")
            lines.append(f"      writes: {', '.join(p.outputs) or '-'}")
            if p.history:
                lines.append(f"      reads from the previous frame: {', '.join(p.history)}")
            if p.scratch:
                lines.append(f"      scratch: {', '.join(p.scratch)}")
            if p.buffer_inputs:
                lines.append(f"      reads buffers:  {', '.join(p.buffer_inputs)}")
            if p.buffer_outputs:
                lines.append(f"      writes buffers: {', '.join(p.buffer_outputs)}")
        return "\n".join(lines)

    def markdown(self) -> str:
        """A Markdown table: pass, reads, writes (buffers in italics)."""
        def names(textures, buffers):
            return ", ".join([f"`{x}`" for x in textures] + [f"*`{x}`*" for x in buffers]) or "–"

        rows = ["| # | pass | reads | writes |", "|---|---|---|---|"]
        rows += [f"| {i + 1} | `{p.name}` | {names(p.inputs, p.buffer_inputs)} | "
                 f"{names(p.outputs, p.buffer_outputs)} |" for i, p in enumerate(self)]
        return "\n".join(rows)
