"""What the Kautham loaders say when a problem is wrong (issue 41, findings 8 and 9), each on
small problems written here: Kautham 2012's query dim=, the robots a message lists, the folders
a missing file was looked for in, and the URI of a mesh that is not there."""
from __future__ import annotations

import pathlib
import re

import pytest

from gui.core.kautham.problem import load_problem
from gui.core.kautham.solutions import KPS, OMPL, ROWS, TASK, read_solution
from gui.errors import PathFileError, ProblemError, ShapeError
from kautham_files import two_link_urdf

CUBE_IV = "#Inventor V2.1 ascii\n\nSeparator { Cube { width 100 height 100 depth 100 } }\n"

ARM_ROB = """<?xml version="1.0"?>
<Robot name="arm" DHType="Modified" robType="Chain"><Joints size="2">
<Joint name="Base" ivFile="cube.iv"><DHPars alpha="0" a="0" theta="0" d="0"/>
 <Description rotational="true" movable="false"/><Limits Hi="0" Low="0"/><Parent name=""/>
</Joint>
<Joint name="J1" ivFile="cube.iv"><DHPars alpha="0" a="0" theta="0" d="0"/>
 <Description rotational="true" movable="true"/><Limits Hi="90" Low="-90"/>
 <Parent name="Base"/></Joint></Joints>
<ControlSet size="2"><Offset><DOF name="J1" value="0.5"/></Offset>
 <Control name="j" eigValue="1.0"><DOF name="J1" value="1.0"/></Control>
 <Control name="k" eigValue="1.0"><DOF name="J1" value="0.5"/></Control></ControlSet>
</Robot>
"""
"""A 2012 arm of one revolute joint (+-90 degrees) moved by two controls."""


BOX = '<box size="0.2 0.2 0.2"/>'


def _write(folder: pathlib.Path, name: str, text: str) -> pathlib.Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def _problem(body: str) -> str:
    return f'<?xml version="1.0"?>\n<Problem>\n{body}\n</Problem>\n'


def _line_of(text: str, needle: str) -> int:
    return text[:text.index(needle)].count("\n") + 1


# -- finding 8: Kautham 2012's dim= ------------------------------------------------------------

def _query_2012(folder: pathlib.Path, init: str, goal: str) -> pathlib.Path:
    _write(folder, "cube.iv", CUBE_IV)
    _write(folder, "arm.rob", ARM_ROB)
    return _write(folder, "p.xml", _problem(
        '<Robot robot="arm.rob"/>\n<Planner><Parameters><Name>PRM</Name></Parameters>\n'
        f'<Queries><Query>\n{init}\n{goal}\n</Query></Queries></Planner>'))


def test_a_2012_query_whose_dim_is_not_its_count_is_refused_as_kautham_2012_does(tmp_path):
    """Kautham 2012's Problem::createCSpaceFromFile reads <Init> and <Goal> only when dim= is
    the workspace's number of controls and the text has dim values. Here the values are the
    controls' two, but dim= says 3: the query is refused, one line naming where, dim, count."""
    problem = _query_2012(tmp_path, '<Init dim="3">0.5 0.5</Init>',
                          '<Goal dim="2">0.7 0.5</Goal>')
    loaded = load_problem(problem)
    assert loaded.instances[0].start is None and loaded.instances[0].goal is None
    line = _line_of(problem.read_text(), "<Init")
    said = [str(i) for i in loaded.ignored if i.what == "<Query>"]
    assert said == [f'{problem}:{line}: <Query>: cannot be used: <Init dim="3"> has 2 values '
                    "(Kautham 2012 reads a query whose dim= is its count of values)"]


def test_a_2012_goal_whose_dim_is_not_its_count_is_refused_too(tmp_path):
    problem = _query_2012(tmp_path, '<Init dim="2">0.5 0.5</Init>',
                          '<Goal dim="1">0.7 0.5</Goal>')
    loaded = load_problem(problem)
    assert loaded.instances[0].goal is None
    assert any(f":{_line_of(problem.read_text(), '<Goal')}:" in str(i)
               and '<Goal dim="1"> has 2 values' in i.why for i in loaded.ignored)


def test_a_2012_query_whose_dim_is_its_count_is_read(tmp_path):
    problem = _query_2012(tmp_path, '<Init dim="2">0.5 0.5</Init>',
                          '<Goal dim="2">1.0 0.5</Goal>')
    loaded = load_problem(problem)
    arm = loaded.instances[0]
    assert arm.start is not None and arm.goal is not None
    assert not [i for i in loaded.ignored if i.what == "<Query>"]


# -- finding 9: the messages -------------------------------------------------------------------

def test_a_control_of_no_robot_lists_each_robot_once_by_the_name_robot_takes(tmp_path):
    """Two robots of one file are Cart and Cart_2; a .cntr DOF of neither is refused with the
    robots listed once each, by their instance names, which a path's --robot accepts."""
    _write(tmp_path, "cart.urdf", two_link_urdf(geometry=BOX, name="Cart"))
    def problem(robot: str) -> pathlib.Path:
        _write(tmp_path, f"{robot}.cntr", f'<ControlSet><Control name="c"><DOF name='
               f'"{robot}/arm" value="1"/></Control></ControlSet>')
        return _write(tmp_path, f"{robot}.xml", _problem(
            '<Robot robot="cart.urdf"/>\n<Robot robot="cart.urdf"><Home X="1"/></Robot>\n'
            f'<Controls robot="{robot}.cntr"/>'))

    with pytest.raises(ProblemError) as refused:
        load_problem(problem("Crane"))
    assert refused.value.reason.endswith('no robot named "Crane" in the problem '
                                         "(robots: Cart, Cart_2)")
    loaded = load_problem(problem("Cart_2"))
    rows = _write(tmp_path, "path.txt", "0.1\n0.2\n")
    for name in ("Cart", "Cart_2"):
        assert list(read_solution(rows, loaded, robot=name).paths) == [name]
    with pytest.raises(PathFileError, match=r"\(robots: Cart, Cart_2\)$"):
        read_solution(rows, loaded, robot="Crane")


def test_a_missing_file_names_every_folder_looked_in_in_order(tmp_path):
    """A current problem's file is looked for in models/ beside the problem and in every
    folder above, then beside the problem (where the other files were found)."""
    folder = tmp_path / "cell"
    _write(folder, "cart.urdf", two_link_urdf(geometry=BOX, name="Cart"))
    problem = _write(folder, "p.xml", _problem('<Robot robot="cart.urdf"/>\n'
                                               '<Obstacle obstacle="table.urdf"/>'))
    with pytest.raises(ProblemError) as refused:
        load_problem(problem)
    searched = [f / "models" for f in (folder, *folder.parents)] + [folder]
    assert refused.value.line == 4
    assert refused.value.reason == ('file "table.urdf" not found (looked in: '
                                    + ", ".join(map(str, searched)) + ")")


def test_a_missing_package_mesh_is_named_by_its_uri(tmp_path):
    uri = "package://odin_cart/meshes/base.stl"
    urdf = _write(tmp_path, "cart.urdf",
                  two_link_urdf(geometry=f'<mesh filename="{uri}"/>', name="Cart"))
    with pytest.raises(ShapeError) as refused:
        load_problem(_write(tmp_path, "p.xml", _problem('<Robot robot="cart.urdf"/>')))
    assert str(refused.value.path) == str(urdf)
    assert refused.value.line == _line_of(urdf.read_text(), "<mesh")
    assert refused.value.reason.startswith(f"<mesh filename='{uri}'>: "
                                           f"{tmp_path / 'meshes' / 'base.stl'}")


def test_the_readme_describes_every_plan_format_tracked_reads():
    """Each of read_solution's formats has its item in the README's list of what
    `run_path --tracked` reads (the reader's docstring holds the details)."""
    readme = (pathlib.Path(__file__).resolve().parents[3] / "README.md").read_text()
    listed = readme[readme.index("The plans `--tracked` reads"):]
    listed = listed[:listed.index("\n\n", listed.index("\n- "))]
    headings = {KPS: "a Kautham 2012 solution", TASK: "a task file", OMPL: "OMPL rows",
                ROWS: "raw rows"}
    assert re.findall(r"^- \*\*(.+?)\*\*", listed, re.M) == list(headings.values())
