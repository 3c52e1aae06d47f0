"""The world a problem asks for: every world parameter and every step value, so that loading
a problem never depends on what ran before it (issue 28).

Each value is the problem's own where it has one, else Odin's documented default: the world
parameters of ``odin_common.world_parameters.WorldParameters`` and the step values of
``odin_common.step_values.StepValues``, never what a previous client left in the world.

Where Kautham's physics applies, the problem has its own values: Kautham's ODE environment sets
gravity -9.8 m/s^2, ERP 0.8 and CFM 1e-5 (``gui.core.kautham.environment``); an ODE planner's
parameters say otherwise for ERP, CFM, Max Contacts and the step (PropagationStepSize).
Kautham gives the planner's ERP and CFM to every contact (its joints keep the world's 0.8 and
1e-5); Odin applies them to the world, which gives them to contacts and joints alike.

One check keeps a problem physical: a CFM that makes contacts so soft that a body would sink
into what holds it by more than ``max_sink`` (m) is not applied (the corpus's Sphere demos ask
for CFM 0.3 with ERP 0.5 at 0.03 s steps: a contact of 55.6 N/m, which would sink their 25 kg
sphere 4.4 m under the ground). ODE's soft constraint is a spring and damper of stiffness
ERP / (h CFM) (h the step), so a mass m rests m |g| h CFM / ERP deep. The CFM set aside is
listed (``gui.core.model.Ignored``) and the world's CFM stays Kautham's 1e-5.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import List, Mapping, Sequence, Tuple

import numpy as np

from gui.core.kautham import environment
from gui.core.model import Ignored, Problem
from odin_common.step_values import StepValues
from odin_common.world_parameters import WorldParameters

DEFAULT_CYCLE_TIME = StepValues().cycle_time
"""s: the simulated time of one publication cycle Odin keeps when a problem sets the step."""


@dataclass(frozen=True)
class WorldSettings:
    """The whole world a problem asks for: Set World ``parameters`` {name: value}, every
    odin_common.world_parameters name, and the Set Step values (``step`` s,
    ``steps_per_cycle``, ``rate`` Hz). ``own``: the names (parameters and step values) the
    problem sets itself; the others are the documented defaults."""
    parameters: dict
    step: float
    steps_per_cycle: int
    rate: float
    own: Tuple[str, ...] = ()

    @property
    def own_parameters(self) -> Tuple[str, ...]:
        """The world parameters (not step values) of ``own``."""
        return tuple(name for name in self.own if name in self.parameters)


def default_world() -> WorldSettings:
    """Every world parameter and step value at its documented default."""
    defaults = StepValues()
    return WorldSettings(_default_parameters(), defaults.step, defaults.steps_per_cycle,
                         defaults.rate)


STEP_NAMES = ("step", "steps_per_cycle", "rate")
"""The Set Step values a WorldSettings carries beside the world parameters."""


def with_values(settings: WorldSettings, values: Mapping[str, object]) -> WorldSettings:
    """``settings`` with ``values`` {name: value} (world parameter and step value names; other
    names, a node's own ~parameters, are left out) as the problem's own: an experiment that
    sets its world keeps it through the load."""
    parameters = {k: tuple(v) if isinstance(v, list) else v for k, v in values.items()
                  if k in settings.parameters}
    steps = {k: values[k] for k in STEP_NAMES if k in values}
    own = tuple(dict.fromkeys(settings.own + tuple(parameters) + tuple(steps)))
    return dataclasses.replace(settings, parameters={**settings.parameters, **parameters},
                               own=own, **steps)


def _default_parameters() -> dict:
    parameters = WorldParameters().as_dict()
    parameters["gravity"] = tuple(parameters["gravity"])
    return parameters


def contact_sink(mass: float, gravity: Sequence[float], step: float, erp: float,
                 cfm: float) -> float:
    """m: how deep a body of ``mass`` kg rests in one contact of ODE's ``erp`` and ``cfm`` at
    ``step`` s under ``gravity`` (m/s^2)."""
    return mass * float(np.linalg.norm(gravity)) * step * cfm / erp


def kautham_world(problem: Problem, masses: Sequence[Tuple[str, float]],
                  max_sink: float) -> Tuple[WorldSettings, List[Ignored]]:
    """The world of Kautham's ODE environment for ``problem`` (its planner's parameters over
    Kautham's world, the documented defaults for the rest), checked against the heaviest of
    the dynamic ``masses`` ((name, kg))."""
    settings = problem.planner.settings if problem.planner is not None else None
    erp = settings.erp if settings and settings.erp is not None else environment.WORLD_ERP
    cfm = environment.WORLD_CFM
    ignored: List[Ignored] = []
    step = settings.step if settings and settings.step is not None else None
    h = step if step is not None else StepValues().step
    if settings and settings.cfm is not None:
        heaviest = max(masses, key=lambda nm: nm[1], default=None)
        sink = contact_sink(heaviest[1], environment.GRAVITY, h, erp, settings.cfm) \
            if heaviest else 0.0
        if sink > max_sink:
            source = problem.planner.source
            ignored.append(Ignored(
                source, problem.planner.line, f"planner parameter \"Constraint Force Mixing\" "
                f"{settings.cfm:g}", f"with ERP {erp:g} at {h:g} s steps contacts would be "
                f"springs of {erp / (h * settings.cfm):.3g} N/m, sinking {heaviest[0]} "
                f"({heaviest[1]:g} kg) {sink:.3g} m (more than {max_sink:g} m): the world "
                f"keeps CFM {cfm:g}"))
        else:
            cfm = settings.cfm
    own = dict(gravity=environment.GRAVITY, erp=erp, cfm=cfm)
    if settings and settings.max_contacts is not None:
        own["max_contacts"] = settings.max_contacts
    parameters = {**_default_parameters(), **own}
    if step is None:
        defaults = default_world()
        return WorldSettings(parameters, defaults.step, defaults.steps_per_cycle,
                             defaults.rate, tuple(own)), ignored
    count = max(1, round(DEFAULT_CYCLE_TIME / step))
    return WorldSettings(parameters, step, count, 1.0 / (step * count),
                         tuple(own) + ("step", "steps_per_cycle", "rate")), ignored


__all__ = ["WorldSettings", "contact_sink", "default_world", "kautham_world", "with_values",
           "DEFAULT_CYCLE_TIME", "STEP_NAMES"]
