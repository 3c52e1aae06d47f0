"""The rehearsal of a build plan (gui.planning.rehearsal.rehearse): the plan built whole in a
Core of this process started as the running world is; the first step the Core refuses is
named, and the plan is left as it was (its predicted IDs, which the real load records)."""
from __future__ import annotations

import dataclasses

import pytest

from gui.errors import GuiError
from gui.planning.rehearsal import rehearse
from odin_common.limits import ResourceLimits
from odin_common.step_values import StepValues
from odin_common.world_parameters import WorldParameters



def _ids(plan) -> list:
    return [(h.motor_ids, h.joint_ids, [b.body_id for b in h.bodies]) for h in plan.robots]


def test_a_plan_the_world_takes_is_taken_and_left_as_it_was(arm_and_box, plan_of):
    plan = plan_of(arm_and_box("fine.xml", 700))
    predicted = _ids(plan)
    rehearse(plan, WorldParameters(), StepValues(), ResourceLimits())
    assert _ids(plan) == predicted


def test_the_first_step_the_core_refuses_is_named(arm_and_box, plan_of):
    plan = plan_of(arm_and_box("away.xml", -4e7))         # 40 km: beyond the 10 km extent
    with pytest.raises(GuiError, match=r"^step \d+/\d+ \(object cube.*\) would be refused: "
                                       r".*world_extent"):
        rehearse(plan, WorldParameters(), StepValues(), ResourceLimits())


def test_the_worlds_limits_are_the_rehearsals(arm_and_box, plan_of):
    plan = plan_of(arm_and_box("three.xml", 700))         # 2 links and a box
    with pytest.raises(GuiError, match="max_objects"):
        rehearse(plan, WorldParameters(), StepValues(), ResourceLimits(max_objects=2))
    rehearse(plan, WorldParameters(), StepValues(), ResourceLimits(max_objects=3))


def test_a_step_over_the_nodes_message_limit_is_refused(arm_and_box, plan_of):
    plan = plan_of(arm_and_box("mesh.xml", 700))
    step = next(s for s in plan.steps if s.bodies and s.owner is None)
    spec = step.spec
    heavy = dataclasses.replace(spec, parameters=tuple(spec.parameters) * 100_000)
    object.__setattr__(step, "spec", heavy)     # 3 numbers x 8 B x 100,000: 2.4 MB
    with pytest.raises(GuiError, match=r"object cube.* would be refused: its request holds "
                                       r"[\d,]+ bytes of mesh arrays.*max_request_mb 1"):
        rehearse(plan, WorldParameters(), StepValues(), ResourceLimits(max_request_mb=1))
