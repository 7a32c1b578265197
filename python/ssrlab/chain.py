"""A chain of passes as Renderer.chain lists it (or derive(), without a renderer), and the raster
floors under the deep G-buffer (Renderer.raster_floor)."""

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
    formats: tuple[str, ...] = ()  # of the textures it creates, in `outputs` order (its rewrites come last)
    channels: tuple[str, ...] = ()  # of the textures it creates: their declared channels ("gbuffer.normal (rgb)")


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

    @classmethod
    def from_native(cls, rows) -> "Chain":
        """From the native chain's rows (pass, inputs, outputs, history, scratch, buffer inputs and outputs)."""
        return cls([ChainPass(name, *(tuple(x) for x in rest)) for name, *rest in rows])

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

    def resources(self) -> str:
        """A Markdown table of every texture of the chain: its format, the channels it declares (the
        Frame view and attribute that shows each, and its components), the pass that creates it, those
        that rewrite it in place and those that read it, in chain order."""
        created, rewritten, read = {}, {}, {}
        for p in self:
            fresh = p.outputs[:len(p.formats)]
            channels = p.channels or ("",) * len(fresh)
            for name, fmt, ch in zip(fresh, p.formats, channels):
                created[name] = (fmt, ch, p.name)
            for name in p.outputs[len(p.formats):]:
                rewritten.setdefault(name, []).append(p.name)
            for name in p.inputs:
                if name not in p.outputs:
                    read.setdefault(name, []).append(p.name)
        rows = ["| texture | format | channels | created by | rewritten by | read by |", "|---|---|---|---|---|---|"]
        for name, (fmt, ch, by) in created.items():
            rows.append(f"| `{name}` | {fmt} | {ch or '–'} | `{by}` | "
                        f"{', '.join(f'`{x}`' for x in rewritten.get(name, [])) or '–'} | "
                        f"{', '.join(f'`{x}`' for x in read.get(name, [])) or '–'} |")
        return "\n".join(rows)

    def markdown(self) -> str:
        """A Markdown table: pass, reads, writes (buffers in italics)."""
        def names(textures, buffers):
            return ", ".join([f"`{x}`" for x in textures] + [f"*`{x}`*" for x in buffers]) or "–"

        rows = ["| # | pass | reads | writes |", "|---|---|---|---|"]
        rows += [f"| {i + 1} | `{p.name}` | {names(p.inputs, p.buffer_inputs)} | "
                 f"{names(p.outputs, p.buffer_outputs)} |" for i, p in enumerate(self)]
        return "\n".join(rows)


def derive(settings=None, scene=None, *, device: str = "cpu", **overrides) -> Chain:
    """The built-in passes a render with `settings` runs on `device` ('cpu': llvmpipe, 'gpu'), in
    order, each with what it reads and writes: what ``Renderer.chain`` lists, computed from the
    settings and the scene's facts alone, without a renderer. No GL context is made and the scene is
    not uploaded. The order is the passes' declarations' (docs/architecture/passes.md): each pass
    after the writers of what it reads. `scene` defaults to ``ssrlab.scenes.stand_in()``, as in
    ``Renderer.chain``; user passes are listed by the renderer they are registered on."""
    from . import _core
    from .settings import Settings

    if device not in ("cpu", "gpu"):
        raise ValueError(f"ssrlab.chain.derive: device must be 'cpu' or 'gpu', got {device!r}")
    settings = settings if settings is not None else Settings()
    if overrides:
        settings = settings.replace(**overrides)
    if scene is None:
        from .scenes import stand_in

        scene = stand_in()
    # The CPU device reads float inputs by imageLoad (Renderer.input_fetch 'auto'), which adds
    # resolve_fetch before the resolve; a GPU reads them by texelFetch.
    native = settings.to_native(device)
    return Chain.from_native(_core.builtin_chain(scene, native, device == "cpu"))
