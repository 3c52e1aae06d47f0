"""Path files read back as the control vectors of a geometric search
(gui.planning.geometric.path_of_solution): the task files ``plan`` writes, and Kautham's, so
that a path found elsewhere is checked on Odin's geometry as Odin's own are (deepest_along)."""
from __future__ import annotations

import numpy as np
import pytest

from gui.core.kautham.solutions import read_solution
from gui.errors import PlanningError
from gui.planning.geometric import deepest_along, path_of_solution, task_rows, write_task
from test_geometric_motions import _plate_plan
from test_geometric_planning import _plan, _problem


def _read_back(plan, path, tmp_path):
    out = tmp_path / "path.xml"
    write_task(out, "back", task_rows(plan, path))
    return read_solution(out, plan.problem)


def test_an_arms_task_file_reads_back_as_the_controls_that_wrote_it(tmp_path):
    plan = _plan(_problem(tmp_path))
    path = np.array([[0.125, 0.5], [0.3, 0.9], [0.61, 0.2], [0.875, 0.5]])
    np.testing.assert_allclose(path_of_solution(plan, _read_back(plan, path, tmp_path)), path,
                               atol=1e-12)


def test_a_sliding_bases_task_file_reads_back_as_its_controls(tmp_path):
    plan = _plate_plan(tmp_path)
    path = np.array([[0.2, 0.2], [0.4, 0.05], [0.8, 0.2]])
    back = path_of_solution(plan, _read_back(plan, path, tmp_path))
    np.testing.assert_allclose(back, path, atol=1e-12)
    assert deepest_along(plan, back) == (0.0, None)      # south of the wall's end


def test_a_path_through_the_post_is_found_as_deep_as_it_goes(tmp_path):
    """The straight way from start to goal passes through the post (as Kautham's paths that
    its coarser checks let through): read back, deepest_along says how deep, and into what."""
    plan = _plan(_problem(tmp_path))
    path = np.array([[0.125, 0.5], [0.875, 0.5]])
    deepest, pair = deepest_along(plan, path_of_solution(plan, _read_back(plan, path, tmp_path)))
    assert deepest > 0.01 and "post" in pair


def test_a_waypoint_outside_the_control_space_is_refused_naming_its_line(tmp_path):
    """A joint no control moves away from its fixed value: no control vector gives it."""
    plan = _plate_plan(tmp_path)
    rows = task_rows(plan, np.array([[0.2, 0.2], [0.8, 0.2]]))
    rows[1][2] += 0.05                                   # the plate's z, which no control moves
    out = tmp_path / "off.xml"
    write_task(out, "off", rows)
    with pytest.raises(PlanningError, match=r"off\.xml:\d+: robot plate's configuration is "
                                            r"0\.05 from any of the problem's control space"):
        path_of_solution(plan, read_solution(out, plan.problem))
