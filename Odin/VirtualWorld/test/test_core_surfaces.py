"""Planes, capsules and per-object surfaces (friction, anisotropic friction, restitution,
soft contacts), each against the figure mechanics gives, and the mixing rule of two surfaces
(Messages/Surface): the smaller friction, the larger restitution, stiffness in series."""
import math

import numpy as np
import pytest

from odin_common.interface import Shape
from odin_common.specs import Surface
from virtual_world.core import (Core, CompositeSpec, ObjectSpec, PartSpec,
                                WorldParameters)
from virtual_world.errors import InvalidArgument

G = 9.81
H = 0.001


def turn(axis, angle):
    """(w, x, y, z) of a turn of ``angle`` rad about the unit ``axis``."""
    s = math.sin(angle / 2)
    return (math.cos(angle / 2), axis[0] * s, axis[1] * s, axis[2] * s)


def world(**parameters) -> Core:
    return Core(WorldParameters(gravity=(0.0, 0.0, -G), **parameters))


def ground_plane(core, surface=Surface(), orientation=(1, 0, 0, 0), position=(0, 0, 0)):
    core.build_object(ObjectSpec("ground", (), shape=Shape.PLANE, geometry_only=True,
                                 position=position, orientation=orientation, surface=surface))


# ------------------------------------------------------------------ planes and capsules

def test_a_ball_rests_on_an_infinite_plane_far_from_the_origin():
    core = world()
    ground_plane(core)
    core.build_object(ObjectSpec("ball", (0.1,), position=(400.0, -300.0, 0.5)))
    core.step(H, 1500)
    position, _, velocity, _ = core.body_state("ball")
    layer = core.world_parameters.contact_surface_layer
    assert 0.1 - layer - 1e-4 < position[2] <= 0.1 + 1e-6
    assert np.linalg.norm(velocity) < 1e-3
    core.close()


def test_a_ball_rolls_down_a_tilted_plane_at_five_sevenths_g_sine():
    slope = math.radians(10)
    core = world(friction=1.0)
    ground_plane(core, orientation=turn((0, 1, 0), slope))   # normal tipped towards +x
    core.build_object(ObjectSpec("ball", (0.1,), position=(0.1 * math.sin(slope), 0,
                                                           0.1 * math.cos(slope) + 0.001)))
    core.step(H, 100)
    v0 = core.body_state("ball")[2]
    core.step(H, 500)
    v1 = core.body_state("ball")[2]
    along = np.array([-math.cos(slope), 0, math.sin(slope)])   # down the slope
    along = -along if along[2] > 0 else along
    acceleration = (v1 - v0) @ along / 0.5
    # a solid sphere rolling without slipping: a = (5/7) g sin(slope)
    assert acceleration == pytest.approx(5 / 7 * G * math.sin(slope), rel=0.02)
    core.close()


def test_a_plane_reports_its_point_nearest_the_origin_and_moves_with_set_poses():
    core = world()
    ground_plane(core, position=(3.0, 4.0, 2.0))     # z = 2, normal +z
    names, positions, quaternions = core.poses()
    assert names == ["ground"]
    np.testing.assert_allclose(positions[0], (0, 0, 2.0), atol=1e-12)
    np.testing.assert_allclose(quaternions[0], (1, 0, 0, 0), atol=1e-12)
    core.set_poses([("ground", (0, 0, -1.0), turn((1, 0, 0), math.pi / 2))])  # normal -y
    _, positions, quaternions = core.poses()
    np.testing.assert_allclose(positions[0], (0, 0, 0), atol=1e-12)   # the plane y = 0
    z_axis = np.array([2 * (quaternions[0][1] * quaternions[0][3] + quaternions[0][0]
                            * quaternions[0][2]), 2 * (quaternions[0][2] * quaternions[0][3]
                                                       - quaternions[0][0] * quaternions[0][1]),
                       1 - 2 * (quaternions[0][1] ** 2 + quaternions[0][2] ** 2)])
    np.testing.assert_allclose(z_axis, (0, -1, 0), atol=1e-12)
    core.close()


@pytest.mark.parametrize("spec", [
    ObjectSpec("p", (), shape=Shape.PLANE),                               # a body
    ObjectSpec("p", (1.0,), shape=Shape.PLANE, geometry_only=True),        # a parameter
    ObjectSpec("p", (), shape=Shape.PLANE, geometry_only=True,
               surface=Surface(friction2=0.1, friction_direction=(1, 0, 0))),
    ObjectSpec("p", (0.1,), shape=Shape.CAPSULE),                          # one parameter
    ObjectSpec("p", (0.1, -1.0), shape=Shape.CAPSULE),
    ObjectSpec("p", (0.1,), shape=9),
    ObjectSpec("p", (0.1,), surface=Surface(friction=-1.0)),
    ObjectSpec("p", (0.1,), surface=Surface(bounce=1.5)),
    ObjectSpec("p", (0.1,), surface=Surface(stiffness=0.0)),
    ObjectSpec("p", (0.1,), surface=Surface(friction2=0.2, friction_direction=(0, 0, 0))),
])
def test_bad_shapes_and_surfaces_are_refused_and_build_nothing(spec):
    core = world()
    with pytest.raises(InvalidArgument):
        core.build_object(spec)
    with pytest.raises(InvalidArgument):
        core.build_composite(CompositeSpec([PartSpec("q", (), shape=Shape.PLANE)]))
    assert core.object_ids() == [] and core.poses()[0] == []
    core.close()


def test_a_capsule_has_its_mass_and_stands_on_its_end():
    core = world()
    ground_plane(core)
    r, length, mass = 0.05, 0.3, 2.0
    core.build_object(ObjectSpec("pill", (r, length), shape=Shape.CAPSULE, mass=mass,
                                 position=(0, 0, length / 2 + r + 0.01)))
    m, com, inertia = core.mass_properties("pill")
    cylinder, sphere = math.pi * r * r * length, 4 / 3 * math.pi * r ** 3
    density = mass / (cylinder + sphere)
    m_c, m_s = density * cylinder, density * sphere
    # about its axis: the cylinder's and the sphere's
    assert inertia[2, 2] == pytest.approx(m_c * r * r / 2 + 2 / 5 * m_s * r * r, rel=1e-9)
    assert m == pytest.approx(mass) and np.allclose(com, 0)
    core.step(H, 800)
    assert core.body_state("pill")[0][2] == pytest.approx(length / 2 + r, abs=2e-3)
    core.close()


# ------------------------------------------------------------------ friction

def slide(box_surface=Surface(), ground_surface=Surface(), push=(1.0, 0.0),
          orientation=(1, 0, 0, 0), **world_params):
    """A 1 kg box (turned by ``orientation``, wxyz) launched at 2 m/s along ``push`` (world
    x, y) on a plane: its deceleration (m/s^2)."""
    core = world(**world_params)
    ground_plane(core, ground_surface)
    core.build_object(ObjectSpec("box", (0.4, 0.4, 0.1), mass=1.0, position=(0, 0, 0.05),
                                 orientation=orientation, surface=box_surface))
    core.step(H, 200)
    core.set_velocity("box", linear=(2.0 * push[0], 2.0 * push[1], 0.0))
    core.step(H, 50)
    v0 = np.linalg.norm(core.body_state("box")[2][:2])
    core.step(H, 100)
    v1 = np.linalg.norm(core.body_state("box")[2][:2])
    core.close()
    return (v0 - v1) / 0.1


def test_the_smaller_friction_of_two_surfaces_holds():
    assert slide(Surface(friction=0.2)) == pytest.approx(0.2 * G, rel=1e-3)        # world 1
    assert slide(Surface(friction=0.8), Surface(friction=0.3)) == \
        pytest.approx(0.3 * G, rel=1e-3)
    assert slide(ground_surface=Surface(friction=0.0)) == pytest.approx(0.0, abs=1e-9)
    assert slide(Surface(friction=0.5), friction=0.1) == pytest.approx(0.1 * G, rel=1e-3)


def test_anisotropic_friction_follows_its_direction():
    skate = Surface(friction=1.0, friction2=0.0, friction_direction=(1, 0, 0))
    assert slide(skate, push=(1.0, 0.0)) == pytest.approx(0.0, abs=1e-6)        # along it
    assert slide(skate, push=(0.0, 1.0)) == pytest.approx(1.0 * G, rel=1e-3)    # across it
    # the direction is the object's: turned a quarter about z, the box skates along world y
    quarter = turn((0, 0, 1), math.pi / 2)
    assert slide(skate, push=(0.0, 1.0), orientation=quarter) == pytest.approx(0.0, abs=1e-6)
    assert slide(skate, push=(1.0, 0.0), orientation=quarter) == pytest.approx(G, rel=1e-3)


def test_set_surface_changes_friction_from_now_on():
    core = world()
    ground_plane(core)
    core.build_object(ObjectSpec("box", (0.4, 0.4, 0.1), mass=1.0, position=(0, 0, 0.05)))
    core.step(H, 200)
    core.set_surface("ground", Surface(friction=0.0))
    core.set_velocity("box", linear=(1.0, 0.0, 0.0))
    core.step(H, 100)
    assert core.body_state("box")[2][0] == pytest.approx(1.0, abs=1e-6)
    with pytest.raises(Exception):
        core.set_surface("nothing", Surface(friction=0.1))
    core.close()


# ------------------------------------------------------------------ restitution and softness

def rebound_ratio(ball_surface=Surface(), ground_surface=Surface()) -> float:
    """Outgoing over incoming speed of a ball dropped 0.5 m onto the plane (rigid contact)."""
    core = world(contact_max_correcting_velocity=0.01, cfm=1e-10)
    ground_plane(core, ground_surface)
    core.build_object(ObjectSpec("ball", (0.05,), position=(0, 0, 0.55), surface=ball_surface))
    previous = 0.0
    for _ in range(1000):
        core.step(H)
        v = core.body_state("ball")[2][2]
        if core.last_step_contacts:
            core.close()
            return -v / previous
        previous = v
    raise AssertionError("no impact")


def test_the_larger_restitution_of_two_surfaces_holds():
    assert rebound_ratio(Surface(bounce=0.6)) == pytest.approx(0.6, abs=1e-4)
    assert rebound_ratio(Surface(bounce=0.3), Surface(bounce=0.7)) == pytest.approx(0.7, abs=1e-4)
    assert rebound_ratio() == pytest.approx(0.0, abs=1e-3)                      # world 0


@pytest.mark.parametrize("ground_kp", [None, 2e5])
def test_a_soft_contact_sinks_by_weight_over_stiffness_in_series(ground_kp):
    kp, mass = 1e5, 2.0
    core = world()
    ground_plane(core, Surface(stiffness=ground_kp, damping=400.0) if ground_kp else Surface())
    core.build_object(ObjectSpec("ball", (0.05,), mass=mass, position=(0, 0, 0.05),
                                 surface=Surface(stiffness=kp, damping=400.0)))
    core.step(H, 3000)
    series = kp if ground_kp is None else kp * ground_kp / (kp + ground_kp)
    sink = 0.05 - core.body_state("ball")[0][2]
    layer = core.world_parameters.contact_surface_layer   # ODE lets this much sink for free
    assert sink - layer == pytest.approx(mass * G / series, rel=0.02)
    core.close()


def test_a_snapshot_with_a_plane_comes_back_bit_for_bit():
    core = world()
    ground_plane(core)
    core.build_object(ObjectSpec("ball", (0.1,), position=(0, 0, 0.5)))
    core.save_state("s")
    core.set_poses([("ground", (0, 0, 0.3), (1, 0, 0, 0))])
    core.step(H, 200)
    core.restore_state("s")
    core.step(H, 400)
    after = core.body_state("ball")[0].tobytes()
    core.restore_state("s")
    core.step(H, 400)
    assert core.body_state("ball")[0].tobytes() == after
    assert core.poses()[1][0][2] == 0.0
    core.close()
