"""The CPU side of reading a frame back: the two readback paths, A/B in one run.

    python benchmarks/timing/readback.py [--sizes 640x360 1920x1080] [--repeats 15] [--device auto|gpu|cpu]

A texture reaches numpy by one of two paths (Renderer.readback_path):
  download  a float texture (the final colour and the rays RGBA32F, lit and the normals RGBA16F,
            depths R32F) downloaded as stored by glGetTextureSubImage (RGBA16F as halves, widened
            with F16C), its rows put top first by the driver (GL_MESA_pack_invert, Mesa) or swapped
            on the CPU; a normalised, sRGB or depth texture decoded to float RGBA by the readback
            copy pass (shaders/passes/readback.comp) into a buffer, then downloaded;
  staged    every texture through the copy pass, the buffer copied by the GPU into pinned client
            memory (a persistently mapped buffer), then into the array by several threads.
For one frame of `hall` per size, the script times the native read of each texture below (the
Python-side cache is bypassed: every read goes to the device), the two paths interleaved read by
read (the protocol's Bench.calls: --repeats rounds after 2 warm-up rounds). Each path's reads are
a record (ssrlab.lab.records) of their samples; the A/B table is rendered from them, with the
per-read ratio staged / download and the verdict of staged against download
(records.figure_verdict: faster, slower, same, or undecided at this noise).

A second table times the colour as the live viewer's page gets it, 8-bit sRGB codes (uint8
(height, width, 3)): "numpy", the float colour downloaded and encoded by
display.to_bytes(display.srgb(...)), against "device", encoded on the device and read back as
those bytes (Frame.srgb8), interleaved call by call.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402

# name: readback path (float formats downloaded directly, the others through the copy pass)
TEXTURES = {"color": "direct", "lit": "direct", "gbuffer.albedo": "copy pass", "gbuffer.material": "copy pass"}
PATHS = ("download", "staged")
# How the colour becomes the page's bytes: encoded by numpy from the float download, or on the device
ENCODINGS = ("numpy", "device")


def time_reads(bench, renderer, frame, name: str) -> tuple[dict[str, list[float]], int]:
    """ms per native read of `name` by each readback path, the paths interleaved read by read."""
    out = {}

    def read(path):
        def run():
            renderer.readback_path = path
            out["nbytes"] = frame.read(name, cache=False).nbytes
        return run

    ms = bench.calls({path: read(path) for path in PATHS})
    renderer.readback_path = "auto"
    return ms, out["nbytes"]


def time_display_bytes(bench, frame) -> dict[str, list[float]]:
    """ms per call of the colour as 8-bit sRGB codes by each encoding, interleaved call by call."""
    from ssrlab import display

    return bench.calls({
        "numpy": lambda: display.to_bytes(display.srgb(frame.read("color", cache=False)[0, :, :, :3])),
        "device": lambda: frame.srgb8(),
    })


def main(argv=None) -> int:
    ap = benchmark_arguments(__doc__, repeats=15)
    ap.add_argument("--sizes", nargs="+", default=["640x360", "1920x1080"], help="WIDTHxHEIGHT")
    args = ap.parse_args(argv)
    import ssrlab

    renderer = open_renderer(args)
    bench = Bench("readback", args, renderer)
    scene = ssrlab.scenes.hall()
    print(f"{args.repeats} native reads per path after {bench.warmup} warm-up reads, the paths interleaved; the "
          f"float32 RGBA array delivered; 'auto' is {renderer.info['readback_path']} on this device; ms")
    for size in args.sizes:
        w, h = (int(v) for v in size.lower().split("x"))
        frame = renderer.render(scene, settings=ssrlab.Settings(width=w, height=h, method="hiz", sampling="mirror"))
        for name, path in TEXTURES.items():
            ms, nbytes = time_reads(bench, renderer, frame, name)
            params = dict(size=f"{w}x{h}", texture=name, download_path=path, bytes=nbytes)
            for p in PATHS:
                bench.record({**params, "path": p}, "read", "ms", ms[p])
        ms = time_display_bytes(bench, frame)
        for e in ENCODINGS:
            bench.record({"size": f"{w}x{h}", "encoding": e}, "display bytes", "ms", ms[e])
        frame.release()
    # "same" and "undecided" say why there is no faster or slower: the two paths' samples overlap
    words = {"same": "same within 2 % (the samples overlap)", "undecided": "no verdict (the samples overlap)"}
    reads = bench.find("read")
    bench.print_ab("path", *PATHS, records=reads, rows=("size", "texture", "download_path", "bytes"), digits=3,
                   words=words)
    print("\nthe colour as the page's 8-bit sRGB codes (uint8 height x width x 3), ms per call:")
    bench.print_ab("encoding", *ENCODINGS, records=bench.find("display bytes"), rows=("size",), digits=3, words=words)
    return 0


if __name__ == "__main__":
    sys.exit(main())
