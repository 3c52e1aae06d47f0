"""``make soak`` in short: the same soak (four clients, the world simulating, the Viewer, a
recorder) for 15 s, so the tool stays true; the 10-minute figures come from `make soak`."""
from __future__ import annotations

import json
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_a_short_soak_runs_without_errors_and_writes_its_figures(tmp_path):
    run = subprocess.run([sys.executable, str(ROOT / "tools/soak/run.py"), "--duration", "15",
                          "--out", str(tmp_path)], capture_output=True, text=True, timeout=600)
    results = json.loads((tmp_path / "results.json").read_text())
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    assert results["soak_errors"] == 0, results["soak_error_examples"]
    assert results["soak_calls"] > 1000
    assert results["soak_world_alive"] == results["soak_viewer_alive"] == 1
    assert results["soak_world_updates_received"] > 0
    for name in ("soak_latency_p99_ms", "soak_rss_growth_world_mb", "soak_rss_growth_viewer_mb",
                 "soak_world_updates_dropped"):
        assert name in results
