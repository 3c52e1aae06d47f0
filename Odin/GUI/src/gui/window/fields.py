"""Input widgets with hard limits: whatever is typed, what leaves them is a valid number.

Every ``QDoubleSpinBox`` here has a finite range (Qt clamps typed text into it and never
produces NaN), so a request can only be refused by the world for reasons of the scene, never
for a malformed number. Quaternions are checked and normalised by ``unit_quaternion``.
"""
from __future__ import annotations

import math
import re
from typing import Optional, Sequence

from PyQt5.QtCore import QRegExp
from PyQt5.QtGui import QRegExpValidator, QValidator
from PyQt5.QtWidgets import (QBoxLayout, QButtonGroup, QCheckBox, QDoubleSpinBox, QHBoxLayout,
                             QLabel, QLineEdit, QRadioButton, QSpinBox, QWidget)

from gui.errors import GuiError

#: object names: no '>' (composites) nor '&' (joint IDs), 1..64 characters
NAME_PATTERN = r"[^>&]{1,64}"
BIG = 1e6


class InputError(GuiError):
    """What the user typed cannot be sent (the window says why; nothing is sent)."""


#: what may be typed on the way to a number: "-", "1.", "2e", "2e-"
_PARTIAL_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d*)?([eE][+-]?\d*)?")


class FloatSpin(QDoubleSpinBox):
    """A spin box that shows its value with the digits it has (1e-05, 0.2, 10000) and takes
    what is typed in any notation: for values spanning orders of magnitude, which fixed
    decimals would round away. Up and down change the value by a tenth of its order of
    magnitude (0.2 by 0.01, 1000 by 100), or by ``zero_step`` at zero; a typed value out of
    range becomes the nearest bound."""

    DIGITS = 12         # significant digits shown: a double's noise (0.21000000000000002) hides

    def __init__(self, value: float, low: float, high: float, suffix: str = "",
                 zero_step: float = 0.01, parent=None):
        super().__init__(parent)
        self.zero_step = zero_step
        self.setDecimals(15)           # Qt rounds every value to this many decimals
        self.setRange(low, high)
        self.setValue(value)
        self.setKeyboardTracking(False)
        self.setAccelerated(True)
        if suffix:
            self.setSuffix(" " + suffix)

    def textFromValue(self, value: float) -> str:
        return f"{value:.{self.DIGITS}g}"

    def valueFromText(self, text: str) -> float:
        try:
            return self._clamped(float(self._number(text)))
        except ValueError:
            return self.value()

    def validate(self, text: str, position: int):
        number = self._number(text)
        try:
            value = float(number)
        except ValueError:
            partial = _PARTIAL_NUMBER.fullmatch(number) is not None
            return (QValidator.Intermediate if partial else QValidator.Invalid), text, position
        inside = math.isfinite(value) and self.minimum() <= value <= self.maximum()
        return (QValidator.Acceptable if inside else QValidator.Intermediate), text, position

    def fixup(self, text: str) -> str:
        try:
            value = self._clamped(float(self._number(text)))
        except ValueError:
            return text
        return self.prefix() + self.textFromValue(value) + self.suffix()

    def stepBy(self, steps: int) -> None:
        magnitude = abs(self.value())
        step = 10.0 ** (math.floor(math.log10(magnitude)) - 1) if magnitude else self.zero_step
        self.setValue(self.value() + steps * step)

    def _number(self, text: str) -> str:
        """``text`` without the prefix and suffix the box shows."""
        if self.prefix() and text.startswith(self.prefix()):
            text = text[len(self.prefix()):]
        if self.suffix() and text.endswith(self.suffix()):
            text = text[:-len(self.suffix())]
        return text.strip()

    def _clamped(self, value: float) -> float:
        if math.isnan(value):
            return self.value()
        return min(max(value, self.minimum()), self.maximum())


def spin(value: float = 0.0, low: float = -BIG, high: float = BIG,
         decimals: Optional[int] = 3, step: float = 0.1, suffix: str = "",
         tip: str = "") -> QDoubleSpinBox:
    """A spin box of ``decimals`` decimals stepping by ``step``; decimals None: a FloatSpin
    (the digits the value has, steps of a tenth of its order of magnitude)."""
    if decimals is None:
        box = FloatSpin(value, low, high, suffix)
        if tip:
            box.setToolTip(tip)
        return box
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


class ChoiceButtons(QWidget):
    """One radio button per name, in a row (or one under the other): ``buttons[i]`` and
    ``value()`` i stand for the i-th name (a bool's: false, true)."""

    def __init__(self, names: Sequence[str], value: int = 0, vertical: bool = False,
                 parent=None):
        super().__init__(parent)
        layout = QBoxLayout(QBoxLayout.TopToBottom if vertical else QBoxLayout.LeftToRight,
                            self)
        layout.setContentsMargins(0, 0, 0, 0)
        self.group = QButtonGroup(self)
        self.buttons = []
        for index, name in enumerate(names):
            button = QRadioButton(name)
            self.group.addButton(button, index)
            self.buttons.append(button)
            layout.addWidget(button)
        self.buttons[value].setChecked(True)

    def value(self) -> int:
        return self.group.checkedId()


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
