"""A sweep on an existing dask cluster: a real `dask scheduler` and two `dask worker` processes on
127.0.0.1, one of them killed mid-sweep; then a resume of a sweep cut short.

Checks: every configuration has exactly one row, each reference was rendered once (by one
reference task, into the shared store) and a resume renders nothing already done."""

import collections
import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

distributed = pytest.importorskip("distributed")


@pytest.fixture(autouse=True)
def _time_limit():
    """The whole test, processes included, stops after TIME_LIMIT_S (no pytest-timeout needed)."""
    def expired(*_):
        raise TimeoutError(f"test_cluster took more than {TIME_LIMIT_S} s")

    old = signal.signal(signal.SIGALRM, expired)
    signal.alarm(TIME_LIMIT_S)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)

REPO = Path(__file__).resolve().parents[1]
DEADLINE_S = 150  # each sweep
TIME_LIMIT_S = 300  # the whole test, cluster start and stop included

# Rows long enough (6 timed renders at 96x64) that the sweep cannot finish between the first
# reference's journal entry and the kill, however the machine schedules the test's polling.
SWEEP = """
scenes = ["mirror_test"]
views = ["default", {name = "low", position = [0.0, 0.6, 4.0], target = [0.0, 0.4, -4.0]}]
repeats = 6
warmup = 1
reference = "thesis"

[base]
width = 96
height = 64
shadow_map_size = 128

[grid]
layers = [1, 2]
"""


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _journal(folder: Path) -> list[dict]:
    path = folder / "journal.jsonl"
    if not path.is_file():
        return []
    out = []
    for line in path.read_text().splitlines():
        try:
            out.append(json.loads(line))
        except ValueError:
            pass
    return out


def _wait(predicate, timeout: float, what: str, procs=()):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return
        for p in procs:
            if p.poll() is not None:
                raise AssertionError(f"{what}: {p.args[:4]} exited with {p.returncode}")
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}")


@pytest.fixture
def cluster(tmp_path):
    """A scheduler and two single-threaded workers without nannies (a killed worker stays dead)."""
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = {**os.environ, "LP_NUM_THREADS": "1", "SSRLAB_CACHE": str(tmp_path / "private-cache")}
    logs = tmp_path / "logs"
    logs.mkdir()
    procs = []

    def start(name, *args):
        log = open(logs / f"{name}.log", "wb")
        p = subprocess.Popen([sys.executable, "-m", *args], stdout=log, stderr=subprocess.STDOUT, env=env,
                             cwd=tmp_path, start_new_session=True)
        procs.append(p)
        return p

    try:
        start("scheduler", "distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", str(port),
              "--no-dashboard")
        workers = [start(f"worker{i}", "distributed.cli.dask_worker", address, "--nthreads", "1", "--no-nanny",
                         "--no-dashboard", "--host", "127.0.0.1", "--death-timeout", "60") for i in range(2)]
        with distributed.Client(address, timeout=60) as client:
            client.wait_for_workers(2, timeout=60)
        yield address, workers, env
    finally:
        for p in reversed(procs):
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGTERM)
        for p in procs:
            try:
                p.wait(timeout=15)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait(timeout=15)


def test_cluster_sweep_survives_a_killed_worker_and_resumes(tmp_path, cluster):
    address, workers, env = cluster
    start = time.monotonic()
    sweep = tmp_path / "tiny.toml"
    sweep.write_text(SWEEP)
    store, out = tmp_path / "store", tmp_path / "out"
    cmd = [sys.executable, "-m", "ssrlab", "bench", str(sweep), "--scheduler", address, "--reference-store",
           str(store), "--out", str(out)]
    bench = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, cwd=tmp_path)
    try:
        # Kill the worker that rendered the first reference as soon as it has: its result (and
        # likely a configuration it took next) is lost with it.
        _wait(lambda: any(e.get("type") == "reference" for e in _journal(out)), 120, "a reference", [bench])
        first = next(e for e in _journal(out) if e.get("type") == "reference")
        victim_pid = int(first["worker"].rsplit(":", 1)[1])
        victim = next(w for w in workers if w.pid == victim_pid)
        os.killpg(victim.pid, signal.SIGKILL)
        rows_at_kill = sum(e.get("type") == "row" for e in _journal(out))
        stdout, stderr = bench.communicate(timeout=DEADLINE_S)
    finally:
        if bench.poll() is None:
            bench.kill()
            bench.wait()
    assert bench.returncode == 0, stderr.decode()[-3000:]
    assert rows_at_kill < 4, "the worker was killed mid-sweep"
    assert b"\r" not in stderr  # progress into a pipe: lines, no redrawn bar
    lines = _journal(out)
    rows = [e for e in lines if e["type"] == "row"]
    refs = [e for e in lines if e["type"] == "reference"]
    # Four configurations (two views x two layer counts), each exactly one row.
    keys = collections.Counter(e["config_key"] for e in rows)
    assert len(keys) == 4 and set(keys.values()) == {1}, keys
    assert len(json.loads((out / "rows.json").read_text())) == 4
    # Two references (one per view; the thesis reference does not depend on the layers), each
    # rendered exactly once, by a reference task, into the shared store; no configuration
    # rendered one itself.
    computed = collections.Counter(e["key"] for e in refs if e["computed"])
    assert len(computed) == 2 and set(computed.values()) == {1}, refs
    assert sorted(p.stem for p in store.glob("*.npz")) == sorted(computed)
    assert not any(e["row"]["reference_rendered"] for e in rows)
    survivor = next(w for w in workers if w.pid != victim_pid)
    assert any(e["row"]["worker"].endswith(f":{survivor.pid}") for e in rows)

    # A sweep cut short: keep the header, two rows and half of the third (a crash mid-write).
    text = (out / "journal.jsonl").read_text().splitlines()
    kept_rows = [line for line in text if json.loads(line)["type"] == "row"][:2]
    header = text[0]
    (out / "journal.jsonl").write_text("\n".join([header, *kept_rows, kept_rows[-1][:40]]))
    before = {json.loads(line)["config_key"]: json.loads(line)["row"]["timestamp"] for line in kept_rows}
    r = subprocess.run([sys.executable, "-m", "ssrlab", "bench", "--resume", str(out), "--scheduler", address,
                        "--reference-store", str(store)], capture_output=True, env=env, cwd=tmp_path,
                       timeout=DEADLINE_S)
    assert r.returncode == 0, r.stderr.decode()[-3000:]
    lines = _journal(out)
    rows = [e for e in lines if e["type"] == "row"]
    keys = collections.Counter(e["config_key"] for e in rows)
    assert len(keys) == 4 and set(keys.values()) == {1}, "the resume ran only the two configurations without a row"
    for e in rows:
        if e["config_key"] in before:
            assert e["row"]["timestamp"] == before[e["config_key"]]
    # The cut journal kept no reference line: every one now is the resume's, and none rendered.
    assert [e["computed"] for e in lines if e["type"] == "reference"] == [False] * len(
        [e for e in lines if e["type"] == "reference"]), "no reference was rendered again"
    assert len(list(store.glob("*.npz"))) == 2
    assert time.monotonic() - start < DEADLINE_S


USER_SWEEP = """
user_modules = ["{module}"]
scenes = ["mirror_test"]
repeats = 1
warmup = 0
reference = "thesis"

[base]
width = 48
height = 32
shadow_map_size = 128
user_passes = ["reflection_gain"]

[grid]
"reflection_gain.gain" = [0.0, 0.5, 1.0]
"""


def test_cluster_sweep_of_a_user_pass_parameter(tmp_path, cluster):
    """The workers started knowing nothing of the user pass: the sweep's settings name its module
    (a .py file beside the tests), which every worker imports and registers before rendering."""
    address, workers, env = cluster
    module = Path(__file__).with_name("data") / "user_passes" / "gain_module.py"
    sweep = tmp_path / "user.toml"
    sweep.write_text(USER_SWEEP.format(module=module))
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "ssrlab", "bench", str(sweep), "--scheduler", address,
                        "--reference-store", str(tmp_path / "store"), "--out", str(out)],
                       capture_output=True, env=env, cwd=tmp_path, timeout=DEADLINE_S)
    assert r.returncode == 0, r.stderr.decode()[-3000:]
    rows = json.loads((out / "rows.json").read_text())
    assert [row["s_reflection_gain.gain"] for row in rows] == [0.0, 0.5, 1.0]
    worker_pids = {w.pid for w in workers}
    for row in rows:  # every row scored, by a worker, with the user pass timed in its frame
        assert row["thesis_error"] is not None and row["thesis_error"] >= 0.0
        assert row["gpu_reflection_gain_ms"] > 0.0
        assert int(row["worker"].rsplit(":", 1)[1]) in worker_pids
        assert row["s_user_modules"] == [str(module.resolve())]
    errors = [row["thesis_error"] for row in rows]
    assert errors[0] > errors[1] > errors[2]  # the gain acted: less of the true reflection, more error
