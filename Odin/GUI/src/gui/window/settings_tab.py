"""Second tab (thesis 7.2): step values and world parameters, in a tool box.

Step: any subset of the four step values (a check box each; unchecked means "not given"); the
world resolves conflicts and answers the values in force, which are shown beside the fields.
World parameters: each with a check box (zero is a valid value of most), sent together in one
Set World (all-or-nothing); the values in force come back and are shown. Their first values,
units and ranges are odin_common.world_parameters'. The values in force are read through the
client when the world comes up (an empty Set Step / Set World answers them).
"""
from __future__ import annotations

from typing import Optional

from PyQt5.QtWidgets import (QButtonGroup, QCheckBox, QComboBox, QGridLayout, QHBoxLayout,
                             QLabel, QPushButton, QRadioButton, QToolBox, QVBoxLayout, QWidget)

from gui.window.fields import VectorRow, checked_spin, int_spin, spin
from odin_common.interface import Solver
from odin_common.step_values import MAX_RATE, MAX_STEP, MAX_STEPS_PER_CYCLE, StepValues
from odin_common.world_parameters import PARAMETER_INFO, default

#: (parameter, label, decimals, step, bound of the field where the parameter has none) of the
#: scalar parameters, per page
SCALARS = {
    "ERP and CFM": [
        ("erp", "Error reduction parameter (ERP)", 4, 0.05, None),
        ("cfm", "Constraint force mixing (CFM)", 7, 1e-5, 1.0),
    ],
    "Speed limits and contact layer": [
        ("max_angular_speed", "Maximum angular speed (0: none)", 3, 1.0, 1e4),
        ("contact_max_correcting_velocity", "Contact max correcting velocity (0: unlimited)",
         3, 0.1, 1e4),
        ("contact_surface_layer", "Contact surface layer", 4, 0.001, 1.0),
    ],
    "Damping": [
        ("linear_damping", "Linear damping", 4, 0.01, None),
        ("linear_damping_threshold", "Linear damping threshold", 4, 0.01, 1e3),
        ("angular_damping", "Angular damping", 4, 0.01, None),
        ("angular_damping_threshold", "Angular damping threshold", 4, 0.01, 1e3),
    ],
    "Contacts": [
        ("friction", "Friction (Coulomb mu; negative: infinite)", 3, 0.1, 1e3),
        ("bounce", "Bounce (restitution)", 3, 0.05, None),
        ("bounce_velocity", "Bounce velocity", 3, 0.05, 1e3),
        ("collision_mesh_tolerance", "Collision mesh tolerance (0: as given; meshes built "
         "afterwards)", 4, 0.001, None),
    ],
}
SOLVER_NAMES = {Solver.QUICKSTEP: "QuickStep", Solver.WORLDSTEP: "WorldStep", Solver.AUTO: "Auto"}
SOLVER_ITEMS = {Solver.QUICKSTEP: "QuickStep (iterative, handles piles)",
                Solver.WORLDSTEP: "WorldStep (exact, the thesis's)",
                Solver.AUTO: "Auto (WorldStep on few constraints, else QuickStep)"}


def _unit(name: str) -> str:
    unit = PARAMETER_INFO[name].unit
    return "" if unit == "-" else unit.replace("^2", "²")


def _range(name: str, bound: Optional[float]) -> tuple:
    """(low, high) of a parameter's field: its range, ``bound`` above where it has no upper
    bound, ``-bound`` below where it has no lower one (friction: negative is infinite)."""
    info = PARAMETER_INFO[name]
    return (float(info.low if info.low is not None else -bound),
            float(info.high if info.high is not None else bound))


class SettingsTab(QWidget):
    def __init__(self, window, parent=None):
        super().__init__(parent)
        self.window = window
        self.toolbox = QToolBox()
        self.in_force: dict = {}
        self.in_force_labels: dict = {}

        # -- step page
        page = QWidget()
        grid = QGridLayout(page)
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
        grid.addWidget(QLabel("<b>send</b>"), 0, 0)
        grid.addWidget(QLabel("<b>in force</b>"), 0, 2)
        for row, (key, (check, box)) in enumerate(self.step_fields.items(), start=1):
            grid.addWidget(check, row, 0)
            grid.addWidget(box, row, 1)
            label = QLabel("?")
            self.in_force_labels[key] = label
            grid.addWidget(label, row, 2)
            box.valueChanged.connect(lambda _v, c=check: c.setChecked(True))
        self.set_step_button = QPushButton("Set step")
        grid.addWidget(self.set_step_button, 5, 1)
        grid.setRowStretch(6, 1)
        self.toolbox.addItem(page, "Step sizes")
        self.set_step_button.clicked.connect(self.send_step)

        # -- world pages
        self.world_checks: dict = {}
        self.world_boxes: dict = {}
        page = QWidget()
        grid = QGridLayout(page)
        self.gravity_check = QCheckBox("Set gravity")
        self.gravity = VectorRow("xyz", default("gravity"), -1e3, 1e3, 3, 0.1,
                                 _unit("gravity"))
        grid.addWidget(self.gravity_check, 0, 0)
        grid.addWidget(self.gravity, 0, 1)
        grid.addWidget(QLabel("in force:"), 1, 0)
        self._in_force_label(grid, "gravity", 1, 1)
        grid.setRowStretch(2, 1)
        self.toolbox.addItem(page, "Gravity")

        page = QWidget()
        grid = QGridLayout(page)
        self.policy_check = QCheckBox("Set collision policy")
        self.contacts_radio = QRadioButton("Create contacts")
        self.highlight_radio = QRadioButton("Detect and report only (highlight objects)")
        self.contacts_radio.setChecked(True)
        group = QButtonGroup(page)
        group.addButton(self.contacts_radio)
        group.addButton(self.highlight_radio)
        grid.addWidget(self.policy_check, 0, 0)
        grid.addWidget(self.contacts_radio, 0, 1)
        grid.addWidget(self.highlight_radio, 1, 1)
        self.max_contacts_check = QCheckBox("Maximum contacts per pair")
        info = PARAMETER_INFO["max_contacts"]
        self.max_contacts = int_spin(default("max_contacts"), int(info.low), int(info.high))
        grid.addWidget(self.max_contacts_check, 2, 0)
        grid.addWidget(self.max_contacts, 2, 1)
        self._in_force_label(grid, "contact_less", 0)
        self._in_force_label(grid, "max_contacts", 2)
        grid.setRowStretch(3, 1)
        self.toolbox.addItem(page, "Collision policy")

        for title, rows in SCALARS.items():
            page = QWidget()
            grid = QGridLayout(page)
            for row, (key, label, decimals, step, bound) in enumerate(rows):
                value, (low, high), unit = default(key), _range(key, bound), _unit(key)
                if key == "bounce_velocity":
                    check = QCheckBox(label + " (sent with bounce)")
                    check.setEnabled(False)
                    box = spin(value, low, high, decimals, step, unit)
                else:
                    check, box = checked_spin(label, value, low, high, decimals, step, unit)
                    box.valueChanged.connect(lambda _v, c=check: c.setChecked(True))
                self.world_checks[key] = check
                self.world_boxes[key] = box
                grid.addWidget(check, row, 0)
                grid.addWidget(box, row, 1)
                self._in_force_label(grid, key, row)
            grid.setRowStretch(len(rows), 1)
            self.toolbox.addItem(page, title)

        page = QWidget()
        grid = QGridLayout(page)
        self.solver_check = QCheckBox("Set solver")
        self.solver = QComboBox()
        self.solver.addItems([SOLVER_ITEMS[s] for s in Solver])        # index = Solver
        self.solver.setCurrentIndex(default("solver"))
        info = PARAMETER_INFO["quickstep_iterations"]
        self.iterations = int_spin(default("quickstep_iterations"), int(info.low),
                                   int(info.high), "QuickStep iterations")
        grid.addWidget(self.solver_check, 0, 0)
        grid.addWidget(self.solver, 0, 1)
        grid.addWidget(QLabel("QuickStep iterations"), 1, 0)
        grid.addWidget(self.iterations, 1, 1)
        self._in_force_label(grid, "solver", 0)
        self.sleep_check = QCheckBox("Set auto-disable")
        self.sleep = QCheckBox("Resting bodies sleep until touched or changed")
        self.sleep.setChecked(default("auto_disable"))
        self.sleep.setToolTip(PARAMETER_INFO["auto_disable"].what)
        grid.addWidget(self.sleep_check, 2, 0)
        grid.addWidget(self.sleep, 2, 1)
        self._in_force_label(grid, "auto_disable", 2)
        grid.setRowStretch(3, 1)
        self.toolbox.addItem(page, "Solver")

        self.set_world_button = QPushButton("Set checked world parameters")
        self.set_world_button.clicked.connect(self.send_world)
        self.gravity_check.setChecked(False)
        for box in self.gravity.boxes:
            box.valueChanged.connect(lambda _v: self.gravity_check.setChecked(True))
        self.solver.currentIndexChanged.connect(lambda _i: self.solver_check.setChecked(True))
        self.iterations.valueChanged.connect(lambda _i: self.solver_check.setChecked(True))
        self.max_contacts.valueChanged.connect(lambda _i: self.max_contacts_check.setChecked(True))
        self.contacts_radio.toggled.connect(lambda _b: self.policy_check.setChecked(True))
        self.sleep.toggled.connect(lambda _b: self.sleep_check.setChecked(True))

        layout = QVBoxLayout(self)
        layout.addWidget(self.toolbox, 1)
        row = QHBoxLayout()
        row.addStretch(1)
        row.addWidget(self.set_world_button)
        layout.addLayout(row)

    def _in_force_label(self, grid: QGridLayout, key: str, row: int, column: int = 2) -> None:
        label = QLabel("?")
        label.setToolTip("value in force in the world")
        self.in_force_labels[key] = label
        grid.addWidget(label, row, column)

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
        """{world parameter: value} of the checked parameters (the names of
        odin_common.world_parameters)."""
        changes: dict = {}
        if self.gravity_check.isChecked():
            changes["gravity"] = self.gravity.values()
        if self.policy_check.isChecked():
            changes["contact_less"] = self.highlight_radio.isChecked()
        if self.max_contacts_check.isChecked():
            changes["max_contacts"] = int(self.max_contacts.value())
        for key, check in self.world_checks.items():
            if key != "bounce_velocity" and check.isChecked():
                changes[key] = float(self.world_boxes[key].value())
        if "bounce" in changes:
            changes["bounce_velocity"] = float(self.world_boxes["bounce_velocity"].value())
        if self.solver_check.isChecked():
            changes["solver"] = Solver(self.solver.currentIndex())
            changes["quickstep_iterations"] = int(self.iterations.value())
        if self.sleep_check.isChecked():
            changes["auto_disable"] = self.sleep.isChecked()
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
        for key, label in self.in_force_labels.items():
            if key in self.step_fields:
                continue
            value = getattr(parameters, key)
            self.in_force[key] = value
            if key == "gravity":
                text = "(" + ", ".join(f"{v:g}" for v in value) + ")"
            elif key == "contact_less":
                text = "detect only" if value else "contacts"
            elif key == "auto_disable":
                text = "on" if value else "off"
            elif key == "solver":
                text = SOLVER_NAMES.get(value, str(value)) + \
                    f", {parameters.quickstep_iterations} it."
            else:
                text = f"{value:g}"
            label.setText(text)
        for check in [self.gravity_check, self.policy_check, self.max_contacts_check,
                      self.solver_check, self.sleep_check, *self.world_checks.values()]:
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
