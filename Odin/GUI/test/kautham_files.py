"""What the tests of Kautham problems share: problem files written here from Kautham's formats
(for what the corpus lacks) and the readers of a build plan they check."""
from __future__ import annotations

import pathlib

from odin_common.world_parameters import WorldParameters

KINEMATIC = "omplRRTConnect"
"""A planner of Kautham's without physics: the problem's URDF is simulated as it says."""

SHELF = """<?xml version="1.0"?><robot name="shelf"><link name="base"><collision><geometry>
 <box size="1 0.4 0.02"/></geometry></collision></link></robot>"""
"""An obstacle without a mass: a 1 m x 0.4 m x 2 cm board."""


def default_parameters() -> dict:
    """Odin's documented world parameters, gravity as a tuple (as a plan carries it)."""
    return {**WorldParameters().as_dict(), "gravity": WorldParameters().gravity}


def plan_steps(plan, kind) -> list:
    """The steps of ``plan`` that are ``kind`` (a step class or a tuple of them), in order."""
    return [s for s in plan.steps if isinstance(s, kind)]


def write_problem(folder: pathlib.Path, files: dict[str, str], name: str,
                  problem: str) -> pathlib.Path:
    """Writes ``files`` (file name -> text: the robot's URDF, its .cntr, the obstacles') into
    ``folder``, then the problem's XML ``problem`` as ``name``; returns the problem's path."""
    for file_name, text in files.items():
        (folder / file_name).write_text(text)
    path = folder / name
    path.write_text(problem)
    return path
