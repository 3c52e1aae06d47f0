"""The two passes of `make corpus` over one problem file (tools/corpus/run.py says what each
records): ``problem_info`` as a user runs it, and ``simulate_all``, the accepted problems
built into a world with a Viewer and simulated."""
from __future__ import annotations

import json
import math
import os
import pathlib
import re
import signal
import sys
import tempfile
import time
import traceback
from typing import Optional

from odin_common.blas import use_reference_blas

use_reference_blas()  # before numpy (odin_common.blas)

import numpy as np  # noqa: E402

PROBLEM_INFO_TIMEOUT = 300.0
"""s: problem_info taking longer has hung (the largest TIAGo problems take ~10 s here)."""
FELL_BELOW = 0.1
"""m: a body's origin this far under the ground plane has fallen through it."""
FIXED_BASE_HOLD = 0.001
"""m: how far a fixed-base robot's links may move in the simulated seconds."""
LIMIT_SLACK = 1e-9
"""rad or m: rounding allowed when a robot is built at a joint limit."""
CHUNK_CYCLES = 25
"""Portal cycles per Step Once call (a call stays short on the heaviest scenes)."""

_NOT_PROBLEM = re.compile(r": is a Kautham (benchmark|configuration) file")
_MISSING = re.compile(r'file "([^"]+)" not found|: (geometry file|robot file|URDF file|'
                      r'control file|problem file) not found')


def preload() -> None:
    """Imports what problem_info uses once, before the children are forked: a child then
    starts in milliseconds (a `rosrun GUI problem_info` process spends seconds importing)."""
    import gui.tools.problem_info  # noqa: F401
    import gui.core.kautham.problem  # noqa: F401
    import gui.core.translate  # noqa: F401
    import trimesh  # noqa: F401
    import collada  # noqa: F401
    from gui.core.shapes import _coin_module
    _coin_module()


def problem_info(corpus: pathlib.Path, relative: str) -> dict:
    """problem_info on one file, as its script runs it (``gui.tools.problem_info.main`` in a
    process of its own, stdout and stderr its own files; an exception that escapes is
    printed as Python prints it): {"status": ok | refused | failed, ...}."""
    started = time.monotonic()
    code, stdout, stderr = _run_forked(
        lambda: _problem_info_main(["--indent", "0", str(corpus / relative)]),
        PROBLEM_INFO_TIMEOUT)
    seconds = round(time.monotonic() - started, 2)
    if code is None:
        return dict(status="failed", reason=f"problem_info hung (over "
                                            f"{PROBLEM_INFO_TIMEOUT:g} s)")
    errors = [line for line in stderr.splitlines() if ": warning: " not in line]
    if code == 0 and not errors:
        description = json.loads(stdout)
        return dict(status="ok", info_s=seconds, bodies=len(description["bodies"]),
                    robot_kinds=[r["kind"] for r in description["robots"]],
                    physics=description["physics"], planner=description["planner"])
    if code == 2 and len(errors) == 1 and errors[0].startswith("problem_info: error: ") \
            and "Traceback" not in stderr:
        reason = errors[0][len("problem_info: error: "):]
        return dict(status="refused", reason=reason, info_s=seconds,
                    refusal=refusal_kind(corpus, relative, reason))
    return dict(status="failed", info_s=seconds, traceback="Traceback" in stderr,
                reason=f"exit {code}: " + " | ".join(errors[-3:])[-600:])


def _problem_info_main(argv: list) -> int:
    from gui.tools.problem_info import main
    return main(argv)


def _run_forked(main, timeout: float):
    """(exit code or None when it ran past ``timeout`` s and was killed, stdout, stderr) of
    ``main()`` run in a forked child whose file descriptors 1 and 2 are files of its own."""
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        deadline = time.monotonic() + timeout
        code = wait(fork(main, out, err), lambda: deadline)
        out.seek(0)
        err.seek(0)
        return code, out.read().decode(errors="replace"), err.read().decode(errors="replace")


def fork(main, out, err) -> int:
    """The process ID of a forked child that runs ``main()`` with its file descriptors 1 and 2
    on the files ``out`` and ``err`` and exits with its status (an exception that escapes
    printed as Python prints it, status 1)."""
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:                    # the child: never returns
        code = 1
        try:
            os.dup2(out.fileno(), 1)
            os.dup2(err.fileno(), 2)
            # Python's streams onto them too, whatever the parent had put there (pytest's)
            sys.stdout = open(1, "w", closefd=False)
            sys.stderr = open(2, "w", closefd=False)
            code = main()
        except SystemExit as exit_:
            code = exit_.code if isinstance(exit_.code, int) else 1
        except BaseException:       # as the interpreter reports an uncaught exception
            traceback.print_exc()
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(code)
    return pid


def wait(pid: int, deadline) -> Optional[int]:
    """The exit status of child ``pid`` (negative: the signal that ended it), or None when it
    ran past ``deadline()`` (time.monotonic() s, asked as it runs) and was killed."""
    try:
        while time.monotonic() < deadline():
            done, status = os.waitpid(pid, os.WNOHANG)
            if done:
                return os.waitstatus_to_exitcode(status)
            time.sleep(0.02)
    except BaseException:               # interrupted: the child goes too
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
        raise
    os.kill(pid, signal.SIGKILL)
    os.waitpid(pid, 0)
    return None


def refusal_kind(corpus: pathlib.Path, relative: str, reason: str) -> str:
    """not a problem | missing file | unexpected. A file the loader did not find is absent
    from the repository at that commit: the tree is laid out whole, but for the files
    SKIPPED.md lists (absent from the repository copy), which the report names."""
    if _NOT_PROBLEM.search(reason):
        return "not a problem"
    return "missing file" if _MISSING.search(reason) else "unexpected"


# -- the world pass ------------------------------------------------------------------------

def simulate_all(corpus: pathlib.Path, files: list, seconds: float) -> dict:
    """{file: what its build and simulation showed}; each batch of files runs in a child
    process with its own roscore, world and Viewer (rospy binds a process to its first
    master): a node that dies fails the file it was on, and the next batch starts afresh."""
    results: dict = {}
    remaining = list(files)
    progress = pathlib.Path(os.environ.get("TMPDIR", "/tmp")) / f"odin-corpus-{os.getpid()}"
    while remaining:
        progress.write_text("")
        pid = os.fork()
        if pid == 0:
            code = 0
            try:
                _simulate_batch(corpus, remaining, seconds, progress)
            except BaseException:       # reported through the progress file; never escapes
                code = 1
            finally:
                os._exit(code)
        _, status = os.waitpid(pid, 0)
        lines = [json.loads(line) for line in progress.read_text().splitlines() if line]
        done = {entry["file"]: entry["result"] for entry in lines if "result" in entry}
        results.update(done)
        started = [entry["file"] for entry in lines if "started" in entry]
        if started and started[-1] not in done:
            results[started[-1]] = dict(world="failed", world_reason=(
                f"the batch process ended (status {status}) while building or simulating it"))
        remaining = [f for f in remaining if f not in results]
        if not lines and remaining:     # the batch could not start at all
            for f in remaining:
                results[f] = dict(world="failed", world_reason="the world could not start")
            break
    progress.unlink(missing_ok=True)
    return results


def _write(progress: pathlib.Path, entry: dict) -> None:
    with open(progress, "a") as out:
        out.write(json.dumps(entry) + "\n")


def _simulate_batch(corpus: pathlib.Path, files: list, seconds: float,
                    progress: pathlib.Path) -> None:
    from odin_common.ros_master import RosMaster
    with RosMaster() as master:
        master.apply_to_this_process()
        world = master.rosrun("VirtualWorld", "virtualWorld")
        viewer = master.rosrun("Viewer", "viewer")
        master.wait_for_service("/virtual_world/step_once", timeout=60)
        master.wait_for_service("/viewer/save_snapshot", timeout=60)
        import rospy
        from gui.ros.client import WorldClient
        rospy.init_node("corpus", anonymous=True, disable_signals=True)
        client = WorldClient(timeout=30.0)
        for relative in files:
            print(f"[world] {relative}", flush=True)
            _write(progress, dict(file=relative, started=True))
            try:
                result = simulate_one(client, corpus / relative, seconds,
                                      lambda: master.log_text(world))
            except Exception as error:      # a refusal of the world, recorded as the failure
                result = dict(world="failed", world_reason=" ".join(
                    f"{type(error).__name__}: {error}".split())[:600],
                    trace=traceback.format_exc()[-1500:])
            dead = [p for p in (world, viewer) if p.poll() is not None]
            if dead:
                result = dict(world="failed", world_reason=(
                    f"{dead[0].log_name} exited with {dead[0].returncode}: "
                    + master.log_text(dead[0])[-400:]))
            _write(progress, dict(file=relative, result=result))
            if dead:
                return


def simulate_one(client, path: pathlib.Path, seconds: float, world_log) -> dict:
    """Builds ``path`` as load_problem does into a world set back to its defaults, simulates
    ``seconds`` s, and checks what the module docstring of run.py says."""
    from gui.core.kautham.problem import load_problem
    from gui.core.translate import plan_problem
    from odin_common.step_values import StepValues
    from odin_common.world_parameters import WorldParameters
    started = time.monotonic()
    plan = plan_problem(load_problem(path))
    client.pause()
    client.new_scene()
    client.set_world(**WorldParameters().as_dict())
    defaults = StepValues()
    client.set_step(step=defaults.step, steps_per_cycle=defaults.steps_per_cycle,
                    rate=defaults.rate)
    overlaps = client.execute(plan)["overlaps"]
    load_s = time.monotonic() - started
    diverged_before = world_log().count(" diverged at ")
    before = _states(client)
    cycle = client.step_values().cycle_time
    cycles = max(1, math.ceil(seconds / cycle - 1e-9))
    sim_started = time.monotonic()
    while cycles > 0:
        client.step_once(min(cycles, CHUNK_CYCLES))
        cycles -= CHUNK_CYCLES
    sim_s = time.monotonic() - sim_started
    after = _states(client)
    result = dict(world="ok", load_s=round(load_s, 2), simulate_s=round(sim_s, 2),
                  objects=len(client.world().objects), bodies=len(after),
                  diverged=world_log().count(" diverged at ") - diverged_before,
                  fell=_fell(plan, before, after), robots=_robots(plan, before, after),
                  overlaps=[list(o) for o in overlaps],
                  ground=plan.world is not None, drop_m=round(max(
                      (float(before[i][0][2] - a[0][2]) for i, a in after.items()
                       if i in before), default=0.0), 4))
    problems = _faults(result, after)
    if problems:
        result.update(world="failed", world_reason="; ".join(problems))
    return result


def _states(client) -> dict:
    """{body ID: (position (3,), linear (3,), angular (3,))} of every body of the world."""
    bodies = client.call("get_state", objects=[], joints=[], motors=[]).bodies
    return {b.id: (np.array(b.position), np.array(b.linear), np.array(b.angular))
            for b in bodies}


def _fell(plan, before: dict, after: dict) -> list:
    """Bodies that went through the ground plane (problems with Kautham's ground only)."""
    if plan.world is None:
        return []
    return sorted(name for name, state in after.items()
                  if name in before and before[name][0][2] >= -FELL_BELOW
                  and state[0][2] < -FELL_BELOW)


def _robots(plan, before: dict, after: dict) -> list:
    """Per robot: kind, its links' largest move (m) and the joints built outside limits."""
    out = []
    for handle in plan.robots:
        if handle.instance.role != "robot":
            continue
        ids = [b.body_id for b in handle.bodies if b is not None and b.body_id in after]
        moves = {i: float(np.linalg.norm(after[i][0] - before[i][0])) for i in ids
                 if i in before}
        most = max(moves, key=moves.get, default=None)
        out.append(dict(name=handle.name, kind=handle.kind, moved_m=moves.get(most, 0.0),
                        moved_body=most, outside_limits=_outside_limits(handle)))
    return out


def _outside_limits(handle) -> list:
    model = handle.instance.model
    outside = []
    for value, i in zip(handle.built_at, model.movable_links()):
        limits = model.links[i].limits
        if limits is not None and not (limits[0] - LIMIT_SLACK <= value <= limits[1]
                                       + LIMIT_SLACK):
            outside.append(model.links[i].name)
    return outside


def _faults(result: dict, after: dict) -> list:
    from gui.core.model import FIXED_BASE
    faults = []
    if result["diverged"]:
        faults.append(f"{result['diverged']} bodies diverged")
    if any(not np.all(np.isfinite(np.concatenate(state))) for state in after.values()):
        faults.append("a body's state is not finite")
    if result["fell"]:
        faults.append(f"fell through the ground: {', '.join(result['fell'][:5])}")
    for robot in result["robots"]:
        if robot["kind"] == FIXED_BASE and robot["moved_m"] > FIXED_BASE_HOLD:
            faults.append(f"fixed-base robot {robot['name']} moved "
                          f"{robot['moved_m'] * 1000:.1f} mm")
        if robot["outside_limits"]:
            faults.append(f"robot {robot['name']} built outside the limits of "
                          f"{', '.join(robot['outside_limits'])}")
    if faults and result["overlaps"]:     # what explains a move: the file's placement
        first, second, depth = result["overlaps"][0]
        faults.append(f"built with {len(result['overlaps'])} pairs inside each other where "
                      f"the problem places them (deepest {first} in {second}, "
                      f"{depth * 1000:.1f} mm)")
    return faults
