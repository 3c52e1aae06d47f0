"""The world parameters and step a problem asks for when Kautham's physics applies to it.

Kautham's ODE environment sets gravity -9.8 m/s^2, ERP 0.8 and CFM 1e-5
(``gui.core.kautham.environment``); an ODE planner's parameters say otherwise for ERP, CFM,
Max Contacts and the step (PropagationStepSize). Kautham gives the planner's ERP and CFM to
every contact (its joints keep the world's 0.8 and 1e-5); Odin applies them to the world,
which gives them to contacts and joints alike.

One check keeps a problem physical: a CFM that makes contacts so soft that a body would sink
into what holds it by more than ``max_sink`` (m) is not applied (the corpus's Sphere demos ask
for CFM 0.3 with ERP 0.5 at 0.03 s steps: a contact of 55.6 N/m, which would sink their 25 kg
sphere 4.4 m under the ground). ODE's soft constraint is a spring and damper of stiffness
ERP / (h CFM) (h the step), so a mass m rests m |g| h CFM / ERP deep. The CFM set aside is
listed (``gui.core.model.Ignored``) and the world's CFM stays Kautham's 1e-5.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple

import numpy as np

from gui.core.kautham import environment
from gui.core.model import Ignored, Problem
from odin_common.step_values import StepValues

DEFAULT_CYCLE_TIME = StepValues().cycle_time
"""s: the simulated time of one publication cycle Odin keeps when a problem sets the step."""


@dataclass(frozen=True)
class WorldSettings:
    """Set World ``parameters`` {name: value} (odin_common.world_parameters names) and the
    Set Step values (``step`` s, ``steps_per_cycle``, ``rate`` Hz; None: unchanged)."""
    parameters: dict
    step: Optional[float] = None
    steps_per_cycle: Optional[int] = None
    rate: Optional[float] = None


def contact_sink(mass: float, gravity: Sequence[float], step: float, erp: float,
                 cfm: float) -> float:
    """m: how deep a body of ``mass`` kg rests in one contact of ODE's ``erp`` and ``cfm`` at
    ``step`` s under ``gravity`` (m/s^2)."""
    return mass * float(np.linalg.norm(gravity)) * step * cfm / erp


def kautham_world(problem: Problem, masses: Sequence[Tuple[str, float]], world_step: float,
                  max_sink: float) -> Tuple[WorldSettings, List[Ignored]]:
    """The settings of Kautham's ODE environment for ``problem`` (its planner's parameters
    over Kautham's world), checked against the heaviest of the dynamic ``masses`` ((name, kg));
    ``world_step``: the step in force when the planner gives none."""
    settings = problem.planner.settings if problem.planner is not None else None
    erp = settings.erp if settings and settings.erp is not None else environment.WORLD_ERP
    cfm = environment.WORLD_CFM
    ignored: List[Ignored] = []
    step = settings.step if settings and settings.step is not None else None
    h = step if step is not None else world_step
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
    parameters = dict(gravity=environment.GRAVITY, erp=erp, cfm=cfm)
    if settings and settings.max_contacts is not None:
        parameters["max_contacts"] = settings.max_contacts
    if step is None:
        return WorldSettings(parameters), ignored
    count = max(1, round(DEFAULT_CYCLE_TIME / step))
    return WorldSettings(parameters, step, count, 1.0 / (step * count)), ignored


__all__ = ["WorldSettings", "contact_sink", "kautham_world", "DEFAULT_CYCLE_TIME"]
