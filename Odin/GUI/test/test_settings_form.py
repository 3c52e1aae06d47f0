"""The Settings tab's world-parameter rows come from odin_common.world_parameters alone:
every parameter has a row, its field enforces the table's range, and Apply sends the checked
flags' parameters. Off-screen Qt, no ROS (each test in a process of its own)."""
from __future__ import annotations

import os

import pytest

pytestmark = pytest.mark.forked


class _Window:
    """What the tab asks of the main window: calls are recorded, not run."""

    def __init__(self):
        self.calls, self.errors = [], []
        self.publication_rate = None

    def call(self, label, work, done=None):
        self.calls.append((label, work, done))

    def show_error(self, text):
        self.errors.append(text)


@pytest.fixture
def tab():
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from gui.window.testing import app
    from gui.window.settings_tab import SettingsTab
    app()
    settings = SettingsTab(_Window())
    settings.show()
    return settings


class _Client:
    def __init__(self):
        self.changes = None

    def set_world(self, **changes):
        self.changes = changes


def _sent(tab) -> dict:
    """The world parameters the tab's Apply sends."""
    tab.send_world()
    label, work, _done = tab.window.calls[-1]
    assert label == "Set World"
    client = _Client()
    work(client, None)
    return client.changes


def test_every_world_parameter_has_a_row_on_the_page_of_its_section(tab):
    from odin_common.world_parameters import PARAMETERS
    assert sorted(tab.world_boxes) == sorted(info.name for info in PARAMETERS)
    pages = [tab.toolbox.itemText(k) for k in range(tab.toolbox.count())]
    assert pages[0] == "Step sizes"
    assert pages[1:] == list(dict.fromkeys(info.group for info in PARAMETERS))
    for info in PARAMETERS:
        page = tab.toolbox.widget(pages.index(info.group))
        assert page.isAncestorOf(tab.world_boxes[info.name]), info.name
        assert tab.in_force_labels[info.name].text() == "?"
        assert info.what[:20] in tab.world_boxes[info.name].toolTip()


def test_fields_start_at_the_defaults_and_hold_the_tables_ranges(tab):
    from gui.window.fields import BIG
    from odin_common.world_parameters import PARAMETERS, WorldParameters
    assert WorldParameters(**{info.name: tab.world_fields[info.name].value()
                              for info in PARAMETERS}) == WorldParameters()
    for info in PARAMETERS:
        box = tab.world_boxes[info.name]
        if info.kind in ("float", "int") and not info.choices:
            low = -BIG if info.low is None else info.low
            high = BIG if info.high is None else info.high
            assert (box.minimum(), box.maximum()) == (low, high), info.name
    assert tab.world_boxes["divergence_speed"].suffix() == " m/s"
    assert tab.world_boxes["gravity"].boxes[2].maximum() == PARAMETERS[0].high


def test_typed_values_stay_in_range_and_keep_small_ones(tab):
    from gui.window.testing import type_into
    type_into(tab.world_boxes["erp"], "7")
    assert tab.world_boxes["erp"].value() == 1.0
    type_into(tab.world_boxes["cfm"], "2.5e-7")
    assert tab.world_boxes["cfm"].value() == pytest.approx(2.5e-7)
    assert tab.world_boxes["cfm"].text() == "2.5e-07"
    type_into(tab.world_boxes["world_extent"], "0.5")            # below its 1 m
    assert tab.world_boxes["world_extent"].value() == 1.0


def test_editing_a_field_checks_its_flag_and_apply_sends_all_the_flags_parameters(tab):
    from gui.window.testing import type_into
    assert tab.world_changes() == {}
    tab.send_world()
    assert "check at least one" in tab.window.errors[-1]
    type_into(tab.world_boxes["world_extent"], "500")
    tab.world_boxes["divergence_policy"].setCurrentIndex(1)
    assert tab.world_checks["divergence_speed"].isChecked()
    assert _sent(tab) == {"divergence_speed": 1000.0, "divergence_angular_speed": 10000.0,
                          "world_extent": 500.0, "divergence_policy": 1}
    tab.highlight_radio.setChecked(True)
    tab.sleep.setChecked(True)
    sent = _sent(tab)
    assert sent["contact_less"] is True and sent["auto_disable"] is True


def test_the_values_in_force_are_shown_by_kind_and_clear_the_checks(tab):
    from odin_common.world_parameters import WorldParameters
    tab.world_checks["erp"].setChecked(True)
    tab.show_world(WorldParameters(gravity=(0, 0, -1.62), solver=1, contact_less=True,
                                   divergence_policy=1, world_extent=500.0))
    texts = {name: label.text() for name, label in tab.in_force_labels.items()}
    assert texts["gravity"] == "(0, 0, -1.62)" and texts["solver"] == "WorldStep"
    assert texts["contact_less"] == "detect only" and texts["auto_disable"] == "off"
    assert texts["divergence_policy"] == "park and pause" and texts["world_extent"] == "500"
    assert not tab.world_checks["erp"].isChecked()
    assert tab.in_force["world_extent"] == 500.0
