"""Benchmarks of the VirtualWorld Core against native C programs doing the same work with libode.

Figures (ratios measured alternately in one run, 7 rounds each: the median of the rounds'
ratios; the two runs of a round are measured back to back, under the same load of a shared
machine):
  core_spheres100_ratio  100 spheres (r 0.1) dropped on a plane (a static box), hash space,
                         3 contacts per pair, mu 1, QuickStep, 2000 steps of 1 ms;
                         native_time / odin_time (goal >= 0.95).
  core_pile_ratio        the same inside four walls so they pile up (~230 contacts a step).
  core_forces_ratio      the pile plus 100 persistent forces and 20 motors (goal >= 0.90).
  core_newscene_leak_kb  resident memory growth (kB) over 1000 New Scene cycles of a
                         100-object scene (50 spheres, 50 box meshes), after 50 warm-up cycles,
                         measured with /proc/self/statm in a subprocess (goal < 5000).
  core_*_instructions_ratio  the same three cases counted in instructions instead of seconds
                         (valgrind's callgrind, 300 steps, only the step loop: native's ODE calls,
                         Odin's odin_world_step): repeatable whatever else the machine does.
The native program (native/core_scene.c) is compiled here with gcc -lode into out_dir.
Odin's side steps with one Core.step(0.001, 2000) call (the whole loop in C), in a
process of its own like the native program.
"""
import pathlib
import statistics
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
STEPS = 2000
ROUNDS = 7
CASES = {  # figure -> (mode, forces, motors)
    "core_spheres100_ratio": (0, 0, 0),
    "core_pile_ratio": (1, 0, 0),
    "core_forces_ratio": (1, 100, 20),
}


def _compile(out_dir: pathlib.Path) -> pathlib.Path:
    exe = out_dir / "core_scene"
    src = HERE / "native" / "core_scene.c"
    subprocess.run(["gcc", "-O2", "-DdDOUBLE", str(src), "-lode", "-o", str(exe)], check=True)
    return exe


def _native(exe: pathlib.Path, mode: int, forces: int, motors: int):
    out = subprocess.run([str(exe), str(mode), str(STEPS), str(forces), str(motors)], check=True,
                         capture_output=True, text=True).stdout.split()
    return float(out[0]), int(out[1])


def build_scene(core, mode: int, forces: int, motors: int) -> None:
    """The scene of native/core_scene.c through the Core API."""
    from virtual_world.core import FORCE, ObjectSpec

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
    ids = [core.create_motor(body1=f"s{i}", axes=[0, 0, 1], axis_frames=[1])
           for i in range(motors)]
    core.set_motor_velocities({motor: [0.5] for motor in ids})


ODIN_TIMED_SCRIPT = (
    "import sys, time; sys.path.insert(0, {here!r}); import bench_core\n"
    "from virtual_world.core import Core\n"
    "core = Core(); bench_core.build_scene(core, {mode}, {forces}, {motors})\n"
    "started = time.perf_counter(); core.step(0.001, {steps})\n"
    "print(time.perf_counter() - started, core.last_step_contacts)\n")


def _odin(mode: int, forces: int, motors: int):
    """Odin's step loop timed in a process of its own, as the native program is: a long-lived
    process that has built and freed many scenes steps a few per cent slower (its heap is
    scattered), which is the process, not the Core (the instruction counts are equal)."""
    script = ODIN_TIMED_SCRIPT.format(here=str(HERE), mode=mode, forces=forces, motors=motors,
                                      steps=STEPS)
    out = subprocess.run([sys.executable, "-c", script], check=True, capture_output=True,
                         text=True).stdout.split()
    return float(out[0]), int(out[1])


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
NATIVE_LOOP = ("dSpaceCollide", "dWorldQuickStep", "dJointGroupEmpty", "dBodyAddForce",
               "dJointSetAMotorParam")
ODIN_LOOP = ("odin_world_step",)
COUNTED_STEPS = 300
ODIN_STEP_SCRIPT = (
    "import sys; sys.path.insert(0, {here!r}); import bench_core\n"
    "from virtual_world.core import Core\n"
    "core = Core(); bench_core.build_scene(core, {mode}, {forces}, {motors})\n"
    "core.step(0.001, {steps})\n")


def _instructions(command: list, functions: tuple, out_file: pathlib.Path) -> int:
    """Instructions executed inside ``functions`` (callgrind, inclusive)."""
    toggles = [f"--toggle-collect={name}" for name in functions]
    subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out_file}",
                    *toggles, *command], check=True, capture_output=True)
    for line in out_file.read_text().splitlines():
        if line.startswith(("summary:", "totals:")):
            return int(line.split()[1])
    raise RuntimeError(f"no instruction total in {out_file}")


def instruction_ratios(exe: pathlib.Path, out_dir: pathlib.Path) -> dict:
    figures = {}
    for figure, (mode, forces, motors) in CASES.items():
        native = _instructions([str(exe), str(mode), str(COUNTED_STEPS), str(forces),
                                str(motors)], NATIVE_LOOP, out_dir / "callgrind.native")
        script = ODIN_STEP_SCRIPT.format(here=str(HERE), mode=mode, forces=forces,
                                         motors=motors, steps=COUNTED_STEPS)
        odin = _instructions([sys.executable, "-c", script], ODIN_LOOP,
                             out_dir / "callgrind.odin")
        figures[figure.replace("_ratio", "_instructions_ratio")] = round(native / odin, 3)
    return figures


def run(out_dir: pathlib.Path) -> dict:
    out_dir.mkdir(parents=True, exist_ok=True)
    exe = _compile(out_dir)
    figures = {}
    details = []
    for figure, (mode, forces, motors) in CASES.items():
        native_times, odin_times = [], []
        for _ in range(ROUNDS):
            t, native_contacts = _native(exe, mode, forces, motors)
            native_times.append(t)
            t, odin_contacts = _odin(mode, forces, motors)
            odin_times.append(t)
        ratio = statistics.median(n / o for n, o in zip(native_times, odin_times))
        figures[figure] = round(ratio, 3)
        details.append(f"{figure}: native {native_times} s ({native_contacts} contacts), "
                       f"odin {odin_times} s ({odin_contacts} contacts)")
    figures["core_newscene_leak_kb"] = _leak_kb()
    figures.update(instruction_ratios(exe, out_dir))
    (out_dir / "bench_core.txt").write_text("\n".join(details) + "\n")
    return figures


if __name__ == "__main__":
    root = HERE.parent.parent
    print(run(root / "out" / "bench"))
