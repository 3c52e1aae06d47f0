"""Writes docs/INTERFACE.md from the .msg/.srv files and the facts below (run: python
tools/interface_doc.py). tests/test_interface_doc.py checks that the file is current and runs
every `rosservice call` example against the live nodes."""
from __future__ import annotations

import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
MSG_DIR = ROOT / "Odin" / "Messages" / "msg"
SRV_DIR = ROOT / "Odin" / "Services" / "srv"
DOC = ROOT / "docs" / "INTERFACE.md"

KNOWN = "known"
RECON = "reconstructed"

# name -> (ROS name, server, provenance, example request YAML or None)
SERVICES = {
    "NewScene": ("/virtual_world/new_scene", "VirtualWorld",
                 f"{KNOWN}: thesis 3.3.1, 4.6 (empty request); response fields {RECON}", "{}"),
    "SetWorld": ("/virtual_world/set_world", "VirtualWorld",
                 f"parameter list {KNOWN} (thesis 4.2, 5.2, 7.2); set_* flags, field names, "
                 f"solver, friction, bounce and the values in force {RECON}",
                 "{set_gravity: true, gravity: [0.0, 0.0, -9.81], set_erp: true, erp: 0.2}"),
    "SetStep": ("/virtual_world/set_step", "VirtualWorld",
                f"the four values and the conflict rule {KNOWN} (thesis 4.5); 0 = not given "
                f"{RECON}", "{step: 0.001, cycle_time: 0.04}"),
    "StepOnce": ("/virtual_world/step_once", "VirtualWorld",
                 f"{KNOWN}: thesis 4.4.1; `cycles` and `sim_time` {RECON}", "{cycles: 1}"),
    "Start": ("/virtual_world/start", "VirtualWorld",
              f"{KNOWN}: the simulate flag (thesis 4.4.1); `simulating` {RECON}",
              "{simulate: false}"),
    "BuildObject": ("/virtual_world/build_object", "VirtualWorld",
                    f"shape by number of parameters, name/quaternion/mass checks {KNOWN} "
                    f"(thesis 4.2.1, evidence: odinObject); field layout {RECON}",
                    "{object: {name: ball, parameters: [0.1], mass: 1.0, position: [0, 0, 1], "
                    "orientation: [1, 0, 0, 0], color: [1, 0, 0, 1]}}"),
    "BuildComposite": ("/virtual_world/build_composite", "VirtualWorld",
                       f"parts as geoms of one body, id \">p1>p2\" {KNOWN} (thesis 4.2.1, 5.1.3); "
                       f"Part fields {RECON}",
                       "{composite: {parts: [{name: top, parameters: [1.0, 0.6, 0.05], mass: 2.0, "
                       "position: [0, 0, 0.4], orientation: [1, 0, 0, 0]}, {name: leg, "
                       "parameters: [0.03, 0.4], mass: 0.3, position: [0.4, 0.2, 0.2], "
                       "orientation: [1, 0, 0, 0]}], position: [2, 0, 0], "
                       "orientation: [1, 0, 0, 0]}}"),
    "BuildEntity": ("/virtual_world/build_entity", "VirtualWorld",
                    f"objects, composites and the internal-collision flag {KNOWN} (thesis 4.2.1);"
                    f" name, all-or-nothing and returned ids {RECON}",
                    "{name: pair, objects: [{name: a, parameters: [0.1], mass: 1.0, "
                    "position: [0, 3, 1], orientation: [1, 0, 0, 0]}, {name: b, "
                    "parameters: [0.1], mass: 1.0, position: [0, 3, 1.1], "
                    "orientation: [1, 0, 0, 0]}], internal_collisions: false}"),
    "RemoveObject": ("/virtual_world/remove_object", "VirtualWorld",
                     f"{KNOWN}: thesis 4.2.1; cascaded removal of joints, motors and forces "
                     f"{RECON}", "{id: a}"),
    "SetJoint": ("/virtual_world/set_joint", "VirtualWorld",
                 f"joint kinds, anchor/axes, stops, \"type:body1&body2\" ids, one joint per pair "
                 f"{KNOWN} (thesis 4.2.2, 5.3, evidence); action field and parameter list "
                 f"{RECON}",
                 "{action: 0, type: 1, body1: ball, body2: '', anchor: [0, 0, 1.5], "
                 "axis1: [0, 1, 0], parameters: [{parameter: 0, axis: 1, value: -1.0}]}"),
    "SetMotor": ("/virtual_world/set_motor", "VirtualWorld",
                 f"angular/linear motors, axis anchoring, infinite force, zero speed, "
                 f"\"motor:\" ids {KNOWN} (thesis 4.2.2, 5.3.1, evidence); fields {RECON}",
                 "{joint: '1:ball&'}"),
    "SetPosition": ("/virtual_world/set_position", "VirtualWorld",
                    f"{KNOWN}: thesis 5.4.1, 7.4.3; several objects per call and reset_velocity "
                    f"{RECON}",
                    "{situations: [{name: ball, position: [0, 0, 2], "
                    "orientation: [1, 0, 0, 0]}]}"),
    "SetVelocity": ("/virtual_world/set_velocity", "VirtualWorld",
                    f"object and motor velocities {KNOWN} (thesis 3.3.1, 4.2, 7.4); fields "
                    f"{RECON}",
                    "{motors: ['motor:1:ball&'], velocities: [0.5]}"),
    "SetExternalForce": ("/virtual_world/set_external_force", "VirtualWorld",
                         f"frames, point of application, persistence and numbered ids {KNOWN} "
                         f"(thesis 4.2.2, 5.4.2); fields and id format {RECON}",
                         "{object: ball, kind: 0, vector: [0, 0, 5.0]}"),
    "SetJointForce": ("/virtual_world/set_joint_force", "VirtualWorld",
                      f"{KNOWN}: thesis 5.4.3; per-axis magnitudes and id format {RECON}",
                      "{joint: '1:ball&', magnitudes: [0.2]}"),
    "ViewObject": ("/viewer/view_object", "Viewer",
                   f"{KNOWN}: thesis 3.3.2, 6.4.1; fields {RECON} (those of Build Object's "
                   f"shape)",
                   "{id: marker, parameters: [0.05], position: [0, 0, 0], "
                   "orientation: [1, 0, 0, 0], color: [0, 1, 0, 1]}"),
    "ViewerRemoveObject": ("/viewer/remove_object", "Viewer", f"{KNOWN}: thesis 3.3.2",
                           "{id: marker}"),
    "ViewerNewScene": ("/viewer/new_scene", "Viewer", f"{KNOWN}: thesis 3.3.2, 6.4.3", None),
    "SaveSnapshot": ("/viewer/save_snapshot", "Viewer", "new (past the thesis)",
                     "{name: example.png}"),
    "SetCamera": ("/viewer/set_camera", "Viewer", "new (past the thesis)",
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
    "JointsData": ("/virtual_world/joint_data (also sensor_msgs/JointState on /joint_states)",
                   "VirtualWorld, every cycle", RECON),
    "Object": ("in Build Object and Build Entity", "-",
               f"the odinObject fields {KNOWN} (evidence); inertia, geometry_only {RECON}"),
    "Part": ("in Composite", "-", RECON),
    "Composite": ("in Build Composite and Build Entity", "-", RECON),
    "Joint": ("joint type constants", "-", f"the kinds {KNOWN} (thesis 5.3); numbering {RECON}"),
    "JointParameter": ("in Set Joint", "-",
                       f"the parameters {KNOWN} (thesis 5.3.2, issue 3); encoding {RECON}"),
}

HEADER = """# Odin's ROS interface

Generated by `tools/interface_doc.py` from `Odin/Messages/msg` and `Odin/Services/srv`; do not
edit by hand. Every example below is run against live nodes by `tests/test_interface_doc.py`.

Conventions (REP 103): SI units (m, kg, s, rad, N, N m); the world frame is right-handed with
z up; **quaternions are (w, x, y, z)**, ODE's order, everywhere they cross a node boundary
(`orientation` fields). Kautham's legacy files (mm, degrees) are converted when the GUI loads
them. Every response starts with `bool success` and `string message`; a refused request
(`success: false`) changes nothing. Creation services return the `id` they gave.

"known" marks what the thesis (`shared/spec/000_7f7d4f850af4f9e9.txt`) or the traces in
`shared/spec/interface-evidence.md` state; "reconstructed" marks what Odin had to design
because the original .msg/.srv files are not public.

## Nodes

| node | executable | serves | publishes | calls |
|---|---|---|---|---|
| `/virtual_world` | `rosrun VirtualWorld virtualWorld` | the 15 world services | `~world_update`, `~collided`, `~contacts`, `~joint_data`, `~real_time_factor`, `/joint_states`, `/clock` | the Viewer's services (optional) |
| `/viewer` | `rosrun Viewer viewer` | View Object, Viewer Remove Object, New Scene, Save Snapshot, Set Camera | `~image` (sensor_msgs/Image, rgb8, 25 Hz) | - |
| `/gui` | `rosrun GUI gui` (window), `problem_info`, `load_problem`, `run_path` | - | - | the world's services |

Node parameters are listed in each Portal's docstring (`Odin/*/src/*/portal.py`) and below.

"""


def _block(path: pathlib.Path) -> str:
    return "```\n" + path.read_text().rstrip() + "\n```\n"


def render() -> str:
    parts = [HEADER, "## Services\n"]
    for name, (ros_name, server, provenance, example) in SERVICES.items():
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
    parts.append((ROOT / "docs" / "parameters.md").read_text())
    return "".join(parts)


def examples() -> list:
    """(ros name, type, YAML) of every documented call, in documentation order."""
    return [(ros_name, f"Services/{name}", example)
            for name, (ros_name, _, _, example) in SERVICES.items()]


def main() -> int:
    missing = ({p.stem for p in SRV_DIR.glob("*.srv")} ^ set(SERVICES)) | \
              ({p.stem for p in MSG_DIR.glob("*.msg")} ^ set(MESSAGES))
    if missing:
        print(f"interface_doc: undocumented or stale names: {sorted(missing)}", file=sys.stderr)
        return 1
    DOC.write_text(render())
    print(f"wrote {DOC}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
