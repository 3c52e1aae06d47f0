"""Whatever a tool is given, a failure is ONE line on stderr and exit status 2, never a
traceback (issue 39; gui.tools.common): hostile option values (a timeout of 1e300 s overflowed
the socket's timer; a control held 1e20 steps reached OMPL as a TypeError; a bad integer
printed argparse's usage before its error), hostile files (a folder, non-UTF-8 bytes, 1e999,
nesting 100,000 deep), for problem_info, load_problem, run_path, plan and benchmark. No ROS
master answers here: every refusal comes before one is needed, or is the master's absence."""
from __future__ import annotations

import os
import pathlib
import subprocess

import pytest

SPHERE = "current_2025/demos/OMPL_ode_demos/Sphere/Sphere.xml"


@pytest.fixture
def hostile(tmp_path) -> pathlib.Path:
    """A folder of hostile inputs: a folder named like a problem, a problem of non-UTF-8
    bytes, 100,000 nested elements, and path files with 1e999 and non-UTF-8 bytes."""
    (tmp_path / "folder.xml").mkdir()
    (tmp_path / "latin.xml").write_bytes(b'<?xml version="1.0"?>\n<Problem \xe9\xff>\x80\n')
    (tmp_path / "deep.xml").write_text('<?xml version="1.0"?>\n' + "<a>" * 100_000
                                       + "</a>" * 100_000)
    (tmp_path / "huge.path").write_text("0 0 0\n1e999 0 0\n")
    (tmp_path / "latin.path").write_bytes(b"0 0 0\n\xe9\xff 0 0\n")
    return tmp_path


def _tool(tool: str, *args, cwd=None) -> subprocess.CompletedProcess:
    """``rosrun GUI tool args`` with no master answering (a port nothing listens on)."""
    env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:9")
    return subprocess.run(["rosrun", "GUI", tool, *map(str, args)], capture_output=True,
                          text=True, timeout=120, env=env, cwd=cwd, stdin=subprocess.DEVNULL)


def _one_line(result: subprocess.CompletedProcess, tool: str, *words: str) -> str:
    lines = [line for line in result.stderr.splitlines() if ": warning: " not in line]
    assert result.returncode == 2, result.stderr
    assert len(lines) == 1 and lines[0].startswith(f"{tool}: error: "), result.stderr
    for word in words:
        assert word in lines[0], lines[0]
    return lines[0]


@pytest.mark.parametrize("option,value", [("--timeout", "1e300"), ("--timeout", "nan"),
                                          ("--timeout", "-1"), ("--timeout", "soon")])
def test_load_problem_refuses_a_bad_timeout_in_one_line(hostile, option, value):
    _one_line(_tool("load_problem", hostile / "folder.xml", option, value), "load_problem",
              option)


@pytest.mark.parametrize("option,value", [("--timeout", "1e300"), ("--rate", "-5"),
                                          ("--rate", "1e-300"), ("--double", "99")])
def test_run_path_refuses_bad_numbers_in_one_line(hostile, option, value):
    _one_line(_tool("run_path", hostile / "folder.xml", "--position", hostile / "huge.path",
                    option, value), "run_path", option)


@pytest.mark.parametrize("options", [
    ("--max-control-steps", "99999999999999999999"), ("--min-control-steps", "-3"),
    ("--world-timeout", "1e300"), ("--time", "inf"), ("--parallel", "100000"),
    ("--seed", "99999999999999999999")])
def test_plan_refuses_bad_numbers_in_one_line(kautham_dir, tmp_path, options):
    _one_line(_tool("plan", kautham_dir / SPHERE, "--out", tmp_path / "p.path", *options),
              "plan", options[0])
    assert not (tmp_path / "p.path").exists()


def test_problem_info_refuses_a_bad_indent_in_one_line(kautham_dir):
    _one_line(_tool("problem_info", kautham_dir / SPHERE, "--indent", "1e9"), "problem_info",
              "--indent")
    _one_line(_tool("problem_info", kautham_dir / SPHERE, "--indent", "100000"),
              "problem_info", "--indent")


@pytest.mark.parametrize("name", ["folder.xml", "latin.xml", "deep.xml"])
def test_every_tool_refuses_a_hostile_problem_in_one_line(hostile, tmp_path, name):
    problem = hostile / name
    _one_line(_tool("problem_info", problem), "problem_info", name)
    _one_line(_tool("plan", problem, "--out", tmp_path / "p.path"), "plan", name)
    _one_line(_tool("benchmark", problem, "--out", tmp_path / "bench"), "benchmark", name)
    _one_line(_tool("benchmark", "--problem", problem, "--out", tmp_path / "bench"),
              "benchmark", name)


def test_benchmark_refuses_a_seed_out_of_ompl_range_in_one_line(kautham_dir, tmp_path):
    _one_line(_tool("benchmark", "--problem", kautham_dir / SPHERE, "--seed", "0", "--out",
                    tmp_path / "bench"), "benchmark", "--seed")
    assert not (tmp_path / "bench").exists()


def test_run_path_refuses_doubling_a_path_past_its_row_limit(ros_master, kautham_dir,
                                                             tmp_path):
    """--double 19 of 3 rows would be 1.5 million rows (gui.tools.run_path.MAX_PATH_ROWS): refused
    before the path is refined or the world is looked for."""
    path = tmp_path / "three.path"
    path.write_text("0 0 0\n10 10 0\n20 20 0\n")
    problem = kautham_dir / "legacy_2012" / "examples" / "TRO" / "2DRR_obstacle.xml"
    result = ros_master.run(["rosrun", "GUI", "run_path", str(problem), "--position",
                             str(path), "--double", "19", "--timeout", "2"], check=False)
    _one_line(result, "run_path", "--double 19", "MAX_PATH_ROWS")


@pytest.mark.parametrize("name", ["huge.path", "latin.path", "folder.xml"])
def test_run_path_refuses_a_hostile_path_file_in_one_line(ros_master, kautham_dir, hostile,
                                                          name):
    problem = kautham_dir / "legacy_2012" / "examples" / "TRO" / "2DRR_obstacle.xml"
    for kind in ("--position", "--tracked"):
        result = ros_master.run(["rosrun", "GUI", "run_path", str(problem), kind,
                                 str(hostile / name), "--timeout", "2"], check=False)
        _one_line(result, "run_path", name)
