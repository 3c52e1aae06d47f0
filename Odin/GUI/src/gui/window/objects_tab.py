"""Third tab (thesis 7.3): create objects, list them, remove them, set their pose.

Create: a free name, a shape from the chooser (sphere, cylinder, box, mesh from a file) whose
parameter page comes up in a stacked widget with presets, mass (> 0), fixed or static flags,
position and orientation (a non-zero quaternion, normalised before sending). A mesh file is read
on the worker: STL/OBJ/PLY through trimesh, .wrl/.iv through Coin (``gui.core.shapes.read_shape``);
a file holding primitives too becomes a composite (``gui.core.bodies.shape_to_body``).
The list below shows every object in the world, whoever built it (Get World).
"""
from __future__ import annotations

import pathlib
from dataclasses import replace

import numpy as np
from PyQt5.QtWidgets import (QCheckBox, QComboBox, QFileDialog, QFormLayout, QGroupBox,
                             QHBoxLayout, QLabel, QLineEdit, QListWidget, QPushButton,
                             QStackedWidget, QVBoxLayout, QWidget)

from gui.window.fields import InputError, VectorRow, name_edit, quaternion_row, spin, \
    unit_quaternion
from gui.window.forms import form_grid, list_box, span
from odin_common.rotations import quaternion_to_matrix
from odin_common.specs import CompositeSpec, ObjectSpec

SHAPES = ["Sphere", "Cylinder", "Box", "Mesh from file"]
#: shape -> [(preset name, parameters)]
PRESETS = {
    "Sphere": [("ball, r 0.1 m", (0.1,)), ("marble, r 0.02 m", (0.02,)),
               ("boulder, r 0.5 m", (0.5,))],
    "Cylinder": [("can, r 0.033 m, 0.12 m", (0.033, 0.12)), ("column, r 0.1 m, 1 m", (0.1, 1.0)),
                 ("disc, r 0.3 m, 0.05 m", (0.3, 0.05))],
    "Box": [("cube, 0.2 m", (0.2, 0.2, 0.2)), ("table top, 1 x 0.6 x 0.05 m", (1.0, 0.6, 0.05)),
            ("floor, 10 x 10 x 0.1 m", (10.0, 10.0, 0.1))],
}


class ObjectsTab(QWidget):
    def __init__(self, window, parent=None):
        super().__init__(parent)
        self.window = window
        create = self._build_create()
        listing = self._build_listing()
        layout = QVBoxLayout(self)
        layout.addWidget(create)
        layout.addWidget(listing, 1)
        self._connect(window)
        self._shape_changed(0)

    def _build_create(self) -> QGroupBox:
        """The Create object group: name, shape and its parameters, mass and flags, pose."""
        self.name = name_edit()
        self.shape = QComboBox()
        self.shape.addItems(SHAPES)
        self.preset = QComboBox()
        self.stack = self._build_shape_pages()
        self.mass = spin(1.0, 1e-6, 1e6, 4, 0.1, "kg")
        self.fixed = QCheckBox("fixed")
        self.fixed.setToolTip("a body held at its pose")
        self.static = QCheckBox("static")
        self.static.setToolTip("geometry only: collides, never moves, no mass")
        self.position = VectorRow("xyz", (0.0, 0.0, 1.0), -1e4, 1e4, 3, 0.1, "m")
        self.orientation = quaternion_row()
        self.create_button = QPushButton("Create it!")

        create = QGroupBox("Create object")
        mass_row = QHBoxLayout()
        mass_row.addWidget(self.mass, 1)
        mass_row.addWidget(self.fixed)
        mass_row.addWidget(self.static)
        form_grid([["Name", self.name], ["Shape", self.shape], ["Preset", self.preset],
                   [span(self.stack, 2)], ["Mass", mass_row], ["Position", self.position],
                   ["Orientation", self.orientation], [None, self.create_button]], create)
        return create

    def _build_shape_pages(self) -> QStackedWidget:
        """One page of parameters a shape, in the order of SHAPES (the chooser's index): the
        primitives' sizes (m), then the mesh file and its scale."""
        stack = QStackedWidget()
        self.radius = spin(0.1, 1e-4, 100.0, 4, 0.01, "m")
        self.cyl_radius = spin(0.033, 1e-4, 100.0, 4, 0.01, "m")
        self.cyl_length = spin(0.12, 1e-4, 100.0, 4, 0.01, "m")
        self.box_sides = VectorRow("xyz", (0.2, 0.2, 0.2), 1e-4, 100.0, 4, 0.05, "m")
        self.mesh_path = QLineEdit()
        self.mesh_path.setPlaceholderText("STL, OBJ, PLY, WRL or IV file")
        self.mesh_browse = QPushButton("Browse...")
        self.mesh_scale = spin(1.0, 1e-6, 1e3, 6, 0.001, tip="metres per file unit "
                               "(0.001 for a file in mm)")
        self.params = {"Sphere": [self.radius], "Cylinder": [self.cyl_radius, self.cyl_length],
                       "Box": self.box_sides.boxes}

        for title, rows in [("Sphere", [("Radius", self.radius)]),
                            ("Cylinder", [("Radius", self.cyl_radius),
                                          ("Length (along z)", self.cyl_length)]),
                            ("Box", [("Sides", self.box_sides)])]:
            page = QWidget()
            form = QFormLayout(page)
            for label, widget in rows:
                form.addRow(label, widget)
            stack.addWidget(page)
        page = QWidget()
        form = QFormLayout(page)
        row = QHBoxLayout()
        row.addWidget(self.mesh_path, 1)
        row.addWidget(self.mesh_browse)
        form.addRow("File", row)
        form.addRow("Scale", self.mesh_scale)
        stack.addWidget(page)
        return stack

    def _build_listing(self) -> QGroupBox:
        """The Object list: every object in the world, Remove, and Set transformation."""
        self.list = QListWidget()
        self.remove_button = QPushButton("Remove")
        self.set_position_check = QCheckBox("Position")
        self.set_position_check.setChecked(True)
        self.set_orientation_check = QCheckBox("Orientation")
        self.set_orientation_check.setChecked(True)
        self.set_button = QPushButton("Set transformation")
        return list_box("Object list", self.list, [
            self.remove_button, QLabel("Set transformation\n(from the fields above):"),
            self.set_position_check, self.set_orientation_check, self.set_button])

    def _connect(self, window) -> None:
        """The widgets to this tab's actions, the scene's changes (of ``window``) to its lists."""
        self.shape.currentIndexChanged.connect(self._shape_changed)
        self.preset.activated.connect(self._apply_preset)
        self.mesh_browse.clicked.connect(self.choose_mesh)
        self.create_button.clicked.connect(self.create)
        self.remove_button.clicked.connect(self.remove)
        self.set_button.clicked.connect(self.set_transformation)
        self.static.toggled.connect(lambda on: (self.mass.setEnabled(not on),
                                                self.fixed.setEnabled(not on)))
        window.scene.changed.connect(self._scene_changed)

    # -- shape chooser ------------------------------------------------------------------------
    def _shape_changed(self, index: int) -> None:
        self.stack.setCurrentIndex(index)
        self.preset.clear()
        shape = SHAPES[index]
        for label, _ in PRESETS.get(shape, []):
            self.preset.addItem(label)
        self.preset.setEnabled(shape in PRESETS)

    def _apply_preset(self, index: int) -> None:
        shape = SHAPES[self.shape.currentIndex()]
        presets = PRESETS.get(shape, [])
        if 0 <= index < len(presets):
            for box, value in zip(self.params[shape], presets[index][1]):
                box.setValue(value)

    def choose_mesh(self) -> None:
        path, _ = QFileDialog.getOpenFileName(
            self, "Mesh file", "", "Meshes (*.stl *.obj *.ply *.off *.wrl *.iv *.vrml);;"
            "All files (*)")
        if path:
            self.mesh_path.setText(path)

    # -- create -------------------------------------------------------------------------------
    def object_request(self):
        """The ObjectSpec to build, or ("mesh", name, file, scale, common fields) for a mesh
        file (read on the worker); ``InputError`` saying what is missing."""
        name = self.name.text().strip()
        if not name:
            raise InputError("Create object: type a name for the object")
        if name in self.window.scene.objects:
            raise InputError(f"Create object: the name {name!r} is already used")
        quaternion = unit_quaternion(self.orientation.values())
        shape = SHAPES[self.shape.currentIndex()]
        static = self.static.isChecked()
        common = dict(mass=float(self.mass.value()), position=self.position.values(),
                      orientation=quaternion, fixed=self.fixed.isChecked() and not static,
                      geometry_only=static)
        if shape != "Mesh from file":
            params = tuple(float(b.value()) for b in self.params[shape])
            return ObjectSpec(name=name, parameters=params, **common)
        path = self.mesh_path.text().strip()
        if not path:
            raise InputError("Create object: choose a mesh file")
        if not pathlib.Path(path).is_file():
            raise InputError(f"Create object: mesh file {path!r} not found")
        return ("mesh", name, path, float(self.mesh_scale.value()), common)

    def create(self) -> None:
        try:
            request = self.object_request()
        except InputError as error:
            self.window.show_error(str(error))
            return
        def work(client, job):
            if isinstance(request, tuple):
                return _build_mesh(client, *request[1:])
            return client.build_object(request), None

        def done(result):
            object_id, _ = result
            self.window.show_info(f"Built object {object_id}")
            self.name.clear()

        self.window.call("Build Object", work, done)

    # -- list ---------------------------------------------------------------------------------
    def _scene_changed(self, what: str) -> None:
        if what != "objects":
            return
        current = self.selected()
        self.list.clear()
        self.list.addItems(self.window.scene.objects)
        if current in self.window.scene.objects:
            self.list.setCurrentRow(self.window.scene.objects.index(current))

    def selected(self):
        item = self.list.currentItem()
        return item.text() if item is not None else None

    def remove(self) -> None:
        object_id = self.selected()
        if object_id is None:
            self.window.show_error("Remove: select an object in the list")
            return

        self.window.call("Remove Object",
                         lambda client, job: client.remove_object(object_id),
                         lambda _: self.window.show_info(f"Removed {object_id}"))

    def set_transformation(self) -> None:
        object_id = self.selected()
        try:
            if object_id is None:
                raise InputError("Set transformation: select an object in the list")
            use_position = self.set_position_check.isChecked()
            use_orientation = self.set_orientation_check.isChecked()
            if not (use_position or use_orientation):
                raise InputError("Set transformation: check Position and/or Orientation")
            position = self.position.values()
            quaternion = unit_quaternion(self.orientation.values())
            if not (use_position and use_orientation):
                known = self.window.scene.pose_of(object_id)
                if known is None:
                    raise InputError(f"Set transformation: the pose of {object_id} is not "
                                     "known yet; check both Position and Orientation")
                position = position if use_position else known[0]
                quaternion = quaternion if use_orientation else known[1]
        except InputError as error:
            self.window.show_error(str(error))
            return
        self.window.call(
            "Set Position",
            lambda client, job: client.set_position([(object_id, position, quaternion)]),
            lambda _: self.window.show_info(f"Moved {object_id}"))


def _build_mesh(client, name: str, path: str, scale: float, common: dict):
    """Reads a mesh file and builds it (worker thread); returns (ID, part names or None)."""
    from gui.core.bodies import shape_to_body
    from gui.core.shapes import read_shape
    shape = read_shape(path, scale)
    if shape.is_empty:
        raise InputError(f"{path}: holds no geometry")
    pose = np.eye(4)
    pose[:3, :3] = quaternion_to_matrix(common["orientation"])
    pose[:3, 3] = common["position"]
    spec, _ = shape_to_body(name, shape, pose, common["mass"], common["geometry_only"])
    spec = replace(spec, fixed=common["fixed"])
    if isinstance(spec, CompositeSpec):
        return client.build_composite(spec), [p.name for p in spec.parts]
    return client.build_object(spec), None
