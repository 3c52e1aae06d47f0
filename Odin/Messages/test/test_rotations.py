"""odin_common.rotations against mathematics written here (no ROS needed).

Rotation matrices come from axis-angle by Rodrigues' formula, quaternions from their definition
(cos(a/2), sin(a/2) n), and vectors are rotated by a quaternion with the sandwich product; none
of these use the module under test. The random rotations (fixed seed) and the half-turns about
the axes reach every branch of Shepperd's method in matrix_to_quaternion, and the test asserts
that they do.
"""
import math

import numpy as np
import pytest

from odin_common.errors import InvalidArgument
from odin_common.rotations import (IDENTITY_WXYZ, QUATERNION_TOLERANCE, axis_angle_matrix,
                                   matrix_to_quaternion, pose_matrix, quaternion_multiply,
                                   quaternion_to_matrix, unit_quaternion)

# ------------------------------------------------------------------ independent mathematics


def rodrigues(axis, angle):
    """R = I + sin(a) K + (1 - cos(a)) K^2, K the cross-product matrix of the unit axis."""
    x, y, z = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    K = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * K @ K


def quaternion(axis, angle):
    n = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    return np.array([math.cos(angle / 2), *(math.sin(angle / 2) * n)])


def rotate(q, v):
    """v rotated by the unit quaternion q: v + 2w (u x v) + 2 u x (u x v), u = (x, y, z)."""
    w, u = q[0], np.asarray(q[1:], dtype=float)
    return v + 2 * w * np.cross(u, v) + 2 * np.cross(u, np.cross(u, v))


def canonical(q):
    """q and -q are one rotation; matrix_to_quaternion answers the one with w >= 0."""
    return -q if q[0] < 0 else q


def shepperd_branch(m):
    """Which of Shepperd's four cases a matrix falls in (the largest of w, x, y, z)."""
    if np.trace(m) > 0:
        return "w"
    if m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        return "x"
    return "y" if m[1, 1] > m[2, 2] else "z"


def random_rotations(n, seed):
    rng = np.random.default_rng(seed)
    axes = rng.normal(size=(n, 3))
    angles = rng.uniform(0.0, 2 * math.pi, size=n)
    return list(zip(axes, angles))


def half_turns_near_the_axes(seed):
    """Rotations of nearly pi about axes near x, y and z: w is small, and the largest of
    x, y, z is the one of the axis, so each lands in that axis's branch."""
    rng = np.random.default_rng(seed)
    rotations = []
    for k in range(3):
        for _ in range(20):
            axis = rng.normal(scale=0.3, size=3)
            axis[k] = rng.choice([-1.0, 1.0])
            rotations.append((axis, math.pi + rng.uniform(-0.3, 0.3)))
    return rotations


ROTATIONS = random_rotations(400, seed=7) + half_turns_near_the_axes(seed=11) + [
    ((1, 0, 0), math.pi), ((0, 1, 0), math.pi), ((0, 0, 1), math.pi),   # w = 0 exactly
    ((1, 0, 0), 0.0), ((0, 0, 1), 1e-9), ((1, 1, 1), 2 * math.pi / 3)]


def test_the_rotations_reach_every_branch_of_matrix_to_quaternion():
    branches = [shepperd_branch(rodrigues(axis, angle)) for axis, angle in ROTATIONS]
    for branch in "wxyz":
        assert branches.count(branch) >= 20, f"branch {branch}: {branches.count(branch)}"


# ------------------------------------------------------------------ matrix <-> quaternion


def test_quaternion_to_matrix_is_rodrigues():
    for axis, angle in ROTATIONS:
        np.testing.assert_allclose(quaternion_to_matrix(quaternion(axis, angle)),
                                   rodrigues(axis, angle), atol=1e-12)


def test_matrix_to_quaternion_gives_the_axis_angle_quaternion_in_every_branch():
    for axis, angle in ROTATIONS:
        R = rodrigues(axis, angle)
        q = matrix_to_quaternion(R)
        expected = quaternion(axis, angle)
        if abs(expected[0]) < 1e-12:   # a half-turn: q and -q both have w = 0
            assert min(np.abs(q - expected).max(), np.abs(q + expected).max()) < 1e-12
        else:
            np.testing.assert_allclose(q, canonical(expected), atol=1e-12,
                                       err_msg=f"branch {shepperd_branch(R)}, axis {axis}, "
                                               f"angle {angle}")
        assert q[0] >= 0 and np.linalg.norm(q) == pytest.approx(1.0, abs=1e-15)


def test_matrix_and_quaternion_round_trip_both_ways():
    for axis, angle in ROTATIONS:
        R = rodrigues(axis, angle)
        np.testing.assert_allclose(quaternion_to_matrix(matrix_to_quaternion(R)), R, atol=1e-12)
        q = canonical(quaternion(axis, angle))
        back = matrix_to_quaternion(quaternion_to_matrix(q))
        assert min(np.abs(back - q).max(), np.abs(back + q).max()) < 1e-12


def test_matrix_to_quaternion_reads_the_rotation_of_a_pose():
    axis, angle = (0.2, -1.0, 0.4), 2.2
    T = np.eye(4)
    T[:3, :3] = rodrigues(axis, angle)
    T[:3, 3] = (5.0, -3.0, 1.0)
    np.testing.assert_allclose(matrix_to_quaternion(T), canonical(quaternion(axis, angle)),
                               atol=1e-12)


def test_matrix_to_quaternion_rotates_vectors_like_the_matrix():
    """The quaternion of R_AB maps coordinates in B to A as R_AB does."""
    rng = np.random.default_rng(3)
    for axis, angle in ROTATIONS[:50]:
        R = rodrigues(axis, angle)
        v = rng.normal(size=3)
        np.testing.assert_allclose(rotate(matrix_to_quaternion(R), v), R @ v, atol=1e-12)


# ------------------------------------------------------------------ product order


def test_quaternion_multiply_is_b_then_a():
    """R(a b) = R(a) R(b): a quarter-turn about x then one about z takes x to y; the other
    order takes x to z."""
    about_z, about_x = quaternion((0, 0, 1), math.pi / 2), quaternion((1, 0, 0), math.pi / 2)
    x = np.array([1.0, 0.0, 0.0])
    np.testing.assert_allclose(rotate(quaternion_multiply(about_z, about_x), x), (0, 1, 0),
                               atol=1e-15)
    np.testing.assert_allclose(rotate(quaternion_multiply(about_x, about_z), x), (0, 0, 1),
                               atol=1e-15)


def test_quaternion_multiply_composes_like_the_matrices():
    rng = np.random.default_rng(5)
    pairs = random_rotations(200, seed=13)
    for (axis_a, angle_a), (axis_b, angle_b) in zip(pairs[::2], pairs[1::2]):
        a, b = quaternion(axis_a, angle_a), quaternion(axis_b, angle_b)
        ab = quaternion_multiply(a, b)
        assert np.linalg.norm(ab) == pytest.approx(1.0, abs=1e-12)
        v = rng.normal(size=3)
        expected = rodrigues(axis_a, angle_a) @ rodrigues(axis_b, angle_b) @ v
        np.testing.assert_allclose(rotate(ab, v), expected, atol=1e-12)


def test_quaternion_multiply_by_identity_and_by_the_conjugate():
    q = quaternion((1.0, -2.0, 0.5), 1.3)
    np.testing.assert_allclose(quaternion_multiply(IDENTITY_WXYZ, q), q, atol=1e-15)
    np.testing.assert_allclose(quaternion_multiply(q, IDENTITY_WXYZ), q, atol=1e-15)
    conjugate = q * (1, -1, -1, -1)
    np.testing.assert_allclose(quaternion_multiply(q, conjugate), IDENTITY_WXYZ, atol=1e-15)


# ------------------------------------------------------------------ unit_quaternion


def test_unit_quaternion_normalises_within_the_tolerance():
    q = quaternion((0.3, 0.4, -1.0), 0.8)
    for scale in (1.0, 1 + 0.9 * QUATERNION_TOLERANCE, 1 - 0.9 * QUATERNION_TOLERANCE):
        result = unit_quaternion(q * scale)
        assert result.shape == (4,)
        np.testing.assert_allclose(result, q, atol=1e-15)
    assert isinstance(unit_quaternion([1, 0, 0, 0])[0], np.floating)   # ints are accepted


def test_unit_quaternion_accepts_values_typed_with_three_decimals():
    np.testing.assert_allclose(unit_quaternion((0.707, 0, 0, 0.707)),
                               (math.sqrt(0.5), 0, 0, math.sqrt(0.5)), atol=1e-15)


@pytest.mark.parametrize("scale", [1 + 1.1 * QUATERNION_TOLERANCE, 1 - 1.1 * QUATERNION_TOLERANCE,
                                   2.0, 0.5])
def test_unit_quaternion_refuses_a_norm_off_by_more_than_the_tolerance(scale):
    q = quaternion((0.3, 0.4, -1.0), 0.8) * scale
    with pytest.raises(InvalidArgument, match="not a unit quaternion"):
        unit_quaternion(q, what="grip")


@pytest.mark.parametrize("value,message", [
    ((0, 0, 0, 0), "zero quaternion"),
    ((math.nan, 0, 0, 1), "not finite"),
    ((1, math.inf, 0, 0), "not finite"),
    ((1, 0, 0), "has 3 values"),
    ((1, 0, 0, 0, 0), "has 5 values"),
    ((), "has 0 values"),
    (("w", 0, 0, 0), "not a quaternion"),
    (None, "expected 4"),   # None becomes one NaN
])
def test_unit_quaternion_refuses_what_is_not_a_rotation(value, message):
    with pytest.raises(InvalidArgument, match=message) as error:
        unit_quaternion(value, what="hand pose")
    assert "hand pose" in str(error.value)
    assert isinstance(error.value, ValueError)


# ------------------------------------------------------------------ axis-angle and poses


def test_axis_angle_matrix_is_rodrigues():
    for axis, angle in ROTATIONS[:100]:
        np.testing.assert_allclose(axis_angle_matrix(axis, angle), rodrigues(axis, angle),
                                   atol=1e-12)
    np.testing.assert_allclose(axis_angle_matrix((0, 0, 0), 0.0), np.eye(3))
    with pytest.raises(InvalidArgument):
        axis_angle_matrix((0, 0, 0), 0.5)


def test_pose_matrix_places_the_rotation_and_the_position():
    axis, angle = (1.0, 1.0, 0.0), 0.7
    T = pose_matrix((1.0, 2.0, 3.0), quaternion(axis, angle))
    np.testing.assert_allclose(T[:3, :3], rodrigues(axis, angle), atol=1e-12)
    np.testing.assert_allclose(T[:3, 3], (1.0, 2.0, 3.0))
    np.testing.assert_allclose(T[3], (0, 0, 0, 1))


def test_quaternions_stacked_give_each_one_s_matrix_bit_for_bit():
    rng = np.random.default_rng(5)
    quaternions = rng.normal(size=(7, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1, keepdims=True)
    stacked = quaternion_to_matrix(quaternions.T)          # (4, n) -> (3, 3, n)
    assert stacked.shape == (3, 3, 7)
    for i, q in enumerate(quaternions):
        assert np.array_equal(stacked[:, :, i], quaternion_to_matrix(q))
