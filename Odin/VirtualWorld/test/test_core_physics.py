"""Analytic physics through the Core: each test compares with a figure written down."""
import math

import numpy as np
import pytest

from odin_common.interface import JOINT_FORCE_MAGNITUDES
from virtual_world import core as vc
from virtual_world.core import Core, JointSpec, MotorSpec, ObjectSpec, WorldParameters
from virtual_world.errors import UnknownName


@pytest.fixture
def core():
    c = Core()
    yield c
    c.close()


def ground(core, half=5.0):
    core.build_object(ObjectSpec("ground", [2 * half, 2 * half, 1.0], position=(0, 0, -0.5),
                                 geometry_only=True))


def test_free_fall_matches_semi_implicit_euler(core):
    core.set_world_parameters(gravity=(0.0, 0.0, -9.81))
    core.build_object(ObjectSpec("ball", [0.1], mass=2.0, position=(0, 0, 10.0)))
    core.set_velocity("ball", linear=(0.5, 0.0, 1.0))
    h, n = 0.001, 500
    core.step(h, n)
    v, x = np.array([0.5, 0.0, 1.0]), np.array([0.0, 0.0, 10.0])
    for _ in range(n):
        v = v + np.array([0, 0, -9.81]) * h
        x = x + v * h
    position, _, velocity, _ = core.body_state("ball")
    np.testing.assert_allclose(velocity, v, atol=1e-9)
    np.testing.assert_allclose(position, x, atol=1e-9)
    assert core.sim_time == pytest.approx(n * h)


def test_hinge_pendulum_small_angle_period(core):
    # a physical pendulum: sphere (I = 2/5 m r^2) on a massless rod;
    # T = 2 pi sqrt((I + m L^2) / (m g L)) (1 + theta0^2 / 16)
    g, L, r, m = 9.81, 1.0, 0.05, 1.0
    core.set_world_parameters(gravity=(0, 0, -g))
    theta0 = 0.05
    core.build_object(ObjectSpec("bob", [r], mass=m,
                                 position=(L * math.sin(theta0), 0, -L * math.cos(theta0))))
    core.add_joint(JointSpec(vc.HINGE, "", "bob", anchor=(0, 0, 0), axis1=(0, 1, 0)))
    h = 0.0005
    angles, times = [], []
    for i in range(8000):
        core.step(h)
        angles.append(core.body_state("bob")[0][0])  # x of the bob, crosses 0 at the bottom
        times.append((i + 1) * h)
    angles = np.array(angles)
    # upward zero crossings
    crossings = [times[i] - angles[i] * h / (angles[i + 1] - angles[i])
                 for i in range(len(angles) - 1) if angles[i] < 0 <= angles[i + 1]]
    period = np.mean(np.diff(crossings))
    inertia = 0.4 * m * r * r
    expected = 2 * math.pi * math.sqrt((inertia + m * L * L) / (m * g * L)) * (1 + theta0 ** 2 / 16)
    assert period == pytest.approx(expected, rel=0.01)


def test_box_at_rest_on_plane_stays_within_surface_layer(core):
    ground(core)
    layer = core.world_parameters.contact_surface_layer
    core.build_object(ObjectSpec("box", [0.4, 0.3, 0.2], mass=3.0, position=(0, 0, 0.1)))
    core.step(0.001, 3000)
    position, q, v, w = core.body_state("box")
    assert 0.1 - layer - 1e-4 <= position[2] <= 0.1 + 1e-6
    assert abs(position[0]) < 1e-6 and abs(position[1]) < 1e-6
    assert np.linalg.norm(v) < 1e-3 and np.linalg.norm(w) < 1e-3
    assert core.last_step_contacts >= 3


def test_angular_motor_reaches_goal_speed(core):
    core.set_world_parameters(gravity=(0, 0, 0))
    core.build_object(ObjectSpec("wheel", [0.2, 0.05], mass=1.0))
    joint = core.add_joint(JointSpec(vc.HINGE, "", "wheel", axis1=(0, 0, 1)))
    motor = core.add_motor(MotorSpec(joint=joint, max_forces=[5.0]))
    assert motor == "motor:" + joint
    core.set_velocity(motors=[motor], velocities=[3.0])
    core.step(0.001, 10)
    assert 0 < core.joint_states()[0].rates[0] < 3.0  # limited force: not there yet
    core.step(0.001, 2000)
    assert core.joint_states()[0].rates[0] == pytest.approx(3.0, rel=1e-3)


def test_linear_motor_reaches_goal_speed(core):
    core.set_world_parameters(gravity=(0, 0, 0))
    core.build_object(ObjectSpec("cart", [0.2, 0.2, 0.2], mass=2.0))
    joint = core.add_joint(JointSpec(vc.SLIDER, "", "cart", axis1=(1, 0, 0)))
    motor = core.add_motor(MotorSpec(joint=joint, kind=vc.LINEAR))
    core.set_velocity(motors=[motor], velocities=[0.7])
    core.step(0.001, 5)
    state = core.joint_states()[0]
    assert state.rates[0] == pytest.approx(0.7, rel=1e-3)


def test_momentum_conserved_in_sphere_collision(core):
    core.set_world_parameters(gravity=(0, 0, 0), bounce=0.5, bounce_velocity=0.0)
    core.build_object(ObjectSpec("a", [0.1], mass=1.0, position=(-0.5, 0, 0)))
    core.build_object(ObjectSpec("b", [0.1], mass=3.0, position=(0.5, 0.02, 0)))
    core.set_velocity("a", linear=(2.0, 0, 0))
    core.set_velocity("b", linear=(-0.5, 0, 0))
    before = 1.0 * np.array([2.0, 0, 0]) + 3.0 * np.array([-0.5, 0, 0])
    collided = False
    for _ in range(1000):
        core.step(0.001)
        collided |= core.last_step_contacts > 0
    assert collided
    va, vb = core.body_state("a")[2], core.body_state("b")[2]
    np.testing.assert_allclose(1.0 * va + 3.0 * vb, before, atol=1e-6)
    assert va[0] < 0.5  # they did interact


def test_penetration_depth_of_overlapping_boxes(core):
    core.set_world_parameters(gravity=(0, 0, 0), contact_less=True)
    core.build_object(ObjectSpec("b1", [1, 1, 1], position=(0, 0, 0)))
    core.build_object(ObjectSpec("b2", [1, 1, 1], position=(0.9, 0.1, 0)))
    core.step(0.001)
    (collision,) = core.read_collisions()
    assert (collision.first, collision.second) == ("b1", "b2")
    assert collision.depth == pytest.approx(0.1, abs=1e-9)
    assert collision.points and all(len(p) == 3 for p in collision.points)


def test_contact_less_set_cleared_on_read(core):
    core.set_world_parameters(gravity=(0, 0, 0), contact_less=True)
    core.build_object(ObjectSpec("a", [0.1], position=(0, 0, 0)))
    core.build_object(ObjectSpec("b", [0.1], position=(0.15, 0, 0)))
    core.build_object(ObjectSpec("c", [0.1], position=(3, 0, 0)))
    core.step(0.001, 5)
    pairs = core.read_collisions()
    assert [(p.first, p.second) for p in pairs] == [("a", "b")]
    assert pairs[0].depth == pytest.approx(0.05, abs=1e-9)
    assert core.read_collisions() == []
    # they slip through each other: no contacts
    assert core.last_step_contacts == 0
    np.testing.assert_allclose(core.body_state("a")[0], (0, 0, 0))
    # pairs since last read: a collision that ended before the read is still reported
    core.set_poses([("c", (0.1, 0.1, 0), (1, 0, 0, 0))])
    core.step(0.001)
    core.set_poses([("c", (3, 0, 0), (1, 0, 0, 0))])
    core.step(0.001)
    names = {(p.first, p.second) for p in core.read_collisions()}
    assert names == {("a", "b"), ("a", "c"), ("b", "c")}


def test_contact_policy_reports_last_step_pairs(core):
    ground(core)
    core.build_object(ObjectSpec("s", [0.1], position=(0, 0, 0.099)))
    core.step(0.001, 3)
    (c,) = core.read_collisions()
    assert (c.first, c.second) == ("ground", "s") and c.depth > 0
    assert core.read_collisions() == [c]  # not cleared in contact mode
    core.set_poses([("s", (0, 0, 2), (1, 0, 0, 0))])
    core.step(0.001)
    assert core.read_collisions() == []


def test_entity_without_internal_collisions_gets_no_contacts(core):
    core.set_world_parameters(gravity=(0, 0, 0))
    entity = core.build_entity(vc.EntitySpec("", [ObjectSpec("a", [0.1]), ObjectSpec(
        "b", [0.1], position=(0.15, 0, 0))], [], internal_collisions=False))
    assert entity.name == "entity1" and entity.ids == ["a", "b"]
    core.build_entity(vc.EntitySpec("robot2", [ObjectSpec("c", [0.1], position=(5, 0, 0)),
                                               ObjectSpec("d", [0.1], position=(5.15, 0, 0))],
                                    [], True))
    core.step(0.001)
    pairs = [(p.first, p.second) for p in core.read_collisions()]
    assert pairs == [("c", "d")]
    assert core.last_step_contacts > 0
    # the entity still collides with others
    core.build_object(ObjectSpec("e", [0.1], position=(-0.15, 0, 0)))
    core.step(0.001)
    assert ("a", "e") in [(p.first, p.second) for p in core.read_collisions()]


def test_joined_bodies_get_no_contacts(core):
    core.set_world_parameters(gravity=(0, 0, 0))
    core.build_object(ObjectSpec("a", [0.1]))
    core.build_object(ObjectSpec("b", [0.1], position=(0.15, 0, 0)))
    core.step(0.001)
    assert core.last_step_contacts > 0
    core.set_poses([("a", (0, 0, 0), (1, 0, 0, 0)), ("b", (0.15, 0, 0), (1, 0, 0, 0))],
                   reset_velocity=True)
    core.add_joint(JointSpec(vc.BALL, "a", "b", anchor=(0.075, 0, 0)))
    core.step(0.001, 10)
    assert core.last_step_contacts == 0
    assert core.read_collisions() == []


def test_fixed_body_does_not_move_and_holds_others(core):
    core.build_object(ObjectSpec("table", [1, 1, 0.1], position=(0, 0, 1), fixed=True))
    core.build_object(ObjectSpec("cup", [0.05], position=(0, 0, 1.1)))
    core.step(0.001, 1000)
    position, q, v, _ = core.body_state("table")
    np.testing.assert_allclose(position, (0, 0, 1))
    assert np.all(v == 0)
    assert core.body_state("cup")[0][2] == pytest.approx(1.1, abs=2e-3)


def test_forces_in_world_and_body_frame_and_at_a_point(core):
    core.set_world_parameters(gravity=(0, 0, 0))
    rot90z = (math.cos(math.pi / 4), 0, 0, math.sin(math.pi / 4))
    core.build_object(ObjectSpec("w", [0.1], mass=2.0))
    core.build_object(ObjectSpec("b", [0.1], mass=2.0, position=(5, 0, 0), orientation=rot90z))
    core.build_object(ObjectSpec("p", [1, 1, 1], mass=6.0, position=(10, 0, 0)))
    fw = core.add_body_force("w", vc.FORCE, (1, 0, 0))
    fb = core.add_body_force("b", vc.FORCE, (1, 0, 0), vector_in_body_frame=True)
    fp = core.add_body_force("p", vc.FORCE, (0, 1, 0), at_point=True, point=(0.5, 0, 0),
                             point_in_body_frame=True)
    assert (fw, fb, fp) == ("force:w:0", "force:b:0", "force:p:0")
    assert core.add_body_force("w", vc.TORQUE, (0, 0, 0)) == "torque:w:0"
    h, n = 0.001, 100
    core.step(h, n)
    t = h * n
    np.testing.assert_allclose(core.body_state("w")[2], (0.5 * t, 0, 0), atol=1e-9)
    np.testing.assert_allclose(core.body_state("b")[2], (0, 0.5 * t, 0), atol=1e-6)
    # box: I = m (1+1)/12 = 1; torque (0.5,0,0) x (0,1,0) = 0.5 z; angular speed 0.5 t
    _, _, v, w = core.body_state("p")
    assert v[1] == pytest.approx(t / 6.0, rel=1e-6)
    assert w[2] == pytest.approx(0.5 * t, rel=1e-2)
    core.remove_body_force(fw)
    core.step(h, n)
    np.testing.assert_allclose(core.body_state("w")[2], (0.5 * t, 0, 0), atol=1e-9)


def test_joint_forces(core):
    core.set_world_parameters(gravity=(0, 0, 0))
    core.build_object(ObjectSpec("wheel", [1, 1, 1], mass=12.0))  # Izz = 12*2/12 = 2
    hinge = core.add_joint(JointSpec(vc.HINGE, "", "wheel", axis1=(0, 0, 1)))
    core.build_object(ObjectSpec("cart", [0.1, 0.1, 0.1], mass=4.0, position=(5, 0, 0)))
    slider = core.add_joint(JointSpec(vc.SLIDER, "", "cart", axis1=(0, 1, 0)))
    core.build_object(ObjectSpec("knob", [1, 1, 1], mass=12.0, position=(10, 0, 0)))
    ball = core.add_joint(JointSpec(vc.BALL, "", "knob", anchor=(10, 0, 0)))
    assert core.add_joint_force(hinge, [1.0]) == f"jointforce:{hinge}:0"
    core.add_joint_force(slider, [2.0])
    core.add_joint_force(ball, [0.0, 2.0, 0.0])
    core.step(0.001, 1000)
    states = {s.id: s for s in core.joint_states()}
    # a body joined to the world is ODE's body 1: +torque (+force) turns (pushes) it along
    # +axis, so the joint rate grows with the magnitude's sign (test_core_joints: every type)
    assert states[hinge].rates[0] == pytest.approx(0.5, rel=1e-3)
    assert states[slider].rates[0] == pytest.approx(0.5, rel=1e-3)
    np.testing.assert_allclose(core.body_state("knob")[3], (0.0, 1.0, 0.0), atol=1e-3)
    assert states[ball].positions == ()


def test_composite_mass_centre_id_and_parts(core):
    core.set_world_parameters(gravity=(0, 0, 0))
    parts = [vc.PartSpec("top", [1.0, 1.0, 0.1], mass=3.0, position=(0, 0, 1.0)),
             vc.PartSpec("leg", [0.05, 1.0], mass=1.0, position=(0, 0, 0.5))]
    cid = core.build_composite(vc.CompositeSpec(parts, position=(2, 0, 0))).id
    assert cid == ">top>leg"
    assert core.geometry_names(cid) == ["top", "leg"]
    mass, com, inertia = core.mass_properties(cid)
    assert mass == pytest.approx(4.0)
    np.testing.assert_allclose(com, (0, 0, (3 * 1.0 + 1 * 0.5) / 4))
    izz = 3 * (1 + 1) / 12 + 1 * 0.05 ** 2 / 2
    assert inertia[2, 2] == pytest.approx(izz)
    ixx_top = 3 * (1 + 0.01) / 12 + 3 * (1.0 - com[2]) ** 2
    ixx_leg = 1 * (3 * 0.05 ** 2 + 1.0) / 12 + 1 * (0.5 - com[2]) ** 2
    assert inertia[0, 0] == pytest.approx(ixx_top + ixx_leg)
    names, positions, quats = core.poses()
    assert names == ["top", "leg"]
    np.testing.assert_allclose(positions, [(2, 0, 1.0), (2, 0, 0.5)], atol=1e-12)
    # the pose of the composite frame round-trips through set_poses
    core.set_poses([(cid, (0, 0, 0), (0, 1, 0, 0))])
    np.testing.assert_allclose(core.poses()[1], [(0, 0, -1.0), (0, 0, -0.5)], atol=1e-12)
    np.testing.assert_allclose(np.abs(core.poses()[2]), [(0, 1, 0, 0)] * 2, atol=1e-12)


def test_mesh_inertia_of_shifted_box(core):
    core.set_world_parameters(gravity=(0, 0, 0))
    a, b, c = 0.4, 0.6, 1.0
    shift = np.array([1.0, -2.0, 0.5])
    corners = np.array([[x, y, z] for x in (0, a) for y in (0, b) for z in (0, c)]) + shift
    faces = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
             [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
    mass = 5.0
    core.build_object(ObjectSpec("mesh", corners.reshape(-1).tolist(),
                                 np.array(faces).reshape(-1).tolist(), mass=mass))
    m, com, inertia = core.mass_properties("mesh")
    assert m == pytest.approx(mass)
    np.testing.assert_allclose(com, shift + [a / 2, b / 2, c / 2], atol=1e-9)
    expected = mass / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    np.testing.assert_allclose(inertia, expected, atol=1e-9)
    # geometry stays where given; the body sits at the centre of mass
    names, positions, _ = core.poses()
    np.testing.assert_allclose(positions[0], (0, 0, 0), atol=1e-12)
    # inverted winding gives the same figures (normals repaired)
    core.build_object(ObjectSpec("inv", corners.reshape(-1).tolist(),
                                 np.array(faces)[:, ::-1].reshape(-1).tolist(), mass=mass))
    np.testing.assert_allclose(core.mass_properties("inv")[2], expected, atol=1e-9)


def test_open_mesh_falls_back_to_bounding_box():
    from virtual_world.core.mass import mesh_mass
    a = 1.0
    corners = np.array([[x, y, z] for x in (0, a) for y in (0, a) for z in (0, a)])
    faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4]])  # two faces missing
    props = mesh_mass(corners + 3.0, faces, 6.0)
    assert props.rule == "bounding box"
    np.testing.assert_allclose(props.inertia, np.eye(3), atol=1e-9)
    np.testing.assert_allclose(props.center, (3.5, 3.5, 3.5))
    flat = mesh_mass(np.array([[0, 0, 0], [2, 0, 0], [0, 1, 0.0]]), np.array([[0, 1, 2]]), 12.0)
    assert flat.rule == "bounding box"
    np.testing.assert_allclose(np.diag(flat.inertia), [1, 4, 5])


PRELOADED_MESH_MASS = """
import sys
from virtual_world.core import mass
assert "trimesh" not in sys.modules
mass.preload_trimesh()
assert mass._PRELOAD.name == "preload trimesh"
import numpy as np
corners = np.array([[x, y, z] for x in (0, 1.0) for y in (0, 1.0) for z in (0, 1.0)])
faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
print(mass.mesh_mass(corners, faces, 6.0).rule)      # waits for the preload, then uses it
assert not mass._PRELOAD.is_alive() and "trimesh" in sys.modules
"""


def test_a_node_preloads_trimesh_and_the_first_mesh_waits_for_that_import():
    """The world node imports trimesh on a thread of its own once it serves; the first mesh
    mass waits for that import rather than making a second one beside it (a fresh process:
    this one has imported trimesh already)."""
    import subprocess
    import sys
    done = subprocess.run([sys.executable, "-c", PRELOADED_MESH_MASS], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["closed"]


def test_mesh_collides_with_sphere(core):
    ground(core)
    corners = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (0, 0.2)])
    faces = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
             [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
    core.build_object(ObjectSpec("slab", corners.reshape(-1).tolist(),
                                 np.array(faces).reshape(-1).tolist(), geometry_only=True))
    core.build_object(ObjectSpec("s", [0.1], position=(0, 0, 0.5)))
    core.step(0.001, 1500)
    assert core.body_state("s")[0][2] == pytest.approx(0.3, abs=5e-3)


@pytest.mark.parametrize("joint_type,n", [(vc.HINGE, 1), (vc.SLIDER, 1), (vc.PISTON, 2),
                                          (vc.UNIVERSAL, 2), (vc.HINGE2, 2), (vc.PR, 2),
                                          (vc.PU, 3), (vc.BALL, 0), (vc.FIXED, 0),
                                          (vc.PLANE2D, 0)])
def test_every_joint_type_steps_and_reports(core, joint_type, n):
    core.set_world_parameters(gravity=(0, 0, -1))
    core.build_object(ObjectSpec("a", [0.1], position=(0, 0, 1)))
    core.build_object(ObjectSpec("b", [0.1], position=(0.3, 0, 1)))
    body2 = "" if joint_type == vc.PLANE2D else "b"
    jid = core.add_joint(JointSpec(joint_type, "a", body2, anchor=(0.15, 0, 1), axis1=(0, 0, 1),
                                   axis2=(0, 1, 0), axis3=(1, 0, 0)))
    assert jid == f"{joint_type}:a&{body2}"
    if joint_type in JOINT_FORCE_MAGNITUDES:
        core.add_joint_force(jid, [0.1] * len(JOINT_FORCE_MAGNITUDES[joint_type]))
    core.step(0.001, 50)
    (state,) = core.joint_states()
    assert len(state.positions) == len(state.rates) == n
    assert all(math.isfinite(v) for v in state.positions + state.rates)


def test_joint_stops_hold(core):
    core.set_world_parameters(gravity=(0, 0, -9.81))
    core.build_object(ObjectSpec("arm", [0.05], position=(0.5, 0, 0)))
    jid = core.add_joint(JointSpec(vc.HINGE, "", "arm", anchor=(0, 0, 0), axis1=(0, 1, 0)))
    core.set_joint_parameters(jid, [(vc.LO_STOP, 1, -0.2), (vc.HI_STOP, 1, 0.2)])
    core.step(0.001, 2000)
    angle = core.joint_states()[0].positions[0]
    assert abs(angle) == pytest.approx(0.2, abs=0.02)


def test_world_step_solver_and_parameters(core):
    params = core.set_world_parameters(solver=vc.WORLDSTEP, max_contacts=4, friction=-1)
    assert params.solver == vc.WORLDSTEP and params.max_contacts == 4
    ground(core)
    core.build_object(ObjectSpec("box", [0.2, 0.2, 0.2], position=(0, 0, 0.1)))
    core.step(0.001, 200)
    assert core.last_step_contacts == 4
    assert isinstance(core.world_parameters, WorldParameters)


def _dense_sphere(radius):
    import trimesh
    sphere = trimesh.creation.icosphere(subdivisions=5, radius=radius)   # 20480 triangles
    return np.asarray(sphere.vertices).reshape(-1).tolist(), np.asarray(sphere.faces)


def test_collision_mesh_tolerance_simplifies_what_collides_not_the_mass(core):
    vertices, faces = _dense_sphere(0.1)
    core.build_object(ObjectSpec("exact", vertices, faces.reshape(-1).tolist(), mass=2.0,
                                 position=(-1, 0, 0)))
    core.set_world_parameters(collision_mesh_tolerance=0.01)
    core.build_object(ObjectSpec("coarse", vertices, faces.reshape(-1).tolist(), mass=2.0,
                                 position=(1, 0, 0)))
    assert core.collision_triangle_count("exact") == len(faces)
    assert 100 < core.collision_triangle_count("coarse") < len(faces) / 5
    assert core.collision_triangle_count("exact") == len(faces)   # built before: unchanged
    for name in ("exact", "coarse"):   # mass and inertia come from the mesh as given
        m, _, inertia = core.mass_properties(name)
        np.testing.assert_allclose(inertia, core.mass_properties("exact")[2], rtol=1e-12)
    # the Viewer is sent the given mesh
    assert len(core.object_spec("coarse").indices) == faces.size


def test_coarse_collision_mesh_rests_within_its_tolerance(core):
    """A dense mesh ball dropped on the ground rests on its clustered surface: within
    sqrt(3) cells of the radius, and exactly as the given mesh would with tolerance 0."""
    vertices, faces = _dense_sphere(0.1)
    ground(core)
    tolerance = 0.004
    core.set_world_parameters(collision_mesh_tolerance=tolerance, max_contacts=4)
    core.build_object(ObjectSpec("ball", vertices, faces.reshape(-1).tolist(), mass=1.0,
                                 position=(0, 0, 0.3)))
    core.step(0.001, 1500)
    height = core.body_state("ball")[0][2]
    assert abs(height - 0.1) < math.sqrt(3) * tolerance + 0.002   # + the surface layer


def test_a_mesh_a_few_cells_across_collides_as_given(core):
    vertices, faces = _dense_sphere(0.02)   # 4 cells across: clustering would lose its shape
    core.set_world_parameters(collision_mesh_tolerance=0.01)
    core.build_object(ObjectSpec("bead", vertices, faces.reshape(-1).tolist(), mass=0.01))
    assert core.collision_triangle_count("bead") == len(faces)
    with pytest.raises(UnknownName):
        core.collision_triangle_count("nothing")


def test_contact_reports_carry_normals_and_the_forces_that_hold_a_box(core):
    ground(core)
    core.build_object(ObjectSpec("box", [0.4, 0.3, 0.2], mass=3.0, position=(0, 0, 0.1)))
    core.step(0.001, 500)
    (pair,) = core.read_collisions()
    assert (pair.first, pair.second) == ("box", "ground")
    np.testing.assert_allclose(pair.normals, [(0, 0, 1)] * len(pair.points), atol=1e-9)
    total = np.sum(pair.forces, axis=0)            # the ground holds the box up: m g
    assert total[2] == pytest.approx(3.0 * 9.81, rel=1e-3)
    assert np.hypot(total[0], total[1]) < 0.05 * total[2]


def test_a_joint_reports_the_force_it_applies(core):
    core.set_world_parameters(solver=vc.WORLDSTEP)
    core.build_object(ObjectSpec("bob", [0.1], mass=2.0, position=(0.5, 0, 0)))
    joint = core.add_joint(JointSpec(vc.HINGE, "bob", "", anchor=(0, 0, 0), axis1=(0, 1, 0)))
    core.add_motor(MotorSpec(joint=joint))          # holds it level
    core.step(0.001, 20)
    _, (reaction,), (motor,) = core.state()
    assert reaction.force1[2] == pytest.approx(2.0 * 9.81, rel=1e-3)   # up, m g
    assert reaction.force2 == (0.0, 0.0, 0.0)      # the static world's side
    assert motor.goals == (0.0,) and motor.max_forces == (math.inf,)
