"""The thesis's three experiments (chapter 10) and Kautham's physics demos end to end: each
runs its own roscore, the world and Viewer nodes by rosrun and this process as the GUI
(tools/experiments), and its outcome is asserted on what the nodes published and what the
Viewer drew.

Each test runs in a forked child (rospy.init_node works once per process). The world is
deterministic for the same calls: two runs of each experiment recorded the same figures.
"""
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools" / "experiments"))

pytestmark = pytest.mark.slow       # 8-50 s each: a whole experiment


@pytest.mark.forked
def test_contactless_pair_greys_exactly_while_touching(kautham_dir):
    import contactless
    facts = contactless.run()
    o = facts["outcome"]
    assert o["pairs_reported"] == [["KukaLWR/Link7", "can"]], \
        f"pairs reported: {o['pairs_reported']}"
    assert o["collision_runs"] == 1, f"the pair touched in {o['collision_runs']} runs of cycles"
    # the meshes first and last overlap at 0.228453 s and 0.563414 s (the can's prescribed
    # motion against the link's mesh, computed without the collision engine); the Collided
    # messages show the pair from 0.230 s and without it from 0.565 s: 1.547 and 1.586 ms
    # later, inside the window [0, 2 ms] of one 1 ms step per cycle whose collisions are
    # those of the poses at its start (contactless.LAG_WINDOW_S)
    low, high = contactless.LAG_WINDOW_S
    slack = contactless.LAG_SLACK_S
    for edge in ("start", "stop"):
        lag = o[f"{edge}_lag_s"]
        assert lag is not None and low - slack <= lag <= high + slack, (
            f"collision {edge} reported at {o[f'collision_{edge}_s']} s, the meshes' overlap "
            f"{edge}s at {o[f'geometric_{edge}_s']} s: {lag} s apart, not in [{low}, {high}] s")
    # 3.56 mm; the link reaches 3.54 mm into the can's outline
    assert 0.0005 < o["max_depth_m"] < 0.01, f"max depth {o['max_depth_m']} m"
    assert o["collided_messages"] >= o["cycles"], \
        f"{o['collided_messages']} Collided messages for {o['cycles']} cycles"
    frames = facts["frames"]
    assert frames["frames_touching"] >= 5 and frames["frames_free"] >= 5, \
        f"{frames['frames_touching']} frames touching, {frames['frames_free']} free"
    assert frames["can_grey_exactly_while_touching"], "frames (t s, touching, red share): " + \
        ", ".join(f"{r['t_s']} {r['touching']} {r['can_red_share']}" for r in frames["per_frame"])
    assert frames["tip_grey_exactly_while_touching"], "frames (t s, touching, brightness): " + \
        ", ".join(f"{r['t_s']} {r['touching']} {r['tip_brightness_ratio']}"
                  for r in frames["per_frame"])


@pytest.mark.forked
def test_pile_cans_knocked_down_fall_and_bounce(kautham_dir):
    import pile
    facts = pile.run(frames=False)
    o = facts["outcome"]
    cans = o["cans"]
    # the base turns from 0.04 s at 0.1 rad/s; the geometry (the arm's meshes turned about the
    # Shoulder axis into the cans' cylinders) puts the first touch at 1.04277 s; the first
    # hand-can contact is reported at 1.08 s (Ring-Med & can_2), 37 ms later
    low, high = pile.CONTACT_WINDOW_S
    assert o["hand_contact_when_the_arm_reaches_the_pile"], (
        f"first hand-can contact at {o['first_hand_contact_s']} s "
        f"({o['first_hand_contact_pairs']}), the arm reaches the pile at "
        f"{o['arm_reaches_pile_at_s']} s: {o['first_hand_contact_lag_s']} s apart, not in "
        f"[{low}, {high}] s")
    for name, can in cans.items():
        # the top can falls at 1.40 s, the bottom one at 1.52 s
        assert can["falls_after_the_hand_touches_the_pile"], (
            f"{name} fell at {can['falls_at_s']} s, the hand first touched the pile at "
            f"{o['first_hand_contact_s']} s")
        assert can["moved_m"] > 0.2, f"{name} moved {can['moved_m']} m"
        assert can["knocked_off_the_table"], f"{name} stayed on the table: {can['end_m']}"
        # on the floor at 3.04 s (top can) and 2.48 s (bottom can), both bounce
        assert can["hit_ground"] and can["bounced"] and not can["fell_past_the_floor_edge"], (
            f"{name}: hit the floor {can['hit_ground']} (at {can['hit_ground_at_s']} s), "
            f"bounced {can['bounced']}, fell past the floor's edge "
            f"{can['fell_past_the_floor_edge']}, ends at {can['end_m']}")


@pytest.mark.forked
def test_grasp_carries_the_can_and_releases_it_when_the_hand_opens(tmp_path, kautham_dir):
    """The thesis's driving: the approach teleported row by row, then velocity rows."""
    import grasp
    facts = grasp.run(frames=False, out_root=tmp_path, mode="velocity")
    o = facts["outcome"]
    h = o["can_height_above_table_while_carried_m"]
    assert h["min"] > 0.1, f"carried as low as {h['min']} m above the table"
    assert o["can_moved_while_carried_m"] > 0.5, f"carried {o['can_moved_while_carried_m']} m"
    # held from the lift until the opening: within millimetres of its place in the palm's
    # frame, and not sinking through the grip (13.6 mm from the lift's start, 3.0 mm during
    # the carry, 0 mm sunk)
    assert o["max_slip_in_hand_before_opening_m"] < 0.02, \
        f"slipped {o['max_slip_in_hand_before_opening_m']} m in the hand from the lift"
    assert o["max_slip_in_hand_while_carried_m"] < 0.015, \
        f"slipped {o['max_slip_in_hand_while_carried_m']} m in the hand while carried"
    assert o["can_sank_in_hand_before_opening_m"] < 0.003, \
        f"sank {o['can_sank_in_hand_before_opening_m']} m in the hand"
    # the release, searched over the whole run: in the hand (within 15 mm of its place in the
    # palm's frame) from 0.92 s; the hand opens at 7.44 s, still touches the can at 7.48 s,
    # the can leaves the hand at 7.52 s (80 ms after the opening; a can let go at the opening
    # could not leave before 49.5 ms) and is on the floor at 7.84 s (free fall: by 7.897 s)
    checks = grasp.release_checks(o)
    failed = [name for name, held in checks.items() if not held]
    assert not failed, (
        f"{', '.join(failed)}: hand opens at {o['hand_opens_at_s']} s; the can in the hand from "
        f"{o.get('in_hand_from_s')} s, leaves it at {o.get('left_hand_at_s')} s "
        f"({o.get('left_hand_after_opening_s')} s after the opening, free fall allows "
        f"{o.get('earliest_free_fall_exit_s')} s), hand last touches it at "
        f"{o.get('hand_last_touches_can_at_s')} s, on the floor at {o.get('on_floor_at_s')} s "
        f"({o.get('on_floor_after_opening_s')} s after the opening, free fall by "
        f"{o.get('latest_on_floor_after_opening_s')} s), never rising: "
        f"{o.get('falls_without_rising')}")
    assert o["can_on_floor_at_end"], f"the can ends at {o['can_final_position_m']}"
    # the carry, propagated again from the snapshot taken when it began (a planner's use),
    # ends with the can exactly where the run's own carry put it
    carry = facts["carry_propagated"]
    assert carry["can_where_the_run_put_it"], carry
    assert carry["simulated_s"] > 1.0 and carry["rtf"] > 0


@pytest.mark.forked
def test_grasp_in_tracked_mode_follows_the_path_files_and_still_holds_the_can(tmp_path,
                                                                              kautham_dir):
    """The TX90 follows its path files through the joint servos under full physics (issue
    12): the approach, the thumb turning, the hand closing, the lift and the carry as one
    tracked path; the hand then opens as in the thesis."""
    import grasp
    facts = grasp.run(frames=False, out_root=tmp_path, mode="tracked")
    o, tracking = facts["outcome"], facts["tracking"]
    # the arm on its path within 1.4 mrad all along, at its goal within 0.1 mrad (measured)
    assert tracking["arm_tracking_error_max_rad"] < 0.01, tracking
    assert tracking["arm_goal_error_rad"] < 0.001, tracking
    # the fingers stop on the can short of their targets (0.85 rad short): they hold it
    assert tracking["goal_error_rad"] > 0.3, tracking
    assert any("can" in pair and "Palm" in pair for pair in tracking["collision_pairs"])
    # 19.1 mm from the lift's start (the grip settles as the arm starts lifting), 8.5 mm
    # while carried, nothing sunk; the release: the can leaves 0.12 s after the opening, free
    # fall allows 0.036 s (one cycle more slack than the velocity mode: TRACKED_FALL_SLACK_S)
    _assert_tracked_grasp_held_carried_and_released(grasp, o)


def _assert_tracked_grasp_held_carried_and_released(grasp, o: dict) -> None:
    _assert_tracked_grasp_held_and_carried(o)
    checks = grasp.release_checks(o, grasp.TRACKED_FALL_SLACK_S)
    failed = [name for name, held in checks.items() if not held]
    assert not failed, (failed, o)


def _assert_tracked_grasp_held_and_carried(o: dict) -> None:
    h = o["can_height_above_table_while_carried_m"]
    assert h["min"] > 0.1, f"carried as low as {h['min']} m above the table"
    assert o["can_moved_while_carried_m"] > 0.5, f"carried {o['can_moved_while_carried_m']} m"
    assert o["max_slip_in_hand_before_opening_m"] < 0.025, o
    assert o["max_slip_in_hand_while_carried_m"] < 0.015, o
    assert o["can_sank_in_hand_before_opening_m"] < 0.003, o
    assert o["can_on_floor_at_end"], f"the can ends at {o['can_final_position_m']}"


@pytest.mark.forked
def test_grasp_with_the_kinematic_drive_lifts_carries_and_drops_the_can(tmp_path, kautham_dir):
    """Tracked mode with the arm, the palm and the hand's placing joints under the kinematic
    drive (grasp.KINEMATIC_LINKS), the flexing finger joints dynamic (issue 30)."""
    import grasp
    facts = grasp.run(frames=False, out_root=tmp_path, mode="tracked", kinematic=True,
                      viewer=False)
    o, tracking = facts["outcome"], facts["tracking"]
    # the arm follows the commanded motion exactly (the servos' law, step by step): what is
    # left is the law's own lag behind the path's targets (1.4 mrad, as the dynamic arm's)
    assert tracking["arm_tracking_error_max_rad"] < 0.01, tracking
    assert tracking["arm_goal_error_rad"] < 1e-9, tracking
    assert tracking["goal_error_rad"] > 0.3, tracking     # the fingers stop on the can
    _assert_tracked_grasp_held_and_carried(o)
    # the release as a rigid arm makes it (grasp.RIGID_ARM_TOUCH_S, RIGID_ARM_FLOOR_S): the can
    # leaves 0.08 s after the opening (the dynamic arm's 0.12 s), then rolls down the palm's
    # face, which does not give way
    checks = grasp.release_checks(o, grasp.TRACKED_FALL_SLACK_S, rigid_arm=True)
    failed = [name for name, held in checks.items() if not held]
    assert not failed, (failed, o)
    assert grasp.verdict(facts)[0]
    # the two checks the compliant arm's release keeps and the rigid one's relaxes: one fails
    # here, or the rigid arm's are no different and the relaxation goes
    compliant = grasp.release_checks(o, grasp.TRACKED_FALL_SLACK_S)
    assert not all(compliant.values()), compliant


@pytest.mark.forked
def test_sphere_demo_rests_on_the_ground_and_a_control_path_drives_it_to_its_goal(kautham_dir):
    """Kautham's ODE sphere demo as the GUI loads it (tools/experiments/sphere.py)."""
    import sphere
    facts = sphere.run(frames=False)
    o = facts["outcome"]
    failed = [name for name, held in sphere.checks(o).items() if not held]
    assert not failed, (failed, {k: v for k, v in o.items() if k != "rest"},
                        [n for n, r in o["rest"].items() if not r["at_rest_on_the_ground"]])
    # built at the query's start (controls 0.544 0.433 0.4 through sp3.cntr and <Limits>), not
    # at its Home (10, 10, 0) outside the walls
    assert o["sphere_built_at_m"] == pytest.approx([0.44, -0.67, 0.2], abs=1e-4)
    # 8 obstacles, each a dynamic body resting on the ground plane
    assert len(o["rest"]) == 9
    # 22.0 m of route in 51 rows and 6 at the goal; at most 0.40 m behind the moving targets
    # (a force that would reach each row's target if nothing else acted; a rolling sphere
    # accelerates at 5/7 of it), 2 mm from the goal at the end
    assert o["rows"] == 57


def _planned_and_replayed(experiment) -> dict:
    """A planning experiment's outcome, after its checks held and the fresh world ended the
    plan at the planner's bits (the worlds are deterministic: the same bits, not merely
    close)."""
    o = experiment.run(frames=False)["outcome"]
    failed = [name for name, held in experiment.checks(o).items() if not held]
    assert not failed, (failed, o)
    assert o["replay_bit_identical"], (o["planned_end_m"], o["executed_end_m"])
    return o


@pytest.mark.forked
def test_plan_sphere_kpiece1_plan_replays_to_the_goal_region_in_a_fresh_world(kautham_dir):
    """KPIECE1 plans the public Sphere in-process; its written control path, run row by row
    through Propagate in a world node only built from the problem, leaves the sphere where the
    planner's own replay did, in the goal region (tools/experiments/plan_sphere.py)."""
    import plan_sphere
    o = _planned_and_replayed(plan_sphere)
    # seed 7 solves it in 340 propagations, 60 rows of 0.03 s, pushing one block (cubeDE1);
    # the search stops when solved, so its length does not depend on the machine's speed
    assert o["planner"]["propagations"] == 340 and o["rows_run"] == 60
    assert o["start_m"] == pytest.approx([0.44, -0.67, 0.2], abs=1e-4)
    assert ["SphereDE", "cubeDE1"] in o["sphere_touched"]


@pytest.mark.forked
def test_plan_sphere_walls_crosses_the_arena_past_the_inner_walls(kautham_dir):
    """KPIECE1 plans Kautham's second sphere demo (k-PMPSphere.xml: three inner walls) and the
    plan replays in a fresh world node to the goal region without touching a wall
    (tools/experiments/plan_sphere_walls.py)."""
    import plan_sphere_walls
    o = _planned_and_replayed(plan_sphere_walls)
    # seed 1 solves it in 2,412 propagations, 114 rows (2,381 and 84 before issue 41, when a
    # block it pushed could touch a wall); the sphere starts on the far side of the inner
    # wall from its goal
    assert o["planner"]["propagations"] == 2412 and o["rows_run"] == 114
    assert o["start_m"][1] > 0.5 > -0.5 > o["goal_xy_m"][1]


@pytest.mark.forked
def test_plan_chain_pushes_box2_aside_and_reaches_kautham_s_goal_threshold():
    """KPIECE1 plans Kautham's chain demo (k-PMPChain.xml, vendored) to within Kautham's
    0.05 m of its goal: the gripper pushes box2 out of link2's way, nothing fixed is touched,
    and the plan replays bit for bit in a fresh world node (tools/experiments/plan_chain.py)."""
    import plan_chain
    o = _planned_and_replayed(plan_chain)
    # seed 4 solves it in 4,700 propagations, 351 rows of 0.02 s; only the fingers push box2
    assert o["planner"]["propagations"] == 4700 and o["rows_run"] == 351
    assert o["goal_tolerance_m"] == 0.05 and o["tracked_link"] == "Chain/gripper"
    assert {"Chain/link1", "Chain/link2"}.isdisjoint(
        name for pair in o["chain_touched"] for name in pair)


# Kautham's car demo planned and driven (tools/experiments/plan_car.py) is not here but in
# `make experiments`, whose verdict checks the same outcomes (plan_car.checks: seed 6's 66,471
# propagations and 1,609 rows, the cube pushed aside, no wall touched, the bit-identical
# replay, the car at rest on its wheels): its 22,006 propagations before issue 41 were 35-40 s
# of one core alone and took 60 s here while three workers share two cores, and make test
# holds no test over 60 s (issue 32). The car's pieces stay here: its planning problem and
# propagations (Odin/GUI/test/test_planning_robots.py), its control paths run in a world
# node and their distance to the goal (tests/nodes/test_run_path_reports.py), its build
# (Odin/GUI/test/test_kautham_physics_mobile.py).


def test_one_command_runs_several_experiments(kautham_dir):
    """`make experiments` runs them one after another from one command; each has a roscore of
    its own, which one rospy process cannot follow (it hung on the second before)."""
    import subprocess
    result = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "experiments" / "run.py"), "--no-frames",
         "contactless", "pile"], capture_output=True, text=True, timeout=600,
        stdin=subprocess.DEVNULL)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert "experiment contactless: outcome held" in result.stdout, result.stdout[-2000:]
    assert "experiment pile: outcome held" in result.stdout, result.stdout[-2000:]
