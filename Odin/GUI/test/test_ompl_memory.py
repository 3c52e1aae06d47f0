"""gui.planning.ompl_memory: OMPL's real-vector states read and written as arrays over their
own memory (issue 42: a propagation moved the world's few hundred values one wheel call at a
time), checked against the wheel's own indexing, and a search that copies through them finds
bit for bit the plan one that copies value by value finds."""
from __future__ import annotations

import hashlib
import multiprocessing
import pathlib
import re

import numpy as np

from gui.planning import ompl_memory

ROOT = pathlib.Path(__file__).resolve().parents[3]
SPHERE = ("current_2025", "demos", "OMPL_ode_demos", "Sphere", "Sphere.xml")


def _space(sizes):
    from ompl import base as ob
    spaces = []
    for size in sizes:
        space = ob.RealVectorStateSpace(size)
        bounds = ob.RealVectorBounds(size)
        bounds.setLow(-1e10)
        bounds.setHigh(1e10)
        space.setBounds(bounds)
        spaces.append(space)
    return ob.CompoundStateSpace(spaces, [1.0] * len(sizes)), spaces


def test_the_pinned_wheel_is_the_one_whose_layout_the_module_reads():
    pinned = re.search(r"^ompl==(\S+)$", (ROOT / "tools" / "requirements.txt").read_text(),
                       re.MULTILINE)
    assert pinned and pinned.group(1) == ompl_memory.KNOWN_WHEEL


def test_arrays_read_and_write_what_the_wheels_indexing_does():
    space, _components = _space((6, 366))
    assert ompl_memory.LayoutProbe.holds(space, (6, 366))
    state = space.allocState()
    world = state[1]
    for i in range(366):
        world[i] = i * 0.25 - 7.0
    array = ompl_memory.values(world, 366)
    assert array.tolist() == [i * 0.25 - 7.0 for i in range(366)]
    array[:] = np.linspace(-1.0, 1.0, 366)
    assert [world[i] for i in range(366)] == np.linspace(-1.0, 1.0, 366).tolist()
    ompl_memory.values(state[0], 6)[:] = [1, 2, 3, 4, 5, 6]
    assert [state[0][i] for i in range(6)] == [1, 2, 3, 4, 5, 6]


def _search(problem_file: str, direct: bool, answer) -> None:
    """One seeded search in a process of its own (OMPL seeds once per process), copying
    through the arrays or value by value; puts (propagations, a digest of its rows)."""
    from gui.planning import bridge
    from gui.planning.backend import CoreBackend
    from gui.planning.problem import planning_problem
    from gui_core_world import quiet_plan
    ompl_memory.LayoutProbe.holds = staticmethod(lambda space, sizes: direct)
    build = quiet_plan(pathlib.Path(problem_file))
    backend = CoreBackend(build, planning_problem(build))
    try:
        result = bridge.plan(backend, "KPIECE1", time_limit=60.0, seed=7)
    finally:
        backend.close()
    rows = hashlib.sha256(repr([(r.controls, r.duration) for r in result.rows]).encode())
    answer.put((result.solved, result.propagations, rows.hexdigest(),
                result.final_position.tobytes()))


def test_a_search_through_the_arrays_finds_the_plan_value_by_value_copies_find(kautham_dir):
    context = multiprocessing.get_context("fork")
    answers = []
    for direct in (True, False):
        queue = context.Queue()
        child = context.Process(target=_search, args=(str(kautham_dir.joinpath(*SPHERE)),
                                                      direct, queue))
        child.start()
        answers.append(queue.get(timeout=300))
        child.join(60)
    assert answers[0][0] and answers[0][1] > 0
    assert answers[0] == answers[1]
