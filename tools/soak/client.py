"""One soak client: mixed calls to the world for a while, every answer and latency counted.

Run by tools/soak/run.py (four at once, each its own process and ROS node); writes a JSON
summary to --out. Each client builds and removes its own objects (names prefixed by its
number), joins them with hinges and motors, pushes them with forces, sets velocities, saves
and restores its own snapshots; client 0 also starts a New Scene now and then. Another
client's New Scene or Restore State can take a client's objects away, so a refusal that
names an unknown ID is *expected*; every other refusal, and every failed call, is an error.
"""
from __future__ import annotations

import argparse
import json
import random
import time

import rospy

from gui.errors import ServiceError
from gui.ros.services import ServiceCaller
from Messages.msg import Object
from odin_common.interface import WORLD_NAMESPACE, WORLD_SERVICES

# refusals another client's action (or a Restore State, which brings back joints the client's
# books had dropped) explains: an ID taken away, a snapshot of a scene changed since it was
# taken, a pair joined again
EXPECTED_REFUSALS = ("no object", "no joint", "no motor", "no force", "no snapshot",
                     "no body force", "unknown", "the scene changed since it was taken",
                     "are already joined")
MAX_OWN_OBJECTS = 25


class Client:
    def __init__(self, number: int, seed: int):
        self.number = number
        self.rng = random.Random(seed)
        self.world = ServiceCaller(WORLD_NAMESPACE, WORLD_SERVICES)
        self.latencies: list = []
        self.calls = self.refusals = self.expected_refusals = 0
        self.errors: list = []
        self.objects: list = []
        self.joints: list = []
        self.joined: set = set()           # pairs of objects this client joined
        self.motors: list = []
        self.forces: list = []
        self.snapshots: list = []
        self.serial = 0

    def call(self, service: str, **fields):
        started = time.perf_counter()
        self.calls += 1
        try:
            answer = self.world.ask(service, **fields)
        except (ServiceError, rospy.ROSException) as error:   # broken: the caller reconnects
            self.errors.append(f"{service}: {type(error).__name__}: {error}")
            return None
        finally:
            self.latencies.append(time.perf_counter() - started)
        if not answer.success:
            self.refusals += 1
            if any(text in answer.message for text in EXPECTED_REFUSALS):
                self.expected_refusals += 1
            else:
                self.errors.append(f"{service}: refused: {answer.message}")
            return None
        return answer

    # -- the mix ---------------------------------------------------------------------------
    def build(self):
        if len(self.objects) >= MAX_OWN_OBJECTS:
            return self.remove()
        self.serial += 1
        name = f"c{self.number}_{self.serial}"
        x, y = self.rng.uniform(-2, 2), self.rng.uniform(-2, 2)
        if self.rng.random() < 0.5:
            parameters = [self.rng.uniform(0.05, 0.2)]
        else:
            parameters = [self.rng.uniform(0.05, 0.3) for _ in range(3)]
        if self.call("build_object", object=Object(
                name=name, parameters=parameters, mass=self.rng.uniform(0.1, 5.0),
                position=[x, y, self.rng.uniform(0.3, 2.0)], orientation=[1, 0, 0, 0])):
            self.objects.append(name)

    def remove(self):
        if self.objects:
            name = self.objects.pop(self.rng.randrange(len(self.objects)))
            self.call("remove_object", id=name)

    def join(self):
        if len(self.objects) < 2:
            return self.build()
        a, b = self.rng.sample(self.objects, 2)
        if frozenset((a, b)) in self.joined:
            return self.move()
        self.joined.add(frozenset((a, b)))
        answer = self.call("set_joint", action=0, type=1, body1=a, body2=b,
                           anchor=[0, 0, 1], axis1=[0, 0, 1])
        if answer:
            self.joints.append(answer.id)
            motor = self.call("set_motor", joint=answer.id, max_forces=[5.0])
            if motor:
                self.motors.append(motor.id)

    def push(self):
        if not self.objects:
            return self.build()
        answer = self.call("set_external_force", object=self.rng.choice(self.objects),
                           kind=self.rng.randrange(2),
                           vector=[self.rng.uniform(-20, 20) for _ in range(3)])
        if answer:
            self.forces.append(answer.id)
        if len(self.forces) > 5:
            self.call("set_external_force", remove=True, id=self.forces.pop(0))

    def move(self):
        if self.motors and self.rng.random() < 0.5:
            self.call("set_velocity", motors=[self.rng.choice(self.motors)],
                      velocities=[self.rng.uniform(-3, 3)])
        elif self.objects:
            self.call("set_velocity", object=self.rng.choice(self.objects), set_linear=True,
                      linear=[self.rng.uniform(-1, 1) for _ in range(3)])

    def snapshot(self):
        if self.snapshots and self.rng.random() < 0.5:
            self.call("restore_state", name=self.rng.choice(self.snapshots))
        else:
            name = f"c{self.number}_s{len(self.snapshots) % 3}"
            if self.call("save_state", name=name) and name not in self.snapshots:
                self.snapshots.append(name)

    def read(self):
        self.call("get_world")

    def new_scene(self):
        if self.call("new_scene"):
            self.objects.clear()
            self.joints.clear()
            self.motors.clear()
            self.forces.clear()
            self.snapshots.clear()

    MIX = (("build", 5), ("remove", 2), ("join", 2), ("push", 3), ("move", 3),
           ("snapshot", 1), ("read", 3))

    def run(self, duration: float, new_scene_period: float) -> None:
        names, weights = zip(*self.MIX)
        end = time.monotonic() + duration
        next_new_scene = time.monotonic() + new_scene_period
        while time.monotonic() < end and not rospy.is_shutdown():
            if self.number == 0 and time.monotonic() > next_new_scene:
                self.new_scene()
                next_new_scene += new_scene_period
            getattr(self, self.rng.choices(names, weights)[0])()
            time.sleep(self.rng.uniform(0.0, 0.02))

    def summary(self) -> dict:
        return dict(calls=self.calls, refusals=self.refusals,
                    expected_refusals=self.expected_refusals, errors=len(self.errors),
                    error_examples=self.errors[:10], latencies_s=self.latencies)


def main() -> int:
    parser = argparse.ArgumentParser(description="one soak client (tools/soak/run.py)")
    parser.add_argument("--number", type=int, required=True)
    parser.add_argument("--duration", type=float, required=True, help="s")
    parser.add_argument("--new-scene-period", type=float, default=30.0, help="s (client 0)")
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    rospy.init_node(f"soak_client_{args.number}", disable_signals=True)
    client = Client(args.number, seed=1000 + args.number)
    client.world.wait("get_world", 60, "no world answering after 60 s")
    client.run(args.duration, args.new_scene_period)
    with open(args.out, "w") as f:
        json.dump(client.summary(), f)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
