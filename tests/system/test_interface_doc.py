"""docs/INTERFACE.md and docs/parameters.md are what the code generates, and every
`rosservice call` example in the interface document works as written."""
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))

import interface_doc  # noqa: E402


def test_interface_and_parameter_docs_are_what_the_code_generates():
    """Compares only: a test never rewrites a document in the working tree."""
    assert interface_doc.stale() == [], "run python tools/interface_doc.py"


@pytest.mark.slow
def test_every_documented_example_succeeds_against_live_nodes(ros_master):
    ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.rosrun("Viewer", "viewer", f"_snapshot_dir:={ros_master.ros_home}")
    ros_master.wait_for_service("/virtual_world/set_joint_force")
    ros_master.wait_for_service("/viewer/set_camera")
    for ros_name, service_type, example in interface_doc.examples():
        arguments = ["rosservice", "call", ros_name] + ([example] if example else [])
        result = ros_master.run(arguments, check=False)
        assert result.returncode == 0, (ros_name, result.stdout, result.stderr)
        assert "success: True" in result.stdout, (ros_name, example, result.stdout)
