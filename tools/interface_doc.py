"""Writes docs/INTERFACE.md and docs/parameters.md from the code: the .msg/.srv files, the
interface tables of odin_common (services, world parameters) and each node's parameter table,
plus the provenance and examples below. Run `python tools/interface_doc.py` after changing any
of them; `--check` only compares (exit 1 when a document is stale). tests/test_interface_doc.py
compares them and runs every `rosservice call` example against the live nodes."""
from __future__ import annotations

import pathlib
import sys

from odin_common import world_parameters
from odin_common.interface import (VIEWER_NAMESPACE, VIEWER_SERVICES, WORLD_NAMESPACE,
                                   WORLD_SERVICES)

ROOT = pathlib.Path(__file__).resolve().parent.parent
MSG_DIR = ROOT / "Odin" / "Messages" / "msg"
SRV_DIR = ROOT / "Odin" / "Services" / "srv"
DOC = ROOT / "docs" / "INTERFACE.md"
PARAMETERS_DOC = ROOT / "docs" / "parameters.md"

KNOWN = "known"
RECON = "reconstructed"
PLANNING = ("new (past the thesis: its first line of future work, planning with collision "
            "detection and physics)")

# service type -> (provenance, example request YAML or None); its ROS name and server come
# from odin_common.interface's service tables
SERVICES = {
    "NewScene": (f"{KNOWN}: thesis 3.3.1, 4.6 (empty request); response fields {RECON}", "{}"),
    "SetWorld": (f"parameter list {KNOWN} (thesis 4.2, 5.2, 7.2); set_* flags, field names, "
                 f"solver, friction, bounce and the values in force {RECON}",
                 "{set_gravity: true, gravity: [0.0, 0.0, -9.81], set_erp: true, erp: 0.2}"),
    "SetStep": (f"the four values and the conflict rule {KNOWN} (thesis 4.5); 0 = not given "
                f"{RECON}", "{step: 0.001, cycle_time: 0.04}"),
    "StepOnce": (f"{KNOWN}: thesis 4.4.1; `cycles` and `sim_time` {RECON}", "{cycles: 1}"),
    "Start": (f"{KNOWN}: the simulate flag (thesis 4.4.1); `simulating` {RECON}",
              "{simulate: false}"),
    "BuildObject": (f"shape by number of parameters, name/quaternion/mass checks {KNOWN} "
                    f"(thesis 4.2.1, evidence: odinObject); field layout {RECON}",
                    "{object: {name: ball, parameters: [0.1], mass: 1.0, position: [0, 0, 1], "
                    "orientation: [1, 0, 0, 0], color: [1, 0, 0, 1]}}"),
    "BuildComposite": (f"parts as geoms of one body, id \">p1>p2\" {KNOWN} (thesis 4.2.1, 5.1.3); "
                       f"Part fields {RECON}",
                       "{composite: {parts: [{name: top, parameters: [1.0, 0.6, 0.05], mass: 2.0, "
                       "position: [0, 0, 0.4], orientation: [1, 0, 0, 0]}, {name: leg, "
                       "parameters: [0.03, 0.4], mass: 0.3, position: [0.4, 0.2, 0.2], "
                       "orientation: [1, 0, 0, 0]}], position: [2, 0, 0], "
                       "orientation: [1, 0, 0, 0]}}"),
    "BuildEntity": (f"objects, composites and the internal-collision flag {KNOWN} (thesis 4.2.1);"
                    f" name, all-or-nothing and returned ids {RECON}",
                    "{name: pair, objects: [{name: a, parameters: [0.1], mass: 1.0, "
                    "position: [0, 3, 1], orientation: [1, 0, 0, 0]}, {name: b, "
                    "parameters: [0.1], mass: 1.0, position: [0, 3, 1.1], "
                    "orientation: [1, 0, 0, 0]}], internal_collisions: false}"),
    "RemoveObject": (f"{KNOWN}: thesis 4.2.1; cascaded removal of joints, motors and forces "
                     f"{RECON}", "{id: a}"),
    "SetJoint": (f"joint kinds, anchor/axes, stops, \"type:body1&body2\" ids, one joint per pair "
                 f"{KNOWN} (thesis 4.2.2, 5.3, evidence); action field and parameter list "
                 f"{RECON}",
                 "{action: 0, type: 1, body1: ball, body2: '', anchor: [0, 0, 1.5], "
                 "axis1: [0, 1, 0], parameters: [{parameter: 0, axis: 1, value: -1.0}]}"),
    "SetMotor": (f"angular/linear motors, axis anchoring, infinite force, zero speed, "
                 f"\"motor:\" ids {KNOWN} (thesis 4.2.2, 5.3.1, evidence); fields {RECON}",
                 "{joint: '1:ball&'}"),
    "SetPosition": (f"{KNOWN}: thesis 5.4.1, 7.4.3; several objects per call and reset_velocity "
                    f"{RECON}",
                    "{situations: [{name: ball, position: [0, 0, 2], "
                    "orientation: [1, 0, 0, 0]}]}"),
    "SetVelocity": (f"object and motor velocities {KNOWN} (thesis 3.3.1, 4.2, 7.4); fields "
                    f"{RECON}",
                    "{motors: ['motor:1:ball&'], velocities: [0.5]}"),
    "SetExternalForce": (f"frames, point of application, persistence and numbered ids {KNOWN} "
                         f"(thesis 4.2.2, 5.4.2); fields and id format {RECON}",
                         "{object: ball, kind: 0, vector: [0, 0, 5.0]}"),
    "SetJointForce": (f"{KNOWN}: thesis 5.4.3; per-axis magnitudes and id format {RECON}",
                      "{joint: '1:ball&', magnitudes: [0.2]}"),
    "GetWorld": ("new (past the thesis): the values in force and what the world holds", None),
    "SetServo": ("new (past the thesis): joint servos (a position target tracked by a motor "
                 "under its force limit), for run_path --tracked; the kinematic drive (issue "
                 "30)", "{motors: ['motor:1:ball&'], targets: [0.2]}"),
    "SetSurface": ("new (past the thesis): per-object contact properties, as Kautham's URDF "
                   "<contact_coefficients> and its environments' contact tables give them",
                   "{id: ball, surface: {set_friction: true, friction: 0.4, set_bounce: true, "
                   "bounce: 0.5, bounce_velocity: 0.05}}"),
    "GetState": ("new (past the thesis): states, masses, joint reactions (ODE's feedback) and "
                 "motor goals", "{objects: [ball], joints: ['1:ball&']}"),
    "SetRobot": ("new (past the thesis, issue 19): a robot's namespace, robot_description, "
                 "joint names and link frames for tf, robot_state_publisher and RViz "
                 "(docs/ROS.md)",
                 "{robot: {name: pendulum, links: [bob], objects: [ball], joint_names: [swing], "
                 "joints: ['1:ball&']}}"),
    "SaveState": (f"{PLANNING}; the whole dynamic state, bit for bit", "{name: start}"),
    "RestoreState": (f"{PLANNING}; refused when the contents changed", "{name: start}"),
    "Reset": (f"{PLANNING}; the state right after the last build or removal", None),
    "Propagate": (f"{PLANNING}; controls as in Set Velocity and Set External Force",
                  "{duration: 0.2, motors: ['motor:1:ball&'], velocities: [1.0], forces: "
                  "[{object: ball, kind: 0, vector: [0, 0, 5.0]}]}"),
    "CheckCollision": (f"{PLANNING}; the thesis's PQP-like use, synchronous",
                       "{situations: [{name: ball, position: [0, 0, 0.05], "
                       "orientation: [1, 0, 0, 0]}]}"),
    "ExemptOverlaps": (f"{PLANNING}; Kautham's geometric problems, which it never "
                       f"simulates, standing as their files place them",
                       "{min_depth: 0.001}"),
    "ViewObject": (f"{KNOWN}: thesis 3.3.2, 6.4.1; fields {RECON} (those of Build Object's "
                   f"shape)",
                   "{id: marker, parameters: [0.05], position: [0, 0, 0], "
                   "orientation: [1, 0, 0, 0], color: [0, 1, 0, 1]}"),
    "ViewerRemoveObject": (f"{KNOWN}: thesis 3.3.2",
                           "{id: marker}"),
    "ViewerNewScene": (f"{KNOWN}: thesis 3.3.2, 6.4.3", None),
    "SaveSnapshot": ("new (past the thesis)",
                     "{name: example.png}"),
    "SetCamera": ("new (past the thesis)",
                  "{set_pose: true, eye: [3, -3, 2], target: [0, 0, 0.5], up: [0, 0, 1]}"),
}

# message -> (topic or use, publisher, provenance)
MESSAGES = {
    "SpaceDistribution": ("/virtual_world/world_update", "VirtualWorld, every cycle",
                          f"array of Situation {KNOWN} (thesis 3.3.2, 4.3.1); header {RECON}"),
    "Situation": ("element of SpaceDistribution; request of Set Position", "-",
                  f"name, position, orientation (w, x, y, z) {KNOWN} (thesis 3.3.2, evidence)"),
    "Collided": ("/virtual_world/collided (contact-less), /virtual_world/contacts (contacts)",
                 "VirtualWorld, every cycle",
                 f"the list of collided objects {KNOWN} (thesis 4.3.2); pairs, depths, points "
                 f"{RECON} (the thesis could not measure depth)"),
    "CollisionPair": ("element of Collided", "-", RECON),
    "JointData": ("element of JointsData", "-",
                  f"positions and speeds of joints published {KNOWN} (thesis 5.6); fields "
                  f"{RECON}"),
    "JointsData": ("/virtual_world/joint_data (also sensor_msgs/JointState on "
                   "/virtual_world/joint_states)",
                   "VirtualWorld, every cycle", RECON),
    "Object": ("in Build Object and Build Entity", "-",
               f"the odinObject fields {KNOWN} (evidence); inertia, geometry_only {RECON}"),
    "Part": ("in Composite", "-", RECON),
    "Composite": ("in Build Composite and Build Entity", "-", RECON),
    "Joint": ("joint type constants", "-", f"the kinds {KNOWN} (thesis 5.3); numbering {RECON}"),
    "JointParameter": ("in Set Joint", "-",
                       f"the parameters {KNOWN} (thesis 5.3.2, issue 3); encoding {RECON}"),
    "WorldParameters": ("in Get World", "-", "new: the fields of Set World's values in force"),
    "Surface": ("in Object, Part and Set Surface", "-",
                "new: per-surface friction, restitution and soft contact, with the mixing "
                "rule of two surfaces"),
    "BodyState": ("in Propagate's answer", "-", "new"),
    "BodyForce": ("in Propagate's request", "-", "new: the fields of Set External Force"),
    "RecordStart": ("`/odin/record/start` in a recording (the world node's `~record`)",
                    "VirtualWorld, once", "new"),
    "ServoStates": ("/virtual_world/servo_states", "VirtualWorld, every cycle with a servo",
                    "new"),
    "Robot": ("in Set Robot and Get World", "-",
              "new (issue 19): a robot over the world's objects and joints (docs/ROS.md)"),
    "Advance": ("`/odin/record/advance` in a recording (`rosrun VirtualWorld replay BAG` "
                "compares its poses bit for bit)", "VirtualWorld, every advance", "new"),
}

_NODE_ROWS = (
    "| `/virtual_world` | `rosrun VirtualWorld virtualWorld` | the 15 world services and Odin's own"
    " | `~world_update`, `~collided`, `~contacts`, `~joint_data`, `~joint_states`,"
    " `~real_time_factor`, `~servo_states`, `~markers`, `~interactive/*`, `/tf`, `/tf_static`,"
    " `/clock`, `/diagnostics`, `<robot>/joint_states` (docs/ROS.md)"
    " | the Viewer's services (optional) |",
    "| `/viewer` | `rosrun Viewer viewer`"
    " | View Object, Viewer Remove Object, New Scene, Save Snapshot, Set Camera"
    " | `~image` (sensor_msgs/Image, rgb8, 25 Hz) | - |",
    "| `/gui` | `rosrun GUI gui` (window), `problem_info`, `load_problem`, `run_path` | - | -"
    " | the world's services |",
)
"""The table of nodes, one markdown row each (a row cannot wrap)."""

HEADER = """# Odin's ROS interface

Generated by `tools/interface_doc.py` from `Odin/Messages/msg` and `Odin/Services/srv`; do not
edit by hand. Every example below is run against live nodes by `tests/test_interface_doc.py`.

Conventions (REP 103): SI units (m, kg, s, rad, N, N m); the world frame is right-handed with
z up; **quaternions are (w, x, y, z)**, ODE's order, everywhere they cross a node boundary
(`orientation` fields). Kautham's legacy files (mm, degrees) are converted when the GUI loads
them. Every response starts with `bool success` and `string message`; a refused request
(`success: false`) changes nothing. Creation services return the `id` they gave.

**Determinism.** The same world, built by the same calls and stepped the same way, gives
bit-identical poses and velocities, whatever the process did before (New Scenes, removals, other
worlds in the same process) and in a fresh process: contacts are made in the order of the
geometries' creation, and each world keeps its own state of ODE's random generator (QuickStep
reorders constraints with it). Restore State puts a saved state back bit for bit, so stepping on
from it repeats what followed the save. The guarantee holds for the same libode build on the same
machine architecture (floating-point results differ between builds and instruction sets), and
for the same calls: a call that depends on the wall clock (Start, with its real-time cycles)
repeats only if the number of steps between calls repeats; Step Once and Propagate always do.

"known" marks what the thesis (`shared/spec/000_7f7d4f850af4f9e9.txt`) or the traces in
`shared/spec/interface-evidence.md` state; "reconstructed" marks what Odin had to design
because the original .msg/.srv files are not public.

## Nodes

| node | executable | serves | publishes | calls |
|---|---|---|---|---|
""" + "\n".join(_NODE_ROWS) + """

Node parameters are listed in each node's parameter table (`Odin/*/src/*/portal/parameters.py`,
`Odin/GUI/src/gui/ros/parameters.py`) and below.

"""


def service_names() -> dict:
    """Service type -> (ROS name, server node), from odin_common.interface."""
    names = {}
    for server, namespace, table in (("VirtualWorld", WORLD_NAMESPACE, WORLD_SERVICES),
                                     ("Viewer", VIEWER_NAMESPACE, VIEWER_SERVICES)):
        for name, type_name in table.items():
            names[type_name] = (f"{namespace}/{name}", server)
    return names


def _block(path: pathlib.Path) -> str:
    return "```\n" + path.read_text().rstrip() + "\n```\n"


def render() -> str:
    names = service_names()
    parts = [HEADER, "## Services\n"]
    for name, (provenance, example) in SERVICES.items():
        ros_name, server = names[name]
        parts.append(f"### {name} — `{ros_name}`\n\n"
                     f"Type `Services/{name}`, served by {server}. Provenance: {provenance}.\n\n")
        parts.append(_block(SRV_DIR / f"{name}.srv"))
        if example is None:
            parts.append(f"\n```\nrosservice call {ros_name}\n```\n\n")
        else:
            parts.append(f"\n```\nrosservice call {ros_name} \"{example}\"\n```\n\n")
    parts.append("## Messages\n")
    for name, (use, publisher, provenance) in MESSAGES.items():
        parts.append(f"### {name}\n\nType `Messages/{name}`; {use}; published by {publisher}. "
                     f"Provenance: {provenance}.\n\n")
        parts.append(_block(MSG_DIR / f"{name}.msg") + "\n")
    parts.append(render_kautham())
    parts.append(render_parameters())
    return "".join(parts)


def render_kautham() -> str:
    """How the GUI builds a Kautham problem and applies a control path, from the docstring of
    gui.core.translate and gui.core.control_path.MAPPING (their one home)."""
    from gui.core import translate
    from gui.core.control_path import MAPPING
    marker = "How a problem maps to the world:\n"
    mapping = translate.__doc__.split(marker, 1)[1].strip()
    return ("## Kautham problems and control paths\n\n"
            "The GUI (`rosrun GUI gui`, `load_problem`, `problem_info`) builds a Kautham problem "
            "with the services above (`gui.core.translate`); `problem_info PROBLEM` shows the "
            "plan as JSON, with what Odin does not use under `ignored`, and its query checked "
            "(unless `--no-checks`: the problem is built in a Core of its own process): the "
            "parts built inside each other (`overlaps`, as `load_problem` warns), per robot the "
            "pairs its start and its goal put inside each other (`collisions`: at, first, "
            "second, depth m; robot with robot included) and the DOFs they ask past their "
            "limits, which Kautham's controls clamp (`outside_limits`), each also a warning "
            "line on stderr. How a problem maps to "
            f"the world:\n\n{mapping}\n\n### Control paths\n\n{MAPPING.strip()}\n\n"
            + render_tracked() + render_kinematic())


def render_tracked() -> str:
    """How a tracked path is timed and followed: gui.core.trajectory.TIMING and the docstring
    of gui.core.execution (their one home)."""
    from gui.core import execution
    from gui.core.trajectory import TIMING
    return (f"### Tracked paths\n\nTiming: {TIMING.strip()}\n\nExecution: "
            f"{execution.__doc__.split(chr(10), 3)[3].strip()}\n\n")


def render_kinematic() -> str:
    """What Set Servo's kinematic drive does: the docstring of virtual_world.core.kinematic
    (its one home) but its first line and last paragraph (the Core's own record)."""
    from virtual_world.core import kinematic
    body = kinematic.__doc__.split("\n", 2)[2].rsplit("\n\n", 1)[0].strip()
    return f"### Kinematic drive\n\n{body}\n\n"


def _value(value) -> str:
    if value is None:
        return "unset"
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    if isinstance(value, str):
        return f"`{value}`"
    return f"{value:g}" if isinstance(value, float) else str(int(value))


def _node_table(parameters) -> list:
    rows = ["| parameter | default | unit | meaning |", "|---|---|---|---|"]
    rows += [f"| `~{p.name}` | {_value(p.default)} | {p.unit} | {p.what} |" for p in parameters]
    return rows


def _world_table() -> list:
    rows = ["| parameter | default | unit | range | meaning |", "|---|---|---|---|---|"]
    for info in world_parameters.PARAMETERS:
        default = world_parameters.default(info.name)
        if info.zero_means and default == 0:
            shown = f"0 ({info.zero_means})"
        else:
            shown = _value(default)
        if info.kind == "bool":
            bounds = "true, false"
        elif info.kind == "vector":
            bounds = "finite"
        else:
            low = "-inf" if info.low is None else _value(info.low)
            high = "inf" if info.high is None else _value(info.high)
            bounds = f"[{low}, {high}]"
        notes = "; ".join(n for n in (f"0: {info.zero_means}" if info.zero_means else "",
                                       f"negative: {info.negative_means}" if info.negative_means
                                       else "") if n)
        rows.append(f"| `~{info.name}` | {shown} | {info.unit} | {bounds} | {info.what}"
                    + (f" ({notes})" if notes else "") + f"; Set World `{info.set_flag}` |")
    return rows


def render_parameters() -> str:
    """docs/parameters.md: every node's ~parameters and the world parameters, from the code."""
    from gui.ros.parameters import NODE_PARAMETERS as GUI_PARAMETERS
    from viewer.portal.parameters import NODE_PARAMETERS as VIEWER_PARAMETERS
    from virtual_world.portal.parameters import NODE_PARAMETERS as WORLD_NODE_PARAMETERS
    lines = ["## Node parameters", "",
             "Generated by `tools/interface_doc.py` from each node's parameter table and "
             "`odin_common.world_parameters`; do not edit by hand. Read once at start "
             "(`rosrun VirtualWorld virtualWorld _rate:=10 _contact_less:=true`); a bad "
             "start-up value ends the node at once with one line saying which parameter and "
             "why.", "", f"### `{WORLD_NAMESPACE}`", ""]
    lines += _node_table(WORLD_NODE_PARAMETERS)
    lines += ["", "The world parameters, each also a `~parameter` of the world node and a field "
              "of Set World (`set_*` flags select them; the answer holds the values in force):",
              ""]
    lines += _world_table()
    lines += ["", f"### `{VIEWER_NAMESPACE}`", ""]
    lines += _node_table(VIEWER_PARAMETERS)
    lines += ["", "Meshes of more than 2,000 triangles are drawn with their vertices clustered "
              "at 1 mm (`odin_common.meshes.DISPLAY_TOLERANCE`); meshes of 500 triangles or "
              "more are drawn at the coarsest level of detail whose grid (2 to 32 mm) is at "
              "most a pixel where they come nearest the camera "
              "(`viewer.core.geometry.MeshLevels`); the world's collision meshes are not "
              "affected.", "", "### `/gui`", ""]
    lines += _node_table(GUI_PARAMETERS)
    return "\n".join(lines) + "\n"


def examples() -> list:
    """(ros name, type, YAML) of every documented call, in documentation order."""
    names = service_names()
    return [(names[name][0], f"Services/{name}", example)
            for name, (_, example) in SERVICES.items()]


def stale() -> list:
    """Problems that make the documents differ from the code: undocumented or stale names,
    and each document whose text is not what render() gives."""
    problems = []
    missing = ({p.stem for p in SRV_DIR.glob("*.srv")} ^ set(SERVICES)) | \
              ({p.stem for p in MSG_DIR.glob("*.msg")} ^ set(MESSAGES))
    if missing:
        problems.append(f"undocumented or stale names: {sorted(missing)}")
    for path, text in ((DOC, render()), (PARAMETERS_DOC, render_parameters())):
        if not path.exists() or path.read_text() != text:
            problems.append(f"{path.relative_to(ROOT)} is stale")
    return problems


def main(argv: list) -> int:
    if "--check" in argv:
        problems = stale()
        for problem in problems:
            print(f"interface_doc: {problem} (run python tools/interface_doc.py)",
                  file=sys.stderr)
        return 1 if problems else 0
    problems = [p for p in stale() if p.startswith("undocumented")]
    if problems:
        print(f"interface_doc: {problems[0]}", file=sys.stderr)
        return 1
    PARAMETERS_DOC.write_text(render_parameters())
    DOC.write_text(render())
    print(f"wrote {DOC} and {PARAMETERS_DOC}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
