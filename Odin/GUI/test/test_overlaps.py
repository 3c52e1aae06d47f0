"""Parts a problem builds inside each other (gui.core.overlaps): which pairs count, and the
line the user reads."""
from __future__ import annotations

from gui.core.overlaps import BUILT_OVERLAP, Overlap, built_overlaps, overlap_warning
from gui.core.kautham.problem import load_problem
from gui.core.translate import plan_problem

TWO_COLUMNS = ("legacy_2012", "examples", "Staubli_R6_two_columns.xml")


def test_deep_pairs_with_a_part_that_moves_count_deepest_first(kautham_dir):
    plan = plan_problem(load_problem(kautham_dir.joinpath(*TWO_COLUMNS)))
    statics = [p.name for b in plan.bodies() if b.geometry_only for p in b.parts]
    assert len(statics) >= 2              # the columns: one composite of static parts
    pairs = [("TX90/Elbow", statics[0], 0.0045),
             ("TX90/Arm", statics[1], 0.02),
             (statics[0], statics[1], 0.5),                  # two static parts: never pushed
             ("TX90/Tcp", statics[0], BUILT_OVERLAP / 2)]   # resting contact's depth
    assert built_overlaps(plan, pairs) == [Overlap("TX90/Arm", statics[1], 0.02),
                                           Overlap("TX90/Elbow", statics[0], 0.0045)]
    assert built_overlaps(plan, []) == []


def test_the_warning_names_the_file_the_deepest_pairs_and_counts_the_rest():
    overlaps = [Overlap(f"arm/link{k}", "floor", 0.01 - k * 0.001) for k in range(5)]
    line = overlap_warning("p.xml", overlaps, exempt=True)
    assert line.startswith("p.xml: built with parts inside each other, where the problem "
                           "places them: arm/link0 in floor by 10.0 mm, arm/link1 in floor by "
                           "9.0 mm, arm/link2 in floor by 8.0 mm and 2 more pairs; they do not "
                           "collide until they have moved apart")
    assert "\n" not in line
    assert "more" not in overlap_warning("p.xml", overlaps[:1], exempt=True)
    assert overlap_warning("p.xml", overlaps[:1], exempt=False).endswith(
        "; their contacts push them apart when the world runs, as in Kautham's ODE world")


def test_a_problem_kautham_never_simulates_stands_where_it_places_its_parts(arm_and_box):
    """A 2012 arm without <Home> at the origin, its link 50 mm inside a box of the scene:
    built, its pair exempt, and after 1 s of simulation the link is where it was built; the
    same arm clear of the box has nothing to exempt."""
    import numpy as np
    from gui_core_world import CoreWorld
    for name, box_x_mm, expected in (("inside.xml", 50.0, 1), ("clear.xml", 500.0, 0)):
        path = arm_and_box(name, box_x_mm)
        plan = plan_problem(load_problem(path))
        world = CoreWorld()
        try:
            ids = world.execute(plan)
            assert ids["overlaps_exempt"] and len(ids["overlaps"]) == expected
            built = world.position("arm/J1")
            world.run(1.0)
            assert np.linalg.norm(world.position("arm/J1") - built) < 0.001
        finally:
            world.close()
