"""Several GPUs: device="gpu:N", the device list, pinning a process with $SSRLAB_DEVICE."""

import os
import subprocess
import sys

import pytest

import ssrlab
from ssrlab.renderer import check_device, resolve_device
from conftest import cpu_device_absence, cpu_device_absence_here


def _hardware():
    return [d for d in ssrlab.devices() if d["index"] is not None]


def test_devices_are_listed_with_indices_and_renderers():
    found = ssrlab.devices()
    assert found, "at least Mesa's software device"
    hardware = [d for d in found if not d["software"]]
    assert [d["index"] for d in hardware] == list(range(len(hardware)))
    assert all(d["index"] is None and d["device"] == "cpu" for d in found if d["software"])
    for d in found:
        assert d["renderer"] or d["error"]
        assert isinstance(d["egl_device_extensions"], str)
    assert any("llvmpipe" in d["renderer"] for d in found if d["software"]) or hardware


def test_a_missing_gpu_index_raises_device_error_naming_the_devices_found():
    n = len(_hardware())  # gpu:n is one past the last hardware device: gpu:0 on a machine without a GPU
    with pytest.raises(ssrlab.DeviceError, match=rf"gpu:{n}.*no hardware EGL device {n}") as e:
        ssrlab.Renderer(f"gpu:{n}")
    message = str(e.value)
    for d in ssrlab.devices():
        assert (d["renderer"] or d["egl_device_extensions"]) in message


def test_a_listed_gpu_index_opens_that_device():
    hardware = _hardware()
    if not hardware:
        pytest.skip("no hardware EGL device here")
    r = ssrlab.Renderer(f"gpu:{len(hardware) - 1}")
    assert r.info["device"] == "gpu" and r.info["device_index"] == str(len(hardware) - 1)
    assert r.info["renderer"] == hardware[-1]["renderer"]


@pytest.mark.parametrize("bad", ["gpu:", "gpu:-1", "gpu:x", "GPU:0", "gpu0", "gpu:٣", 3, None])
def test_bad_device_names_are_rejected_naming_the_parameter(bad):
    with pytest.raises(ValueError, match="Renderer.device"):
        ssrlab.Renderer(bad)


def test_ssrlab_device_pins_auto_only(monkeypatch):
    monkeypatch.setenv("SSRLAB_DEVICE", "gpu:5")
    assert resolve_device("auto") == "gpu:5"
    assert resolve_device("cpu") == "cpu"  # an explicit device wins over the pin
    monkeypatch.setenv("SSRLAB_DEVICE", "gpu:five")
    with pytest.raises(ValueError, match=r"\$SSRLAB_DEVICE"):
        resolve_device("auto")
    monkeypatch.setenv("SSRLAB_DEVICE", "cpu")
    assert resolve_device("auto") == "cpu"
    assert check_device("gpu:12") == "gpu:12"


@pytest.mark.needs_cpu_device
def test_a_renderer_pinned_to_the_cpu_device_opens_it(monkeypatch):
    monkeypatch.setenv("SSRLAB_DEVICE", "cpu")
    r = ssrlab.Renderer()
    assert r.device == "cpu" and r.info["requested"] == "cpu" and r.info["device"] == "cpu"


class _Opened:
    def __init__(self, device):
        self.info = {"device": device, "renderer": "NVIDIA H100 80GB HBM3/PCIe/SSE2" if device == "gpu" else "llvmpipe"}


def _refused():
    raise ssrlab.DeviceError("could not open a headless OpenGL 4.5 core context through EGL; surfaceless: no display")


def test_the_cpu_device_marker_skips_with_the_reason_where_there_is_none():
    """tests/conftest.py's needs_cpu_device: a test of device='cpu' runs where Renderer("cpu") opens
    Mesa's llvmpipe, and skips naming why where it raises (a GPU machine without Mesa's EGL) or
    where it would open something else."""
    assert cpu_device_absence(lambda: _Opened("cpu")) is None
    why = cpu_device_absence(_refused)
    assert why.startswith("no CPU device") and "surfaceless: no display" in why
    assert "not a software rasteriser" in cpu_device_absence(lambda: _Opened("gpu"))
    # This machine: where EGL lists a software device that opened, the CPU device is here.
    if any(d["software"] and not d["error"] for d in ssrlab.devices()):
        assert cpu_device_absence_here() is None


def test_cli_info_lists_every_device_with_its_index():
    r = subprocess.run([sys.executable, "-m", "ssrlab", "info"], capture_output=True, text=True, timeout=120,
                       env={**os.environ, "SSRLAB_DEVICE": ""})
    assert r.returncode == 0, r.stderr
    for d in ssrlab.devices():
        name = f"gpu:{d['index']}" if d["index"] is not None else "software"
        assert name in r.stdout and (d["renderer"] or d["error"]) in r.stdout
    assert "renderer" in r.stdout


def test_a_sweep_warns_when_two_workers_shared_one_gpu():
    from ssrlab.lab import run

    rows = [{"worker": "node1:10", "device_index": "0"}, {"worker": "node1:11", "device_index": "0"},
            {"worker": "node1:12", "device_index": "1"}, {"worker": "node2:10", "device_index": "1"}]
    with pytest.warns(UserWarning, match=r"gpu:0 on node1: node1:10, node1:11"):
        run._warn_shared_gpus(rows)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        run._warn_shared_gpus(rows[2:] + [{"worker": "node1:13", "device_index": None}])
