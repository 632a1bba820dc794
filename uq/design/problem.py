"""What `ies design` is asked (the design problem): the operating range, the grid of clearances and spheres, the
uncertainty box (D_1's interval from the host, `ModalModel.damping_box`; Table 2's others), the host, and the reading of its options and study file with
units; one line (StudyError) for anything wrong."""
from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sim.model.materials import STEEL_WALL, Material, material
from sim.model.parameters import PARAMETERS, UncertainParameter, boxed_parameters
from uq.errors import StudyError

#: Table 2's intervals as the default uncertainty box, each the spread of its row of the one vocabulary
#: (`sim.model.parameters.Spread`): D_1, the clearance's tolerance above its nominal value (0.58 -> 0.612 mm) and the
#: factor on Eq. 8's k_H (282e3 -> 428e3 N/mm^1.5)
D_INTERVAL = (PARAMETERS["D"].spread.low, PARAMETERS["D"].spread.high)
CLEARANCE_TOLERANCE = (PARAMETERS["g"].spread.low, PARAMETERS["g"].spread.high)
K_H_FACTOR = (PARAMETERS["k_H"].spread.low, PARAMETERS["k_H"].spread.high)
#: the rows whose box the design's options set (the row -> the `DesignProblem` field holding its spread's ends);
#: every other row with a spread enters the box with its own
BOX_OPTIONS = {"D": "D", "g": "clearance_tolerance", "k_H": "k_H_factor"}


#: the built-in rig's block across the cavity and its walls (Sect. 2: 28 mm, 17 mm cavity in the paper's design)
BLOCK_WIDTH = 28e-3
MIN_WALL = 5.5e-3


#: the modal restitution r (Eq. D.1) the screening uses unless told: the simulator's value at the seed rig's APR
RESTITUTION = 0.86


#: the stepped sine of a verification run: Fig. 6's quick study (26 frequencies, 2 s wait, 3 s hold, up, eta 0.96-1.01)
PROTOCOL = {"eta_start": 0.96, "eta_stop": 1.01, "n_eta": 26, "wait": 2.0, "hold": 3.0, "sequence": "up",
            "start": "base-velocity", "repetition": "run", "integrator": "exact"}


#: the margin to the switch a design must keep above the top of the operating range (item "admissible", `uq.design`)
MARGIN = 0.2


#: the most values a range may have (COUNT); a design's runs are limited as a study's (`uq.problem.tasks.MAX_RUNS`,
#: `--allow-large`), estimated at about SECONDS_PER_RUN each on one core (the rig's stepped sine of PROTOCOL)
MAX_COUNT = 1000
SECONDS_PER_RUN = 0.5
#: the most (design, level) pairs the slow flow screens at once (its arrays: tens of MB)
MAX_SCREENED = 2_000_000


@dataclass(frozen=True)
class Design:
    """One design: clearance g (m) and the sphere, its radius (m) and material name (`sim.model.materials`), striking
    walls of `wall` (`sim.model.materials.Material`, the host's; the same for every design of a problem, so it takes no
    part in comparing designs). Its mass and k_H* come from `sim.model.sphere` (the paper's sphere on steel keeps
    Tables 1-2's 17.7 g and 282e3 N/mm^1.5, any other the solid sphere's mass and Eq. 8 with both bodies' E and nu), so
    that `ies sweep --radius R --material M --wall-material W` simulates the same sphere."""

    clearance: float
    radius: float
    material: str
    wall: Material = field(default=STEEL_WALL, compare=False)

    @property
    def sphere(self) -> Any:
        """The sphere (`sim.model.sphere.Sphere`) on this design's walls."""
        from sim.model.sphere import sphere_of

        return sphere_of(self.radius, material(self.material), wall=self.wall)

    @property
    def mass(self) -> float:
        """m_a (kg) of the sphere (`sim.model.sphere.Sphere.mass`)."""
        return self.sphere.mass

    @property
    def k_H(self) -> float:
        """k_H* (N/m^1.5) of Eq. 8, the sphere on the host's wall (`sim.model.sphere.Sphere.k_H_star`)."""
        return self.sphere.k_H_star

    def cavity(self) -> float:
        """The cavity's width 2R + 2g (m)."""
        return 2.0 * (self.radius + self.clearance)

    def moved(self, axis: str, value: Any) -> "Design":
        """This design with one of clearance, radius or material changed."""
        return dataclasses.replace(self, **{axis: value})

    def label(self) -> str:
        return f"g {self.clearance * 1e3:.3f} mm, {self.material} R {self.radius * 1e3:.2f} mm"

    def describe(self) -> dict[str, Any]:
        return {"clearance_m": self.clearance, "radius_m": self.radius, "material": self.material,
                "wall_material": self.wall.name, "mass_kg": self.mass, "k_H_N_per_m1p5": self.k_H,
                "cavity_m": self.cavity()}

    def value(self, row: UncertainParameter) -> float:
        """This design's nominal value of a parameter row: its clearance (g), k_H (Eq. 8), mass (m_a), or the row's
        nominal value."""
        return {"g": self.clearance, "k_H": self.k_H, "m_a": self.mass}.get(row.name, row.nominal)


@dataclass(frozen=True)
class DesignProblem:
    """What `ies design` is asked: the operating base amplitudes a_base (m), the design grid, the uncertainty box (D: the
    interval of D_1, where it comes from in `damping_source`), the objective, how many screened candidates to verify,
    the repetitions and the stepped sine of a verification run, the cavity walls' material (`wall`, Eq. 8)."""

    excitation: tuple[float, ...]
    clearances: tuple[float, ...]
    radii: tuple[float, ...]
    materials: tuple[str, ...] = ("brass",)
    D: tuple[float, float] = D_INTERVAL
    clearance_tolerance: tuple[float, float] = CLEARANCE_TOLERANCE
    k_H_factor: tuple[float, float] = K_H_FACTOR
    objective: str = "mean"
    margin: float = MARGIN
    allow_large: bool = False
    candidates: int = 5
    repetitions: int = 3
    restitution: float = RESTITUTION
    block_width: float = BLOCK_WIDTH
    min_wall: float = MIN_WALL
    modal_file: str | None = None
    baseline: Design | None = None
    seed: int = 2024
    wall: Material = STEEL_WALL
    damping_source: str = "Table 2"
    protocol: Mapping[str, Any] = field(default_factory=lambda: dict(PROTOCOL))

    def check(self) -> None:
        """Refuse a problem that cannot be designed, with one line (StudyError)."""
        from sim.common.errors import SimulationInputError
        from sim.model.materials import material

        for name, values, unit in (("--excitation", self.excitation, "m"), ("--clearance", self.clearances, "m"),
                                   ("--radius", self.radii, "m")):
            if not values:
                raise StudyError(f"{name}: the range is empty; give START:STOP[:COUNT] with units, e.g. "
                                 f"{_EXAMPLES[name]}")
            if any(not math.isfinite(v) or v <= 0 for v in values):
                raise StudyError(f"{name}: every value must be a positive number of {unit}, got "
                                 f"{', '.join(f'{v:g}' for v in values)}")
        for name in self.materials:
            try:
                material(name)
            except SimulationInputError as exc:  # one line naming the known materials
                raise StudyError(f"--material: {exc}") from None
        from uq.design.objectives import objective_named

        objective_named(self.objective)
        if not (math.isfinite(self.margin) and 0.0 < self.margin <= 1.0):
            raise StudyError(f"--margin {self.margin:g}: give the margin to the switch as a fraction in (0, 1], e.g. 0.2 "
                             "for 20 % above the top of the operating range")
        for name, (lo, hi) in (("--damping", self.D), ("--clearance-tolerance", self.clearance_tolerance),
                               ("--k-H-factor", self.k_H_factor)):
            if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
                raise StudyError(f"{name}: give an interval LOW:HIGH with LOW <= HIGH, got {lo:g}:{hi:g}")
        if not (0 < self.D[0] and self.D[1] < 1):
            raise StudyError(f"--damping: D_1 must lie in (0, 1), got {self.D[0]:g}:{self.D[1]:g}")
        if self.k_H_factor[0] <= 0:
            raise StudyError(f"--k-H-factor: the factor on Eq. 8's k_H must be > 0, got {self.k_H_factor[0]:g}")
        if min(self.clearances) + self.clearance_tolerance[0] <= 0:
            raise StudyError("--clearance-tolerance: the lower end makes the smallest clearance <= 0")
        if not 0 < self.restitution <= 1:
            raise StudyError(f"--restitution must lie in (0, 1], got {self.restitution:g}")
        if self.candidates < 1 or self.repetitions < 1:
            raise StudyError("--candidates and --reps must be >= 1")
        if not (math.isfinite(self.block_width) and self.block_width > 0 and math.isfinite(self.min_wall)
                and self.min_wall > 0):
            raise StudyError(f"--block-width and --min-wall must be positive lengths, got {self.block_width * 1e3:g} mm "
                             f"and {self.min_wall * 1e3:g} mm")
        if self.room() <= 0:
            raise StudyError(f"--min-wall {self.min_wall * 1e3:g} mm: two walls of {self.min_wall * 1e3:g} mm leave no "
                             f"room in the {self.block_width * 1e3:g} mm block for a cavity; give --min-wall below "
                             f"{self.block_width * 1e3 / 2:g} mm or a wider --block-width")
        if self.baseline is not None and not self.fits(self.baseline):
            raise StudyError(f"--baseline: {self.baseline.label()} needs a {self.baseline.cavity() * 1e3:.2f} mm cavity;"
                             f" {self.room() * 1e3:.2f} mm fit between {self.min_wall * 1e3:g} mm walls")
        screened = len(self.clearances) * len(self.radii) * len(self.materials) * len(self.excitation)
        if screened > MAX_SCREENED:
            raise StudyError(f"the grid of {len(self.clearances)} clearances x {len(self.radii)} radii x "
                             f"{len(self.materials)} materials at {len(self.excitation)} levels is {screened:,} "
                             f"(design, level) pairs, more than the {MAX_SCREENED:,} the screening holds in memory: give "
                             "fewer values to --clearance, --radius or --excitation")
        if not any(self.fits(s) for s in self.grid()):
            raise StudyError(f"no design fits: the cavity 2R + 2g must stay within {self.room() * 1e3:.2f} mm "
                             f"({self.block_width * 1e3:g} mm block, walls of {self.min_wall * 1e3:g} mm); "
                             f"the smallest design needs {min(s.cavity() for s in self.grid()) * 1e3:.2f} mm: "
                             "give smaller radii or clearances")

    def room(self) -> float:
        """The widest cavity (m) that leaves walls of min_wall."""
        return self.block_width - 2.0 * self.min_wall

    def fits(self, design: Design) -> bool:
        return design.cavity() <= self.room() * (1 + 1e-12)

    def fitting_text(self) -> str:
        """How many designs of the grid fit the block and which (their clearances per sphere), and, where larger ones
        are cut off, the --block-width that would take the whole grid."""
        grid = self.grid()
        fitting = [d for d in grid if self.fits(d)]
        by_sphere: dict[tuple[str, float], list[float]] = {}
        for d in fitting:
            by_sphere.setdefault((d.material, d.radius), []).append(d.clearance)
        which = "; ".join(f"{m} R {R * 1e3:.3g} mm: g {', '.join(f'{g * 1e3:.3g}' for g in gs)} mm"
                          for (m, R), gs in by_sphere.items())
        text = (f"{len(fitting)} of {len(grid)} designs fit the {self.block_width * 1e3:g} mm block (cavity 2R + 2g "
                f"<= {self.room() * 1e3:.3g} mm between {self.min_wall * 1e3:g} mm walls)" + (f": {which}" if which else ""))
        if len(fitting) < len(grid):
            wide = max(d.cavity() for d in grid) + 2.0 * self.min_wall
            text += f"; the larger ones need a wider block (--block-width {math.ceil(wide * 1e4) / 10:g}mm takes them all)"
        return text

    def edge_text(self, design: Design) -> str:
        """Where a design lies on an edge of the grid that can hold it (the largest or smallest clearance of its sphere
        that fits the block, the largest or smallest radius), in words with the option that would look beyond; "" inside.
        The search sees only the grid: an optimum on its edge may lie beyond it."""
        said = []
        fitting = sorted(g for g in self.clearances if self.fits(Design(g, design.radius, design.material, self.wall)))
        if len(fitting) > 1 and design.clearance == fitting[-1]:
            cut = fitting[-1] < max(self.clearances)
            said.append(f"the largest clearance {'that fits the block' if cut else 'of --clearance'} "
                        f"({design.clearance * 1e3:.3g} mm): larger ones were not tried"
                        f" ({'--block-width' if cut else 'widen --clearance'})")
        elif len(fitting) > 1 and design.clearance == fitting[0]:
            said.append(f"the smallest clearance of --clearance ({design.clearance * 1e3:.3g} mm): smaller ones were "
                        "not tried (widen --clearance)")
        if len(self.radii) > 1 and design.radius in (min(self.radii), max(self.radii)):
            end = "largest" if design.radius == max(self.radii) else "smallest"
            said.append(f"the {end} radius of --radius ({design.radius * 1e3:.3g} mm)")
        return ("on the edge of the grid: " + "; ".join(said)) if said else ""

    def box_text(self) -> str:
        """The uncertainty box in words, with where D_1's interval comes from."""
        t, f = self.clearance_tolerance, self.k_H_factor
        return (f"box: D_1 {100 * self.D[0]:.4g}-{100 * self.D[1]:.4g} % ({self.damping_source}), clearance + "
                f"{t[0] * 1e3:.3g}-{t[1] * 1e3:.3g} mm, k_H x {f[0]:.3g}-{f[1]:.3g} of Eq. 8 on {self.wall.name} walls")

    def grid(self) -> list[Design]:
        """Every design of the grid, material by material, radius by radius, clearance by clearance."""
        return [Design(g, R, m, self.wall) for m in self.materials for R in self.radii for g in self.clearances]

    def spreads(self) -> list[tuple[UncertainParameter, Any]]:
        """The uncertainty box: each row with a `Spread` (`sim.model.parameters.boxed_parameters`) with its spread,
        the ends set by this problem's options for D, g and k_H (`BOX_OPTIONS`)."""
        boxed = []
        for row in boxed_parameters():
            spread = row.spread
            if row.name in BOX_OPTIONS:
                spread = dataclasses.replace(spread, low=getattr(self, BOX_OPTIONS[row.name])[0],
                                             high=getattr(self, BOX_OPTIONS[row.name])[1])
            boxed.append((row, spread))
        return boxed

    def margin_level(self) -> float:
        """The base amplitude (m) of the margin check: the top of the operating range times 1 + margin."""
        return max(self.excitation) * (1.0 + self.margin)

    def corners(self, sphere: Design) -> list[dict[str, float]]:
        """The uncertainty box of one design as task parameters (SI; the rows with a spread, then m_a): its corners
        (each once), then the nominal point (the box's centre) for the monotonicity check."""
        import itertools

        boxed = self.spreads()
        points = []
        for ends in itertools.product(*[(spread.low, spread.high) for _, spread in boxed]):
            point = {row.name: spread.at(sphere.value(row), end) for (row, spread), end in zip(boxed, ends)}
            points.append({**point, "m_a": sphere.mass})
        nominal = {**{row.name: spread.centre(sphere.value(row)) for row, spread in boxed}, "m_a": sphere.mass}
        unique = {tuple(sorted(p.items())): p for p in points}
        return [*unique.values(), nominal]


_EXAMPLES = {"--excitation": "0.66um:6.6um:10", "--clearance": "0.3mm:1.2mm:10", "--radius": "5mm:8mm:4"}


def host_model(problem: DesignProblem) -> Any:
    """The host's modal model (`sim.model.system.ModalModel`): the built-in rig or the problem's model file, through the
    one host resolver (`sim.hosts.sources.resolve_host`: a modal-model file or a file kind another source reads)."""
    from sim.common.errors import SimulationInputError
    from sim.hosts.sources import resolve_host

    try:
        return resolve_host({"model": problem.modal_file}).model
    except SimulationInputError as exc:
        raise StudyError(f"--model: {exc}") from None


def host_mode(model: Any) -> Any:
    """The slow flow's view of the host (`sim.reduced.slow_flow.HostMode`), refused with one line when the host lacks
    what the design needs (a first mode that moves the walls and is excited by the base)."""
    from sim.common.errors import SimulationInputError
    from sim.model.system import check_resonant_mode
    from sim.reduced.slow_flow import host_mode as mode_of

    try:
        check_resonant_mode(model)  # the command's own words for a host the IES cannot act on
        return mode_of(model)
    except SimulationInputError as exc:
        raise StudyError(f"the host model cannot be designed for: {exc}") from None


def levels_of(model: Any, a_base: Sequence[float]) -> np.ndarray:
    """Excitation levels a_base / a_base* (-) of base amplitudes (m), a_base* of the host's nominal D_1* and the paper's
    g* (Sect. 5.3, `sim.model.system.Nominal.of`)."""
    from sim.model.system import a_base_star

    return np.asarray(a_base, dtype=float) / a_base_star(model)


def no_absorber(model: Any, a_base: Sequence[float]) -> np.ndarray:
    """Resonant tip amplitude (m) of the host alone at its nominal D_1* (Sect. 5's a_noabs*, `Nominal.of`)."""
    from sim.model.system import a_noabs_star

    return a_noabs_star(model, np.asarray(a_base, dtype=float))


def first_impacts(mode: Any, clearance: float) -> float:
    """The base amplitude (m) at which the host's linear resonant wall amplitude reaches `clearance` (Eq. 7, mode 1
    at resonance: |phi_c gamma| a_base / (2 D))."""
    return 2.0 * mode.D * clearance / mode.coupling


def micrometres(a: float) -> str:
    return f"{a * 1e6:.3g}"


def _quantities() -> dict[str, Any]:
    """The quantities of the design's ranges: the clearance and the radius of the one vocabulary (`sim.common.units`,
    the clearance's row of `PARAMETERS`), and the excitation as a base amplitude or acceleration."""
    from sim.common.units import LENGTH_UNITS, RADIUS, Quantity

    return {"excitation": Quantity("base amplitude a_base", "m", {**LENGTH_UNITS, "nm": 1e-9}, (1e-10, 1e-2), "2um"),
            "acceleration": Quantity("base acceleration", "m/s2", {"m/s2": 1.0, "m/s^2": 1.0}, (1e-4, 1e4), "1m/s2"),
            "clearance": PARAMETERS["g"].quantity, "radius": RADIUS, "damping": PARAMETERS["D"].quantity,
            "block_width": Quantity("block width", "m", LENGTH_UNITS, (1e-3, 1.0), "28mm"),
            "min_wall": Quantity("wall thickness", "m", LENGTH_UNITS, (1e-5, 0.5), "5.5mm")}


#: a number alone, without a unit (`2e-3`, `0.5`): refused in a range, on the command line as in a study file
_BARE_NUMBER = re.compile(r"^\s*[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?\s*$")


def option_name(kind: str) -> str:
    """The option of a setting: `--min-wall` for min_wall."""
    return "--" + kind.replace("_", "-")


def parse_range(text: str, kind: str, *, count: int, omega: float | None = None) -> tuple[float, ...]:
    """`START:STOP[:COUNT]` or one value, each a number with its unit (`0.2mm:1.2mm`, `2um:8um:7`, `7.92mm`) or, for
    the excitation, base accelerations (`0.5m/s2:2m/s2`, turned into amplitudes a / omega^2 at the resonance omega);
    returns the COUNT (default `count`, at most MAX_COUNT) equispaced values in SI. One line (StudyError) for a
    malformed, empty, reversed, unitless (`1e-3m:2e-3`: every number needs its unit) or implausible range, or one of
    more than MAX_COUNT values (with what it would cost)."""
    from sim.common.errors import SimulationInputError
    from sim.common.units import implausible, parse_quantity

    quantities = _quantities()
    option = option_name(kind)
    parts = [t.strip() for t in str(text).split(":")]
    if len(parts) > 3 or not all(parts[:2]):
        raise StudyError(f"{option} {text!r}: give START:STOP[:COUNT] or one value, with units, e.g. "
                         f"{_EXAMPLES.get(option, '1mm')}")
    n = count if len(parts) < 3 else _count(parts[2], option, text)
    accelerating = kind == "excitation" and any(u in parts[0] for u in ("m/s2", "m/s^2"))
    quantity = quantities["acceleration" if accelerating else kind]
    values = []
    for part in parts[:2]:
        if _BARE_NUMBER.match(part):
            raise StudyError(f"{option} {text!r}: {part!r} has no unit; write every number with one, e.g. "
                             f"{quantity.example}")
        try:
            value = parse_quantity(part, quantity)
        except SimulationInputError as exc:
            raise StudyError(f"{option}: {exc}") from None
        if value <= 0:
            raise StudyError(f"{option} {text!r}: {quantity.name} must be > 0")
        if (why := implausible(value, quantity)) is not None:
            raise StudyError(f"{option}: {why}")
        values.append(value)
    if len(parts) == 1:
        values = values[:1]
        n = 1
    elif values[1] < values[0]:
        raise StudyError(f"{option} {text!r}: the range is reversed; give START:STOP with START <= STOP")
    elif values[1] == values[0]:
        n = 1
    if accelerating:
        if omega is None:
            raise StudyError(f"{option}: base accelerations need the host's first frequency")
        values = [v / omega**2 for v in values]
    return tuple(float(v) for v in np.linspace(values[0], values[-1], n)) if n > 1 else (float(values[0]),)


def _count(text: str, option: str, whole: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise StudyError(f"{option}: COUNT {text!r} must be a whole number >= 1") from None
    if n < 1:
        raise StudyError(f"{option}: COUNT must be >= 1 (an empty range), got {n}")
    if n > MAX_COUNT:
        per_design = 9 * (n + 1) * 3 if option == "--excitation" else 9 * 11 * 3
        what = (f"each verified design alone would take {per_design:.3g} runs (9 points of the box x {n} levels x 3 "
                f"repetitions, about {duration(per_design * SECONDS_PER_RUN)} on one core)" if option == "--excitation"
                else f"the screening would hold {n:.3g} values on this axis alone")
        raise StudyError(f"{option} {whole!r}: COUNT {n} is more than {MAX_COUNT} values: {what}; give a COUNT of at "
                         f"most {MAX_COUNT}")
    return n


def duration(seconds: float) -> str:
    """A duration in words: s, min, h, days or years."""
    for unit, size in (("years", 3.15e7), ("days", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if seconds >= 2 * size:
            return f"{seconds / size:.3g} {unit}"
    return f"{seconds:.0f} s"


def _number(value: Any, option: str, what: str) -> float:
    """A plain number of a setting, or one line (StudyError) saying what it should be."""
    try:
        if isinstance(value, bool):
            raise ValueError
        return float(value)
    except (TypeError, ValueError):
        raise StudyError(f"{option} {value!r}: give {what}") from None


def parse_interval(text: str, what: str, quantity: str | None = None) -> tuple[float, float]:
    """`LOW:HIGH` (plain numbers, or with units: lengths for the clearance tolerance, % for the damping) -> (low,
    high)."""
    from sim.common.errors import SimulationInputError
    from sim.common.units import parse_quantity

    parts = str(text).split(":")
    if len(parts) != 2:
        raise StudyError(f"{what} {text!r}: give LOW:HIGH, e.g. {'0:0.032mm' if quantity else '0.00075:0.0009'}")
    try:
        if quantity:
            lo, hi = (parse_quantity(p.strip(), _quantities()[quantity]) for p in parts)
        else:
            lo, hi = (float(p) for p in parts)
    except (ValueError, SimulationInputError) as exc:
        raise StudyError(f"{what} {text!r}: {exc}") from None
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo > hi:
        raise StudyError(f"{what} {text!r}: give LOW:HIGH with LOW <= HIGH")
    return lo, hi


def parse_baseline(text: str, radii: Sequence[float], materials: Sequence[str], wall: Material = STEEL_WALL) -> Design:
    """`G[,R[,MATERIAL]]` -> a Design on `wall`; R and the material default to the first of the grid's."""
    parts = [t.strip() for t in str(text).split(",", 2)]
    if not 1 <= len(parts) <= 3 or not parts[0]:
        raise StudyError(f"--baseline {text!r}: give G[,R[,MATERIAL]], e.g. 0.58mm,7.92mm,brass")
    g = parse_range(parts[0], "clearance", count=1)[0]
    R = parse_range(parts[1], "radius", count=1)[0] if len(parts) > 1 and parts[1] else radii[0]
    name = material_names(parts[2], "--baseline")[0] if len(parts) > 2 else materials[0]
    return Design(g, R, name, wall)


def material_names(text: str, option: str = "--material") -> tuple[str, ...]:
    """The sphere materials of a comma-separated list (`brass,steel`; one of one's own keeps its commas:
    `brass,E=200GPa,nu=0.29,density=7850kg/m3`), each by its canonical name (`sim.model.materials.material_of`); one
    line (StudyError) naming the known ones for an unknown material."""
    from sim.common.errors import SimulationInputError

    items: list[str] = []
    for part in (t.strip() for t in str(text).split(",")):
        if not part:
            continue
        if "=" in part and items and "=" in items[-1]:
            items[-1] += "," + part  # E=...,nu=...,density=... is one material
        else:
            items.append(part)
    if not items:
        raise StudyError(f"{option}: give at least one sphere material, e.g. brass")
    try:
        return tuple(dict.fromkeys(material(item).name for item in items))
    except SimulationInputError as exc:
        raise StudyError(f"{option}: {exc}") from None


def protocol_of(table: Mapping[str, Any], where: str) -> dict[str, Any]:
    """The stepped-sine settings of a design study's [excitation] table (eta = {start, stop, n}, wait, hold, sequence,
    start, repetition, integrator), checked by building the protocol."""
    from sim.common.errors import SimulationInputError
    from sim.stepped_sine.protocol import SteppedSine

    settings = {k: v for k, v in table.items() if k != "eta"}
    eta = table.get("eta", {})
    if not isinstance(eta, Mapping) or set(eta) - {"start", "stop", "n"}:
        raise StudyError(f"{where} eta must be a table {{ start = ..., stop = ..., n = ... }}")
    settings.update({{"start": "eta_start", "stop": "eta_stop", "n": "n_eta"}[k]: v for k, v in eta.items()})
    try:
        SteppedSine(**{**PROTOCOL, **settings})
    except (TypeError, SimulationInputError) as exc:
        raise StudyError(f"{where}: {exc}") from None
    return settings


#: setting (the option `--NAME` with - for _, the key of a design study's [design] table) -> default
DESIGN_SETTINGS: dict[str, Any] = {
    "excitation": None, "clearance": "0.3mm:1.2mm:10", "radius": "7.92mm", "material": "brass", "model": None,
    "objective": "mean", "damping": None, "clearance_tolerance": None, "k_H_factor": None, "calibration": None,
    "candidates": 5, "reps": 3, "restitution": None, "baseline": None, "block_width": None, "min_wall": None,
    "margin": None, "allow_large": False, "wall_material": None, "output": "ies-out/design"}


@dataclass(frozen=True)
class DesignFile:
    """What a design study file (`[study] kind = "design"`) holds: its [design] settings (and [study] output), the
    stepped sine of its [excitation] table over `PROTOCOL`, and its [cluster] table (`uq.engine.cluster`) or None."""

    settings: Mapping[str, Any] = field(default_factory=dict)
    protocol: Mapping[str, Any] = field(default_factory=lambda: dict(PROTOCOL))
    cluster: Any = None


def read_design_file(path: Any) -> DesignFile:
    """Read and check a design study file; one line (StudyError) for an unreadable file, another kind or an unknown
    key."""
    import tomllib

    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise StudyError(f"cannot read design study {path}: {exc}") from None
    if data.get("study", {}).get("kind") != "design":
        raise StudyError(f"{path}: [study] kind must be \"design\" for ies design")
    settings = dict(data.get("design", {}))
    unknown = sorted(set(settings) - set(DESIGN_SETTINGS))
    if unknown:
        raise StudyError(f"{path}: unknown key(s) in [design]: {', '.join(unknown)}; known: {', '.join(DESIGN_SETTINGS)}")
    if "output" in data.get("study", {}):
        settings.setdefault("output", data["study"]["output"])
    cluster = None
    if "cluster" in data:
        from uq.problem.cluster_settings import parse_cluster_table

        cluster = parse_cluster_table(data["cluster"])
    return DesignFile(settings, {**PROTOCOL, **protocol_of(data.get("excitation", {}), f"{path}: [excitation]")},
                      cluster)


def problem_of(settings: Mapping[str, Any], protocol: Mapping[str, Any] = PROTOCOL) -> DesignProblem:
    """The checked `DesignProblem` of a design's settings (`DESIGN_SETTINGS` keys; ranges and lengths as text with
    units) and stepped sine; one line (StudyError) for anything wrong. The host decides what is not given: the interval
    of D_1 (its `damping_box`: its own interval, else Table 2's relative one around its D_1*) and the cavity walls'
    material (its `wall_material`, else steel) that Eq. 8 takes for every sphere's k_H*."""
    from sim.common.errors import SimulationInputError
    from sim.model.materials import material_of
    from sim.model.system import check_damping_interval

    value = {**DESIGN_SETTINGS, **settings}
    if value["excitation"] is None:
        raise StudyError("--excitation is required: the operating base amplitudes, e.g. --excitation 0.66um:6.6um:10")
    problem = DesignProblem(excitation=(), clearances=(), radii=(), modal_file=value["model"], protocol=dict(protocol))
    model = host_model(problem)
    mode = host_mode(model)
    wall = model.wall_material
    if value["wall_material"] is not None:
        try:
            wall = material_of(str(value["wall_material"]), "wall")
        except SimulationInputError as exc:
            raise StudyError(f"--wall-material: {exc}") from None
    materials = material_names(value["material"])
    radii = parse_range(value["radius"], "radius", count=4)
    box, said = model.damping_box()
    fields: dict[str, Any] = dict(
        excitation=parse_range(value["excitation"], "excitation", count=10, omega=mode.omega),
        clearances=parse_range(value["clearance"], "clearance", count=10), radii=radii, materials=materials,
        objective=value["objective"], candidates=int(value["candidates"]), repetitions=int(value["reps"]), wall=wall,
        D=tuple(box), damping_source=said)
    if value["damping"] is not None:
        interval = parse_interval(value["damping"], "--damping", "damping")
        try:
            fields["D"] = check_damping_interval(interval, model.D_star)
        except SimulationInputError as exc:
            raise StudyError(f"--damping {value['damping']}: {exc}") from None
        fields["damping_source"] = "--damping"
    for name, key, quantity in (("clearance_tolerance", "clearance_tolerance", "clearance"),
                                ("k_H_factor", "k_H_factor", None)):
        if value[name] is not None:
            fields[key] = parse_interval(value[name], "--" + name.replace("_", "-"), quantity)
    for name in ("block_width", "min_wall"):
        if value[name] is not None:
            fields[name] = parse_range(value[name], name, count=1)[0]
    if value["calibration"] is not None:
        if value["k_H_factor"] is not None:
            raise StudyError("give --calibration or --k-H-factor, not both: the calibration sets the factor's upper end")
        from uq.problem.space import K_H_STAR, calibrated_k_H

        ratio = calibrated_k_H(value["calibration"]) / K_H_STAR
        if ratio < 1.0:
            raise StudyError(f"--calibration: k_H / k_H* = {ratio:.3f} < 1; a crater should stiffen the contact")
        fields["k_H_factor"] = (1.0, ratio)
    if value["restitution"] is not None:
        fields["restitution"] = float(value["restitution"])
    if value["margin"] is not None:
        fields["margin"] = _number(value["margin"], "--margin", "a fraction in (0, 1], e.g. 0.2 for 20 %")
    fields["allow_large"] = bool(value["allow_large"])
    if value["baseline"] is not None:
        fields["baseline"] = parse_baseline(value["baseline"], radii, materials, wall)
    problem = dataclasses.replace(problem, **fields)
    problem.check()
    return problem
