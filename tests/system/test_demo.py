"""`make demo`'s script end to end, as in a bare clone (no Kautham corpus): snapshots in which
the sphere moves, one line about the corpus, nothing left running. (With the corpus, its second
part is the grasp experiment, which tests/system/test_experiments.py runs.)"""
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _processes_pointing_at(uri: str) -> list:
    """PIDs of live processes whose environment names this master."""
    found = []
    for entry in pathlib.Path("/proc").iterdir():
        if not entry.name.isdigit() or int(entry.name) == os.getpid():
            continue
        try:
            environ = (entry / "environ").read_bytes()
        except OSError:
            continue
        if f"ROS_MASTER_URI={uri}".encode() in environ.split(b"\0"):
            found.append(int(entry.name))
    return found


@pytest.mark.slow
def test_demo_writes_moving_snapshots_and_stops_every_process():
    bare = dict(os.environ, ODIN_KAUTHAM_DIR=str(ROOT / "out" / "no-kautham-here"))
    result = subprocess.run([sys.executable, str(ROOT / "tools" / "demo.py")],
                            capture_output=True, text=True, timeout=300, env=bare)
    assert result.returncode == 0, result.stdout + result.stderr
    skipped = [line for line in result.stdout.splitlines() if "Kautham part is skipped" in line]
    assert len(skipped) == 1 and "tools/get_kautham.sh" in skipped[0]
    uri = next(line.split()[-1] for line in result.stdout.splitlines()
               if line.startswith("demo: master"))
    assert _processes_pointing_at(uri) == []
    frames = sorted((ROOT / "out" / "demo").glob("demo_*.png"))
    assert len(frames) >= 10
    images = [np.asarray(Image.open(path).convert("RGB")).astype(int) for path in frames]
    red = [(im[..., 0] > 140) & (im[..., 1] < 90) & (im[..., 2] < 90) for im in images]
    rows = [np.nonzero(mask)[0].mean() for mask in red if mask.sum() > 20]
    assert len(rows) >= 10, "the sphere is missing from some snapshots"
    moves = sum(abs(a - b) > 2 for a, b in zip(rows, rows[1:]))
    assert moves >= 5, f"the sphere moved between only {moves} pairs of snapshots"
