"""Re-exports the compiled cffi module: ``from virtual_world.ode.bindings import ffi, lib``."""
from _odin_ode import ffi, lib  # noqa: F401  (built by build_ode.py into the devel space)
