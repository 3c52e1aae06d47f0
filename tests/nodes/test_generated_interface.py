"""The generated interface: every service and message is there, in Python and in C++."""
import os
import pathlib
import subprocess

ROOT = pathlib.Path(__file__).resolve().parents[2]
DEVEL = ROOT / "build" / "ws" / "devel"

GUI_TO_WORLD = ["NewScene", "SetWorld", "SetStep", "StepOnce", "Start", "BuildObject",
                "BuildComposite", "BuildEntity", "RemoveObject", "SetJoint", "SetMotor",
                "SetPosition", "SetVelocity", "SetExternalForce", "SetJointForce"]
WORLD_TO_VIEWER = ["ViewObject", "ViewerRemoveObject", "ViewerNewScene"]
MESSAGES = ["Situation", "SpaceDistribution", "Collided", "CollisionPair", "JointData",
            "JointsData", "Object", "Part", "Composite", "Joint", "JointParameter"]


def _lines(command):
    return subprocess.run(command, capture_output=True, text=True, check=True).stdout.split()


def test_rossrv_lists_the_thesis_services():
    listed = set(_lines(["rossrv", "list"]))
    for name in GUI_TO_WORLD + WORLD_TO_VIEWER:
        assert f"Services/{name}" in listed


def test_rosmsg_lists_the_messages():
    listed = set(_lines(["rosmsg", "list"]))
    for name in MESSAGES:
        assert f"Messages/{name}" in listed


def test_every_response_says_success_and_message():
    from Services import srv
    for name in GUI_TO_WORLD + WORLD_TO_VIEWER + ["SaveSnapshot", "SetCamera"]:
        slots = getattr(srv, name)._response_class.__slots__
        assert slots[:2] == ["success", "message"], name


def test_creation_services_return_the_id_they_gave():
    from Services import srv
    for name in ["BuildObject", "BuildComposite", "BuildEntity", "SetJoint", "SetMotor",
                 "SetExternalForce", "SetJointForce"]:
        assert "id" in getattr(srv, name)._response_class.__slots__, name


def test_cpp_headers_compile(tmp_path):
    headers = sorted((DEVEL / "include").glob("*/*.h"))
    assert len(headers) >= len(MESSAGES) + 3 * len(GUI_TO_WORLD + WORLD_TO_VIEWER)
    source = tmp_path / "all_headers.cpp"
    source.write_text("".join(f'#include <{h.parent.name}/{h.name}>\n' for h in headers)
                      + "int main() { Services::BuildObject srv; Messages::SpaceDistribution m;\n"
                        "  return (int)srv.request.object.parameters.size()"
                        " + (int)m.situations.size(); }\n")
    subprocess.run(["g++", "-std=c++17", "-I", str(DEVEL / "include"), "-c", str(source),
                    "-o", str(tmp_path / "all_headers.o")], check=True)


def test_catkin_lint_is_clean():
    result = subprocess.run(["catkin_lint", "--strict", "-W2", str(ROOT / "Odin")],
                            capture_output=True, text=True, env=dict(os.environ))
    assert result.returncode == 0, result.stdout + result.stderr
    assert "found 0 problems" in result.stdout + result.stderr
