"""Where the window is drawn, decided once at start-up from the GUI process's own environment.

Qt picks its platform plugin from ``QT_QPA_PLATFORM``; with no display to open (no ``DISPLAY``
or ``WAYLAND_DISPLAY``: CI, Docker, ssh without -X) the default plugin aborts the process, so
the window is drawn off-screen there. The choice is made here and said in one line, never
inherited silently from the shell: a shell that sourced setup.bash without a display and set
``DISPLAY`` later must get a visible window.
"""
from __future__ import annotations

from typing import MutableMapping, Optional

OFFSCREEN_PLATFORMS = ("offscreen", "minimal")
"""Qt platform plugins that draw nothing on a screen."""


def choose_platform(environ: MutableMapping[str, str]) -> Optional[str]:
    """Sets ``QT_QPA_PLATFORM=offscreen`` in ``environ`` when there is no display and none is
    chosen; returns the line to say when the window will not be seen (None when it will)."""
    display = environ.get("DISPLAY") or environ.get("WAYLAND_DISPLAY")
    chosen = environ.get("QT_QPA_PLATFORM", "")
    plugin = chosen.split(":", 1)[0]
    if not chosen and not display:
        environ["QT_QPA_PLATFORM"] = "offscreen"
        return ("no display (DISPLAY and WAYLAND_DISPLAY are unset): the window is drawn "
                "off-screen; set DISPLAY to see it")
    if plugin in OFFSCREEN_PLATFORMS:
        where = f" although DISPLAY={display} is set" if display else ""
        return (f"QT_QPA_PLATFORM={chosen}: the window is drawn off-screen{where}; unset "
                "QT_QPA_PLATFORM to see it")
    return None
