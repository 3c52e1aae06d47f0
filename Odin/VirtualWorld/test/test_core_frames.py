"""Frames and offsets through the Core, checked against mathematics written here.

Rotation matrices come from axis-angle by Rodrigues' formula and quaternions from their
definition (cos(a/2), sin(a/2) n); the Core's quaternions are read back by rotating vectors
with the sandwich product. Nothing here uses the Core's or odin_common's rotation helpers.
The composites have parts of different masses, so their centre of mass (where ODE puts the
body) is off the composite's frame: every body-frame point must be shifted by it, and every
part's pose must compose T_world_composite @ T_composite_part in that order.
"""
import math

import numpy as np
import pytest

from odin_common import interface
from virtual_world.core import CompositeSpec, FORCE, ObjectSpec, PartSpec, TORQUE


# ------------------------------------------------------------------ independent mathematics


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def rodrigues(axis, angle):
    """R = I + sin(a) K + (1 - cos(a)) K^2, K the cross-product matrix of the unit axis."""
    x, y, z = unit(axis)
    K = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * K @ K


def quaternion(axis, angle):
    """(w, x, y, z) of the rotation by `angle` about `axis`."""
    return (math.cos(angle / 2), *(math.sin(angle / 2) * unit(axis)))


def rotate(q, v):
    """v rotated by the unit quaternion q: v + 2w (u x v) + 2 u x (u x v), u = (x, y, z)."""
    w, u = q[0], np.asarray(q[1:], dtype=float)
    v = np.asarray(v, dtype=float)
    return v + 2 * w * np.cross(u, v) + 2 * np.cross(u, np.cross(u, v))


def matrix_of(q):
    """The rotation matrix of a quaternion the Core returned: its columns are the images of
    the axes (a quaternion and its negative give the same matrix)."""
    q = np.asarray(q, dtype=float)
    assert np.linalg.norm(q) == pytest.approx(1.0, abs=1e-9)
    return np.column_stack([rotate(q, e) for e in np.eye(3)])


def transform(position, R):
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = position
    return T


def box_inertia(mass, sides):
    a, b, c = sides
    return mass / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def moved_inertia(inertia_about_own_centre, R, mass, offset):
    """A part's inertia rotated into the body's axes and moved (parallel axes) by `offset`."""
    d = np.asarray(offset, dtype=float)
    return R @ inertia_about_own_centre @ R.T + mass * (d @ d * np.eye(3) - np.outer(d, d))


# ------------------------------------------------------------------ the scene

# rotations chosen so that no two commute: swapping a product's order changes the result
COMPOSITE_ROTATION = ((1.0, 2.0, 0.5), 0.9)
PARTS = (   # name, shape, mass, position in the composite frame, (axis, angle) in that frame
    ("slab", (0.4, 0.2, 0.1), 3.0, (0.4, 0.1, 0.0), ((0.0, 0.0, 1.0), math.pi / 3)),
    ("peg", (0.05, 0.3), 0.5, (0.0, -0.3, 0.2), ((1.0, 0.0, 0.0), math.pi / 2)),
    ("knob", (0.08,), 1.0, (-0.2, 0.2, -0.1), ((0.3, -1.0, 0.2), 2.0)),
)
TOTAL_MASS = sum(p[2] for p in PARTS)
CENTRE = sum(p[2] * np.array(p[3]) for p in PARTS) / TOTAL_MASS   # composite frame


def part_inertia(shape, mass):
    if len(shape) == 3:
        return box_inertia(mass, shape)
    if len(shape) == 2:   # cylinder along z
        r, length = shape
        side = mass * (3 * r * r + length * length) / 12.0
        return np.diag([side, side, mass * r * r / 2.0])
    return 0.4 * mass * shape[0] ** 2 * np.eye(3)


INERTIA = sum(moved_inertia(part_inertia(shape, m), rodrigues(*rotation), m,
                            np.array(position) - CENTRE)
              for _, shape, m, position, rotation in PARTS)   # about CENTRE, composite axes


def composite(prefix, position, rotation=COMPOSITE_ROTATION, **flags):
    parts = [PartSpec(prefix + name, list(shape), mass=m, position=p,
                      orientation=quaternion(*rot))
             for name, shape, m, p, rot in PARTS]
    return CompositeSpec(parts, position=position, orientation=quaternion(*rotation), **flags)


def composite_id(prefix):
    return interface.composite_id([prefix + p[0] for p in PARTS])


def assert_parts_posed(core, prefix, position, rotation):
    """Every part's world pose from core.poses() equals T_world_composite @ T_composite_part."""
    names, positions, quaternions = core.poses()
    T_world_composite = transform(position, rodrigues(*rotation))
    for name, _, _, part_position, part_rotation in PARTS:
        i = names.index(prefix + name)
        expected = T_world_composite @ transform(part_position, rodrigues(*part_rotation))
        np.testing.assert_allclose(positions[i], expected[:3, 3], atol=1e-12,
                                   err_msg=f"position of part {prefix + name}")
        np.testing.assert_allclose(matrix_of(quaternions[i]), expected[:3, :3], atol=1e-12,
                                   err_msg=f"orientation of part {prefix + name}")


# ------------------------------------------------------------------ part poses


def test_the_scene_rotations_do_not_commute():
    composite_R = rodrigues(*COMPOSITE_ROTATION)
    for *_, rotation in PARTS:
        R = rodrigues(*rotation)
        assert np.abs(composite_R @ R - R @ composite_R).max() > 0.1


def test_parts_of_a_rotated_static_composite_are_posed_composite_then_part(core):
    position = (1.0, -2.0, 0.5)
    core.build_composite(composite("s_", position, geometry_only=True))
    assert_parts_posed(core, "s_", position, COMPOSITE_ROTATION)


def test_a_rotated_static_composite_moved_by_set_poses_keeps_its_parts_in_place(core):
    core.build_composite(composite("s_", (0.0, 0.0, 0.0), geometry_only=True))
    rotation = ((-0.4, 0.7, 1.0), 2.5)
    core.set_poses([(composite_id("s_"), (3.0, 1.0, -1.0), quaternion(*rotation))])
    assert_parts_posed(core, "s_", (3.0, 1.0, -1.0), rotation)


@pytest.mark.parametrize("fixed", [False, True], ids=["dynamic", "fixed"])
def test_parts_of_a_rotated_body_composite_are_posed_composite_then_part(core, fixed):
    position = (-1.0, 0.5, 2.0)
    core.build_composite(composite("d_", position, fixed=fixed))
    assert_parts_posed(core, "d_", position, COMPOSITE_ROTATION)
    # the body state gives the composite's frame back (not the centre of mass)
    origin, q, _, _ = core.body_state(composite_id("d_"))
    np.testing.assert_allclose(origin, position, atol=1e-12)
    np.testing.assert_allclose(matrix_of(q), rodrigues(*COMPOSITE_ROTATION), atol=1e-12)
    rotation = ((0.0, 1.0, -1.0), -1.2)
    core.set_poses([(composite_id("d_"), (0.0, 4.0, 0.0), quaternion(*rotation))])
    assert_parts_posed(core, "d_", (0.0, 4.0, 0.0), rotation)
    core.step(0.001, 10)   # no gravity, no velocity: nothing moves
    assert_parts_posed(core, "d_", (0.0, 4.0, 0.0), rotation)


def test_a_composite_of_rotated_parts_has_their_rotated_and_moved_inertia(core):
    core.build_composite(composite("d_", (0.0, 0.0, 0.0)))
    mass, centre, inertia = core.mass_properties(composite_id("d_"))
    assert mass == pytest.approx(TOTAL_MASS)
    np.testing.assert_allclose(centre, CENTRE, atol=1e-12)
    np.testing.assert_allclose(inertia, INERTIA, atol=1e-12)


# a file's mass properties (a URDF <inertial>): a tensor about a centre of mass off the origin
GIVEN_INERTIA = np.array([[0.30, 0.02, -0.01], [0.02, 0.25, 0.03], [-0.01, 0.03, 0.20]])
GIVEN_CENTRE = np.array([0.05, -0.10, 0.20])


def _six(i):
    return [i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]]


def test_an_object_takes_a_given_inertia_about_a_given_centre_of_mass(core):
    core.build_object(ObjectSpec("arm", [0.1, 0.2, 0.3], mass=2.0, inertia=_six(GIVEN_INERTIA),
                                 center_of_mass=tuple(GIVEN_CENTRE), position=(1.0, 0, 0)))
    mass, centre, inertia = core.mass_properties("arm")
    assert mass == pytest.approx(2.0)
    np.testing.assert_allclose(centre, GIVEN_CENTRE, atol=1e-12)
    np.testing.assert_allclose(inertia, GIVEN_INERTIA, atol=1e-12)
    # the body sits at the centre of mass: a force there (world point) gives no spin
    core.add_body_force("arm", FORCE, (0.0, 0.0, 10.0), at_point=True,
                        point=tuple(np.array([1.0, 0, 0]) + GIVEN_CENTRE))
    core.step(H)
    _, _, linear, angular = core.body_state("arm")
    np.testing.assert_allclose(linear, (0.0, 0.0, 10.0 * H / 2.0), atol=1e-12)
    np.testing.assert_allclose(angular, 0.0, atol=1e-12)


def test_a_composite_takes_a_given_inertia_instead_of_its_parts_and_keeps_their_mass(core):
    spec = composite("g_", (0.0, 0.0, 0.0))
    spec = CompositeSpec(spec.parts, orientation=spec.orientation,
                         inertia=_six(GIVEN_INERTIA), center_of_mass=tuple(GIVEN_CENTRE))
    core.build_composite(spec)
    mass, centre, inertia = core.mass_properties(composite_id("g_"))
    assert mass == pytest.approx(TOTAL_MASS)
    np.testing.assert_allclose(centre, GIVEN_CENTRE, atol=1e-12)
    np.testing.assert_allclose(inertia, GIVEN_INERTIA, atol=1e-12)


@pytest.mark.parametrize("spec,fragment", [
    (ObjectSpec("c", [0.1], center_of_mass=(0.0, 0.0, 0.1)), "center_of_mass needs an inertia"),
    (ObjectSpec("c", [0.1], inertia=[1, 1, 1, 0, 0, 0], center_of_mass=(0.0, 0.1)),
     "expected 3"),
])
def test_a_bad_centre_of_mass_is_refused_and_builds_nothing(core, spec, fragment):
    from virtual_world.errors import InvalidArgument
    with pytest.raises(InvalidArgument, match=fragment):
        core.build_object(spec)
    assert core.object_ids() == []


# ------------------------------------------------------------------ forces at points

H = 0.01          # one step: from rest, ODE's step is exact (v = F h / m, I w = tau h)
POSITION = np.array([1.0, 2.0, 3.0])


def build_rotated(core):
    """A rotated composite at rest; returns its id, rotation matrix and world centre of mass."""
    core.build_composite(composite("f_", tuple(POSITION)))
    R = rodrigues(*COMPOSITE_ROTATION)
    return composite_id("f_"), R, POSITION + R @ CENTRE


def angular_momentum(core, object_id, R):
    """I_world w about the centre of mass (R the orientation the step started from)."""
    return R @ INERTIA @ R.T @ core.body_state(object_id)[3]


def test_the_scene_centre_of_mass_is_off_the_composite_frame():
    assert np.linalg.norm(CENTRE) > 0.1


def test_a_force_through_the_centre_of_mass_at_a_world_point_gives_no_spin(core):
    cid, R, centre_W = build_rotated(core)
    F = np.array([3.0, -4.0, 2.0])
    core.add_body_force(cid, FORCE, F, at_point=True, point=centre_W)
    core.step(0.001, 200)
    _, _, v, w = core.body_state(cid)
    np.testing.assert_allclose(w, 0.0, atol=1e-9)
    np.testing.assert_allclose(v, F / TOTAL_MASS * 0.2, rtol=1e-9)


def test_a_force_through_the_centre_of_mass_at_a_body_frame_point_gives_no_spin(core):
    cid, R, _ = build_rotated(core)
    F_body = np.array([0.0, 5.0, -1.0])
    core.add_body_force(cid, FORCE, F_body, vector_in_body_frame=True, at_point=True,
                        point=CENTRE, point_in_body_frame=True)
    core.step(0.001, 200)
    origin, q, v, w = core.body_state(cid)
    np.testing.assert_allclose(w, 0.0, atol=1e-9)
    np.testing.assert_allclose(matrix_of(q), R, atol=1e-9)
    np.testing.assert_allclose(v, R @ F_body / TOTAL_MASS * 0.2, rtol=1e-9)


OFF_CENTRE_BODY = np.array([0.3, -0.2, 0.25])    # a point in the composite frame


@pytest.mark.parametrize("vector_in_body", [False, True], ids=["world_vector", "body_vector"])
@pytest.mark.parametrize("point_in_body", [False, True], ids=["world_point", "body_point"])
def test_an_off_centre_force_gives_the_torque_r_cross_f(core, vector_in_body, point_in_body):
    cid, R, centre_W = build_rotated(core)
    F = np.array([1.0, -2.0, 4.0])   # in the frame the call says
    F_W = R @ F if vector_in_body else F
    point_W = POSITION + R @ OFF_CENTRE_BODY
    point = OFF_CENTRE_BODY if point_in_body else point_W
    core.add_body_force(cid, FORCE, F, vector_in_body_frame=vector_in_body, at_point=True,
                        point=point, point_in_body_frame=point_in_body)
    core.step(H)
    torque = np.cross(point_W - centre_W, F_W)
    assert np.linalg.norm(torque) > 0.5
    np.testing.assert_allclose(angular_momentum(core, cid, R), torque * H, rtol=1e-9,
                               atol=1e-12)
    np.testing.assert_allclose(core.body_state(cid)[2], F_W / TOTAL_MASS * H, rtol=1e-9)


def test_a_force_below_the_centre_of_mass_turns_the_body_the_signed_way(core):
    """Unrotated, so the sign reads off: r = (0, 0, -0.5) below the centre, F = (2, 0, 0):
    r x F = (0, -1, 0), the bottom goes +x and the top -x (a turn about -y)."""
    core.build_composite(composite("u_", (0.0, 0.0, 0.0), rotation=((0.0, 0.0, 1.0), 0.0)))
    cid = composite_id("u_")
    core.add_body_force(cid, FORCE, (2.0, 0.0, 0.0), at_point=True,
                        point=CENTRE - (0.0, 0.0, 0.5), point_in_body_frame=True)
    core.step(H)
    w = core.body_state(cid)[3]
    L = INERTIA @ w
    np.testing.assert_allclose(L, (0.0, -1.0 * H, 0.0), atol=1e-12)


@pytest.mark.parametrize("vector_in_body", [False, True], ids=["world_torque", "body_torque"])
def test_a_torque_in_the_world_or_the_body_frame(core, vector_in_body):
    cid, R, _ = build_rotated(core)
    tau = np.array([0.5, 1.0, -0.3])
    core.add_body_force(cid, TORQUE, tau, vector_in_body_frame=vector_in_body)
    core.step(H)
    tau_W = R @ tau if vector_in_body else tau
    np.testing.assert_allclose(angular_momentum(core, cid, R), tau_W * H, rtol=1e-9)
    np.testing.assert_allclose(core.body_state(cid)[2], 0.0, atol=1e-12)


def test_a_body_frame_force_on_a_single_rotated_object_acts_along_its_rotated_axis(core):
    rotation = ((0.0, 0.0, 1.0), math.pi / 2)   # body x is world y
    core.build_object(ObjectSpec("o", [0.2, 0.2, 0.2], mass=2.0, position=(0.0, 0.0, 0.0),
                                 orientation=quaternion(*rotation)))
    core.add_body_force("o", FORCE, (1.0, 0.0, 0.0), vector_in_body_frame=True)
    core.step(H)
    np.testing.assert_allclose(core.body_state("o")[2], (0.0, 0.5 * H, 0.0), atol=1e-12)
