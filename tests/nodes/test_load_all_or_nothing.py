"""load_problem builds a problem whole or leaves the scene as it was (issue 39): a problem the
world would refuse midway (a box beyond the world's extent, more objects than the node's
``~max_objects``) is refused in one line, exit status 2, before New Scene, and the problem
built before keeps its objects, robots, joints, motors and state, bit for bit. Before, New
Scene went first and the refused step left half a robot, without its motors."""
from __future__ import annotations

import pathlib

import numpy as np
import pytest

from world_client import running_world

pytestmark = pytest.mark.forked


def _boxes(path: pathlib.Path, count: int, spacing_mm: float) -> pathlib.Path:
    """A Kautham problem of the arm (``arm_and_box``'s arm.rob, in the same folder) and
    ``count`` 100 mm boxes of its scene, ``spacing_mm`` apart along y, 300 mm up."""
    scenes = "".join(f'<Scene scene="cube.iv" scale="1.0"><Location X="700" Y="{k * spacing_mm}"'
                     ' Z="300" WX="0" WY="0" WZ="1" TH="0"/></Scene>\n' for k in range(count))
    path.write_text('<?xml version="1.0"?>\n<Problem>\n<Robot robot="arm.rob"/>\n'
                    f'{scenes}</Problem>\n')
    return path


def _scene(client):
    """What a refused load must leave as it was: every ID, robot and every body's state."""
    world = client.world()
    state = np.array(client.call("get_state").state_vector)
    return (world.objects, world.entities, world.joints, world.motors, world.robots,
            world.parameters, world.step_values), state.tobytes()


def _load(master, problem: pathlib.Path, *options: str):
    return master.run(["rosrun", "GUI", "load_problem", str(problem), *options], check=False,
                      timeout=120)


def _refused_in_one_line(result, *words: str) -> str:
    errors = [line for line in result.stderr.splitlines() if ": warning: " not in line]
    assert result.returncode == 2, result.stderr
    assert len(errors) == 1 and errors[0].startswith("load_problem: error: "), result.stderr
    for word in words:
        assert word in errors[0], errors[0]
    return errors[0]


@pytest.fixture
def small_world(ros_master):
    """A world node that holds at most 6 objects."""
    yield from running_world(ros_master, "_max_objects:=6")


def test_a_problem_beyond_the_world_extent_leaves_the_scene_built_before(world, arm_and_box):
    from gui.ros.client import WorldClient
    good = arm_and_box("good.xml", 600)
    far = arm_and_box("far.xml", 3.5e7)          # 35 km: beyond the 10 km world extent
    assert _load(world, good).returncode == 0
    client = WorldClient()
    before = _scene(client)
    assert before[0][4] and before[0][3], "the good problem built a robot with motors"

    refused = _load(world, far)
    assert _scene(client) == before
    line = _refused_in_one_line(refused, "far.xml", "world_extent")
    assert "unchanged" in line
    client.close()


def test_more_objects_than_the_node_holds_leave_the_scene_built_before(small_world,
                                                                          arm_and_box):
    from gui.ros.client import WorldClient
    good = _boxes(arm_and_box("unused.xml", 600).with_name("two.xml"), 2, 200)
    many = _boxes(good.with_name("many.xml"), 9, 200)    # 2 links + 9 boxes > 6
    assert _load(small_world, good).returncode == 0
    client = WorldClient()
    before = _scene(client)
    assert len(before[0][0]) == 4

    refused = _load(small_world, many)
    assert _scene(client) == before
    _refused_in_one_line(refused, "many.xml", "max_objects")
    # --keep: the problem alone is over the limit; what the world holds leaves less room
    refused = _load(small_world, many, "--keep")
    assert _scene(client) == before
    _refused_in_one_line(refused, "max_objects")
    client.close()


def test_the_window_refuses_a_problem_beyond_the_world_extent_and_keeps_its_scene(
        world, arm_and_box):
    """The window's Open file has the same rule (gui.planning.rehearsal.load_scene)."""
    import os
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from gui.ros.client import WorldClient
    from gui.window.testing import open_window, wait_for
    window = open_window()
    try:
        wait_for(lambda: window.connected and window.updates > 0, 15, "the window to connect")
        tab = window.simulation
        tab.open_problem(str(arm_and_box("near.xml", 450)))
        wait_for(lambda: not tab.building and "arm" in window.scene.robots, 30, "the arm")
        client = WorldClient(node_name="probe")
        before = _scene(client)
        shown = tab.element_count()
        tab.open_problem(str(arm_and_box("beyond.xml", -2.5e7)))    # 25 km away
        wait_for(lambda: not tab.building, 30, "the refusal")
        assert _scene(client) == before
        assert "beyond.xml" in window.last_error and "world_extent" in window.last_error
        wait_for(lambda: tab.element_count() == shown, 5, "the tree as it was")
        client.close()
    finally:
        window.shutdown()


def test_keep_with_a_clash_only_the_world_sees_is_undone(world, arm_and_box):
    """--keep rehearses the problem alone: that its names are taken in the world is found by
    the world only, midway; what the load set and built is then undone, the scene as it was
    (its world parameters included), and the line names the step."""
    from gui.ros.client import WorldClient
    problem = arm_and_box("twice.xml", 800)
    assert _load(world, problem).returncode == 0
    client = WorldClient()
    client.set_world(gravity=(0.0, 0.0, -1.62))     # the problem sets Earth's: undone too
    before = _scene(client)
    client.start()                                  # the problem pauses it: started again
    refused = _load(world, problem, "--keep")
    assert client.world().simulating
    client.pause()
    assert _scene(client)[0] == before[0]           # the states moved while it ran
    line = _refused_in_one_line(refused, "twice.xml", "the world refused step")
    assert "the scene is as it was" in line, line
    client.close()


def _grid_stl(path: pathlib.Path, side: int) -> pathlib.Path:
    """A binary STL of a rippled square, side x side vertices 1 mm apart (2 (side-1)^2
    triangles)."""
    import struct
    x, y = np.meshgrid(np.arange(side, dtype=float), np.arange(side, dtype=float))
    z = 0.1 * np.sin(x / 3.0) * np.cos(y / 5.0)
    points = np.stack([x, y, z], axis=-1)
    corners = [points[:-1, :-1], points[1:, :-1], points[1:, 1:], points[:-1, 1:]]
    triangles = np.concatenate([np.stack(corners[:3], axis=2).reshape(-1, 3, 3),
                                np.stack([corners[0], corners[2], corners[3]],
                                         axis=2).reshape(-1, 3, 3)])
    records = np.zeros(len(triangles), dtype=[("normal", "<f4", 3), ("vertices", "<f4", (3, 3)),
                                              ("attributes", "<u2")])
    records["vertices"] = triangles
    path.write_bytes(b"\0" * 80 + struct.pack("<I", len(triangles)) + records.tobytes())
    return path


@pytest.fixture
def capped_world(ros_master):
    """A world node that reads no message over 1 MB."""
    yield from running_world(ros_master, "_max_request_mb:=1")


def test_a_mesh_over_the_nodes_message_limit_leaves_the_scene_built_before(capped_world,
                                                                           arm_and_box):
    """The node's ~max_request_mb is a limit its Core does not know: the rehearsal checks a
    step's mesh arrays against it (a 2 MB mesh in a world that reads 1 MB)."""
    from gui.ros.client import WorldClient
    good = arm_and_box("small.xml", 600)
    _grid_stl(good.with_name("grid.stl"), 200)
    big = good.with_name("big.xml")
    big.write_text('<?xml version="1.0"?>\n<Problem>\n<Robot robot="arm.rob"/>\n'
                   '<Scene scene="grid.stl" scale="1.0"><Location X="700" Y="0" Z="300" '
                   'WX="0" WY="0" WZ="1" TH="0"/></Scene>\n</Problem>\n')
    assert _load(capped_world, good).returncode == 0
    client = WorldClient()
    before = _scene(client)
    refused = _load(capped_world, big)
    assert _scene(client) == before
    _refused_in_one_line(refused, "big.xml", "max_request_mb", "unchanged")
    client.close()
