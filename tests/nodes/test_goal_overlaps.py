"""load_problem names a query's goal that puts the robot inside something (issue 41, finding
7): a crane of our own whose goal swings its boom through a post is warned about in one line
naming the pair and its depth; the same crane with its goal clear of the post loads with no
such warning; the world is built either way."""
from __future__ import annotations

import pytest
from crane import crane_and_post

pytestmark = pytest.mark.forked


def test_a_goal_through_a_post_is_warned_about_and_a_clear_one_is_not(world, tmp_path):
    through = world.run(["rosrun", "GUI", "load_problem", str(crane_and_post(tmp_path, "0.5"))],
                        timeout=60)
    warned = [line for line in through.stderr.splitlines() if "the query's goal" in line]
    assert len(warned) == 1, through.stderr
    assert warned[0].startswith("load_problem: warning: ")
    # the boom (5 cm thick) across the post (10 cm): 2.5 + 5 cm deep along the boom's width
    assert "crane/boom in post by 75.0 mm" in warned[0], warned[0]
    assert "built " in through.stdout
    clear = world.run(["rosrun", "GUI", "load_problem", str(crane_and_post(tmp_path, "0.75"))],
                      timeout=60)
    assert "the query's goal" not in clear.stderr and "built " in clear.stdout
