"""Odin's GUI window (thesis chapter 7): ``rosrun GUI gui``.

Modules: ``main_window`` (the window, message log, connection state), one module per tab
(``simulation_tab``, ``settings_tab``, ``objects_tab``, ``motion_tab`` with its
``solve_panel`` (a geometric query solved, shown and run), ``joints_tab``),
``plot_panel`` (joint positions and speeds from the world's ~joint_states), ``viewer_panel``
(the Viewer's image), ``worker`` (service calls on a QThread, never the GUI thread),
``ros_link`` (topics -> Qt signals), ``scene`` (what the window knows of the scene), ``fields``
(input limits), ``display`` (on-screen or off-screen, decided at start-up).

    rosrun GUI gui [--master-timeout S] [_world:=/virtual_world] [_viewer:=/viewer]

Node ``gui``; parameters: ``~world`` ("/virtual_world": namespace of the world's services and
topics), ``~viewer`` ("/viewer": namespace of the Viewer's image topic).
Services called: every ``<~world>/*`` service, ``<~viewer>/set_camera``. Topics read:
``<~world>/world_update``, ``<~world>/joint_data``, ``<~world>/joint_states``,
``<~viewer>/image``. Services and topics go through gui.ros: this package imports no ROS client
library.
"""
from __future__ import annotations

import argparse
import signal
import sys
from typing import List, Optional, Sequence, Tuple

MASTER_TIMEOUT_S = 30.0
"""s the window waits for a ROS master at start, saying so, before it says none answers and
exits 2: long enough for a roscore started beside it (a script, a launch, a test) to come up."""


def _options(argv: Sequence[str]) -> Tuple[argparse.Namespace, List[str]]:
    """The window's own options, and the rest of ``argv`` for Qt (argv[0] first)."""
    parser = argparse.ArgumentParser(prog="gui", description="Odin's GUI window")
    parser.add_argument("--master-timeout", type=float, default=MASTER_TIMEOUT_S, metavar="S",
                        help=f"s to wait for a ROS master at start (default {MASTER_TIMEOUT_S:g})")
    options, rest = parser.parse_known_args(list(argv[1:]))
    if not options.master_timeout > 0:
        parser.error(f"--master-timeout must be > 0 s, got {options.master_timeout:g}")
    return options, [argv[0], *rest]


def main(argv: Optional[Sequence[str]] = None) -> int:
    import os

    from gui.ros.node import without_remappings
    from gui.window.display import choose_platform
    options, qt_argv = _options(without_remappings(argv if argv is not None else sys.argv))
    offscreen = choose_platform(os.environ)        # before Qt reads the environment
    if offscreen:
        print(f"gui: {offscreen}", file=sys.stderr)

    from PyQt5.QtCore import QTimer
    from PyQt5.QtWidgets import QApplication

    from gui.ros.node import start_gui_node, stop_gui_node
    from gui.window.main_window import MainWindow
    from odin_common.errors import NoMasterError
    app = QApplication(qt_argv)
    try:
        parameters = start_gui_node("gui", master_timeout=options.master_timeout)
    except NoMasterError as error:
        print(f"gui: error: {error}", file=sys.stderr)
        return 2
    window = MainWindow(world=parameters["world"], viewer=parameters["viewer"])
    window.show()
    signal.signal(signal.SIGINT, lambda *_: app.quit())
    tick = QTimer()
    tick.timeout.connect(lambda: None)      # lets Python see Ctrl-C while Qt runs
    tick.start(200)
    status = app.exec_()
    window.shutdown()
    stop_gui_node("window closed")
    return status
