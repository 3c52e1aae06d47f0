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


@pytest.mark.forked
def test_every_documented_example_succeeds_against_live_nodes(ros_master):
    """Each example is read as ``rosservice call NAME 'YAML'`` reads it (rosservice's own
    parsing: yaml.safe_load, then genpy's fill_message_args) and called; the first also through
    the command itself, word for word (a process per example cost a second of CPU each)."""
    import rosservice
    import yaml
    ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.rosrun("Viewer", "viewer", f"_snapshot_dir:={ros_master.ros_home}")
    ros_master.wait_for_service("/virtual_world/set_joint_force")
    ros_master.wait_for_service("/viewer/set_camera")
    examples = list(interface_doc.examples())
    ros_name, _, example = examples[0]
    result = ros_master.run(["rosservice", "call", ros_name] + ([example] if example else []),
                            check=False)
    assert result.returncode == 0 and "success: True" in result.stdout, (ros_name, result)
    for ros_name, service_type, example in examples:
        arguments = [yaml.safe_load(example)] if example else []
        _, answer = rosservice.call_service(ros_name, arguments)
        assert answer.success, (ros_name, example, answer)
