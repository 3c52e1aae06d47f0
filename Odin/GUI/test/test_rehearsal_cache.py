"""What a rehearsal proved, kept by content (gui.planning.rehearsal_cache): a plan taken once
by a Core that started as a world is not rehearsed again for that world; anything that could
change the outcome (a value of a step, the world, the Core's code) is another entry; refusals
are never kept; --no-cache turns it off."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from gui.core import shape_cache
from gui.errors import GuiError
from gui.planning import rehearsal, rehearsal_cache as cache
from odin_common.limits import ResourceLimits
from odin_common.step_values import StepValues
from odin_common.world_parameters import WorldParameters

WORLD = (WorldParameters(), StepValues(), ResourceLimits())


@pytest.fixture(autouse=True)
def private_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("ODIN_CACHE_DIR", str(tmp_path / "cache"))
    shape_cache.set_enabled(True)
    yield
    shape_cache.set_enabled(True)


@pytest.fixture
def rehearsals(monkeypatch):
    """The plans rehearse was really asked to build, in order."""
    built = []
    real = rehearsal.rehearse

    def counted(plan, *world):
        built.append(plan)
        real(plan, *world)
    monkeypatch.setattr(rehearsal, "rehearse", counted)
    return built



def test_the_same_problem_read_twice_has_one_digest_and_another_value_another(arm_and_box, plan_of):
    path = arm_and_box("same.xml", 700)
    first, again = plan_of(path), plan_of(path)
    assert cache.plan_digest(first) == cache.plan_digest(again) is not None
    step = next(s for s in again.steps if s.bodies and s.owner is None)
    moved = np.array(step.spec.position, dtype=float)
    moved[0] = np.nextafter(moved[0], np.inf)           # the last bit of one coordinate
    object.__setattr__(step, "spec", dataclasses.replace(step.spec, position=tuple(moved)))
    assert cache.plan_digest(again) != cache.plan_digest(first)


def test_a_plan_taken_is_not_rehearsed_again_for_that_world_only(arm_and_box, plan_of, rehearsals):
    plan = plan_of(arm_and_box("taken.xml", 700))
    key = cache.plan_digest(plan)
    assert not cache.seen(key)
    for _ in range(2):
        rehearsal._rehearse_once(plan, *WORLD, key)
    assert len(rehearsals) == 1 and cache.seen(key)
    fewer = ResourceLimits(max_objects=50)               # another world: rehearsed again
    rehearsal._rehearse_once(plan, WORLD[0], WORLD[1], fewer, key)
    assert len(rehearsals) == 2


def test_a_refusal_is_never_kept(arm_and_box, plan_of, rehearsals):
    plan = plan_of(arm_and_box("three.xml", 700))         # 2 links and a box
    key, small = cache.plan_digest(plan), ResourceLimits(max_objects=2)
    for _ in range(2):
        with pytest.raises(GuiError, match="max_objects"):
            rehearsal._rehearse_once(plan, WORLD[0], WORLD[1], small, key)
    assert len(rehearsals) == 2 and not cache.seen(key)


def test_no_cache_rehearses_every_time(arm_and_box, plan_of, rehearsals):
    plan = plan_of(arm_and_box("nocache.xml", 700))
    key = cache.plan_digest(plan)
    shape_cache.set_enabled(False)
    for _ in range(2):
        rehearsal._rehearse_once(plan, *WORLD, key)
    assert len(rehearsals) == 2 and not cache.seen(key)


def test_a_value_the_digest_cannot_encode_exactly_keeps_nothing(arm_and_box, plan_of, rehearsals):
    plan = plan_of(arm_and_box("odd.xml", 700))
    plan.steps.append(object())                        # no exact encoding: not kept
    assert cache.plan_digest(plan) is None
    plan.steps.pop()
    for _ in range(2):
        rehearsal._rehearse_once(plan, *WORLD, None)
    assert len(rehearsals) == 2


def test_the_cores_code_is_part_of_the_digest(arm_and_box, plan_of, monkeypatch):
    plan = plan_of(arm_and_box("code.xml", 700))
    before = cache.plan_digest(plan)
    monkeypatch.setattr(cache, "_code_digest", "another Core")
    assert cache.plan_digest(plan) != before
