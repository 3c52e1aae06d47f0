"""Exempt Overlaps: pairs built inside each other do not collide until they have parted, then
collide as any pair; which pairs are still exempt is state that snapshots and body state
vectors carry bit for bit (virtual_world.core.exemptions)."""
import numpy as np
import pytest

from virtual_world.core import ObjectSpec
from virtual_world.errors import InvalidArgument

H = 0.001
WALL_FACE = 0.4      # m: the wall spans x 0.4 .. 0.6
BOX_HALF = 0.1       # m: the box's half size


def box_in_wall(core, x=0.35, name="box", y=0.0):
    """A static wall and a free box (no gravity) built x + 0.1 - 0.4 m (50 mm) inside it."""
    if "wall" not in core.object_ids():
        core.build_object(ObjectSpec("wall", [0.2, 1, 1], position=(0.5, 0, 0),
                                     geometry_only=True))
    core.build_object(ObjectSpec(name, [2 * BOX_HALF] * 3, position=(x, y, 0)))


def x_of(core, name="box"):
    return float(core.body_state(name)[0][0])


def test_without_an_exemption_the_wall_pushes_the_box_out(core):
    box_in_wall(core)
    core.step(H, 200)
    assert x_of(core) < 0.34        # ODE's contacts moved it by more than 10 mm


def test_an_exempt_box_stays_where_it_was_built_then_meets_the_wall_once_out(core):
    box_in_wall(core)
    (pair,) = core.exempt_overlaps(0.001)
    assert (pair.first, pair.second) == ("box", "wall") and pair.depth == pytest.approx(0.05)
    core.step(H, 200)
    assert x_of(core) == 0.35                              # not pushed, not a bit
    assert [(c.first, c.second) for c in core.read_collisions()] == [("box", "wall")]
    core.set_velocity("box", linear=(-0.5, 0, 0))          # out of the wall...
    core.step(H, 150)
    assert x_of(core) + BOX_HALF < WALL_FACE - 0.02
    core.set_velocity("box", linear=(0.5, 0, 0))           # ...and back: it has parted
    core.step(H, 400)
    assert x_of(core) + BOX_HALF < WALL_FACE + 0.002       # stopped at the face
    assert x_of(core) + BOX_HALF > WALL_FACE - 0.01


def test_an_exempt_pair_may_move_apart_never_further_in(core):
    box_in_wall(core)
    core.exempt_overlaps(0.001)
    core.set_velocity("box", linear=(0.5, 0, 0))           # further into the wall
    core.step(H, 200)
    assert core.body_state_vector()[-1] == 0.0             # parted: it collides
    assert x_of(core) < 0.35 + 0.0015                      # stopped 1 mm deeper than built


def test_a_collision_query_changes_no_exemption(core):
    box_in_wall(core)
    core.exempt_overlaps(0.001)
    for x, touching in ((0.2, False), (0.45, True)):       # apart; far deeper than built
        assert bool(core.check_collision([("box", (x, 0, 0), (1, 0, 0, 0))])) == touching
    assert core.body_state_vector()[-1] == 1.0
    core.step(H, 100)
    assert x_of(core) == 0.35                              # still exempt: not pushed


def test_a_pair_parts_when_no_deeper_than_the_depth_asked(core):
    box_in_wall(core)
    core.exempt_overlaps(0.03)                             # 50 mm deep: exempt
    core.set_velocity("box", linear=(-0.5, 0, 0))          # 20 mm out in 40 ms: 30 mm deep
    core.step(H, 45)
    assert core.body_state_vector()[-1] == 0.0             # parted while still inside


def test_shallow_and_static_pairs_are_not_exempt(core):
    core.build_object(ObjectSpec("wall", [0.2, 1, 1], position=(0.5, 0, 0), geometry_only=True))
    core.build_object(ObjectSpec("post", [0.2, 0.2, 0.2], position=(0.35, 0, 0),
                                 geometry_only=True))      # static in static
    core.build_object(ObjectSpec("box", [0.2] * 3, position=(0.2995, 0.5, 0)))  # 0.5 mm deep
    assert core.exempt_overlaps(0.001) == []
    assert core.body_state_vector().size == 1 + 26


def test_the_state_vector_carries_the_exemptions_and_propagation_is_bit_identical(core):
    box_in_wall(core)
    core.exempt_overlaps(0.001)
    inside = core.body_state_vector()
    assert inside.size == 1 + 26 + 1 and inside[-1] == 1.0
    core.set_velocity("box", linear=(-0.5, 0, 0))
    core.step(H, 150)
    assert core.body_state_vector()[-1] == 0.0             # parted
    fast = core.propagate_state(inside, 0.05, H)
    assert fast.state[-1] == 1.0 and fast.state[1] == 0.35  # put back: still exempt, unpushed
    kept = core.propagate(0.05, H, start_state=inside, keep=True)
    assert kept.state.tobytes() == fast.state.tobytes()
    core.set_body_state_vector(inside)
    core.step(H, 50)
    assert core.body_state_vector().tobytes() == fast.state.tobytes()


def test_a_bad_exempt_state_is_refused_and_changes_nothing(core):
    box_in_wall(core)
    core.exempt_overlaps(0.001)
    good = core.body_state_vector()
    for value in (0.5, np.nan, 2.0):
        bad = good.copy()
        bad[-1] = value
        with pytest.raises(InvalidArgument, match="exempt pair's state"):
            core.set_body_state_vector(bad)
        with pytest.raises(InvalidArgument, match="exempt pair's state"):
            core.propagate_state(bad, 0.01, H)
        assert core.body_state_vector().tobytes() == good.tobytes()
    with pytest.raises(InvalidArgument, match=r"1 \+ 26 per body \+ 1 exempt pairs"):
        core.set_body_state_vector(good[:-1])
    with pytest.raises(InvalidArgument, match="negative"):
        core.exempt_overlaps(-0.001)


def test_snapshots_hold_the_exemptions_and_refuse_another_list(core):
    box_in_wall(core)
    core.save_state("before")                              # no exemptions yet
    core.exempt_overlaps(0.001)
    core.save_state("inside")
    core.set_velocity("box", linear=(-0.5, 0, 0))
    core.step(H, 150)                                      # parted
    core.restore_state("inside")
    core.step(H, 100)
    assert x_of(core) == 0.35                              # exempt again: not pushed
    with pytest.raises(InvalidArgument, match="exempt pairs added since"):
        core.restore_state("before")


def test_removing_an_object_drops_its_pairs_and_keeps_the_others_state(core):
    box_in_wall(core)
    box_in_wall(core, x=0.38, name="other", y=0.3)         # 80 mm in, beside the box
    core.exempt_overlaps(0.001)
    assert core.body_state_vector().size == 1 + 2 * 26 + 2
    core.set_velocity("box", linear=(-0.5, 0, 0))
    core.step(H, 150)                                      # box parted, other still inside
    assert list(core.body_state_vector()[-2:]) == [0.0, 1.0]
    core.remove_object("box")
    vector = core.body_state_vector()
    assert vector.size == 1 + 26 + 1 and vector[-1] == 1.0
    core.step(H, 100)
    assert x_of(core, "other") == 0.38


def test_a_new_scene_has_no_exemptions(core):
    box_in_wall(core)
    core.exempt_overlaps(0.001)
    core.new_scene()
    box_in_wall(core)
    assert core.body_state_vector().size == 1 + 26
    core.step(H, 200)
    assert x_of(core) < 0.34
