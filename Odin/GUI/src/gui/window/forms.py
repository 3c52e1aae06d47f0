"""Forms: grids of labelled fields, and the field a world parameter's row of the table asks for.

``form_grid`` lays out rows of cells (a text becomes a label, a cell may span columns, a row
may take the spare height), so a tab lists its rows instead of placing each widget by hand;
``list_box`` is a tab's list of what the world holds with its buttons beside it.
``ParameterField`` is the input of one ``odin_common.world_parameters.ParameterInfo``, chosen by
its kind and range: the Settings tab's rows come from the table alone.
"""
from __future__ import annotations

import html
from typing import Any, Callable, NamedTuple, Optional, Sequence, Union

from PyQt5.QtWidgets import (QCheckBox, QComboBox, QGridLayout, QGroupBox, QHBoxLayout,
                             QLabel, QLayout, QListWidget, QVBoxLayout, QWidget)

from gui.window.fields import BIG, ChoiceButtons, VectorRow, int_spin, spin
from odin_common.world_parameters import ParameterInfo


class Span(NamedTuple):
    """A cell over ``columns`` columns."""
    item: Union[QWidget, QLayout, str]
    columns: int


class Growing(list):
    """A row that takes the spare height of its grid."""


Cell = Union[QWidget, QLayout, str, Span, None]


def span(item: Union[QWidget, QLayout, str], columns: int) -> Span:
    return Span(item, columns)


def growing(*cells: Cell) -> Growing:
    """A row (empty when no cells) that takes the spare height, e.g. after the last row."""
    return Growing(cells)


def form_grid(rows: Sequence[Sequence[Cell]], parent: Optional[QWidget] = None) -> QGridLayout:
    """A grid of ``rows``, cells left to right: a widget or layout, a text (becomes a QLabel),
    ``span(item, columns)``, or None (an empty cell). The grid is ``parent``'s layout when
    given."""
    grid = QGridLayout(parent) if parent is not None else QGridLayout()
    for row, cells in enumerate(rows):
        column = 0
        for cell in cells:
            item, columns = (cell.item, cell.columns) if isinstance(cell, Span) else (cell, 1)
            if isinstance(item, str):
                item = QLabel(item)
            if isinstance(item, QLayout):
                grid.addLayout(item, row, column, 1, columns)
            elif item is not None:
                grid.addWidget(item, row, column, 1, columns)
            column += columns
        if isinstance(cells, Growing):
            grid.setRowStretch(row, 1)
    return grid


def list_box(title: str, items: QListWidget, side: Sequence[QWidget]) -> QGroupBox:
    """A group box ``title``: the list ``items`` over its spare width, the widgets of ``side``
    (buttons, notes, check boxes) in a column at its right, from the top."""
    box = QGroupBox(title)
    row = QHBoxLayout(box)
    row.addWidget(items, 1)
    column = QVBoxLayout()
    for widget in side:
        column.addWidget(widget)
    column.addStretch(1)
    row.addLayout(column)
    return box


# -- world parameters ---------------------------------------------------------------------------
def parameter_title(info: ParameterInfo) -> str:
    """The label of a parameter's row: its title and what 0 or a negative value stands for."""
    notes = "; ".join(note for note in (f"0: {info.zero_means}" if info.zero_means else "",
                                        f"negative: {info.negative_means}"
                                        if info.negative_means else "") if note)
    return f"{info.label} ({notes})" if notes else info.label


def parameter_tip(info: ParameterInfo) -> str:
    """A tool tip (rich text, so it wraps): what the parameter means, its unit and range."""
    text = f"{parameter_title(info)}: {info.what}."
    if info.kind != "bool":
        low = "-inf" if info.low is None else f"{info.low:g}"
        high = "inf" if info.high is None else f"{info.high:g}"
        unit = "" if info.unit == "-" else f" {info.unit}"
        each = " each component" if info.kind == "vector" else ""
        text += f" Range [{low}, {high}]{unit}{each}."
    return f"<p>{html.escape(text, quote=False)}</p>"


def parameter_text(info: ParameterInfo, value: Any) -> str:
    """``value`` of the parameter ``info`` as a form shows it: its value's name, on/off, a
    number or (x, y, z)."""
    if info.kind == "vector":
        return "(" + ", ".join(f"{v:g}" for v in value) + ")"
    if info.choices:
        return info.choices[int(value) - int(info.low or 0)]
    if info.kind == "bool":
        return "on" if value else "off"
    return f"{value:g}"


def _unit(info: ParameterInfo) -> str:
    return "" if info.unit == "-" else info.unit.replace("^2", "²")


def _bounds(info: ParameterInfo) -> tuple:
    """(low, high) of the field: the parameter's range, +-BIG where it has no bound."""
    return (float(-BIG if info.low is None else info.low),
            float(BIG if info.high is None else info.high))


class ParameterField:
    """The input of one world parameter, by its kind: a float is a spin box of its range and
    unit (FloatSpin: any order of magnitude), an int a spin box of its range, or a combo box
    of its named values, a bool radio buttons of its named values or a check box ("on"), a
    vector three spin boxes. ``widget`` is what a form shows; ``value()`` is in the kind the
    world takes."""

    def __init__(self, info: ParameterInfo, value: Any):
        self.info = info
        low, high = _bounds(info)
        if info.kind == "vector":
            widget = VectorRow("xyz", value, low, high, None, suffix=_unit(info))
            self._signals = [box.valueChanged for box in widget.boxes]
            self._read = widget.values
        elif info.kind == "float":
            widget = spin(float(value), low, high, None, suffix=_unit(info))
            self._signals = [widget.valueChanged]
            self._read = lambda: float(widget.value())
        elif info.kind == "int" and info.choices:
            widget = QComboBox()
            widget.addItems(info.choices)                       # index = value - low
            widget.setCurrentIndex(int(value) - int(low))
            self._signals = [widget.currentIndexChanged]
            self._read = lambda: widget.currentIndex() + int(low)
        elif info.kind == "int":
            widget = int_spin(int(value), int(low), int(high))
            self._signals = [widget.valueChanged]
            self._read = lambda: int(widget.value())
        elif info.choices:                                      # a bool: false, true
            widget = ChoiceButtons(info.choices, int(value), vertical=True)
            self._signals = [widget.group.buttonToggled]
            self._read = lambda: widget.value() == 1
        else:
            widget = QCheckBox("on")
            widget.setChecked(bool(value))
            self._signals = [widget.toggled]
            self._read = widget.isChecked
        widget.setToolTip(parameter_tip(info))
        self.widget = widget

    def value(self) -> Any:
        """The value shown, of the parameter's kind (a vector: a tuple of 3 floats)."""
        return self._read()

    def on_edit(self, callback: Callable[[], None]) -> None:
        """Calls ``callback()`` whenever the user changes the value."""
        for signal in self._signals:
            signal.connect(lambda *_args: callback())
