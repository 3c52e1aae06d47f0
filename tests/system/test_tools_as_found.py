"""The command-line tools as a user finds them (issue 28), without a ROS master: Ctrl-C stops
``plan`` at once and writes nothing, its children included; every tool refuses a missing
output folder or an absent master in one line before it starts its work; ``plan`` always
says and writes the seed that repeats its run."""
from __future__ import annotations

import os
import signal
import subprocess
import time

import pytest

SPHERE = "current_2025/demos/OMPL_ode_demos/Sphere/Sphere.xml"
NO_MASTER = "http://127.0.0.1:9"        # the discard port: nothing listens, the kernel refuses


def _tool(*args: str, env: dict | None = None) -> subprocess.Popen:
    return subprocess.Popen(["rosrun", "GUI", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            env=env)


def _read_until(stream, text: str) -> str:
    said = ""
    while text not in said:
        line = stream.readline()
        assert line, f"ended before saying {text!r}: {said}"
        said += line
    return said


def _errors(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if ": warning:" not in line]


def _children(pid: int) -> list[int]:
    """The processes whose parent is ``pid``."""
    found = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as stat:
                    fields = stat.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                found.append(int(entry))
    return found


def _group_alive(group: int) -> bool:
    try:
        os.killpg(group, 0)
    except ProcessLookupError:
        return False
    return True


@pytest.mark.parametrize("parallel", [1, 2])
def test_ctrl_c_stops_a_search_at_once_writing_nothing(kautham_dir, tmp_path,
                                                               parallel):
    """A goal region of 1 mm: no search ends by itself within its 120 s."""
    out = tmp_path / "sphere.path"
    tool = _tool("plan", str(kautham_dir / SPHERE), "--time", "120", "--goal-tolerance",
                 "0.001", "--parallel", str(parallel), "--out", str(out))
    try:
        said = _read_until(tool.stdout, "searching")
        assert "seed" in said
        if parallel > 1:                 # both children exist before the Ctrl-C
            while len(_children(tool.pid)) < parallel:
                assert tool.poll() is None, tool.stderr.read()
                time.sleep(0.05)
        time.sleep(0.5)                  # into the search (C++ OMPL) itself
        os.killpg(tool.pid, signal.SIGINT)
        sent = time.monotonic()
        status = tool.wait(timeout=30)
        took = time.monotonic() - sent
        err = tool.stderr.read()
        assert status == 128 + signal.SIGINT, err
        # the Ctrl-C ended it, not its 120 s: about 0.1 s on a quiet host here; the bound keeps
        # margin for a loaded one (timings are the bench's, not a test's)
        assert took < 10.0, took
        assert "Traceback" not in err and _errors(err) == [], err
        assert list(tmp_path.iterdir()) == []
        deadline = time.monotonic() + 5.0      # no orphan search left in the group
        while _group_alive(tool.pid) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not _group_alive(tool.pid)
    finally:
        if _group_alive(tool.pid):
            os.killpg(tool.pid, signal.SIGKILL)
        tool.wait()


def test_plan_without_a_seed_says_and_writes_the_one_it_drew(kautham_dir, tmp_path):
    out = tmp_path / "sphere.path"
    run = subprocess.run(["rosrun", "GUI", "plan", str(kautham_dir / SPHERE), "--time", "60",
                          "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    first = run.stdout.splitlines()[0]
    assert first.startswith("plan: KPIECE1 searching") and "--seed" in first, first
    seed = int(first.split("--seed ")[1].split()[0].rstrip(")"))
    assert 0 < seed < 2 ** 31
    assert f'"seed": {seed},' in run.stdout
    assert f"seed {seed}," in out.read_text()


@pytest.mark.parametrize("tool, option", [("plan", "--out"), ("run_path", "--summary"),
                                          ("run_path", "--plot")])
def test_an_output_in_a_missing_folder_is_refused_before_any_work(kautham_dir, tmp_path,
                                                                  tool, option):
    """Nothing answers at the master's URI either: the folder is what is named, at once."""
    missing = tmp_path / "missing"
    args = ["--time", "60"] if tool == "plan" else ["--tracked", str(tmp_path / "p.kps")]
    env = dict(os.environ, ROS_MASTER_URI=NO_MASTER, ROS_HOME=str(tmp_path))
    started = time.monotonic()
    run = subprocess.run(["rosrun", "GUI", tool, str(kautham_dir / SPHERE), *args, option,
                          str(missing / "x")], capture_output=True, text=True, timeout=60,
                         env=env)
    assert run.returncode == 2, run.stderr
    assert _errors(run.stderr) == [f"{tool}: error: {option} {missing / 'x'}: no folder "
                                   f"{missing}"]
    assert time.monotonic() - started < 10.0        # not after a search
    assert "searching" not in run.stdout


@pytest.mark.parametrize("args", [
    ["load_problem", SPHERE, "--timeout", "3"],
    ["run_path", SPHERE, "--controls", "p.path", "--timeout", "3"],
    ["plan", SPHERE, "--backend", "pool", "--world-timeout", "3", "--out", "p.path"],
])
def test_a_tool_without_a_master_says_so_in_one_line_within_its_timeout(kautham_dir,
                                                                        tmp_path, args):
    env = dict(os.environ, ROS_MASTER_URI=NO_MASTER, ROS_HOME=str(tmp_path))
    args = [str(kautham_dir / a) if a == SPHERE else a for a in args]
    started = time.monotonic()
    run = subprocess.run(["rosrun", "GUI", *args], capture_output=True, text=True,
                         timeout=60, env=env, cwd=tmp_path)
    took = time.monotonic() - started
    assert run.returncode == 2, run.stderr
    assert _errors(run.stderr) == [
        f"{args[0]}: error: no ROS master answers at {NO_MASTER} after 3 s (is roscore "
        "running? is ROS_MASTER_URI right?)"]
    assert 3.0 <= took < 3.0 + 10.0, took       # the tool's own start: a few seconds here


def test_the_window_without_a_master_or_a_display_says_both_and_exits(tmp_path):
    """With no display the window says it is drawn off-screen (one line, decided from its own
    environment); it waits for a roscore started beside it for --master-timeout s (default
    MASTER_TIMEOUT_S), saying so, then says none answers and exits 2."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("DISPLAY", "WAYLAND_DISPLAY", "QT_QPA_PLATFORM")}
    env.update(ROS_MASTER_URI=NO_MASTER, ROS_HOME=str(tmp_path), XDG_RUNTIME_DIR=str(tmp_path))
    started = time.monotonic()
    run = subprocess.run(["rosrun", "GUI", "gui", "--master-timeout", "2"], capture_output=True,
                         text=True, timeout=120, env=env)
    assert time.monotonic() - started < 2 + 15.0
    assert run.returncode == 2, run.stderr
    assert "gui: no display (DISPLAY and WAYLAND_DISPLAY are unset): the window is drawn " \
        "off-screen" in run.stderr
    assert f"gui: waiting for the ROS master at {NO_MASTER}" in run.stderr
    assert f"gui: error: no ROS master answers at {NO_MASTER} after 2 s" in run.stderr
    assert "Traceback" not in run.stderr
    bad = subprocess.run(["rosrun", "GUI", "gui", "--master-timeout", "0"], capture_output=True,
                         text=True, timeout=60, env=env)
    assert bad.returncode == 2 and "--master-timeout must be > 0 s" in bad.stderr
