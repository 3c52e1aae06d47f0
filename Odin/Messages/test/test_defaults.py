"""The tuning constants have one home, odin_common.defaults, each with its unit and why; the
interface module holds the interface's facts and no tuning number."""
import ast
import inspect
from enum import Enum

import odin_common.defaults as defaults
import odin_common.interface as interface


def _documented_constants(module) -> dict:
    """{NAME: docstring} of the module's upper-case constants, each docstring the string
    written right below its assignment ("" when there is none)."""
    body = ast.parse(inspect.getsource(module)).body
    found = {}
    for statement, following in zip(body, body[1:] + [None]):
        targets = (statement.targets if isinstance(statement, ast.Assign) else
                   [statement.target] if isinstance(statement, ast.AnnAssign) else [])
        for target in targets:
            if isinstance(target, ast.Name) and target.id.isupper() and target.id != "__ALL__":
                text = (following.value.value if isinstance(following, ast.Expr)
                        and isinstance(following.value, ast.Constant) else "")
                found[target.id] = text if isinstance(text, str) else ""
    return found


def test_every_default_is_exported_and_documented_with_its_unit():
    documented = _documented_constants(defaults)
    assert sorted(documented) == sorted(defaults.__all__)
    for name, text in documented.items():
        unit, _, why = text.partition(":")
        assert unit and len(why.split()) >= 5, f"{name}: say its unit, then why ({text!r})"


def _is_tuning_number(value) -> bool:
    if isinstance(value, (bool, Enum)):
        return False
    if isinstance(value, float):
        return True
    return isinstance(value, tuple) and any(_is_tuning_number(v) for v in value)


def test_the_interface_holds_no_tuning_number():
    """A float (a threshold, a gain) or a tuple of floats (a colour) in the interface module
    is a choice, not a fact of the .msg/.srv files: it belongs in odin_common.defaults."""
    numbers = [name for name, value in vars(interface).items()
               if not name.startswith("_") and _is_tuning_number(value)]
    assert numbers == []
    assert not set(interface.__all__) & set(defaults.__all__)
