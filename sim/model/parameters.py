"""The vocabulary of the seed paper's quantities, defined once for every stage: the sphere and its cavity (Table 1,
Sects. 2, 4.1), the uncertain parameters and their intervals (Table 2), the tangential contact (Appendix C), and
`PARAMETERS`, the one table of the parameters a study may vary or a command may set. The materials and Eq. 8 are
in `sim.model.materials`; the units and plausible ranges of typed quantities in `sim.common.units`.

Every other module takes names, units, nominal values, intervals and plausible ranges from here: the simulator
(`sim.model.system` re-exports the nominal values), the commands' options and JSON keys (`sim.cli`), the study
files and spaces (`uq.problem`), the design's uncertainty box (`uq.design.problem`) and the calibration
(`bem_contact.pipeline`).

A row of `PARAMETERS` (an `UncertainParameter`) says everything the workbench needs to know about a parameter:
its name and unit, its nominal value and interval (Table 2 for D, g, k_H; `Spread`: how the interval sits around
the nominal value, and so carries over to another sphere in `ies design`), its physical limits (`Bounds`: checked
the same on the command line and in study files, `UncertainParameter.problem`), what it feeds in the simulated
system (`Feed`: a field of `SystemSettings`, set, scaled, derived, or an input of its own such as a contact law's
constant), its option of `ies sweep` / `ies overview` / `ies trace` (with aliases), its key in a study file
(``[parameters.KEY]``) and in the commands' JSON. Adding a parameter is adding a row (`register_parameter`); a
contact law with a constant of its own registers the constant's row with the law (`sim.model.contact_law.register`).
"""
from __future__ import annotations

import argparse
import math
from dataclasses import dataclass, fields, replace
from typing import Any, Callable, Mapping

from sim.common.errors import SimulationInputError
from sim.common.units import CLEARANCE, DAMPING, K_H, K_T, Quantity, implausible, parse_quantity

# ---- the sphere and its cavity (Table 1, Sects. 2 and 4.1) ------------------------------------------------------
SPHERE_MASS = 0.0177  # kg, Table 1
SPHERE_RADIUS = 7.92e-3  # m, Sect. 2: nominal diameter 15.84 mm
CLEARANCE_NOMINAL = 0.58e-3  # m, Sect. 2: (17 - 15.84) / 2 mm
#: m, Table 2: the clearance's upper end 0.612 mm is g* widened by the crater (0.012 mm) and the sphere's flattening
#: (0.02 mm per side, Sect. 4.1)
CLEARANCE_WIDENING = 0.032e-3
SPHERE_FLATTENING = 0.02e-3  # m per side, Sect. 4.1: 15.80 mm across the flattened regions
GRAVITY = 9.81  # m/s^2: the sphere's weight m_a g is the floor contact's normal load (Appendix C)

# ---- the Hertzian contact (Eq. 8, Table 2, Sect. 4.1) ------------------------------------------------------------
N_PER_MM15 = 1e3**1.5  # N/m^1.5 per N/mm^1.5
#: k_H* of Table 2 (Eq. 8 with Table 1's brass on steel gives 281.76e3 N/mm^1.5, which the paper rounds to 282e3:
#: `sim.model.materials.hertz_constant`; tests/sim/model/test_materials.py)
K_H_NOMINAL = 282e3 * N_PER_MM15  # N/m^1.5
K_H_UPPER_FACTOR = 428.0 / 282.0  # Table 2: 428e3 N/mm^1.5 (+52 %), the crater's stiffening found by BEM (Sect. 4.1)
K_H_BEST_ESTIMATE_FACTOR = 1.25  # Sect. 4.1: k_H's best estimate 1.25 k_H*

# ---- the modal damping of the resonant mode (Table 2) -----------------------------------------------------------
D1_NOMINAL = 0.00085
D1_INTERVAL = (0.00075, 0.00090)

# ---- the damped contact (Eq. 10, Sect. 5.5) and dry friction (Appendix C) --------------------------------------
DEFAULT_R_CONT = 0.99  # r_cont,diss of the damped law (Eq. 10) when none is given: the paper's value (Sect. 5.5)
K_T_PAPER = 22e6  # N/m, Appendix C ("22 kN/mm")
MU_PAPER = 0.07  # Appendix C


def column_name(name: str, unit: str) -> str:
    """A CSV column or JSON key for a quantity and its unit: ``g`` in ``m`` -> ``g_m``, ``k_H`` in ``N/m^1.5`` ->
    ``k_H_N_per_m1p5``, a dimensionless quantity (unit "-", "1" or "") keeps its name."""
    if unit in ("", "-", "1"):
        return name
    token = unit.replace("/", "_per_").replace("^", "").replace(".", "p").replace(" ", "_")
    return f"{name}_{token}"


@dataclass(frozen=True)
class SystemSettings:
    """The values the parameters feed: what `sim.model.system.build_system` builds a simulated system from (SI).

    D1: damping ratio of mode 1 (-; None keeps the modal model's); mass (kg), clearance g (m), k_H (N/m^1.5) of the
    sphere (Eqs. 3-6); contact_law: a name of `sim.model.contact_law.LAWS` (None: damped when r_cont is given);
    r_cont: r_cont,diss of Eq. 10 (None: the law's default); friction: Coulomb mu at the floor (0: off) and k_t (N/m)
    the floor contact's tangential stiffness (Appendix C); inputs: (name, value) of every parameter fed, in feeding
    order (a contact law's own constant is read from here, `sim.model.system.Impactor.input`).
    """

    D1: float | None = None
    mass: float = SPHERE_MASS
    clearance: float = CLEARANCE_NOMINAL
    k_H: float = K_H_NOMINAL
    contact_law: str | None = None
    r_cont: float | None = None
    friction: float = 0.0
    k_t: float = K_T_PAPER
    inputs: tuple[tuple[str, float], ...] = ()


_SETTINGS_FIELDS = tuple(f.name for f in fields(SystemSettings) if f.name != "inputs")


@dataclass(frozen=True)
class Feed:
    """Where a parameter's value goes: the `SystemSettings` field it sets (or multiplies, `scale`), or, with
    `derive`, a function (settings, value) -> settings that works it into several fields (e.g. a sphere that is
    smaller than nominal: more clearance, less mass, a softer contact). field None and no `derive`: an input of its
    own, read by whoever needs it (a contact law's constant). Every value fed is also kept in `SystemSettings.inputs`.
    """

    field: str | None = None
    scale: bool = False
    derive: Callable[[SystemSettings, float], SystemSettings] | None = None

    def __post_init__(self) -> None:
        if self.field is not None and self.field not in _SETTINGS_FIELDS:
            raise ValueError(f"Feed: unknown field {self.field!r}; known: {', '.join(_SETTINGS_FIELDS)}")
        if self.derive is not None and self.field is not None:
            raise ValueError("Feed: give a field or derive, not both")

    def apply(self, settings: SystemSettings, value: float, name: str = "") -> SystemSettings:
        """The settings with this parameter's value (named `name` in `SystemSettings.inputs`) fed in."""
        value = float(value)
        settings = replace(settings, inputs=(*settings.inputs, (name, value)))
        if self.derive is not None:
            return self.derive(settings, value)
        if self.field is None:
            return settings
        if self.scale:
            value *= getattr(settings, self.field)
        return replace(settings, **{self.field: value})

    def describe(self) -> str:
        """Human-readable target, e.g. "clearance" or "mass x value"."""
        if self.derive is not None:
            return getattr(self.derive, "__name__", "derived")
        if self.field is None:
            return "an input of its own"
        return f"{self.field} x value" if self.scale else self.field


@dataclass(frozen=True)
class Spread:
    """How a parameter's interval sits around its nominal value (Table 2), and so carries over to another sphere
    (`ies design`'s uncertainty box): "absolute" ends (D_1: the host's damping does not depend on the sphere),
    "offset" ends added to the nominal value (g: the crater and the flattening widen any clearance by 0 .. 0.032 mm)
    or "factor" ends multiplying it (k_H: the crater stiffens Eq. 8's value of any sphere by 1 .. 1.52)."""

    kind: str
    low: float
    high: float

    def __post_init__(self) -> None:
        if self.kind not in ("absolute", "offset", "factor"):
            raise ValueError(f"Spread: kind must be absolute, offset or factor, got {self.kind!r}")

    def at(self, value: float, end: float) -> float:
        """The parameter at one end of the spread around `value` (the nominal value of a design)."""
        if self.kind == "absolute":
            return end
        return value + end if self.kind == "offset" else end * value

    def ends(self, value: float) -> tuple[float, float]:
        """(low, high) of the interval around `value`."""
        return self.at(value, self.low), self.at(value, self.high)

    def centre(self, value: float) -> float:
        """The interval's midpoint around `value`."""
        mid = 0.5 * (self.low + self.high)
        if self.kind == "absolute":
            return mid
        return value + mid if self.kind == "offset" else mid * value


@dataclass(frozen=True)
class Bounds:
    """The physical limits of a parameter (SI): lower (the value must be above it, or may equal it when
    `lower_closed`) and upper (the value must be below it, or may equal it when `upper_closed`)."""

    lower: float = 0.0
    lower_closed: bool = False
    upper: float = math.inf
    upper_closed: bool = False

    def text(self) -> str:
        """The rule in words, e.g. "must be a positive number", "must lie in (0, 1)"."""
        if math.isinf(self.upper) and self.lower == 0.0:
            return "must be >= 0" if self.lower_closed else "must be a positive number"
        if math.isinf(self.upper):
            return f"must be {'>=' if self.lower_closed else '>'} {self.lower:g}"
        return (f"must lie in {'[' if self.lower_closed else '('}{self.lower:g}, {self.upper:g}"
                f"{']' if self.upper_closed else ')'}")

    def contains(self, value: float) -> bool:
        """True when `value` is a finite number within the bounds."""
        return (math.isfinite(value) and (value > self.lower or (value == self.lower and self.lower_closed))
                and (value < self.upper or (value == self.upper and self.upper_closed)))

    def side(self, value: float) -> str:
        """Which limit a finite `value` outside two finite bounds breaks, e.g. "must be below 1"; "" otherwise."""
        if not (math.isfinite(value) and math.isfinite(self.upper)):
            return ""
        if value >= self.upper:
            return f"must be {'at most' if self.upper_closed else 'below'} {self.upper:g}"
        return f"must be {'>=' if self.lower_closed else '>'} {self.lower:g}"


@dataclass(frozen=True)
class CliOption:
    """A parameter's option of `ies sweep`, `ies overview` and `ies trace` (argparse dest = the parameter's name).

    flag: the option; aliases: other names users already type for it (`--clearance` for `--g`), said in the help;
    parse: a value type of its own (None: the row's, `UncertainParameter.option_value`: a number, with a unit when
    the row has a `quantity`, checked against the row's bounds; an implausible magnitude is refused by the command,
    `check_plausible`, unless --allow-implausible)."""

    flag: str
    metavar: str
    help: str
    parse: Callable[[str], float] | None = None
    aliases: tuple[str, ...] = ()

    @property
    def flags(self) -> tuple[str, ...]:
        """The option and its aliases."""
        return (self.flag, *self.aliases)

    def help_text(self) -> str:
        """The help, with the aliases named."""
        if not self.aliases:
            return self.help
        return f"{self.help}; also {', '.join(self.aliases)} (the same option)"


@dataclass(frozen=True)
class UncertainParameter:
    """One row of `PARAMETERS`.

    name, unit, label: as in CSV headers, figures and messages; nominal, interval (min, max): SI values, Table 2's
    for D, g, k_H (an optional parameter's interval is its nominal value: a study lists it to vary it);
    feeds: what it sets in the simulated system; study_key: ``[parameters.KEY]`` of a study file; option: its
    command-line option (None: studies only); table2: one of Table 2's parameters, in every study of the simulator
    (the others enter a study only when it lists them); upper_limit: exclusive physical bound (1 for a damping
    ratio); positive: every value must be > 0 (False: >= 0 allowed, e.g. mu = 0 switches friction off); quantity:
    the unit parser and plausible range of strings like "0.58 mm" (`sim.common.units`), None for plain numbers;
    what: how messages name it ("D", "clearance g"; default the name); hint: what a valid value looks like;
    bounds: the physical limits (default from upper_limit and positive; `Bounds`); spread: how the interval sits
    around the nominal value (`Spread`; None: not in `ies design`'s uncertainty box); json_key: its key in the JSON
    of `ies sweep` / `ies overview` / `ies trace` (default: the CSV column, `column_name`).
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
    what: str = ""
    hint: str = ""
    bounds: Bounds | None = None
    spread: Spread | None = None
    json_key: str = ""

    def __post_init__(self) -> None:
        if self.bounds is None:
            object.__setattr__(self, "bounds", Bounds(lower_closed=not self.positive, upper=self.upper_limit))
        if not self.what:
            object.__setattr__(self, "what", self.name)
        if not self.json_key:
            object.__setattr__(self, "json_key", column_name(self.name, self.unit))
        if self.spread is not None and tuple(self.interval) != self.spread.ends(self.nominal):
            raise ValueError(f"{self.name}: interval {self.interval} is not its spread {self.spread} around "
                             f"{self.nominal:g}")

    @property
    def column(self) -> str:
        """Its CSV column: the name with the unit in machine-friendly form (g_m, k_H_N_per_m1p5)."""
        return column_name(self.name, self.unit)

    def problem(self, value: float) -> str | None:
        """None when `value` (SI) is physically possible (`bounds`); else one sentence that says what is wrong,
        e.g. "D must lie in (0, 1): must be below 1 (a damping ratio, e.g. 0.00085), got 1.5"."""
        value = float(value)
        if self.bounds.contains(value):
            return None
        side = self.bounds.side(value)
        hint = f" ({self.hint})" if self.hint else ""
        return f"{self.what} {self.bounds.text()}{': ' + side if side else ''}{hint}, got {value!r}"

    def check(self, value: float) -> float:
        """`value` as a float if physically possible (`problem`), else SimulationInputError with that line."""
        why = self.problem(value)
        if why is not None:
            raise SimulationInputError(why)
        return float(value)

    def parse(self, text: str | float) -> float:
        """The SI value of `text`: a number, or with a unit when the row has a `quantity` ("0.58mm");
        SimulationInputError naming the accepted units otherwise."""
        if self.quantity is not None:
            return parse_quantity(text, self.quantity)
        if isinstance(text, bool):
            raise SimulationInputError(f"{self.what} must be a number, got {text!r}")
        try:
            return float(text)
        except (TypeError, ValueError):
            raise SimulationInputError(f"{self.what}: cannot read {text!r}; give a number"
                                       + (f" in {self.unit}" if self.unit not in ("", "-", "1") else "")) from None

    def implausible(self, value: float) -> str | None:
        """One sentence when `value` lies outside the quantity's plausible range (`sim.common.units.implausible`),
        else None (also for a row without a quantity)."""
        return None if self.quantity is None else implausible(float(value), self.quantity, getattr(value, "text", None))

    def option_value(self, text: str) -> "Typed":
        """argparse type of the row's option: `parse` and `check` (one line ``argument --X: ...`` otherwise); the
        value keeps the text typed, for the line of `check_plausible`."""
        try:
            return Typed(self.check(self.parse(text)), text)
        except SimulationInputError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    def feed(self, settings: SystemSettings, value: float) -> SystemSettings:
        """The settings with this row's value fed in (`Feed.apply`)."""
        return self.feeds.apply(settings, value, self.name)

    def reported(self, settings: SystemSettings) -> float | None:
        """The row's value in a built system's settings (`sim.model.system.settings_of`): the field it sets, or the
        value it was given (None when it was not)."""
        if self.feeds.field is not None and not self.feeds.scale and self.feeds.derive is None:
            return getattr(settings, self.feeds.field)
        return dict(settings.inputs).get(self.name)


class Typed(float):
    """A number read from the command line (SI) that keeps the text it was read from (`text`), for messages."""

    text: str

    def __new__(cls, value: float, text: str) -> "Typed":
        number = super().__new__(cls, value)
        number.text = str(text)
        return number

    def __getnewargs__(self) -> tuple[float, str]:  # pickled or copied (to a worker) with its text
        return float(self), self.text


#: the option that runs a value whose magnitude is implausible (`check_plausible`)
ALLOW_IMPLAUSIBLE = "--allow-implausible"


def check_plausible(values: Mapping[str, float | None], *, allow: bool = False,
                    where: Callable[[UncertainParameter, float], str] | None = None) -> None:
    """Refuse (SimulationInputError, one line) the first value of a row of `PARAMETERS` whose magnitude is implausible
    for its quantity (`UncertainParameter.implausible`: a unit slip, ``--g 0.6`` for 0.6 mm, ``--D 0.085`` for
    0.085 %), naming the reading that would make it plausible, unless `allow` (--allow-implausible). `where(row,
    value)` names the value in the line (default: the row's option and the text typed, "--g 0.6")."""
    if allow:
        return
    for name, value in values.items():
        row = PARAMETERS.get(name)
        if row is None or value is None or (why := row.implausible(value)) is None:
            continue
        if where is not None:
            place = where(row, value)
        else:
            place = f"{row.option.flag if row.option else row.name} {getattr(value, 'text', f'{value:g}')}"
        way_out = f"pass {ALLOW_IMPLAUSIBLE} to compute with it as given"
        if why.endswith("?"):  # a reading that is plausible: the number typed without its unit
            raise SimulationInputError(f"{place}: {why} Give the unit, or {way_out}")
        raise SimulationInputError(f"{place}: {why}; {way_out}")


def _table2(name: str, unit: str, label: str, nominal: float, spread: Spread, feeds: Feed, **kwargs: Any) -> UncertainParameter:
    """A row of Table 2: its interval is its spread around the nominal value (bit for bit the paper's numbers)."""
    return UncertainParameter(name, unit, label, nominal, spread.ends(nominal), feeds, name, table2=True, spread=spread,
                              **kwargs)


#: every parameter of the simulator, in the order of Table 2 and then the optional ones
PARAMETERS: dict[str, UncertainParameter] = {p.name: p for p in (
    _table2("D", "-", "modal damping ratio D_1", D1_NOMINAL, Spread("absolute", *D1_INTERVAL), Feed("D1"),
            upper_limit=1.0, hint="a damping ratio, e.g. 0.00085 or 0.085%", json_key="D1", quantity=DAMPING,
            option=CliOption("--D", "D1", f"modal damping ratio of mode 1 (-), or in %%: 0.085%% (default the model's, "
                                          f"{D1_NOMINAL:g}); above 5 %% it needs {ALLOW_IMPLAUSIBLE}")),
    _table2("g", "m", "clearance g", CLEARANCE_NOMINAL, Spread("offset", 0.0, CLEARANCE_WIDENING), Feed("clearance"),
            quantity=CLEARANCE, what="clearance g",
            option=CliOption("--g", "G", "clearance g in m, or with a unit: 0.58mm, 580um (default 0.58 mm)",
                             aliases=("--clearance",))),
    _table2("k_H", "N/m^1.5", "Hertzian spring constant k_H", K_H_NOMINAL, Spread("factor", 1.0, K_H_UPPER_FACTOR),
            Feed("k_H"), quantity=K_H,
            option=CliOption("--k-H", "K_H", "Hertz constant k_H in N/m^1.5, or with a unit: 282e3N/mm^1.5 (default "
                                             "282e3 N/mm^1.5 = 8.918e9 N/m^1.5)")),
    UncertainParameter(
        "r_cont", "-", "r_cont,diss of the damped contact law (Eq. 10)", DEFAULT_R_CONT, (DEFAULT_R_CONT,) * 2,
        Feed("r_cont"), "r_cont", bounds=Bounds(upper=1.0, upper_closed=True), hint="1 = elastic, e.g. 0.99",
        option=CliOption("--r-cont", "R", "r_cont,diss of Eq. 10 in (0, 1]: the coefficient of restitution the damped "
                                          "law is designed for (1 = elastic, bit for bit); implies --contact-law "
                                          "hertz-damped (default there 0.99)")),
    UncertainParameter(
        "friction", "-", "friction coefficient mu at the floor (App. C)", MU_PAPER, (MU_PAPER,) * 2, Feed("friction"),
        "friction", positive=False, what="the friction coefficient mu", hint="0: no friction, e.g. 0.07",
        option=CliOption("--friction", "MU", "Coulomb coefficient of dry friction between the sphere and the cavity "
                                             "floor (Appendix C; 0 = off, the default; the paper: 0.07); needs "
                                             "--integrator ode3 and the model's phi_floor")),
    UncertainParameter(
        "k_t", "N/m", "tangential stiffness k_t at the floor (App. C)", K_T_PAPER, (K_T_PAPER,) * 2, Feed("k_t"), "k_t",
        quantity=K_T, what="k_t (N/m)",
        option=CliOption("--k-t", "K_T", "tangential stiffness of the floor contact in N/m, or with a unit: 22kN/mm "
                                         "(default, Appendix C)")),
    UncertainParameter(
        "m_a", "kg", "sphere mass m_a (Table 1)", SPHERE_MASS, (SPHERE_MASS,) * 2, Feed("mass"), "m_a",
        what="sphere mass", json_key="mass_kg"),
)}


def register_parameter(row: UncertainParameter) -> UncertainParameter:
    """Add a row to `PARAMETERS` (the one registry line of a new parameter); refuses a name, study key, option or
    JSON key that another row has. Returns the row."""
    for other in PARAMETERS.values():
        if other.name == row.name:
            continue
        clash = [what for what, mine, theirs in (
            ("study key", row.study_key, other.study_key), ("JSON key", row.json_key, other.json_key),
            ("option", set(row.option.flags if row.option else ()), set(other.option.flags if other.option else ())))
            if (mine & theirs if isinstance(mine, set) else mine == theirs)]
        if clash:
            raise ValueError(f"parameter {row.name!r}: its {', '.join(clash)} is {other.name!r}'s already")
    PARAMETERS[row.name] = row
    return row


def table2_parameters() -> list[UncertainParameter]:
    """The rows of Table 2 (in every study of the simulator), in table order."""
    return [p for p in PARAMETERS.values() if p.table2]


def optional_parameters() -> list[UncertainParameter]:
    """The rows a study adds by listing them (``[parameters.KEY]``), in table order."""
    return [p for p in PARAMETERS.values() if not p.table2]


def boxed_parameters() -> list[UncertainParameter]:
    """The rows with a `Spread`: the dimensions of `ies design`'s uncertainty box, in table order."""
    return [p for p in PARAMETERS.values() if p.spread is not None]


def system_settings(values: Mapping[str, float], base: SystemSettings = SystemSettings()) -> SystemSettings:
    """`base` with every value of a parameter of `PARAMETERS` fed in (`Feed.apply`, table order); names that are
    not in the table (e.g. other models' inputs) are ignored, so are values that are None (not given)."""
    settings = base
    for name, parameter in PARAMETERS.items():
        value = values.get(name)
        if value is not None:
            settings = parameter.feed(settings, value)
    return settings
