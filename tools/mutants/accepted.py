"""Survivors accepted as equivalent: mutants that change no behaviour anyone can observe
through the Core, each with the reason. They are reported, but not counted against the score.

A C entry names a mutation of c_mutations.py. A Python entry names the file, the function and
the change (the stripped source lines mutmut removed and added), so it survives renumbering.
Add an entry only with the argument that no test could tell the mutant from the original;
anything else is a gap to close with a test.
"""
from __future__ import annotations

from typing import NamedTuple, Optional, Tuple

C = {
    # ODE adds the bounce term as c = e * v_in only where it exceeds the contact's position
    # correction (contact.cpp: `if (newc > info->c[0])`); with e = 0 it is 0, never above the
    # correction (>= 0): the flag set with bounce 0 changes nothing.
    "bounce_always_set": "with bounce 0 ODE's bounce term e v_in is 0 and never exceeds the "
                         "contact's own correction, so the flag changes nothing",
    # After a grow the pair table forgets the earlier records, so a pair seen again before the
    # next read is recorded a second time. readout.carry_collisions merges a pair's records by
    # name (keeping the deepest), so no read, depth or point differs; what grows is the record
    # buffer, until the next read clears it (the contact policy clears it every step).
    "grown_table_loses_entries": "duplicate records of a pair are merged by name in "
                                 "readout.carry_collisions: no read differs, only the buffer's "
                                 "size until the next read",
    # Only dMessage (level 0) messages are ever drained: dError and dDebug end the process as
    # soon as their handler returns (odin_step.c's report_fatal prints them first), so the ring
    # never holds two levels at once and the newest message's level is the oldest's.
    "drain_returns_newest": "every message the ring can hold when it is drained has level 0 "
                            "(dError and dDebug end the process), so the levels are equal",
}


class AcceptedPython(NamedTuple):
    file: str                  # virtual_world/...
    function: str              # name, or Class.method
    removed: Tuple[str, ...]   # stripped lines mutmut removed
    added: Tuple[str, ...]     # stripped lines it put instead
    reason: str


P = AcceptedPython
_CALLER_PASSES = "the Core, the function's only caller, always passes this argument"
_TAGS = "entity tags stay distinct and non-zero, which is all the near-callback reads"
_RESHAPE = "numpy's reshape takes any negative size as 'the rest': -2 is -1"

PYTHON: Tuple[AcceptedPython, ...] = (
    # the two names of a pair are two geometries' names, which are unique: never equal
    P("virtual_world/core/readout.py", "_named_records", ("if second < first:",),
      ("if second <= first:",), "a pair's two geometry names are never equal, so < and <= "
      "sort it alike"),
    # two occurrences of a pair at exactly the same depth: either is "the deepest occurrence"
    # (Core.read_collisions); which one's points are kept is not specified
    P("virtual_world/core/readout.py", "carry_collisions",
      ("if old is None or c.depth > old.depth:",), ("if old is None or c.depth >= old.depth:",),
      "differs only for two occurrences at exactly equal depth, where either is the deepest"),

    # Defaults of topic functions that their one caller, the Core, always passes explicitly
    # (Core.add_body_force passes all seven arguments, Core.set_poses passes reset_velocity).
    P("virtual_world/core/forces.py", "add_body_force",
      ("vector_in_body_frame: bool = False, at_point: bool = False,",),
      ("vector_in_body_frame: bool = True, at_point: bool = False,",), _CALLER_PASSES),
    P("virtual_world/core/forces.py", "add_body_force",
      ("vector_in_body_frame: bool = False, at_point: bool = False,",),
      ("vector_in_body_frame: bool = False, at_point: bool = True,",), _CALLER_PASSES),
    P("virtual_world/core/forces.py", "add_body_force",
      ("point=(0.0, 0.0, 0.0), point_in_body_frame: bool = False) -> str:",),
      ("point=(0.0, 0.0, 0.0), point_in_body_frame: bool = True) -> str:",), _CALLER_PASSES),
    P("virtual_world/core/objects.py", "set_poses", ("reset_velocity: bool = False) -> None:",),
      ("reset_velocity: bool = True) -> None:",), _CALLER_PASSES),

    # Entity tags only need to be distinct and non-zero (0 means "no entity"): starting at 2
    # or stepping by 2 gives other numbers with the same meaning.
    P("virtual_world/core/scene.py", "Scene.__init__",
      ("self.next_tag = 1                               # geom tag of the next entity",),
      ("self.next_tag = 2                               # geom tag of the next entity",),
      _TAGS),
    P("virtual_world/core/objects.py", "build_entity", ("scene.next_tag += 1",),
      ("scene.next_tag += 2",), _TAGS),

    # numpy (1.24, Debian's) reads any negative size in reshape as "the rest", not only -1.
    *(P(file, function, (line,), (line.replace("reshape(-1", "reshape(-2"),), _RESHAPE)
      for file, function, line in (
          ("virtual_world/core/objects.py", "_built_geometries",
           "tuple(int(i) for i in np.asarray(r.indices).reshape(-1)),"),
          ("virtual_world/core/shapes.py", "prepare_shape",
           "values = np.array(parameters, dtype=float).reshape(-1)"),
          ("virtual_world/core/shapes.py", "prepare_shape",
           "index_values = np.array(indices, dtype=float).reshape(-1)"),
          ("virtual_world/core/shapes.py", "prepare_shape",
           "return _mesh(what, values.reshape(-1, 3), index_values)"),
          ("virtual_world/core/shapes.py", "_mesh",
           "triangles = index_values.astype(np.uint32).reshape(-1, 3)"),
          ("virtual_world/core/shapes.py", "collision_mesh",
           "return vertices, indices.astype(np.uint32).reshape(-1, 3)"),
          ("virtual_world/core/validation.py", "vector",
           "array = np.array(value, dtype=float).reshape(-1)"),
      )),
)


def python_reason(mutant: dict) -> Optional[str]:
    """The reason a Python mutant is accepted as equivalent, or None."""
    for a in PYTHON:
        if (a.file == mutant["file"] and a.function == mutant["function"]
                and a.removed == tuple(mutant.get("removed", ()))
                and a.added == tuple(mutant.get("added", ()))):
            return a.reason
    return None
