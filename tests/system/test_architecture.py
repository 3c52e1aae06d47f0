"""The layers of docs/ARCHITECTURE.md hold: every module of the stack imports only what its
layer may (read from the source with ast, lazy imports inside functions included)."""
import ast
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SOURCES = ROOT / "Odin"

ROS = ("rospy", "rosgraph", "roslib", "rospkg", "genpy", "tf2_ros", "interactive_markers",
       "rosbag")
MESSAGES = ("Messages.msg", "Services", "std_msgs", "sensor_msgs", "geometry_msgs",
            "rosgraph_msgs", "visualization_msgs", "diagnostic_msgs", "tf2_msgs")
QT = ("PyQt5",)

# layer (module prefix) -> prefixes it must never import
RULES = {
    "odin_common": ROS + QT + ("Services", "virtual_world", "viewer", "gui"),
    "virtual_world.core": ROS + MESSAGES + QT + ("virtual_world.portal", "virtual_world.ode"
                                                  ".bindings", "viewer", "gui",
                                                  "odin_common.messages"),
    "virtual_world.ode": ROS + MESSAGES + QT + ("virtual_world.core", "virtual_world.portal",
                                                "viewer", "gui"),
    "viewer.core": ROS + MESSAGES + QT + ("viewer.portal", "virtual_world", "gui",
                                          "odin_common.messages"),
    "gui.core": ROS + MESSAGES + QT + ("gui.ros", "gui.window", "virtual_world", "viewer",
                                       "odin_common.messages"),
    # a build plan and a shape's body, whatever file they come from: no Kautham reader
    "gui.core.plan": ("gui.core.kautham", "gui.core.translate"),
    "gui.core.bodies": ("gui.core.kautham", "gui.core.translate"),
    "gui.ros": QT + ("gui.window", "virtual_world", "viewer"),
    # the window reaches nodes through gui.ros only
    "gui.window": ROS + MESSAGES,
    # the planning bridge runs the Core in process; its ROS back end (gui.planning.pool,
    # below) reaches the world nodes through gui.ros only
    "gui.planning": ROS + MESSAGES + QT + ("gui.ros", "gui.window", "virtual_world.portal",
                                           "virtual_world.ode", "viewer",
                                           "odin_common.messages"),
    "gui.planning.pool": QT + ("gui.window", "virtual_world.core", "virtual_world.ode",
                               "virtual_world.portal", "viewer"),
    # the executables reach a world through gui.ros and gui.planning, never its packages
    "gui.tools": ("virtual_world", "viewer"),
    "virtual_world.portal": QT + ("viewer", "gui", "virtual_world.ode"),
    "viewer.portal": QT + ("virtual_world", "gui"),
}
# the generated message classes are allowed in odin_common.messages only, rospy in
# odin_common.node only (what every node's Portal does with rospy: start, outlive its master);
# the planning bridge's pool back end calls the world nodes through gui.ros; the test
# harness's master sets the ROS version parameters as roscore does, with rosversion's rospkg
EXCEPTIONS = {"odin_common.messages": ("Messages.msg",),
              "odin_common.ros_master": ("rospkg.rosversion",),
              "odin_common.node": ("rospy", "rosgraph"),
              "gui.planning.pool": ("gui.ros", "odin_common.messages")}


def _modules():
    for path in sorted(SOURCES.glob("*/src/**/*.py")):
        src = next(p for p in path.parents if p.name == "src")
        parts = path.relative_to(src).with_suffix("").parts
        yield ".".join(p for p in parts if p != "__init__"), path


def _imports(path: pathlib.Path):
    tree = ast.parse(path.read_text(), str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, node.lineno
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            yield node.module, node.lineno
            for alias in node.names:   # "from Messages import msg" imports Messages.msg
                yield f"{node.module}.{alias.name}", node.lineno


def _matches(imported: str, prefix: str) -> bool:
    return imported == prefix or imported.startswith(prefix + ".")


MODULES = list(_modules())


def test_every_source_module_is_in_a_layer():
    layered = [name for name, _ in MODULES
               if any(_matches(name, layer) for layer in RULES)
               or name.startswith(("gui.window", "gui.errors", "virtual_world.errors",
                                   "viewer.errors"))
               or name in ("virtual_world", "viewer", "gui")]
    assert sorted(layered) == sorted(name for name, _ in MODULES)


@pytest.mark.parametrize("name,path", MODULES, ids=[name for name, _ in MODULES])
def test_module_imports_only_what_its_layer_may(name, path):
    forbidden = [prefix for layer, prefixes in RULES.items() if _matches(name, layer)
                 for prefix in prefixes]
    allowed = EXCEPTIONS.get(name, ())
    wrong = [(imported, line) for imported, line in _imports(path)
             if any(_matches(imported, prefix) for prefix in forbidden)
             and not any(_matches(imported, ok) for ok in allowed)]
    assert not wrong, f"{path.relative_to(ROOT)} imports {wrong}"


# the roscore test harness (a private master per test, process groups, rosrun's search) is for
# tests and tools: no node loads it when it starts, not even through odin_common's modules
PORTALS = ("virtual_world.portal", "viewer.portal", "gui.ros", "gui.window")
HARNESS = "odin_common.ros_master"
_NAMED = {name: path for name, path in MODULES}


def _loaded_with(name: str) -> set:
    """The modules of the stack that importing ``name`` may load: its packages, what it
    imports (lazily too) and so on, followed through every module read."""
    loaded, frontier = set(), [name]
    while frontier:
        module = frontier.pop()
        if module in loaded:
            continue
        loaded.add(module)
        parts = module.split(".")
        packages = [".".join(parts[:k]) for k in range(1, len(parts))]
        imported = [i for i, _ in _imports(_NAMED[module])]
        frontier += [m for m in packages + imported if m in _NAMED and m not in loaded]
    return loaded


@pytest.mark.parametrize("name", [n for n, _ in MODULES if n.startswith(PORTALS)])
def test_no_portal_loads_the_test_harness(name):
    assert HARNESS not in _loaded_with(name), f"{name} loads {HARNESS}"
