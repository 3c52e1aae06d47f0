"""setup.bash keeps ROS on the loopback address unless the user names one (docs/SECURITY.md):
rospy and the master then bind their ports to 127.0.0.1 only."""
from __future__ import annotations

import pathlib
import subprocess

ROOT = pathlib.Path(__file__).resolve().parents[2]
PROBE = ("source setup.bash >/dev/null && python -c 'import os, rosgraph.network as n; "
         "print(os.environ.get(\"ROS_IP\", \"\"), os.environ[\"ROS_MASTER_URI\"], "
         "n.get_bind_address())'")


def sourced(**env) -> list:
    """ROS_IP, ROS_MASTER_URI and rosgraph's bind address after sourcing setup.bash in a
    shell that has only ``env`` (and PATH, HOME)."""
    base = {"PATH": "/usr/bin:/bin", "HOME": "/root"}
    out = subprocess.run(["bash", "-c", PROBE], cwd=ROOT, env={**base, **env}, check=True,
                         capture_output=True, text=True, timeout=120).stdout.split()
    return out if len(out) == 3 else [""] + out


def test_ros_stays_on_loopback_unless_the_user_names_an_address():
    ip, master, bind = sourced()
    assert ip == "127.0.0.1" and bind == "127.0.0.1"
    assert master.split("//")[1].split(":")[0] in ("127.0.0.1", "localhost")
    ip, master, bind = sourced(ROS_IP="10.1.2.3", ROS_MASTER_URI="http://10.1.2.1:11311")
    assert (ip, master, bind) == ("10.1.2.3", "http://10.1.2.1:11311", "0.0.0.0")
    ip, _, bind = sourced(ROS_HOSTNAME="robot-7")
    assert ip == "" and bind == "0.0.0.0"
