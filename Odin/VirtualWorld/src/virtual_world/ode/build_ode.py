"""Compiles the cffi extension ``_odin_ode`` (API mode) over Debian's libode.

Layers, each in its own file (pymunk's layout):
  * ``ode_cdef.h``  -- the part of ODE's C API cffi exposes to Python (a real header text);
  * ``odin_step.h`` -- Odin's own C declarations, read into the cdef too (one source);
  * ``odin_step.c`` -- Odin's own C code compiled into the extension: the per-step hot work;
  * ``odin_state.c`` -- bodies' state read and written bit for bit (snapshots);
  * ``odin_kinematic.c`` -- the kinematic drive's forward kinematics, every step;
  * ``odin_query.c`` -- the geometric planner's collision queries;
  * ``odin_motion.c`` -- its motion check (kinematics and the walk) in one call;
  * this module     -- the build; ``bindings.py`` only re-exports ``ffi, lib``.

Usage: ``python build_ode.py --out DIR [--tmp DIR]`` (CMake runs it during the catkin build).
"""
import argparse
import pathlib
import re
import subprocess

import cffi

HERE = pathlib.Path(__file__).resolve().parent


def _pkg_config(*args: str) -> list:
    return subprocess.run(["pkg-config", *args, "ode"], check=True, capture_output=True,
                          text=True).stdout.split()


def odin_declarations(header: str) -> str:
    """The cdef text of odin_step.h: comments and preprocessor lines dropped, except integer
    constants, which stay (cffi checks them against the compiled value) and are written into
    the array sizes that use them (cffi's parser wants literal sizes)."""
    text = re.sub(r"/\*.*?\*/", "", header, flags=re.S)
    constants = dict(re.findall(r"^#define\s+(ODIN_\w+)\s+(\d+)\s*$", text, flags=re.M))
    text = "\n".join(line for line in text.splitlines() if not line.lstrip().startswith("#"))
    for name, value in constants.items():
        text = text.replace(f"[{name}]", f"[{value}]")
    defines = "".join(f"#define {name} {value}\n" for name, value in constants.items())
    return defines + text


def make_builder() -> cffi.FFI:
    ffibuilder = cffi.FFI()
    ffibuilder.cdef((HERE / "ode_cdef.h").read_text()
                    + odin_declarations((HERE / "odin_step.h").read_text()))
    ffibuilder.set_source(
        "_odin_ode",
        '#include <ode/ode.h>\n#include "odin_step.h"\n',
        sources=[str(HERE / "odin_step.c"), str(HERE / "odin_state.c"),
                 str(HERE / "odin_kinematic.c"), str(HERE / "odin_query.c"),
                 str(HERE / "odin_motion.c"), str(HERE / "odin_plan.c")],
        include_dirs=[str(HERE)],
        extra_compile_args=["-O2", "-DdDOUBLE"] + _pkg_config("--cflags"),
        libraries=["ode"],
        extra_link_args=_pkg_config("--libs"),
    )
    return ffibuilder


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="folder that receives _odin_ode*.so")
    parser.add_argument("--tmp", default=None, help="folder for intermediate files")
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    tmp = pathlib.Path(args.tmp or out / "_odin_ode_build")
    tmp.mkdir(parents=True, exist_ok=True)
    library = make_builder().compile(tmpdir=str(tmp), verbose=False)
    target = out / pathlib.Path(library).name
    target.write_bytes(pathlib.Path(library).read_bytes())
    print(f"built {target}")


if __name__ == "__main__":
    main()
