"""Fifth tab (thesis 7.5): create joints, set their parameters, list and remove them.

The joint type chooses which rows are enabled (anchor; first, second, third axis), as the
world uses them. The two bodies come from the objects in the world, or the static environment.
Parameters (stops, bounce, ERP, CFM, stop ERP / CFM, suspension ERP / CFM, fudge factor), each
with a check box, go with a new joint (applied after creation) or to the joint chosen in the
list (Set parameters). A motor can be put on the chosen joint (then driven from the Motion tab).
"""
from __future__ import annotations

from PyQt5.QtCore import Qt
from PyQt5.QtWidgets import (QComboBox, QGroupBox, QHBoxLayout, QListWidget, QListWidgetItem,
                             QPushButton, QVBoxLayout, QWidget)

from gui.window.fields import InputError, VectorRow, checked_spin, int_spin
from gui.window.forms import form_grid, list_box
from gui.window.scene import JOINT_TYPE_NAMES
from odin_common.interface import (JOINT_AXES_USED, JOINT_USES_ANCHOR, JointParameter,
                                   JointType, MotorKind)
from odin_common.specs import JointSpec, MotorSpec
from odin_common.world_parameters import default

STATIC = "Static environment"
#: (parameter, label, value shown first, low, high); a joint's ERP and CFM start at the world's
PARAMETERS = [
    (JointParameter.LO_STOP, "Low stop (rad or m)", -1.0, -1e3, 1e3),
    (JointParameter.HI_STOP, "High stop (rad or m)", 1.0, -1e3, 1e3),
    (JointParameter.BOUNCE, "Stop bounce", 0.0, 0.0, 1.0),
    (JointParameter.CFM, "CFM", default("cfm"), 0.0, 1.0),
    (JointParameter.ERP, "ERP", default("erp"), 0.0, 1.0),
    (JointParameter.STOP_ERP, "Stop ERP", default("erp"), 0.0, 1.0),
    (JointParameter.STOP_CFM, "Stop CFM", default("cfm"), 0.0, 1.0),
    (JointParameter.SUSPENSION_ERP, "Suspension ERP (hinge2)", default("erp"), 0.0, 1.0),
    (JointParameter.SUSPENSION_CFM, "Suspension CFM (hinge2)", default("cfm"), 0.0, 1.0),
    (JointParameter.FUDGE_FACTOR, "Fudge factor", 1.0, 0.0, 1.0),
]
#: joint type -> the motor "Add motor" puts on it: its kind and number of axes
MOTORS = {
    JointType.HINGE: (MotorKind.ANGULAR, 1), JointType.SLIDER: (MotorKind.LINEAR, 1),
    JointType.PISTON: (MotorKind.LINEAR, 1), JointType.UNIVERSAL: (MotorKind.ANGULAR, 2),
    JointType.HINGE2: (MotorKind.ANGULAR, 2), JointType.PR: (MotorKind.LINEAR, 1),
    JointType.PU: (MotorKind.ANGULAR, 2),
}


class JointsTab(QWidget):
    def __init__(self, window, parent=None):
        super().__init__(parent)
        self.window = window
        self.type = QComboBox()
        self.type.addItems([JOINT_TYPE_NAMES[t] for t in JointType])   # index = JointType
        self.type.setCurrentIndex(JointType.HINGE)
        self.body1 = QComboBox()
        self.body2 = QComboBox()
        self.anchor = VectorRow("xyz", (0.0, 0.0, 0.0), -1e4, 1e4, 3, 0.1, "m")
        self.axes = [VectorRow("xyz", v, -1e3, 1e3, 3, 0.1)
                     for v in ((0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0))]
        self.create_button = QPushButton("Create joint")

        create = QGroupBox("New joint")
        axis_rows = [[title, row] for title, row in
                     zip(("First axis", "Second axis", "Third axis"), self.axes)]
        form_grid([["Joint type", self.type], ["First object", self.body1],
                   ["Second object", self.body2], ["Anchor", self.anchor], *axis_rows,
                   [None, self.create_button]], create)

        params = QGroupBox("Parameters (for a new joint, or Set on the chosen one)")
        self.param_axis = int_spin(1, 1, 3, "axis the parameters apply to")
        self.param_fields = {}
        cells = []
        for parameter, label, value, low, high in PARAMETERS:
            check, box = checked_spin(label, value, low, high, 6, 0.05)
            box.valueChanged.connect(lambda _v, c=check: c.setChecked(True))
            self.param_fields[parameter] = (check, box)
            cells += [check, box]
        pairs = [cells[k:k + 4] for k in range(0, len(cells), 4)]    # two parameters a row
        form_grid([["Axis", self.param_axis], *pairs], params)

        self.list = QListWidget()
        self.remove_button = QPushButton("Remove")
        self.set_button = QPushButton("Set parameters")
        self.motor_button = QPushButton("Add motor")
        listing = list_box("Joint list", self.list,
                           [self.remove_button, self.set_button, self.motor_button])

        top = QHBoxLayout()
        top.addWidget(create, 1)
        layout = QVBoxLayout(self)
        layout.addLayout(top)
        layout.addWidget(params)
        layout.addWidget(listing, 1)

        self.type.currentIndexChanged.connect(self._type_changed)
        self.create_button.clicked.connect(self.create)
        self.remove_button.clicked.connect(self.remove)
        self.set_button.clicked.connect(self.set_parameters)
        self.motor_button.clicked.connect(self.add_motor)
        window.scene.changed.connect(self._scene_changed)
        self._scene_changed("objects")
        self._type_changed(self.type.currentIndex())

    def _type_changed(self, index: int) -> None:
        joint_type = JointType(index)
        self.anchor.setEnabled(joint_type in JOINT_USES_ANCHOR)
        axes = len(JOINT_AXES_USED[joint_type])
        for k, row in enumerate(self.axes):
            row.setEnabled(k < axes)
        self.body2.setEnabled(joint_type != JointType.PLANE2D)    # body1 only

    def enabled_rows(self) -> list:
        """Names of the enabled geometry rows (for tests and tool tips)."""
        names = ["anchor"] if self.anchor.isEnabled() else []
        return names + [f"axis{k + 1}" for k, row in enumerate(self.axes) if row.isEnabled()]

    def _scene_changed(self, what: str) -> None:
        scene = self.window.scene
        if what == "objects":
            for combo in (self.body1, self.body2):
                current = combo.currentText()
                combo.blockSignals(True)
                combo.clear()
                combo.addItems([STATIC] + scene.objects)
                if current in scene.objects:
                    combo.setCurrentText(current)
                combo.blockSignals(False)
        elif what in ("joints", "robots"):
            current = self.selected()
            self.list.clear()
            for row, (label, joint_id) in enumerate(scene.grouped(scene.joints,
                                                                  scene.joint_label)):
                item = QListWidgetItem(label if label == joint_id else f"{label}   [{joint_id}]")
                item.setData(Qt.UserRole, joint_id)
                self.list.addItem(item)
                if joint_id == current:
                    self.list.setCurrentRow(row)

    def selected(self):
        """The world ID of the joint chosen in the list (None: none)."""
        item = self.list.currentItem()
        return item.data(Qt.UserRole) if item is not None else None

    def parameters(self) -> list:
        """(JointParameter, axis, value) of the checked parameters."""
        axis = int(self.param_axis.value())
        return [(parameter, axis, float(box.value()))
                for parameter, (check, box) in self.param_fields.items() if check.isChecked()]

    def _clear_checks(self) -> None:
        for check, _ in self.param_fields.values():
            check.setChecked(False)

    def create(self) -> None:
        joint_type = JointType(self.type.currentIndex())
        body1 = self.body1.currentText()
        body2 = self.body2.currentText() if self.body2.isEnabled() else STATIC
        body1 = "" if body1 in (STATIC, "") else body1
        body2 = "" if body2 in (STATIC, "") else body2
        if not body1 and not body2:
            self.window.show_error("Create joint: choose at least one object (both are the "
                                   "static environment)")
            return
        if body1 and body1 == body2:
            self.window.show_error(f"Create joint: {body1} cannot be joined to itself")
            return
        spec = JointSpec(type=joint_type, body1=body1, body2=body2, anchor=self.anchor.values(),
                         axis1=self.axes[0].values(), axis2=self.axes[1].values(),
                         axis3=self.axes[2].values(), parameters=tuple(self.parameters()))
        for k, axis in enumerate(JOINT_AXES_USED[joint_type], start=1):
            if not any(getattr(spec, axis)):
                self.window.show_error(f"Create joint: axis {k} is zero; give it a direction")
                return

        def done(joint_id):
            self._clear_checks()
            self.window.show_info(f"Built joint {joint_id}")

        self.window.call("Create Joint", lambda client, job: client.add_joint(spec), done)

    def set_parameters(self) -> None:
        joint_id = self.selected()
        params = self.parameters()
        try:
            if joint_id is None:
                raise InputError("Set parameters: choose a joint in the list")
            if not params:
                raise InputError("Set parameters: check at least one parameter")
        except InputError as error:
            self.window.show_error(str(error))
            return

        def done(_):
            self._clear_checks()
            self.window.show_info(f"Parameters of {joint_id} set")

        self.window.call("Set Joint parameters", lambda client, job:
                         client.set_joint_parameters(joint_id, params), done)

    def remove(self) -> None:
        joint_id = self.selected()
        if joint_id is None:
            self.window.show_error("Remove: choose a joint in the list")
            return

        self.window.call("Remove Joint", lambda client, job: client.remove_joint(joint_id),
                         lambda _: self.window.show_info(f"Removed {joint_id}"))

    def add_motor(self) -> None:
        joint_id = self.selected()
        joint_type = self.window.scene.joints.get(joint_id)
        if joint_id is None or joint_type not in MOTORS:
            self.window.show_error("Add motor: choose a hinge, slider, piston, universal, "
                                   "hinge2, PR or PU joint in the list")
            return
        kind, axes = MOTORS[joint_type]

        def done(motor_id):
            self.window.scene.add_motor(motor_id, axes)
            self.window.show_info(f"Built motor {motor_id}")

        self.window.call("Add motor", lambda client, job: client.add_motor(
            MotorSpec(joint=joint_id, kind=kind)), done)
