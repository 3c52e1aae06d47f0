"""The GUI window driven as a user would, off-screen, against the real VirtualWorld node.

Each test has its own roscore and world (ros_master fixture) and runs in a forked process
(rospy.init_node and QApplication once per process). Screenshots of each tab go to out/gui/.
"""
from __future__ import annotations

import math
import os
import pathlib

import pytest

pytestmark = pytest.mark.forked

ROOT = pathlib.Path(__file__).resolve().parents[2]
SHOTS = ROOT / "out" / "gui"


@pytest.fixture
def window(ros_master):
    """A running world (paused) and the window connected to it."""
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    node = ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/set_joint_force")
    from gui.window.testing import open_window, wait_for
    win = open_window()
    wait_for(lambda: win.connected and win.updates > 0, 15, "the window to connect")
    yield win
    win.shutdown()
    assert node.poll() is None, "virtualWorld died:\n" + ros_master.log_text(node)[-3000:]


def _world():
    from world_client import WorldClient
    return WorldClient()


def test_simulation_tab_opens_a_problem_simulates_and_clears(window, kautham_dir, monkeypatch):
    from PyQt5.QtWidgets import QFileDialog
    from gui.window.testing import click, screenshot, wait_for
    tab = window.simulation
    problem = kautham_dir / "legacy_2012/examples/Kuka_two_columns.xml"
    monkeypatch.setattr(QFileDialog, "getOpenFileName",
                        staticmethod(lambda *a, **k: (str(problem), "")))
    click(tab.open_button)
    wait_for(lambda: not tab.building, 30, "the problem to be built")
    assert window.last_error == ""
    # 8 links (the base a fixed body) + 7 hinges + 7 motors + the columns
    assert tab.element_count() == 8 + 7 + 7 + 1
    labels = [tab.tree.topLevelItem(i).text(0) for i in range(tab.tree.topLevelItemCount())]
    assert labels == ["KukaLWR (robot)", "Scene objects"]
    wait_for(lambda: "KukaLWR/Link7" in window.scene.objects
             and any(o.startswith(">columns#0") for o in window.scene.objects), 5,
             "links and columns in world_update")
    wait_for(lambda: len(window.scene.joints) == 7, 5, "joints from joint_data")
    assert len(window.scene.motors) == 7
    assert "KukaLWR" in window.scene.robots
    screenshot(window, SHOTS / "simulation.png")

    click(tab.simulate_button)
    wait_for(lambda: tab.simulating, 5, "running")
    assert "running" in tab.simulate_button.text()
    # the button follows the world's real state: pause it from another client
    world = _world()
    assert world.ok("start", simulate=False).simulating is False
    wait_for(lambda: not tab.simulating, 5, "the window to see the pause")
    assert tab.simulate_button.text() == "Simulate!"
    world.ok("start", simulate=True)
    wait_for(lambda: tab.simulating, 5, "the window to see the start")
    screenshot(window, SHOTS / "simulation_running.png")
    click(tab.simulate_button)
    wait_for(lambda: not tab.simulating, 5, "paused by the button")
    assert world("start", simulate=False).simulating is False

    click(tab.new_scene_button)
    wait_for(lambda: tab.tree.topLevelItemCount() == 0 and not window.scene.objects, 5,
             "an empty scene")
    assert world.poses() == {}
    assert not window.scene.robots and not window.scene.motors

    # a broken problem file: refused with file and line, nothing crashes
    bad = problem.parent / "does_not_exist.xml"
    tab.open_problem(str(bad))
    wait_for(lambda: not tab.building, 10, "the failure")
    assert "does_not_exist.xml" in window.last_error


def test_settings_tab_step_values_and_world_parameters(window):
    from gui.window.testing import click, screenshot, type_into, wait_for
    tab = window.settings
    window.tabs.setCurrentWidget(tab)
    wait_for(lambda: tab.in_force_labels["rate"].text() != "?", 5,
             "values in force: " + window.last_error)
    assert tab.in_force["steps_per_cycle"] == 40
    # only the step is given: the world keeps the cycle time and recomputes steps per cycle
    check, box = tab.step_fields["step"]
    type_into(box, "0.002")
    assert check.isChecked()
    click(tab.set_step_button)
    wait_for(lambda: tab.in_force.get("step") == pytest.approx(0.002), 5, "step in force")
    assert tab.in_force["steps_per_cycle"] * tab.in_force["step"] == pytest.approx(
        tab.in_force["cycle_time"])
    assert tab.in_force_labels["step"].text() == "0.002"
    assert not check.isChecked()

    # world parameters: gravity, ERP = 0 (zero is valid), friction, collision policy, solver,
    # auto-disable
    tab.toolbox.setCurrentIndex(1)
    type_into(tab.gravity.boxes[2], "-1.62")
    type_into(tab.world_boxes["erp"], "0")
    tab.world_checks["erp"].setChecked(True)      # zero: the check box says "send it"
    type_into(tab.world_boxes["friction"], "0.5")
    tab.highlight_radio.setChecked(True)
    tab.solver.setCurrentIndex(1)
    assert tab.in_force_labels["auto_disable"].text() == "off"
    tab.sleep.setChecked(True)
    assert tab.sleep_check.isChecked()
    click(tab.set_world_button)
    wait_for(lambda: tab.in_force.get("gravity") is not None
             and tab.in_force["gravity"][2] == pytest.approx(-1.62), 5, "gravity in force")
    assert tab.in_force["erp"] == 0.0
    assert tab.in_force["friction"] == pytest.approx(0.5)
    assert tab.in_force["contact_less"] is True and tab.in_force["solver"] == 1
    assert tab.in_force["auto_disable"] is True
    assert tab.in_force_labels["auto_disable"].text() == "on"
    response = _world().ok("set_world", set_erp=True, erp=0.0)   # answers all values in force
    assert response.gravity[2] == pytest.approx(-1.62) and response.erp == 0.0
    assert response.auto_disable is True
    # hard limits: ERP cannot go past 1, whatever is typed
    type_into(tab.world_boxes["erp"], "7")
    assert tab.world_boxes["erp"].value() <= 1.0
    tab.toolbox.setCurrentIndex(0)
    screenshot(window, SHOTS / "settings.png")
    tab.toolbox.setCurrentIndex(1)
    screenshot(window, SHOTS / "settings_gravity.png")


def test_objects_tab_create_list_move_remove(window, tmp_path):
    import trimesh
    from gui.window.testing import click, screenshot, type_into, wait_for
    window.tabs.setCurrentWidget(window.objects)
    tab = window.objects
    world = _world()

    # a sphere from its preset
    type_into(tab.name, "ball")
    tab.shape.setCurrentIndex(0)
    tab.preset.setCurrentIndex(2)
    tab.preset.activated.emit(2)
    assert tab.radius.value() == pytest.approx(0.5)
    type_into(tab.mass, "-3")                        # hard limit: mass stays positive
    assert tab.mass.value() > 0
    tab.position.set_values((0, 0, 2))
    click(tab.create_button)
    wait_for(lambda: "ball" in window.scene.objects, 5, "ball in the world")
    assert world.poses()["ball"][0] == pytest.approx((0, 0, 2))
    assert tab.name.text() == ""

    # a box, fixed, turned 90 degrees about z
    type_into(tab.name, "crate")
    tab.shape.setCurrentIndex(2)
    assert tab.stack.currentIndex() == 2
    tab.box_sides.set_values((0.4, 0.3, 0.2))
    tab.fixed.setChecked(True)
    tab.position.set_values((1, 0, 0.5))
    tab.orientation.set_values((1, 0, 0, 1))         # normalised before sending
    click(tab.create_button)
    wait_for(lambda: "crate" in window.scene.objects, 5, "crate")
    q = world.poses()["crate"][1]
    assert q == pytest.approx((math.sqrt(0.5), 0, 0, math.sqrt(0.5)), abs=1e-6)

    # a mesh from an STL file (trimesh), then a cylinder
    stl = tmp_path / "cone.stl"
    trimesh.creation.cone(0.1, 0.3).export(stl)
    type_into(tab.name, "cone")
    tab.shape.setCurrentIndex(3)
    tab.mesh_path.setText(str(stl))
    tab.position.set_values((-1, 0, 1))
    tab.orientation.set_values((1, 0, 0, 0))
    tab.fixed.setChecked(False)
    click(tab.create_button)
    wait_for(lambda: "cone" in window.scene.objects, 10, "the STL cone")
    type_into(tab.name, "can")
    tab.shape.setCurrentIndex(1)
    click(tab.create_button)
    wait_for(lambda: "can" in window.scene.objects, 5, "can")
    assert [tab.list.item(i).text() for i in range(tab.list.count())] == \
        ["ball", "can", "cone", "crate"]

    # refusals: a used name, a zero quaternion (both caught here), a bad mesh path
    errors = len(window.errors)
    type_into(tab.name, "ball")
    click(tab.create_button)
    assert "already used" in window.last_error
    type_into(tab.name, "zero")
    tab.orientation.set_values((0, 0, 0, 0))
    click(tab.create_button)
    assert "quaternion" in window.last_error
    tab.orientation.set_values((1, 0, 0, 0))
    type_into(tab.name, "a>b")                       # '>' is refused by the validator
    assert ">" not in tab.name.text()
    assert len(window.errors) == errors + 2

    # set position only: keeps the orientation the world reports
    tab.list.setCurrentRow(3)                        # crate
    tab.set_orientation_check.setChecked(False)
    tab.position.set_values((2, 2, 0.5))
    click(tab.set_button)
    wait_for(lambda: window.scene.pose_of("crate")[0] == pytest.approx((2, 2, 0.5)), 5,
             "crate moved")
    assert window.scene.pose_of("crate")[1] == pytest.approx(q, abs=1e-6)
    screenshot(window, SHOTS / "objects.png")

    tab.list.setCurrentRow(0)                        # ball
    click(tab.remove_button)
    wait_for(lambda: "ball" not in window.scene.objects, 5, "ball removed")
    assert "ball" not in world.poses()
    # a refusal from the world is shown with its message
    world.ok("remove_object", id="can")
    tab.list.setCurrentRow(0)
    wait_for(lambda: "can" not in window.scene.objects, 5, "can gone")
    window.call("Remove Object", lambda client, job: client.call("remove_object", id="can"))
    wait_for(lambda: "remove_object" in window.last_error, 5, "the world's refusal")
    assert "can" in window.last_error


def test_joints_tab_rows_create_parameters_remove(window):
    from gui.window.testing import click, screenshot, type_into, wait_for
    window.tabs.setCurrentWidget(window.joints)
    tab = window.joints
    world = _world()
    from world_client import box, sphere
    world.ok("build_object", object=box("door", (0.1, 1.0, 2.0), (0, 0.5, 1.0)))
    world.ok("build_object", object=sphere("bob", 0.1, (1, 0, 1)))
    wait_for(lambda: tab.body1.count() == 3, 5, "objects in the body choosers")

    rows = {}
    for index in range(tab.type.count()):
        tab.type.setCurrentIndex(index)
        rows[tab.type.currentText().split()[0]] = tab.enabled_rows()
    assert rows["Hinge"] == ["anchor", "axis1"]
    assert rows["Slider"] == ["axis1"]
    assert rows["Universal"] == ["anchor", "axis1", "axis2"]
    assert rows["PU"] == ["anchor", "axis1", "axis2", "axis3"]
    assert rows["Fixed"] == [] and rows["Ball"] == ["anchor"]

    # a hinge between the door and the static environment, with stops
    tab.type.setCurrentIndex(1)
    tab.body1.setCurrentText("door")
    tab.body2.setCurrentText("Static environment")
    tab.anchor.set_values((0, 0, 1))
    tab.axes[0].set_values((0, 0, 1))
    type_into(tab.param_fields[0][1], "-0.5")
    type_into(tab.param_fields[1][1], "0.5")
    click(tab.create_button)
    wait_for(lambda: tab.list.count() == 1, 5, "the hinge in the list")
    hinge = tab.list.item(0).text()
    assert hinge == "1:door&"
    assert not tab.param_fields[0][0].isChecked()

    # the same pair again: the world refuses (one joint per pair) and the window says why
    click(tab.create_button)
    wait_for(lambda: "set_joint" in window.last_error, 5, "the refusal")
    # a ball joint between bob and the door
    tab.type.setCurrentIndex(0)
    tab.body1.setCurrentText("bob")
    tab.body2.setCurrentText("door")
    click(tab.create_button)
    wait_for(lambda: tab.list.count() == 2, 5, "the ball joint")

    # parameters on the existing hinge, then a motor on it
    tab.list.setCurrentRow([tab.list.item(i).text() for i in range(2)].index(hinge))
    type_into(tab.param_fields[4][1], "0.8")
    click(tab.set_button)
    wait_for(lambda: "Parameters of" in window.last_info, 5, "parameters set")
    click(tab.motor_button)
    wait_for(lambda: "motor:" + hinge in window.scene.motors, 5, "motor",
             lambda: window.last_error)
    screenshot(window, SHOTS / "joints.png")

    tab.list.setCurrentRow([tab.list.item(i).text() for i in range(2)].index(hinge))
    click(tab.remove_button)
    wait_for(lambda: tab.list.count() == 1, 5, "hinge removed")
    assert hinge not in window.scene.joints and not window.scene.motors


def test_motion_tab_forces_joints_motors_and_robot_paths(window, kautham_dir, tmp_path):
    from gui.window.testing import click, screenshot, type_into, wait_for
    window.tabs.setCurrentWidget(window.motion)
    tab = window.motion
    world = _world()
    from world_client import sphere
    world.ok("build_object", object=sphere("ball", 0.1, (0, 0, 5)))
    wait_for(lambda: tab.object.currentText() == "ball", 5, "ball in the chooser")

    # a force at a point, in the body frame: listed with the world's ID, then deleted
    tab.action_buttons[0].setChecked(True)
    tab.at_point.setChecked(True)
    tab.vector_relative.setChecked(True)
    tab.vector.set_values((0, 0, 9.81))
    tab.point.set_values((0.1, 0, 0))
    click(tab.move_button)
    wait_for(lambda: tab.forces.count() == 1, 5, "the force in the list")
    assert tab.forces.item(0).text() == "force:ball:0"
    tab.action_buttons[1].click()
    click(tab.move_button)
    wait_for(lambda: tab.forces.count() == 2, 5, "the torque")
    tab.forces.setCurrentRow(0)
    click(tab.delete_force_button)
    wait_for(lambda: tab.forces.count() == 1, 5, "force deleted")
    assert tab.forces.item(0).text().startswith("torque:ball")

    # a linear velocity: the ball rises while simulating
    tab.action_buttons[3].click()
    tab.vector.set_values((0, 0, 3))
    click(tab.move_button)
    wait_for(lambda: "Velocity of ball" in window.last_info, 5, "velocity set")
    world.ok("step_once", cycles=2)
    assert world.poses()["ball"][0][2] > 5.0

    # robot: the Kuka problem, then joint force, motor velocity and the three path kinds
    window.simulation.open_problem(str(kautham_dir / "legacy_2012/examples/Kuka_two_columns.xml"))
    wait_for(lambda: "KukaLWR" in window.scene.robots and not window.simulation.building, 30,
             "the Kuka")
    wait_for(lambda: tab.joint.count() == 7, 5, "joints listed")
    tab.toolbox.setCurrentIndex(1)
    tab.joint.setCurrentText("1:KukaLWR/Base&KukaLWR/Link1")
    assert tab.magnitudes.boxes[0].isEnabled() and not tab.magnitudes.boxes[1].isEnabled()
    click(tab.joint_force_button)
    wait_for(lambda: tab.joint_forces.count() == 1, 5, "joint force")
    tab.joint_forces.setCurrentRow(0)
    click(tab.delete_joint_force_button)
    wait_for(lambda: tab.joint_forces.count() == 0, 5, "joint force deleted")

    tab.toolbox.setCurrentIndex(2)
    tab.motor.setCurrentText("motor:1:KukaLWR/Base&KukaLWR/Link1")
    type_into(tab.motor_speeds.boxes[0], "0.5")
    click(tab.motor_button)
    wait_for(lambda: "goal [0.5]" in window.last_info, 5, "motor goal")
    world.ok("step_once", cycles=5)
    window.plot.choose("1:KukaLWR/Base&KukaLWR/Link1")
    wait_for(lambda: window.plot.samples.get("1:KukaLWR/Base&KukaLWR/Link1")
             and window.plot.samples["1:KukaLWR/Base&KukaLWR/Link1"][-1][2]
             == pytest.approx(0.5, abs=0.05), 5, "the joint turning at 0.5 rad/s")

    tab.toolbox.setCurrentIndex(3)
    assert tab.robot.currentText() == "KukaLWR" and tab.units.currentIndex() == 0  # degrees
    initial = tmp_path / "initial.txt"
    initial.write_text("90 0 0 0 0 0 0\n")
    tab.run_path("initial", str(initial))
    wait_for(lambda: "initial position set" in window.last_info, 5, "initial position")
    # a position path is checked for jumps as run_path checks it: its first row against
    # where the robot is in the world (joint 1 at 90 deg), on the path worker
    far = tmp_path / "far.txt"
    far.write_text("".join(f"{k} 10 0 0 0 0 0\n" for k in range(0, 40, 10)))
    tab.run_path("position", str(far))
    wait_for(lambda: "from where the robot is" in window.last_error, 5, "the jump refused")
    assert "far.txt:1: joint " in window.last_error and "Allow jumps" in window.last_error
    position = tmp_path / "position.txt"
    position.write_text("".join(f"{90 + k} 10 0 0 0 0 0\n" for k in range(0, 40, 10)))
    tab.double.setValue(1)                           # 4 rows -> 7
    tab.run_path("position", str(position))
    wait_for(lambda: "position path done (7 rows)" in window.last_info, 10, "position path")
    velocity = tmp_path / "velocity.txt"
    velocity.write_text("10 0 0 0 0 0 0\n" * 200)
    tab.run_path("velocity", str(velocity))
    wait_for(lambda: tab.stop_button.isEnabled() and "row" in tab.path_status.text(), 5,
             "the velocity path running")
    # the window stays usable while the path runs: other calls go through at once
    click(window.simulation.simulate_button)
    wait_for(lambda: window.simulation.simulating, 5, "simulating during the path")
    screenshot(window, SHOTS / "motion.png")
    click(tab.stop_button)
    wait_for(lambda: not tab.stop_button.isEnabled(), 5, "the path stopped")
    assert "stopped" in tab.path_status.text()
    # a bad path file: refused with file and line
    bad = tmp_path / "bad.txt"
    bad.write_text("1 2 3\n")
    tab.run_path("position", str(bad))
    assert "bad.txt:1" in window.last_error
    window.tabs.setCurrentWidget(window.simulation)
    screenshot(window, SHOTS / "window.png")


def test_motion_tab_runs_a_control_path_on_the_sphere_demo(window, kautham_dir, tmp_path):
    """Kautham's Sphere demo opened, then a control path (the query's goal, 8 rows of 0.3 s) in
    real time: the sphere ends at the goal; a row out of [0, 1] is refused with file and line."""
    from gui.window.testing import screenshot, wait_for
    problem = kautham_dir / "current_2025/demos/OMPL_ode_demos/Sphere/Sphere.xml"
    window.simulation.open_problem(str(problem))
    wait_for(lambda: "SphereDE" in window.scene.robots and not window.simulation.building, 30,
             "the sphere demo")
    # the demo builds its ball 50 mm into the ground: pushed out, as Kautham's ODE world does
    wait_for(lambda: "SphereDE in ground by 50.0 mm" in window.log.toPlainText(), 5,
             "the overlap's line in the log")
    assert "push them apart when the world runs, as in Kautham's ODE" in window.log.toPlainText()
    window.tabs.setCurrentWidget(window.motion)
    tab = window.motion
    tab.toolbox.setCurrentIndex(3)
    assert tab.robot.currentText() == "SphereDE"
    controls = tmp_path / "controls.txt"
    controls.write_text("0.426 0.578 0.4 0.3\n" * 10)
    tab.run_path("control", str(controls))
    wait_for(lambda: ": row " in tab.path_status.text(), 5, "the control path running")
    screenshot(window, SHOTS / "motion_controls.png")
    wait_for(lambda: "control path done (10 rows)" in window.last_info, 20, "the control path")
    goal = (-5 + 10 * 0.426, -5 + 10 * 0.578)             # sp3.cntr and <Limits>: x, y
    position = _world().ok("get_state", objects=["SphereDE"]).bodies[0].position
    assert math.dist(position[:2], goal) < 0.02
    bad = tmp_path / "bad.txt"
    bad.write_text("0.4 0.5 0.4 0.3\n0.4 0.5 0.4 -1\n")
    tab.run_path("control", str(bad))
    assert "bad.txt:2" in window.last_error and "not positive" in window.last_error


def test_motion_tab_runs_a_tracked_plan_and_plots_it(window, kautham_dir, tmp_path):
    """Kautham's public 2DRR_obstacle problem opened, then its .kps solution as a tracked path
    in real time: the robot ends at the solution's goal and the plot shows target against
    actual per joint; a mismatched plan is refused with file and line, running nothing."""
    from gui.ros.client import WorldClient
    from gui.window.testing import screenshot, wait_for
    from odin_common.interface import Solver
    tro = kautham_dir / "legacy_2012" / "examples" / "TRO"
    window.simulation.open_problem(str(tro / "2DRR_obstacle.xml"))
    wait_for(lambda: "2D-Robot" in window.scene.robots and not window.simulation.building, 30,
             "the 2DRR problem")
    # the exact solver, as tests/nodes/test_tracked_path.py says why
    WorldClient().set_world(solver=Solver.WORLDSTEP)
    window.tabs.setCurrentWidget(window.motion)
    tab = window.motion
    tab.toolbox.setCurrentIndex(3)
    bad = tmp_path / "bad.kps"
    bad.write_text('<?xml version="1.0"?>\n<Planner>\n <Queries>\n  <Query Solved="True">\n'
                   '   <Result name="Path">0 1</Result>\n  </Query>\n </Queries>\n'
                   ' <SampleSet dim="2" size="2">\n  <Sample>0.5 0.5</Sample>\n'
                   '  <Sample>0.5 0.5 0.5</Sample>\n </SampleSet>\n</Planner>\n')
    tab.run_path("tracked", str(bad))
    assert "bad.kps:10" in window.last_error and tab.tracking_plot.report is None
    tab.run_path("tracked", str(tro / "2DRR_obstacle_sol.kps"))
    wait_for(lambda: "tracked path 2DRR_obstacle_sol.kps: " in tab.path_status.text()
             and " s" in tab.path_status.text(), 10, "the tracked path running")
    wait_for(lambda: tab.tracking_plot.report is not None, 60, "the tracked path's end",
             lambda: tab.path_status.text())
    report = tab.tracking_plot.report
    assert report.goal_error <= 0.01, tab.path_status.text()
    assert "goal error" in window.last_info
    # built at the query's start (where Kautham 2012 leaves a problem it loads), the robot
    # is where the solution begins: no move first
    assert "move to its start" not in window.last_info, window.last_info
    assert report.names == ["2D-Robot/link1", "2D-Robot/link2", "2D-Robot/tcp"]
    assert report.targets[-1, 0] == pytest.approx(-0.4335, abs=1e-3)
    screenshot(window, SHOTS / "motion_tracked.png")
