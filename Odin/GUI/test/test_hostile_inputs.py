"""Every kind of file a problem can name, put where a path can lead to something that is not a
file: a character device (endless: /dev/zero, /dev/urandom), a FIFO (an open that would
block for ever), a directory, a symbolic link loop, a dangling link, a sparse file of 8 GB.
Each is refused with one line naming the file and saying what it is, quickly, with the shape
cache on and off, and nothing is read from it (gui.core.sizes.read_input_file)."""
from __future__ import annotations

import contextlib
import io
import os
import pathlib

import pytest

from gui.tools.problem_info import main as problem_info_main
from gui.core import shape_cache, shapes, sizes
from gui.core.control_path import read_control_path
from gui.core.kautham.problem import load_problem
from gui.core.kautham.solutions import read_solution
from gui.core.paths import read_path
from gui.errors import ProblemError
from gui.planning.benchmark_spec import read_benchmark_file

BOX_URDF = ('<robot name="crate"><link name="body"><inertial><mass value="2"/>'
            '<inertia ixx="0.1" iyy="0.1" izz="0.1"/></inertial><collision><geometry>'
            '<box size="0.3 0.2 0.1"/></geometry></collision></link></robot>\n')
ARM_URDF = ('<robot name="arm"><link name="base"><collision><geometry><box size="0.2 0.2 0.1"/>'
            '</geometry></collision></link><link name="upper"><collision><geometry>'
            '<cylinder radius="0.03" length="0.4"/></geometry></collision></link>'
            '<joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>'
            '<axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="5" velocity="1"/></joint>'
            '</robot>\n')
MESH_URDF = ('<robot name="meshy"><link name="shell"><visual><geometry>'
             '<mesh filename="{uri}"/></geometry></visual></link></robot>\n')
PROBLEM = ('<Problem><Robot robot="arm.urdf"><Home X="0" Y="0" Z="0" WX="0" WY="0" WZ="1" '
           'TH="0"/></Robot>{more}</Problem>\n')


def _problem_with(folder: pathlib.Path, more: str, name: str = "problem.xml") -> pathlib.Path:
    (folder / "arm.urdf").write_text(ARM_URDF)
    (folder / "crate.urdf").write_text(BOX_URDF)
    problem = folder / name
    problem.write_text(PROBLEM.format(more=more))
    return problem


def _problem_info(problem: pathlib.Path) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = problem_info_main([str(problem), "--indent", "0"])
    return status, out.getvalue(), err.getvalue()


def _tool_error(problem: pathlib.Path) -> str:
    """problem_info's one error line for ``problem`` (it must refuse it)."""
    shapes._CACHE.clear()
    status, out, err = _problem_info(problem)
    lines = [line for line in err.splitlines() if ": warning: " not in line]
    assert status == 2 and out == "", err
    assert len(lines) == 1 and lines[0].startswith("problem_info: error: "), err
    return lines[0]


def _api_error(call) -> str:
    with pytest.raises(ProblemError) as caught:
        call()
    text = str(caught.value)
    assert "\n" not in text
    return text


# each kind of file: (file name under the test's folder, how the test is run -> the error)
def _as_problem(folder, target):
    return _tool_error(target)


def _as_robot(folder, target):
    return _tool_error(_write(folder / "p_robot.xml",
                              f'<Problem><Robot robot="{target.name}"/></Problem>'))


def _as_obstacle(folder, target):
    return _tool_error(_write(folder / "p_obstacle.xml",
                              f'<Problem><Obstacle obstacle="{target.name}"/></Problem>'))


def _as_mesh(uri):
    def run(folder, target):
        (folder / "meshy.urdf").write_text(MESH_URDF.format(uri=uri(target)))
        return _tool_error(_problem_with(folder, '<Obstacle obstacle="meshy.urdf"/>'))
    return run


def _as_named(text: str, outer: str):
    """A VRML or Inventor obstacle ``outer`` whose node names the target (Coin would open
    it itself)."""
    def run(folder, target):
        _write(folder / outer, text.replace("NAME", target.name))
        return _tool_error(_write(folder / "p_named.xml",
                                  f'<Problem><Obstacle obstacle="{outer}"/></Problem>'))
    return run


def _as_controls(folder, target):
    return _tool_error(_problem_with(folder, f'<Controls robot="{target.name}"/>'))


def _as_path(folder, target):
    return _api_error(lambda: read_path(target, 1))


def _as_control_path(folder, target):
    return _api_error(lambda: read_control_path(target, 1))


def _as_solution(folder, target):
    problem = load_problem(_problem_with(folder, ""))
    return _api_error(lambda: read_solution(target, problem))


def _as_benchmark(folder, target):
    return _api_error(lambda: read_benchmark_file(str(target)))


def _write(path: pathlib.Path, text: str) -> pathlib.Path:
    path.write_text(text)
    return path


KINDS = {
    "problem": ("hostile.xml", _as_problem),
    "URDF robot": ("hostile.urdf", _as_robot),
    "rob robot": ("hostile.rob", _as_robot),
    "dh robot": ("hostile.dh", _as_robot),
    "geometry obstacle": ("hostile.iv", _as_obstacle),
    "URDF mesh (STL)": ("hostile.stl", _as_mesh(lambda t: t.name)),
    "URDF mesh (VRML)": ("hostile.wrl", _as_mesh(lambda t: t.name)),
    "URDF mesh (Collada, package://)": ("meshes/hostile.dae",
                                        _as_mesh(lambda t: "package://kit/meshes/hostile.dae")),
    "URDF mesh (OBJ, file://)": ("hostile.obj", _as_mesh(lambda t: f"file://{t}")),
    "VRML Inline": ("hostile_inline.wrl", _as_named(
        '#VRML V2.0 utf8\nInline { url "NAME" }\nShape { geometry Sphere { radius 1 } }\n',
        "outer.wrl")),
    "Inventor File": ("hostile_file.iv", _as_named(
        '#Inventor V2.1 ascii\nSeparator { File { name "NAME" } Sphere { radius 1 } }\n',
        "outer.iv")),
    "control file": ("hostile.cntr", _as_controls),
    "path file": ("hostile.txt", _as_path),
    "control path file": ("hostile.ctl", _as_control_path),
    "solution file": ("hostile.kps", _as_solution),
    "benchmark file": ("hostile_bench.xml", _as_benchmark),
}


def _make(target: pathlib.Path, what: str) -> None:
    target.parent.mkdir(parents=True, exist_ok=True)
    if what == "zero":
        target.symlink_to("/dev/zero")
    elif what == "urandom":
        target.symlink_to("/dev/urandom")
    elif what == "fifo":
        os.mkfifo(target)
    elif what == "directory":
        target.mkdir()
    elif what == "loop":
        other = target.with_name(target.name + ".other")
        other.symlink_to(target.name)
        target.symlink_to(other.name)
    elif what == "dangling":
        target.symlink_to(target.name + ".gone")
    else:
        with open(target, "wb") as f:
            f.truncate(8 * 2 ** 30)          # sparse: nothing is written


HOSTILE = {"zero": "is a character device, not a file",
           "urandom": "is a character device, not a file",
           "fifo": "is a FIFO (named pipe), not a file",
           "directory": "is a directory, not a file",
           "loop": "is a symbolic link loop",
           "dangling": "not found",
           "sparse 8 GB": "of 8,192 MB is larger than the 256 MB the GUI reads"}


@pytest.fixture(params=[True, False], ids=["cache", "no-cache"])
def cache_on(request, tmp_path, monkeypatch):
    monkeypatch.setenv("ODIN_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(shape_cache, "_enabled", request.param)
    shapes._CACHE.clear()
    yield request.param
    shapes._CACHE.clear()


@pytest.mark.timeout(60)
@pytest.mark.parametrize("hostile", sorted(HOSTILE))
@pytest.mark.parametrize("kind", sorted(KINDS))
def test_a_file_that_is_not_a_regular_file_is_refused_by_what_it_is(kind, hostile, tmp_path,
                                                                   cache_on):
    name, run = KINDS[kind]
    folder = tmp_path / "problem"
    folder.mkdir()
    target = folder / name
    _make(target, hostile)
    error = run(folder, target)
    assert str(target) in error and HOSTILE[hostile] in error, error
    if kind.endswith("package://)"):
        assert "package://kit/meshes/hostile.dae" in error, error


@pytest.mark.timeout(60)
def test_a_urdf_mesh_at_a_device_uri_is_refused_unread(tmp_path, cache_on):
    for uri in ("file:///dev/zero", "/dev/urandom", "file:///dev/null"):
        folder = tmp_path / uri.replace("/", "_")
        folder.mkdir()
        (folder / "meshy.urdf").write_text(MESH_URDF.format(uri=uri))
        error = _tool_error(_problem_with(folder, '<Obstacle obstacle="meshy.urdf"/>'))
        assert uri in error and "is a character device, not a file" in error, error
        assert "meshy.urdf:1:" in error, error


def test_a_file_longer_than_it_says_is_refused_past_the_bound(tmp_path, monkeypatch):
    """/proc files say they are empty and hold more: the bound is on what is read, not on
    what fstat says."""
    status = pathlib.Path("/proc/self/status")
    assert status.stat().st_size == 0 and len(status.read_bytes()) > 100
    monkeypatch.setattr(sizes, "max_input_bytes", lambda: 100)
    error = _api_error(lambda: sizes.read_input_file(status, "path file"))
    assert "/proc/self/status: path file holds more than" in error and "0 bytes" in error
    small = tmp_path / "small.txt"
    small.write_bytes(b"x" * 100)
    assert sizes.read_input_file(small, "path file") == b"x" * 100      # at the bound: read


def test_an_unreadable_file_is_said_to_be_unreadable(tmp_path):
    if os.geteuid() == 0:
        pytest.skip("root reads every file")
    secret = tmp_path / "secret.urdf"
    secret.write_text(BOX_URDF)
    secret.chmod(0)
    error = _tool_error(_write(tmp_path / "p.xml",
                               '<Problem><Obstacle obstacle="secret.urdf"/></Problem>'))
    assert f"{secret}: URDF file is not readable (permission denied)" in error, error


def test_each_file_is_opened_once(tmp_path, monkeypatch):
    """A problem, its URDF and their mesh: each opened by one os.open, none by a reader."""
    (tmp_path / "tri.stl").write_text("solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                                      "vertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
                                      "endsolid t\n")
    (tmp_path / "meshy.urdf").write_text(MESH_URDF.format(uri="tri.stl"))
    problem = _problem_with(tmp_path, '<Obstacle obstacle="meshy.urdf"/>')
    opened = []
    real_open = os.open
    monkeypatch.setattr(os, "open", lambda path, *a, **k: opened.append(str(path))
                        or real_open(path, *a, **k))
    monkeypatch.setattr(shape_cache, "_enabled", True)
    monkeypatch.setenv("ODIN_CACHE_DIR", str(tmp_path / "cache"))
    shapes._CACHE.clear()
    status, _, err = _problem_info(problem)
    assert status == 0, err
    mine = [p for p in opened if p.startswith(str(tmp_path)) and "/cache/" not in p]
    assert sorted(mine) == sorted(str(tmp_path / n) for n in
                                  ("problem.xml", "arm.urdf", "meshy.urdf", "tri.stl")), mine


@pytest.mark.timeout(120)
def test_the_problem_info_tool_refuses_devices_and_fifos_in_one_line(tmp_path):
    """The installed tool, as a user runs it: exit 2 and one line, at once."""
    import subprocess
    import sys
    fifo = tmp_path / "problem.xml"
    os.mkfifo(fifo)
    script = pathlib.Path(shapes.__file__).parents[3] / "scripts" / "problem_info"
    for target, said in (("/dev/zero", "is a character device, not a file"),
                         (str(fifo), "is a FIFO (named pipe), not a file")):
        run = subprocess.run([sys.executable, str(script), target], capture_output=True,
                             text=True, timeout=60)
        assert run.returncode == 2 and run.stdout == "", run.stderr
        assert run.stderr == f"problem_info: error: {target}: problem file {said}\n"


def test_a_urdf_link_without_geometry_is_named_not_an_internal_error(tmp_path):
    """A link with neither <collision> nor <visual> (a tool frame, base_footprint) between
    two links with shapes: every link is built as a body with a shape, so the link is named
    in one line instead of "internal error: AttributeError"."""
    (tmp_path / "frames.urdf").write_text(
        '<robot name="frames">'
        '<link name="foot"><collision><geometry><sphere radius="0.1"/></geometry></collision>'
        '</link><link name="tool0"/>'
        '<link name="finger"><visual><geometry><box size="0.02 0.02 0.1"/></geometry></visual>'
        '</link>'
        '<joint name="a" type="prismatic"><parent link="foot"/><child link="tool0"/>'
        '<origin xyz="0 0 0.3"/><limit lower="0" upper="0.2" effort="5" velocity="1"/></joint>'
        '<joint name="b" type="fixed"><parent link="tool0"/><child link="finger"/></joint>'
        '</robot>')
    problem = tmp_path / "frames.xml"
    problem.write_text('<?xml version="1.0"?><Problem><Robot robot="frames.urdf" scale="1">'
                       '<Home X="0" Y="0" Z="0" WX="0" WY="0" WZ="1" TH="0"/></Robot>'
                       '</Problem>')
    line = _tool_error(problem)
    assert "link 'tool0' of 'frames' has no geometry" in line and "frames.urdf" in line
    assert "internal error" not in line
