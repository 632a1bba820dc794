"""The seed paper's nominal values of the sphere and its contact (Table 1, Sects. 2, 4.1, Table 2, Appendix C), and
`PARAMETERS`: the one table of the parameters a study may vary or a command may set.

Every other module takes the nominal values from here (`sim.model.system` re-exports them for its callers).

A row of `PARAMETERS` (an `UncertainParameter`) says everything the workbench needs to know about a parameter: its
name and unit, its nominal value and interval (Table 2 for D, g, k_H), what it feeds in the simulated system (a
field of `SystemSettings`, set or scaled: `Feed`), its option of `ies sweep` / `ies overview` / `ies trace` and its
key in a study file (``[parameters.KEY]``). Adding a parameter is adding a row: the study files
(`uq.problem.study`, `uq.problem.space`), the simulator's response model (`uq.problem.models.IESModel`), the commands' options
(`sim.cli`) and the impactor builder (`sim.model.system.build_system`) all read this table.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Callable, Mapping

from sim.common.options import clearance, friction_coefficient, hertz_constant, tangential_stiffness
from sim.common.units import CLEARANCE, K_H, K_T, Quantity

SPHERE_MASS = 0.0177  # kg, Table 1
CLEARANCE_NOMINAL = 0.58e-3  # m, Sect. 2
K_H_NOMINAL = 282e3 * 1e3**1.5  # N/m^1.5  (282e3 N/mm^1.5, Eq. 8)
D1_NOMINAL = 0.00085  # Table 2
K_T_PAPER = 22e6  # N/m, Appendix C ("22 kN/mm")
MU_PAPER = 0.07  # Appendix C
DEFAULT_R_CONT = 0.99  # r_cont,diss of the damped law (Eq. 10) when none is given: the paper's value (Sect. 5.5)
N_PER_MM15 = 1e3**1.5  # N/m^1.5 per N/mm^1.5


@dataclass(frozen=True)
class SystemSettings:
    """The values the parameters feed: what `sim.model.system.build_system` builds a simulated system from (SI).

    D1: damping ratio of mode 1 (-; None keeps the modal model's); mass (kg), clearance g (m), k_H (N/m^1.5) of the
    sphere (Eqs. 3-6); contact_law: "hertz" (Eq. 4) or "hertz-damped" (Eq. 10; None: damped when r_cont is given);
    r_cont: r_cont,diss of Eq. 10 (None: the law's default); friction: Coulomb mu at the floor (0: off) and k_t (N/m)
    the floor contact's tangential stiffness (Appendix C).
    """

    D1: float | None = None
    mass: float = SPHERE_MASS
    clearance: float = CLEARANCE_NOMINAL
    k_H: float = K_H_NOMINAL
    contact_law: str | None = None
    r_cont: float | None = None
    friction: float = 0.0
    k_t: float = K_T_PAPER


_SETTINGS_FIELDS = tuple(f.name for f in fields(SystemSettings))


@dataclass(frozen=True)
class Feed:
    """Where a parameter's value goes: the `SystemSettings` field it sets, or multiplies when `scale` is True."""

    field: str
    scale: bool = False

    def __post_init__(self) -> None:
        if self.field not in _SETTINGS_FIELDS:
            raise ValueError(f"Feed: unknown field {self.field!r}; known: {', '.join(_SETTINGS_FIELDS)}")

    def apply(self, settings: SystemSettings, value: float) -> SystemSettings:
        """The settings with this parameter's value fed in."""
        value = float(value)
        if self.scale:
            value *= getattr(settings, self.field)
        return replace(settings, **{self.field: value})

    def describe(self) -> str:
        """Human-readable target, e.g. "impactor clearance" or "impactor mass x value"."""
        return f"{self.field} x value" if self.scale else self.field


@dataclass(frozen=True)
class CliOption:
    """A parameter's option of `ies sweep`, `ies overview` and `ies trace` (argparse dest = the parameter's name)."""

    flag: str
    metavar: str
    help: str
    parse: Callable[[str], float] = float


@dataclass(frozen=True)
class UncertainParameter:
    """One row of `PARAMETERS`.

    name, unit, label: as in CSV headers, figures and messages; nominal, interval (min, max): SI values, Table 2's
    for D, g, k_H (an optional parameter's interval is its nominal value: a study lists it to vary it);
    feeds: what it sets in the simulated system; option: its command-line option (None: studies only);
    study_key: ``[parameters.KEY]`` of a study file; table2: one of Table 2's parameters, in every study of the
    simulator (the others enter a study only when it lists them); upper_limit: exclusive physical bound (1 for a
    damping ratio); positive: every value must be > 0 (False: >= 0 allowed, e.g. mu = 0 switches friction off);
    quantity: the unit parser of study-file strings like "0.58 mm" (`sim.common.units`), None for plain numbers.
    """

    name: str
    unit: str
    label: str
    nominal: float
    interval: tuple[float, float]
    feeds: Feed
    study_key: str
    option: CliOption | None = None
    table2: bool = False
    upper_limit: float = math.inf
    positive: bool = True
    quantity: Quantity | None = None


#: every parameter of the simulator, in the order of Table 2 and then the optional ones
PARAMETERS: dict[str, UncertainParameter] = {p.name: p for p in (
    UncertainParameter(
        "D", "-", "modal damping ratio D_1", D1_NOMINAL, (0.00075, 0.00090), Feed("D1"), "D", table2=True,
        upper_limit=1.0,
        option=CliOption("--D", "D1", "modal damping ratio of mode 1 (-), default the model's (0.00085)")),
    UncertainParameter(
        "g", "m", "clearance g", CLEARANCE_NOMINAL, (CLEARANCE_NOMINAL, 0.612e-3), Feed("clearance"), "g", table2=True,
        quantity=CLEARANCE,
        option=CliOption("--g", "G", "clearance g in m, or with a unit: 0.58mm, 580um (default 0.58 mm)", clearance)),
    UncertainParameter(
        "k_H", "N/m^1.5", "Hertzian spring constant k_H", K_H_NOMINAL, (K_H_NOMINAL, 428e3 * N_PER_MM15), Feed("k_H"),
        "k_H", table2=True, quantity=K_H,
        option=CliOption("--k-H", "K_H", "Hertz constant k_H in N/m^1.5, or with a unit: 282e3N/mm^1.5 (default "
                                         "282e3 N/mm^1.5 = 8.918e9 N/m^1.5)", hertz_constant)),
    UncertainParameter(
        "r_cont", "-", "r_cont,diss of the damped contact law (Eq. 10)", DEFAULT_R_CONT, (DEFAULT_R_CONT,) * 2,
        Feed("r_cont"), "r_cont",
        option=CliOption("--r-cont", "R", "r_cont,diss of Eq. 10 in (0, 1]: the coefficient of restitution the damped "
                                          "law is designed for (1 = elastic, bit for bit); implies --contact-law "
                                          "hertz-damped (default there 0.99)")),
    UncertainParameter(
        "friction", "-", "friction coefficient mu at the floor (App. C)", MU_PAPER, (MU_PAPER,) * 2, Feed("friction"),
        "friction", positive=False,
        option=CliOption("--friction", "MU", "Coulomb coefficient of dry friction between the sphere and the cavity "
                                             "floor (Appendix C; 0 = off, the default; the paper: 0.07); needs "
                                             "--integrator ode3 and the model's phi_floor", friction_coefficient)),
    UncertainParameter(
        "k_t", "N/m", "tangential stiffness k_t at the floor (App. C)", K_T_PAPER, (K_T_PAPER,) * 2, Feed("k_t"), "k_t",
        quantity=K_T,
        option=CliOption("--k-t", "K_T", "tangential stiffness of the floor contact in N/m, or with a unit: 22kN/mm "
                                         "(default, Appendix C)", tangential_stiffness)),
    UncertainParameter(
        "m_a", "kg", "sphere mass m_a (Table 1)", SPHERE_MASS, (SPHERE_MASS,) * 2, Feed("mass"), "m_a"),
)}


def table2_parameters() -> list[UncertainParameter]:
    """The rows of Table 2 (in every study of the simulator), in table order."""
    return [p for p in PARAMETERS.values() if p.table2]


def optional_parameters() -> list[UncertainParameter]:
    """The rows a study adds by listing them (``[parameters.KEY]``), in table order."""
    return [p for p in PARAMETERS.values() if not p.table2]


def system_settings(values: Mapping[str, float], base: SystemSettings = SystemSettings()) -> SystemSettings:
    """`base` with every value of a parameter of `PARAMETERS` fed in (`Feed.apply`, table order); names that are
    not in the table (e.g. other models' inputs) are ignored, so are values that are None (not given)."""
    settings = base
    for name, parameter in PARAMETERS.items():
        value = values.get(name)
        if value is not None:
            settings = parameter.feeds.apply(settings, value)
    return settings
