"""The world parameters' table says what every form needs to show a parameter: a title, a
section, and the names of the values of an enum-like int (pinned to its IntEnum)."""
import pytest

from odin_common import world_parameters
from odin_common.interface import DivergencePolicy, Solver
from odin_common.world_parameters import PARAMETER_INFO, PARAMETERS, ParameterInfo


def test_every_parameter_has_a_title_and_a_section():
    for info in PARAMETERS:
        assert info.label and info.group, info.name


def test_a_parameter_without_a_title_or_section_is_refused_where_it_is_written():
    with pytest.raises(ValueError, match="label and group"):
        ParameterInfo("spin", "float", "-", "a parameter", "set_spin", label="Spin")


def test_named_values_cover_the_range_exactly():
    with pytest.raises(ValueError, match="2 choices for 3 values"):
        ParameterInfo("mode", "int", "-", "a mode", "set_mode", 0, 2, label="Mode",
                      group="Modes", choices=("a", "b"))
    for info in PARAMETERS:
        if info.choices:
            count = 2 if info.kind == "bool" else int(info.high - info.low) + 1
            assert len(info.choices) == count, info.name


@pytest.mark.parametrize("name,enum", [("solver", Solver),
                                       ("divergence_policy", DivergencePolicy)])
def test_an_enum_like_parameter_names_each_member_of_its_enum(name, enum):
    info = PARAMETER_INFO[name]
    assert len(info.choices) == len(enum)
    assert (info.low, info.high) == (min(enum), max(enum))


def test_a_gravity_component_beyond_the_tables_range_is_refused():
    info = PARAMETER_INFO["gravity"]
    world_parameters.WorldParameters(gravity=(0.0, 0.0, info.low)).validate()
    with pytest.raises(world_parameters.InvalidArgument, match="beyond the limit"):
        world_parameters.WorldParameters().replace(gravity=(0.0, 2 * info.high, 0.0))
