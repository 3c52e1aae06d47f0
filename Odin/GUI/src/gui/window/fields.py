"""Input widgets with hard limits: whatever is typed, what leaves them is a valid number.

Every ``QDoubleSpinBox`` here has a finite range (Qt clamps typed text into it and never
produces NaN), so a request can only be refused by the world for reasons of the scene, never
for a malformed number. Quaternions are checked and normalised by ``unit_quaternion``.
"""
from __future__ import annotations

import math
from typing import Sequence

from PyQt5.QtCore import QRegExp
from PyQt5.QtGui import QRegExpValidator
from PyQt5.QtWidgets import (QCheckBox, QDoubleSpinBox, QHBoxLayout, QLabel, QLineEdit,
                             QSpinBox, QWidget)

from gui.errors import GuiError

#: object names: no '>' (composites) nor '&' (joint IDs), 1..64 characters
NAME_PATTERN = r"[^>&]{1,64}"
BIG = 1e6


class InputError(GuiError):
    """What the user typed cannot be sent (the window says why; nothing is sent)."""


def spin(value: float = 0.0, low: float = -BIG, high: float = BIG, decimals: int = 3,
         step: float = 0.1, suffix: str = "", tip: str = "") -> QDoubleSpinBox:
    box = QDoubleSpinBox()
    box.setRange(low, high)
    box.setDecimals(decimals)
    box.setSingleStep(step)
    box.setValue(value)
    box.setKeyboardTracking(False)
    box.setAccelerated(True)
    if suffix:
        box.setSuffix(" " + suffix)
    if tip:
        box.setToolTip(tip)
    return box


def int_spin(value: int, low: int, high: int, tip: str = "") -> QSpinBox:
    box = QSpinBox()
    box.setRange(low, high)
    box.setValue(value)
    if tip:
        box.setToolTip(tip)
    return box


def name_edit(placeholder: str = "insert name") -> QLineEdit:
    edit = QLineEdit()
    edit.setPlaceholderText(placeholder)
    edit.setMaxLength(64)
    edit.setValidator(QRegExpValidator(QRegExp(NAME_PATTERN)))
    return edit


class VectorRow(QWidget):
    """A row of labelled spin boxes, e.g. x y z or w x y z."""

    def __init__(self, labels: Sequence[str] = "xyz", values: Sequence[float] = (0, 0, 0),
                 low: float = -BIG, high: float = BIG, decimals: int = 3, step: float = 0.1,
                 suffix: str = "", parent=None):
        super().__init__(parent)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        self.boxes = []
        for label, value in zip(labels, values):
            layout.addWidget(QLabel(label))
            box = spin(value, low, high, decimals, step, suffix)
            layout.addWidget(box, 1)
            self.boxes.append(box)

    def values(self) -> tuple:
        return tuple(float(b.value()) for b in self.boxes)

    def set_values(self, values: Sequence[float]) -> None:
        for box, value in zip(self.boxes, values):
            box.setValue(float(value))


def quaternion_row(values: Sequence[float] = (1, 0, 0, 0)) -> VectorRow:
    return VectorRow("wxyz", values, -1.0, 1.0, 4, 0.05)


def unit_quaternion(values: Sequence[float], what: str = "orientation") -> tuple:
    """(w, x, y, z) normalised; ``InputError`` for a zero (or near-zero) quaternion."""
    norm = math.sqrt(sum(v * v for v in values))
    if not math.isfinite(norm) or norm < 1e-6:
        raise InputError(f"{what}: the quaternion {tuple(values)} has no direction "
                         "(all components zero); give w = 1 for no rotation")
    return tuple(float(v) / norm for v in values)


def checked_spin(label: str, value: float, low: float, high: float, decimals: int = 4,
                 step: float = 0.1, suffix: str = "", tip: str = ""):
    """(check box, spin box): the check box says "send this value" (zero is a valid value)."""
    check = QCheckBox(label)
    box = spin(value, low, high, decimals, step, suffix, tip)
    return check, box
