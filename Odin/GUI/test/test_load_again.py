"""Loading the TX90 + hand problem again into the same world builds the same world, bit for
bit: the second load goes through the world's caches (core.arrays' converted tuples, the
checked meshes of core.objects, the mesh markers, the trimesh data and mass properties), the
first one did not. Every request goes as bytes through the real client (WorldClient.execute,
its packed Build Entity) into the world's services (WorldServices over a Core, answered as the
Portal answers them), without ROS."""
from __future__ import annotations

import io
import os
import struct

import numpy as np
import pytest

from gui.ros.client import WorldClient
from gui_core_world import quiet_plan
from odin_common import replies
from odin_common.interface import WORLD_SERVICES
from odin_common.step_values import StepValues
from Services import srv
from visualization_msgs.msg import Marker
from virtual_world.core import Core
from virtual_world.portal.mirror import WorldMirror
from virtual_world.portal.services import WorldServices

PROBLEM = os.path.join(os.environ.get("ODIN_KAUTHAM_DIR", "/work/shared/kautham"),
                       "legacy_2012", "examples", "TX90_RHand_ICRA10_5PMD_TwoCan.xml")


class _Loop:
    """The loop's values the world's services read (a paused world)."""

    def __init__(self):
        self.step_values = StepValues()
        self.simulate = False
        self.sim_time = 0.0


class _Viewer:
    """Keeps the bytes of every View Object request the world sends."""

    def __init__(self):
        self.sent = []

    def view(self, requests) -> None:
        self.sent.extend(_bytes(r) for r in requests)

    def remove(self, ids) -> None:
        pass

    def new_scene(self) -> None:
        self.sent.clear()


class _BytesCaller:
    """A ServiceCaller whose requests travel as bytes into WorldServices' handlers."""

    def __init__(self, services: WorldServices):
        self.services = services

    def _answer(self, name, request):
        service_class = getattr(srv, WORLD_SERVICES[name])
        received = service_class._request_class()
        received.deserialize(_bytes(request))
        answer = replies.guarded(service_class, getattr(self.services, name))(received)
        if not answer.success:
            raise AssertionError(f"{name} refused: {answer.message}")
        return answer

    def call(self, name, /, **fields):
        return self._answer(name, getattr(srv, WORLD_SERVICES[name])._request_class(**fields))

    def send(self, name, request):
        return self._answer(name, request)


def _bytes(message) -> bytes:
    buffer = io.BytesIO()
    message.serialize(buffer)
    return buffer.getvalue()


def _world():
    core = Core()
    services = WorldServices(core, _Loop(), _Viewer(), WorldMirror())
    client = WorldClient.__new__(WorldClient)     # no ROS graph: requests go as bytes
    client._caller = _BytesCaller(services)
    client.namespace = "/virtual_world"
    return core, services, client


def _state(core: Core, services: WorldServices) -> dict:
    """Everything the world holds that a load sets, as bytes or plain values."""
    names, positions, quaternions = core.poses()
    objects = sorted(core._scene.objects)
    return {
        "geometries": (tuple(names), positions.tobytes(), quaternions.tobytes()),
        "objects": objects,
        "entities": {k: list(v) for k, v in core._scene.entities.items()},
        "mass": [tuple(np.asarray(v).tobytes() for v in core.mass_properties(o))
                 for o in objects if core._scene.objects[o].body is not None],
        "joints": [(s.id, s.type, tuple(s.positions), tuple(s.rates))
                   for s in core.joint_states()],
        "servos": [tuple(map(tuple, (s.targets, s.positions, s.errors)))
                   for s in core.servo_states()],
        "state": core.body_state_vector().tobytes(),
        "viewer": list(services.viewer.sent),
        "markers": _markers(services.mirror),
        "robots": [(r.name, tuple(link.object_id for link in r.links))
                   for r in services.mirror.robots],
    }


def _markers(mirror: WorldMirror) -> list:
    """Each geometry's marker as serialised, its marker ID left out (IDs keep counting
    across New Scene)."""
    kept = []
    for name, marker in mirror.markers._markers.items():
        numbered = struct.pack("<iii", marker.id, marker.shape.type, Marker.ADD)
        unnumbered = struct.pack("<iii", 0, marker.shape.type, Marker.ADD)
        kept.append((name, marker.serialised().replace(numbered, unnumbered, 1)))
    return kept


@pytest.mark.skipif(not os.path.exists(PROBLEM), reason="the Kautham corpus is not here")
def test_a_problem_loaded_again_builds_the_same_world_bit_for_bit(tmp_path):
    plan = quiet_plan(PROBLEM)
    core, services, client = _world()
    built, after = [], []
    for _ in range(2):
        client.new_scene()
        ids = client.execute(plan, mesh_dir=str(tmp_path))
        built.append((ids, _state(core, services)))
        core.step(0.001, 200)            # the same dynamics from the same build
        after.append(core.body_state_vector().tobytes())
    (ids_cold, cold), (ids_warm, warm) = built
    assert ids_warm == ids_cold
    assert warm.keys() == cold.keys()
    for key in cold:
        assert warm[key] == cold[key], key
    assert after[1] == after[0]
    assert len(cold["viewer"]) == len(cold["geometries"][0])
