"""A run driven through the GUI's client, recorded by the world node (~record), replays
exactly: `rosrun VirtualWorld replay BAG` re-runs it in a fresh world and finds every pose bit
for bit; a recording that no longer fits is reported with where it departs."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

pytestmark = pytest.mark.forked


def _drive(client) -> None:
    """A session as a user would drive it: a scene, a joint with a motor, forces, a snapshot,
    steps, a kept propagation, a restore, more steps."""
    from odin_common.interface import ForceKind, JointType
    from odin_common.specs import EntitySpec, JointSpec, MotorSpec, ObjectSpec
    client.new_scene()
    client.set_world(erp=0.3, bounce=0.3)
    client.build_object(ObjectSpec("ground", (4, 4, 0.2), position=(0, 0, -0.1),
                                   geometry_only=True))
    client.build_entity(EntitySpec("pile", [ObjectSpec(f"s{i}", (0.1,), position=(
        0.03 * i, 0, 0.3 + 0.21 * i)) for i in range(6)]))
    client.build_object(ObjectSpec("bob", (0.1,), position=(2, 0, 1)))
    joint = client.add_joint(JointSpec(JointType.HINGE, "bob", "", anchor=(2, 0, 1.5),
                                       axis1=(0, 1, 0)))
    motor = client.add_motor(MotorSpec(joint, max_forces=(3.0,)))
    client.set_velocities([motor], [1.0])
    client.add_body_force("s5", ForceKind.FORCE, (0.5, 0, 0))
    client.step_once(5)
    client.save_state("mid")
    client.set_position([("s0", (0.5, 0.5, 1.0), (1, 0, 0, 0))])
    client.step_once(3)
    client.propagate(0.3, keep=True)
    client.restore_state("mid")
    client.step_once(4)


def test_a_recorded_session_replays_bit_for_bit(ros_master, tmp_path):
    recording = tmp_path / "session.bag"
    node = ros_master.rosrun("VirtualWorld", "virtualWorld", f"_record:={recording}",
                             "_solver:=1")
    ros_master.wait_for_service("/virtual_world/build_entity")
    from gui.ros.client import WorldClient
    client = WorldClient()
    _drive(client)
    client.close()
    ros_master.stop()                       # the node closes its recording on the way out
    assert node.returncode is not None and recording.stat().st_size > 0
    result = ros_master.run(["rosrun", "VirtualWorld", "replay", str(recording)], check=False)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "identical" in result.stdout and "12 advances" in result.stdout


def _replay(path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", "import sys; from virtual_world.portal."
                           f"replay import main; sys.exit(main([{str(path)!r}]))"],
                          capture_output=True, text=True, timeout=60)


def test_a_recording_that_no_longer_fits_says_where_it_departs(tmp_path):
    from Services.srv import BuildObjectRequest
    from odin_common.step_values import StepValues
    from odin_common.world_parameters import WorldParameters
    from virtual_world.portal.recorder import Recorder
    from world_client import sphere
    forged = tmp_path / "forged.bag"   # a ball that "fell" 10 mm in 10 ms
    recorder = Recorder(str(forged), WorldParameters(), StepValues())
    recorder.request("build_object", BuildObjectRequest(object=sphere("ball", 0.1, (0, 0, 1))))
    recorder.advance(0.001, 10, 0.01, ["ball"], [np.array([0.0, 0.0, 0.99])],
                     [np.array([1.0, 0.0, 0.0, 0.0])])
    recorder.close()
    result = _replay(forged)
    assert result.returncode == 1
    assert "entry 2" in result.stderr and "ball is at" in result.stderr
    garbage = tmp_path / "garbage.bag"
    garbage.write_bytes(b"not a bag")
    result = _replay(garbage)
    assert result.returncode == 2 and len(result.stderr.strip().splitlines()) == 1
