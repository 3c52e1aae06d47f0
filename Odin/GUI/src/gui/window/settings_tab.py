"""Second tab (thesis 7.2): step values and world parameters, in a tool box.

Step: any subset of the four step values (a check box each; unchecked means "not given"); the
world resolves conflicts and answers the values in force, which are shown beside the fields.
World parameters: one row each, generated from odin_common.world_parameters.PARAMETERS (its
title, field, unit, range, first value, tool tip and page: ``gui.window.forms``), so a new
parameter shows up here with no edit. Each Set World flag has a check box (zero is a valid
value of most) that sends the parameters it applies; the checked ones go together in one Set
World (all-or-nothing) and the values in force come back and are shown. The values in force
are read through the client when the world comes up (an empty Set Step / Set World answers
them).
"""
from __future__ import annotations

from typing import Dict, List

from PyQt5.QtWidgets import (QCheckBox, QHBoxLayout, QLabel, QPushButton, QToolBox,
                             QVBoxLayout, QWidget)

from gui.window.fields import checked_spin, int_spin
from gui.window.forms import (ParameterField, form_grid, growing, parameter_text,
                              parameter_tip, parameter_title)
from odin_common.step_values import MAX_RATE, MAX_STEP, MAX_STEPS_PER_CYCLE, StepValues
from odin_common.world_parameters import (PARAMETER_INFO, PARAMETERS, ParameterInfo, default,
                                          set_world_flags)


def _pages() -> Dict[str, List[ParameterInfo]]:
    """Page title -> its parameters, pages in the order of their first parameter."""
    pages: Dict[str, List[ParameterInfo]] = {}
    for info in PARAMETERS:
        pages.setdefault(info.group, []).append(info)
    return pages


class SettingsTab(QWidget):
    def __init__(self, window, parent=None):
        super().__init__(parent)
        self.window = window
        self.toolbox = QToolBox()
        self.in_force: dict = {}
        self.in_force_labels: dict = {}
        self.toolbox.addItem(self._step_page(), "Step sizes")

        self.world_fields: Dict[str, ParameterField] = {}
        self.world_boxes: dict = {}         # parameter -> its input widget
        self.world_checks: dict = {}        # parameter -> the check box that sends it
        self.flags = set_world_flags()
        self.flag_checks = {flag: self._send_check(PARAMETER_INFO[names[0]])
                            for flag, names in self.flags.items()}
        for title, infos in _pages().items():
            self.toolbox.addItem(self._world_page(infos), title)
        self.set_world_button = QPushButton("Set checked world parameters")
        self.set_world_button.clicked.connect(self.send_world)

        layout = QVBoxLayout(self)
        layout.addWidget(self.toolbox, 1)
        row = QHBoxLayout()
        row.addStretch(1)
        row.addWidget(self.set_world_button)
        layout.addLayout(row)

    def _step_page(self) -> QWidget:
        first = StepValues()   # shown until the world answers with the values in force
        self.step_fields = {
            "step": checked_spin("Step", first.step, 1e-6, MAX_STEP, 6, 0.0005, "s"),
            "steps_per_cycle": (QCheckBox("Steps per cycle"),
                                int_spin(first.steps_per_cycle, 1, MAX_STEPS_PER_CYCLE)),
            "cycle_time": checked_spin("Cycle time", first.cycle_time, 1e-6, 10.0, 5, 0.01,
                                       "s"),
            "rate": checked_spin("Rate (publications / s)", first.rate, 0.01, MAX_RATE, 2, 1.0,
                                 "Hz"),
        }
        rows = [["<b>send</b>", None, "<b>in force</b>"]]
        for key, (check, box) in self.step_fields.items():
            rows.append([check, box, self._in_force_label(key)])
            box.valueChanged.connect(lambda _v, c=check: c.setChecked(True))
        self.set_step_button = QPushButton("Set step")
        self.set_step_button.clicked.connect(self.send_step)
        rows += [[None, self.set_step_button], growing()]
        page = QWidget()
        form_grid(rows, page)
        return page

    def _world_page(self, infos: List[ParameterInfo]) -> QWidget:
        """One row per parameter: the check box of its Set World flag (the first parameter of
        a flag holds it; the others show it, disabled), its field, its value in force."""
        rows = []
        for info in infos:
            field = ParameterField(info, default(info.name))
            sender = self.flag_checks[info.set_flag]
            first = PARAMETER_INFO[self.flags[info.set_flag][0]]
            check = sender if first is info else self._sent_with(info, first, sender)
            field.on_edit(lambda c=sender: c.setChecked(True))
            self.world_fields[info.name] = field
            self.world_boxes[info.name] = field.widget
            self.world_checks[info.name] = sender
            rows.append([check, field.widget, self._in_force_label(info.name)])
        page = QWidget()
        form_grid(rows + [growing()], page)
        return page

    @staticmethod
    def _sent_with(info: ParameterInfo, first: ParameterInfo, sender: QCheckBox) -> QCheckBox:
        """A disabled check box that follows ``sender``: Set World applies ``info`` with
        ``first``, its flag's first parameter."""
        check = QCheckBox(parameter_title(info))
        check.setEnabled(False)
        check.setToolTip(f"sent with {first.label}: tick {first.label} to send it")
        sender.toggled.connect(check.setChecked)
        return check

    @staticmethod
    def _send_check(info: ParameterInfo) -> QCheckBox:
        check = QCheckBox(parameter_title(info))
        check.setToolTip(parameter_tip(info))
        return check

    def _in_force_label(self, key: str) -> QLabel:
        label = QLabel("?")
        label.setToolTip("value in force in the world")
        self.in_force_labels[key] = label
        return label

    # the widgets tests drive the tab by
    @property
    def gravity(self):
        return self.world_boxes["gravity"]

    @property
    def highlight_radio(self):
        return self.world_boxes["contact_less"].buttons[1]     # true: detect only

    @property
    def solver(self):
        return self.world_boxes["solver"]

    @property
    def sleep(self):
        return self.world_boxes["auto_disable"]

    @property
    def sleep_check(self):
        return self.world_checks["auto_disable"]

    # -- step ---------------------------------------------------------------------------------
    def step_request(self) -> dict:
        fields = {}
        for key, (check, box) in self.step_fields.items():
            if check.isChecked():
                fields[key] = int(box.value()) if key == "steps_per_cycle" else float(box.value())
        return fields

    def send_step(self) -> None:
        fields = self.step_request()
        self.window.call("Set Step", lambda client, job: client.set_step(**fields),
                         self.show_step)

    def show_step(self, values) -> None:
        """Shows the step values in force (odin_common.step_values.StepValues)."""
        for key in self.step_fields:
            value = getattr(values, key)
            self.in_force[key] = value
            self.in_force_labels[key].setText(f"{value:g}")
        for check, _ in self.step_fields.values():
            check.setChecked(False)
        self.window.publication_rate = float(values.rate)

    # -- world --------------------------------------------------------------------------------
    def world_changes(self) -> dict:
        """{world parameter: value} of the checked flags' parameters (the names of
        odin_common.world_parameters)."""
        changes: dict = {}
        for flag, names in self.flags.items():
            if self.flag_checks[flag].isChecked():
                changes.update({name: self.world_fields[name].value() for name in names})
        return changes

    def send_world(self) -> None:
        changes = self.world_changes()
        if not changes:
            self.window.show_error("Set World: check at least one parameter to send")
            return
        self.window.call("Set World", lambda client, job: client.set_world(**changes),
                         self.show_world)

    def show_world(self, parameters) -> None:
        """Shows the world parameters in force (odin_common WorldParameters)."""
        for info in PARAMETERS:
            value = getattr(parameters, info.name)
            self.in_force[info.name] = value
            self.in_force_labels[info.name].setText(parameter_text(info, value))
        for check in self.flag_checks.values():
            check.setChecked(False)

    def refresh(self) -> None:
        """Shows the step values and world parameters in force, read through the client."""
        def read(client, job):
            world = client.world()
            return world.step_values, world.parameters

        def done(values):
            self.show_step(values[0])
            self.show_world(values[1])

        self.window.call("Read the world's parameters", read, done)
