"""Benchmarks of the VirtualWorld Core against native C programs doing the same work with libode.

Figures (ratios measured in one run, ROUNDS paired rounds each: the median of the rounds'
ratios; the two runs of a round are measured back to back, under the same load of a shared
machine, native first in even rounds and Odin first in odd ones):
  core_spheres100_ratio  100 spheres (r 0.1) dropped on a plane (a static box), Odin's
                         broad phase (sweep and prune), 3 contacts per pair made in serial
                         order as Odin makes them (native/ordered_contacts.h), mu 1,
                         QuickStep, 2000 steps of 1 ms; native_time / odin_time
                         (goal >= 0.95).
  core_pile_ratio        the same inside four walls so they pile up (~230 contacts a step).
  core_forces_ratio      the pile plus 100 persistent forces and 20 motors (goal >= 0.90).
  core_newscene_leak_kb  resident memory growth (kB) over 1000 New Scene cycles of a
                         100-object scene (50 spheres, 50 box meshes), after 50 warm-up cycles,
                         measured with /proc/self/statm in a subprocess (goal < 5000).
  core_*_instructions_ratio  the same three cases counted in instructions instead of seconds
                         (valgrind's callgrind, 300 steps, only the step loop: native's ODE calls,
                         Odin's odin_world_step): repeatable whatever else the machine does.
Same work: both sides print the last step's contact count and the final pose of every body
(position and quaternion, read back as the same doubles). A ratio is given only if, in every
round, the counts are equal and the poses bit-identical (POSE_TOLERANCE 0: measured so on
2026-11-22, both sides run the same libode calls in the same order); otherwise the figure is
refused (report.Refused) with the difference. The native program (native/core_scene.c) is
compiled here with gcc -lode into out_dir. Odin's side steps with one Core.step(0.001, 2000)
call (the whole loop in C), in a process of its own like the native program.
"""
import os
import pathlib
import statistics
import subprocess
import sys
from typing import Dict, List, NamedTuple, Optional, Tuple

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from report import Refused  # noqa: E402

STEPS = 2000
ROUNDS = int(os.environ.get("ODIN_BENCH_ROUNDS", "7"))
POSE_TOLERANCE = 0.0    # largest |difference| allowed in a pose coordinate (m, quaternion)
CASES = {  # figure -> (mode, forces, motors)
    "core_spheres100_ratio": (0, 0, 0),
    "core_pile_ratio": (1, 0, 0),
    "core_forces_ratio": (1, 100, 20),
}


def _compile(out_dir: pathlib.Path, name: str = "core_scene") -> pathlib.Path:
    exe = out_dir / name
    src = HERE / "native" / "core_scene.c"
    subprocess.run(["gcc", "-O2", "-DdDOUBLE", str(src), "-lode", "-o", str(exe)], check=True)
    return exe


def host_steps_per_s(exe: pathlib.Path) -> float:
    """The host's speed now: the native program's steps per second on the 100-sphere scene
    (STEPS steps; run.py probes it around every module: host_native_ode_steps_per_s)."""
    return STEPS / _native(exe, 0, 0, 0).seconds


class Run(NamedTuple):
    """One side's run: seconds in the step loop, the last step's contacts, and the final pose
    (x, y, z, qw, qx, qy, qz) of each of the 100 bodies in order."""
    seconds: float
    contacts: int
    poses: Tuple[Tuple[float, ...], ...]


def _blocks(stdout: str) -> List[Tuple[str, Run]]:
    """The output native/core_scene.c prints (and Odin's side imitates): blocks of a head line
    ("seconds contacts", or "after STEPS contacts" at a checkpoint) and 100 pose lines."""
    lines = stdout.strip().splitlines()
    blocks = []
    for start in range(0, len(lines), 101):
        head, body = lines[start].split(), lines[start + 1:start + 101]
        poses = tuple(tuple(float(v) for v in line.split()) for line in body)
        if len(poses) != 100 or any(len(pose) != 7 for pose in poses):
            raise RuntimeError(f"expected 100 poses of 7 numbers after {lines[start]!r}, got "
                               f"{len(poses)}:\n{stdout[:500]}")
        if head[0] == "after":
            blocks.append((head[1], Run(float("nan"), int(head[2]), poses)))
        else:
            blocks.append(("end", Run(float(head[0]), int(head[1]), poses)))
    if not blocks:
        raise RuntimeError("no output")
    return blocks


def parse_run(stdout: str) -> Run:
    """The last block: seconds in the step loop, the last step's contacts, the final poses."""
    return _blocks(stdout)[-1][1]


def parse_checkpoints(stdout: str) -> Dict[int, Run]:
    """{step count: its block} of the checkpoints asked for on the command line."""
    return {int(name): run for name, run in _blocks(stdout) if name != "end"}


def pose_difference(native, odin, tolerance: float = POSE_TOLERANCE) -> Optional[str]:
    """None if every coordinate of the two pose lists is within ``tolerance``, else the
    largest difference."""
    if len(native) != len(odin):
        return f"{len(native)} native poses, {len(odin)} Odin poses"
    worst, where = 0.0, None
    for body, (a, b) in enumerate(zip(native, odin)):
        for k, (x, y) in enumerate(zip(a, b)):
            d = abs(x - y)
            if not d <= tolerance:          # a NaN is a difference too
                if where is None or not d <= worst:
                    worst, where = d, (body, "x y z qw qx qy qz".split()[k], x, y)
    if where is None:
        return None
    body, coordinate, x, y = where
    return (f"final poses differ beyond {tolerance}: largest at s{body}.{coordinate}, native "
            f"{x!r}, Odin {y!r} (|difference| {worst:.3g})")


def work_difference(native: Run, odin: Run, tolerance: float = POSE_TOLERANCE) -> Optional[str]:
    """None if both runs did the same work (same contacts, poses within ``tolerance``), else
    what differs."""
    if native.contacts != odin.contacts:
        return f"last step's contacts differ: native {native.contacts}, Odin {odin.contacts}"
    return pose_difference(native.poses, odin.poses, tolerance)


def _native(exe: pathlib.Path, mode: int, forces: int, motors: int) -> Run:
    return parse_run(subprocess.run([str(exe), str(mode), str(STEPS), str(forces), str(motors)],
                                    check=True, capture_output=True, text=True).stdout)


def build_scene(core, mode: int, forces: int, motors: int) -> None:
    """The scene of native/core_scene.c through the Core API."""
    from virtual_world.core import FORCE, MotorSpec, ObjectSpec

    # native/core_scene.c steps with QuickStep; the Core's default solver (auto) would take
    # dWorldStep for the pile's first steps (few contact rows) and do other work
    core.set_world_parameters(solver=0)
    core.build_object(ObjectSpec("ground", [20, 20, 1], position=(0, 0, -0.5),
                                 geometry_only=True))
    if mode == 1:
        for name, pos, size in (("w1", (0.65, 0, 1), (0.2, 1.5, 2)),
                                ("w2", (-0.65, 0, 1), (0.2, 1.5, 2)),
                                ("w3", (0, 0.65, 1), (1.5, 0.2, 2)),
                                ("w4", (0, -0.65, 1), (1.5, 0.2, 2))):
            core.build_object(ObjectSpec(name, list(size), position=pos, geometry_only=True))
    for i in range(100):
        if mode == 0:
            pos = ((i % 10) * 0.25 - 1.125, (i // 10) * 0.25 - 1.125, 0.5)
        else:
            layer = i // 25
            o = 0.06 if layer % 2 else 0.0
            pos = ((i % 5) * 0.21 - 0.42 + o + 0.001 * (i % 7), ((i // 5) % 5) * 0.21 - 0.42 + o,
                   0.15 + layer * 0.21)
        core.build_object(ObjectSpec(f"s{i}", [0.1], mass=1.0, position=pos))
    for i in range(forces):
        core.add_body_force(f"s{i % 100}", FORCE, (0.0, 0.0, 0.5))
    ids = [core.add_motor(MotorSpec(body1=f"s{i}", axes=[0, 0, 1], axis_frames=[1]))
           for i in range(motors)]
    if ids:
        core.set_velocity(motors=ids, velocities=[0.5] * len(ids))


def print_poses(core) -> None:
    """The final poses as native/core_scene.c prints them (repr reads back as the same double)."""
    for i in range(100):
        position, quaternion, _, _ = core.body_state(f"s{i}")
        print(" ".join(repr(float(v)) for v in (*position, *quaternion)))


ODIN_TIMED_SCRIPT = (
    "import sys, time; sys.path.insert(0, {here!r}); import bench_core\n"
    "from virtual_world.core import Core\n"
    "core = Core(); bench_core.build_scene(core, {mode}, {forces}, {motors})\n"
    "started = time.perf_counter(); core.step(0.001, {steps})\n"
    "print(time.perf_counter() - started, core.last_step_contacts)\n"
    "bench_core.print_poses(core)\n")


def _odin(mode: int, forces: int, motors: int) -> Run:
    """Odin's step loop timed in a process of its own, as the native program is: a long-lived
    process that has built and freed many scenes steps a few per cent slower (its heap is
    scattered), which is the process, not the Core (the instruction counts are equal)."""
    script = ODIN_TIMED_SCRIPT.format(here=str(HERE), mode=mode, forces=forces, motors=motors,
                                      steps=STEPS)
    return parse_run(subprocess.run([sys.executable, "-c", script], check=True,
                                    capture_output=True, text=True).stdout)


LEAK_SCRIPT = r"""
import os, sys
from virtual_world.core import Core, ObjectSpec
page_kb = os.sysconf("SC_PAGE_SIZE") // 1024
def rss_kb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * page_kb
corners = [(x, y, z) for x in (-.1, .1) for y in (-.1, .1) for z in (-.1, .1)]
V = [c for p in corners for c in p]
I = [0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4,
     1, 5, 7, 1, 7, 3]
core = Core()
cycles, warm = int(sys.argv[1]), 50
start = None
for cycle in range(warm + cycles):
    if cycle == warm:
        start = rss_kb()
    core.new_scene()
    core.build_object(ObjectSpec("ground", [20, 20, 1], position=(0, 0, -0.5), geometry_only=True))
    for i in range(50):
        core.build_object(ObjectSpec(f"s{i}", [0.1], position=(i * 0.3, 0, 0.2)))
        core.build_object(ObjectSpec(f"m{i}", V, I, position=(i * 0.3, 1, 0.2)))
    core.step(0.001, 5)
    core.poses()
core.close()
print(rss_kb() - start)
"""


def _leak_kb(cycles: int = 1000) -> float:
    out = subprocess.run([sys.executable, "-c", LEAK_SCRIPT, str(cycles)], check=True,
                         capture_output=True, text=True).stdout.split()
    return float(out[-1])


#: functions whose instructions make up the step loop (callgrind --toggle-collect)
NATIVE_LOOP = ("collide_in_order", "dWorldQuickStep", "dJointGroupEmpty", "dBodyAddForce",
               "dJointSetAMotorParam")
ODIN_LOOP = ("odin_world_step",)
COUNTED_STEPS = 300
ODIN_STEP_SCRIPT = (
    "import sys; sys.path.insert(0, {here!r}); import bench_core\n"
    "from virtual_world.core import Core\n"
    "core = Core(); bench_core.build_scene(core, {mode}, {forces}, {motors})\n"
    "core.step(0.001, {steps})\n"
    "print(0, core.last_step_contacts)\n"
    "bench_core.print_poses(core)\n")


def _instructions(command: list, functions: tuple, out_file: pathlib.Path) -> Tuple[int, Run]:
    """Instructions executed inside ``functions`` (callgrind, inclusive), and the run's output."""
    toggles = [f"--toggle-collect={name}" for name in functions]
    done = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out_file}",
                           *toggles, *command], check=True, capture_output=True, text=True)
    for line in out_file.read_text().splitlines():
        if line.startswith(("summary:", "totals:")):
            return int(line.split()[1]), parse_run(done.stdout)
    raise RuntimeError(f"no instruction total in {out_file}")


def instruction_ratios(exe: pathlib.Path, out_dir: pathlib.Path) -> dict:
    figures = {}
    for figure, (mode, forces, motors) in CASES.items():
        native, native_run = _instructions([str(exe), str(mode), str(COUNTED_STEPS), str(forces),
                                            str(motors)], NATIVE_LOOP,
                                           out_dir / "callgrind.native")
        script = ODIN_STEP_SCRIPT.format(here=str(HERE), mode=mode, forces=forces,
                                         motors=motors, steps=COUNTED_STEPS)
        odin, odin_run = _instructions([sys.executable, "-c", script], ODIN_LOOP,
                                       out_dir / "callgrind.odin")
        name = figure.replace("_ratio", "_instructions_ratio")
        difference = work_difference(native_run, odin_run)
        figures[name] = (Refused(f"not the same work under callgrind: {difference}")
                         if difference else round(native / odin, 3))
    return figures


def paired_rounds(exe: pathlib.Path, mode: int, forces: int, motors: int,
                  rounds: int = ROUNDS) -> Tuple[List[Run], List[Run]]:
    """``rounds`` rounds of one native and one Odin run, native first in even rounds."""
    native_runs, odin_runs = [], []
    for k in range(rounds):
        if k % 2 == 0:
            native_runs.append(_native(exe, mode, forces, motors))
            odin_runs.append(_odin(mode, forces, motors))
        else:
            odin_runs.append(_odin(mode, forces, motors))
            native_runs.append(_native(exe, mode, forces, motors))
    return native_runs, odin_runs


def run(out_dir: pathlib.Path) -> dict:
    out_dir.mkdir(parents=True, exist_ok=True)
    exe = _compile(out_dir)
    figures = {}
    details = []
    for figure, (mode, forces, motors) in CASES.items():
        native_runs, odin_runs = paired_rounds(exe, mode, forces, motors)
        differences = [(k, d) for k, d in enumerate(map(work_difference, native_runs, odin_runs))
                       if d]
        if differences:
            k, difference = differences[0]
            figures[figure] = Refused(f"not the same work in {len(differences)} of "
                                      f"{len(native_runs)} rounds (round {k}: {difference})")
        else:
            figures[figure] = round(statistics.median(
                n.seconds / o.seconds for n, o in zip(native_runs, odin_runs)), 3)
        details.append(f"{figure}: native {[n.seconds for n in native_runs]} s "
                       f"({native_runs[-1].contacts} contacts), odin "
                       f"{[o.seconds for o in odin_runs]} s ({odin_runs[-1].contacts} contacts), "
                       f"same work: {differences[0][1] if differences else 'yes'}")
    figures["core_newscene_leak_kb"] = _leak_kb()
    figures.update(instruction_ratios(exe, out_dir))
    (out_dir / "bench_core.txt").write_text("\n".join(details) + "\n")
    return figures


if __name__ == "__main__":
    root = HERE.parent.parent
    print(run(root / "out" / "bench"))
