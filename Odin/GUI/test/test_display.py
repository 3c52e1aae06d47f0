"""The window decides at start-up, from its own environment, whether it can be seen."""
from gui.window.display import choose_platform


def test_no_display_and_no_choice_draws_off_screen_and_says_so():
    environ = {}
    said = choose_platform(environ)
    assert environ["QT_QPA_PLATFORM"] == "offscreen"
    assert said.startswith("no display (DISPLAY and WAYLAND_DISPLAY are unset)")


def test_a_display_set_after_setup_gets_a_visible_window():
    environ = {"DISPLAY": ":0"}
    assert choose_platform(environ) is None
    assert "QT_QPA_PLATFORM" not in environ
    assert choose_platform({"WAYLAND_DISPLAY": "wayland-0"}) is None
    assert choose_platform({"DISPLAY": ":1", "QT_QPA_PLATFORM": "xcb"}) is None


def test_an_off_screen_platform_chosen_beside_a_display_is_said():
    environ = {"DISPLAY": ":0", "QT_QPA_PLATFORM": "offscreen"}
    said = choose_platform(environ)
    assert environ["QT_QPA_PLATFORM"] == "offscreen"
    assert "drawn off-screen although DISPLAY=:0 is set" in said
    assert "unset QT_QPA_PLATFORM" in said
    assert "off-screen" in choose_platform({"QT_QPA_PLATFORM": "minimal:fontengine=freetype"})
