"""The world seam holds its shape (gui.core.world_port, docs/ARCHITECTURE.md): exactly two
implementations of WorldPort, each with every member the protocol names and its parameters;
no other class of the stack or its tools writes the seam again; gui.core names no service.
(That the two answer alike is tests/nodes/test_world_port_conformance.py's.)"""
import ast
import inspect
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
#: what makes a class an implementation of the seam's running half, written again
RUNNING = {"body_state", "set_servo", "advance"}


def _protocol_members():
    from gui.core.world_port import WorldPort
    return {name: member for name, member in vars(WorldPort).items()
            if callable(member) and not name.startswith("_")}


def _implementations():
    from gui.planning.core_world import CoreWorld
    from gui.ros.world_port import ClientWorldPort
    return [ClientWorldPort, CoreWorld]


@pytest.mark.parametrize("index", [0, 1], ids=["ClientWorldPort", "CoreWorld"])
def test_each_implementation_has_every_member_of_the_protocol(index):
    implementation = _implementations()[index]
    for name, member in _protocol_members().items():
        assert callable(getattr(implementation, name, None)), (implementation, name)
        wanted = list(inspect.signature(member).parameters)
        assert list(inspect.signature(getattr(implementation, name)).parameters) == wanted, \
            (implementation.__name__, name)


def _classes(paths):
    for path in paths:
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.ClassDef):
                yield path, node


def test_no_other_class_writes_the_seam_again():
    """A class with the running half of the seam is one of the two (a subclass of one may
    change how time advances: tools/experiments)."""
    sources = [p for p in (ROOT / "Odin").rglob("*.py") if "test" not in p.parts]
    sources += list((ROOT / "tools").rglob("*.py"))
    found = []
    for path, node in _classes(sources):
        methods = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        if RUNNING <= methods and "Protocol" not in {ast.unparse(b) for b in node.bases}:
            found.append(f"{path.relative_to(ROOT)} {node.name}")
    assert sorted(found) == ["Odin/GUI/src/gui/planning/core_world.py CoreWorld",
                             "Odin/GUI/src/gui/ros/world_port.py ClientWorldPort"]


def test_gui_core_names_no_service():
    """gui.core asks the world through WorldPort alone: no string in it is a service's name
    used in a call, and it never calls ``call``/``ask`` (WorldClient's untyped doors)."""
    from odin_common.interface import WORLD_SERVICES
    offences = []
    for path in (ROOT / "Odin" / "GUI" / "src" / "gui" / "core").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and \
                    node.func.attr in ("call", "ask") and node.args and \
                    isinstance(node.args[0], ast.Constant) and \
                    node.args[0].value in WORLD_SERVICES:
                offences.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert offences == []
