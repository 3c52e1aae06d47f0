"""Odin across machines (docs/ROS.md: several machines): the master, the world, the Viewer and
a GUI client each on a test host of its own (a Linux network namespace with its own address on
a private bridge, made here as root; CI runs as root), talking over that network only. The
demo's chain runs across them: the client builds a scene in the world, the world sends it to
the Viewer, the client steps it and sees the sphere fall on world_update and the Viewer's image
change.

Every host is a network namespace with only its loopback and one veth on the bridge, so a node
that advertised 127.0.0.1 or a host name would be unreachable: this is what ROS_IP is for."""
from __future__ import annotations

import json
import os
import pathlib
import shutil
import subprocess
import sys
import time

import pytest

SUBNET = "10.19.0"
HOSTS = {"master": 1, "world": 2, "viewer": 3, "gui": 4}
PORT = 11311

pytestmark = pytest.mark.skipif(
    os.geteuid() != 0 or shutil.which("ip") is None,
    reason="needs root and iproute2 to make network namespaces (CI runs as root)")

CLIENT = r"""
import json, sys, time
import numpy as np
import rospy
from Messages.msg import SpaceDistribution
from sensor_msgs.msg import Image
from gui.ros.client import WorldClient
from odin_common.specs import ObjectSpec

client = WorldClient(timeout=60)
before = rospy.wait_for_message("/viewer/image", Image, timeout=60)
client.new_scene()
client.build_object(ObjectSpec("ground", (4.0, 4.0, 0.1), position=(0, 0, -0.05),
                               color=(0.55, 0.6, 0.55, 1), geometry_only=True))
client.build_object(ObjectSpec("sphere", (0.3,), position=(0, 0, 2.0),
                               color=(0.9, 0.25, 0.2, 1)))
heights = []
for _ in range(15):
    client.step_once(1)
    update = rospy.wait_for_message("/virtual_world/world_update", SpaceDistribution, timeout=10)
    heights += [s.position[2] for s in update.situations if s.name == "sphere"]
time.sleep(1.0)
after = rospy.wait_for_message("/viewer/image", Image, timeout=30)
changed = np.mean(np.frombuffer(before.data, np.uint8) != np.frombuffer(after.data, np.uint8))
print(json.dumps({"heights": heights, "image_changed": float(changed),
                  "world_host": rospy.get_master().lookupNode("/virtual_world")[2]}))
client.close()
"""


class HostNetwork:
    """Namespaces ``<prefix>_<host>`` joined by a bridge in ``<prefix>_lan``."""

    def __init__(self, prefix: str):
        self.prefix = prefix
        self.made = []
        lan = self.namespace("lan")
        self._ip("netns", "add", lan)
        self.made.append(lan)
        self._ip("-n", lan, "link", "add", "br0", "type", "bridge")
        self._ip("-n", lan, "link", "set", "br0", "up")
        for host, number in HOSTS.items():
            ns = self.namespace(host)
            self._ip("netns", "add", ns)
            self.made.append(ns)
            port = f"v{number}"
            self._ip("-n", lan, "link", "add", port, "type", "veth", "peer", "name", "eth0",
                     "netns", ns)
            self._ip("-n", lan, "link", "set", port, "master", "br0", "up")
            self._ip("-n", ns, "addr", "add", f"{self.address(host)}/24", "dev", "eth0")
            self._ip("-n", ns, "link", "set", "eth0", "up")
            self._ip("-n", ns, "link", "set", "lo", "up")

    def namespace(self, host: str) -> str:
        return f"{self.prefix}_{host}"

    @staticmethod
    def address(host: str) -> str:
        return f"{SUBNET}.{HOSTS[host]}"

    @staticmethod
    def _ip(*args: str) -> None:
        subprocess.run(["ip", *args], check=True, capture_output=True, timeout=30)

    def command(self, host: str, args) -> list:
        return ["ip", "netns", "exec", self.namespace(host), *args]

    def close(self) -> None:
        for ns in reversed(self.made):
            subprocess.run(["ip", "netns", "del", ns], capture_output=True, timeout=30)


def _env(host: str, ros_home: pathlib.Path) -> dict:
    env = dict(os.environ)
    env.update(ROS_MASTER_URI=f"http://{HostNetwork.address('master')}:{PORT}",
               ROS_IP=HostNetwork.address(host), ROS_HOME=str(ros_home / host),
               ROS_LOG_DIR=str(ros_home / host / "log"))
    env.pop("ROS_HOSTNAME", None)
    return env


def test_the_demo_chain_runs_with_master_world_viewer_and_gui_on_four_hosts(tmp_path):
    network = HostNetwork(f"odin{os.getpid()}")
    processes = []
    logs = tmp_path / "logs"
    logs.mkdir()

    def start(host: str, args) -> subprocess.Popen:
        log = open(logs / f"{host}.out", "wb")
        process = subprocess.Popen(network.command(host, args), env=_env(host, tmp_path),
                                   stdout=log, stderr=subprocess.STDOUT,
                                   stdin=subprocess.DEVNULL, start_new_session=True)
        processes.append((process, log))
        return process

    def logs_text() -> str:
        return "\n".join(f"--- {p.name}\n{p.read_text(errors='replace')[-1500:]}"
                         for p in sorted(logs.iterdir()))

    try:
        start("master", ["roscore", "-p", str(PORT)])
        start("world", ["rosrun", "VirtualWorld", "virtualWorld"])
        start("viewer", ["rosrun", "Viewer", "viewer", "_eye:=[3.2, -3.2, 1.8]",
                         "_target:=[0, 0, 1.0]"])
        result = subprocess.run(network.command("gui", [sys.executable, "-c", CLIENT]),
                                env=_env("gui", tmp_path), capture_output=True, text=True,
                                timeout=180)
        assert result.returncode == 0, result.stderr[-3000:] + logs_text()
        report = json.loads(result.stdout.strip().splitlines()[-1])
        heights = report["heights"]
        assert heights[0] - heights[-1] > 0.1, heights          # the sphere fell
        assert report["image_changed"] > 0.01, report           # the Viewer drew the scene
        # the world was reached at its own host's address
        assert report["world_host"].startswith(f"http://{HostNetwork.address('world')}:")
    finally:
        for process, log in reversed(processes):
            try:
                os.killpg(process.pid, 2)
                process.wait(timeout=20)
            except (ProcessLookupError, subprocess.TimeoutExpired):
                try:
                    os.killpg(process.pid, 9)
                except ProcessLookupError:
                    pass
                process.wait()
            log.close()
        network.close()


def test_the_network_is_the_only_way_between_hosts(tmp_path):
    """The test hosts are separate: a host reaches another by its address on the bridge, not
    by its own loopback (what makes the test above mean something)."""
    network = HostNetwork(f"odinp{os.getpid()}")
    try:
        listen = subprocess.Popen(network.command("master", [
            sys.executable, "-c", "import socket; s = socket.socket(); "
            "s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1); "
            f"s.bind(('0.0.0.0', {PORT})); s.listen(); s.accept(); print('ok')"]),
            stdout=subprocess.PIPE, text=True)
        time.sleep(1.0)
        probe = ("import socket, sys; s = socket.socket(); s.settimeout(3); "
                 "sys.exit(s.connect_ex((sys.argv[1], %d)))" % PORT)
        local = subprocess.run(network.command("gui", [sys.executable, "-c", probe,
                                                       "127.0.0.1"]), timeout=30)
        across = subprocess.run(network.command("gui", [sys.executable, "-c", probe,
                                                        HostNetwork.address("master")]),
                                timeout=30)
        assert local.returncode != 0 and across.returncode == 0
        assert listen.communicate(timeout=10)[0].strip() == "ok"
    finally:
        network.close()
