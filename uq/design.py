"""Design of an IES for a user's structure under uncertainty (issue 28, `ies design`): which clearance g and which
sphere (radius R, material) keep the resonant tip amplitude lowest over an operating range of base excitation, in
the worst case over the uncertain D_1, clearance tolerance and k_H factor (Table 2's intervals by default).

Method, in two stages:

1. **Screening** by the slow flow (`sim.reduced.slow_flow.screen`): the one-mode slow flow predicts, in
   milliseconds, the resonant tip amplitude (m) and the regime of every (g, m_a, a_base) on the grid. Its inputs are
   the host's resonant mode and the modal restitution r (Eq. D.1; default the simulator's value for the seed rig,
   0.86). With rigid walls the slow flow depends on g and a_base only through a_base/g, which is the similarity law
   of Eqs. 2-7 (g -> s g, a_base -> s a_base, k_H -> s^-1/2 k_H; `tests/sim/test_similarity.py`): k_H does not enter
   the screening. The worst case of a screened design is taken over the two ends of the D interval and of the
   clearance tolerance (the response is assumed monotone in each, as the paper does for Fig. 8).
2. **Verification** of the best screened designs that fit the cavity, their clearance neighbours on the grid and
   the user's baseline, by full stepped-sine simulation through the study runner (cached, resumable, joblib or
   Dask): at every operating level, every corner of the uncertainty box (D, g + tolerance, k_H factor: 8 corners)
   and the nominal point as the monotonicity check, each with the study's repetitions. The recommendation is always
   a verified design: the one with the lowest verified worst case.

The objective of a design is the worst case over the operating levels and the uncertainty corners of the resonant
tip amplitude in m (the mean over a period's amplitudes at the resonant frequency, Sect. 5.3; `--objective max`
takes the maximum amplitude instead), averaged over the repetitions.

Geometry: the cavity is 2R + 2g wide; a design whose cavity leaves walls thinner than `min_wall` (the rig's 5.5 mm
each across its 28 mm block) is refused or, on a grid, left out. The host's modes are taken as they are: the change
of the host's mass by a different cavity is neglected (said in the output). Dry friction (mu m_a g_grav) would break
the similarity law; the design runs without it.
"""
from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sim.common.outputs import Column, OutputFile
from uq.errors import StudyError

#: Table 2's intervals as the default uncertainty box: D_1, the clearance's tolerance above its nominal value
#: (0.58 -> 0.612 mm) and the factor on Eq. 8's k_H (282e3 -> 428e3 N/mm^1.5)
D_INTERVAL = (0.00075, 0.00090)
CLEARANCE_TOLERANCE = (0.0, 0.032e-3)
K_H_FACTOR = (1.0, 428.0 / 282.0)
#: the built-in rig's block across the cavity and its walls (Sect. 2: 28 mm, 17 mm cavity in the paper's design)
BLOCK_WIDTH = 28e-3
MIN_WALL = 5.5e-3
#: the modal restitution r (Eq. D.1) the screening uses unless told: the simulator's value at the seed rig's APR
RESTITUTION = 0.86
#: the stepped sine of a verification run: Fig. 6's quick study (26 frequencies, 2 s wait, 3 s hold, up, eta 0.96-1.01)
PROTOCOL = {"eta_start": 0.96, "eta_stop": 1.01, "n_eta": 26, "wait": 2.0, "hold": 3.0, "sequence": "up",
            "start": "base-velocity", "repetition": "run", "integrator": "exact"}
OBJECTIVES = ("mean", "max")
DESIGN_JSON = OutputFile("design.json", "ies design", "The design's settings, host and result.", (
    Column("settings", "", "the design problem (SI units: excitation, clearances, radii in m; D, tolerance and k_H "
                           "factor intervals; objective, candidates, repetitions, restitution, protocol)"),
    Column("host", "", "the host's mode 1 as the slow flow uses it (omega_1 rad/s, D_1, phi_c, phi_tip, participation) "
                       "and the operating levels a_base/a_base*"),
    Column("screening", "", "designs screened, how many fit the cavity, seconds, the restitution r used"),
    Column("verified", "", "every verified design: its variables, worst_m (m), runs, per level low_m, high_m, "
                           "nominal_m (m), apr_fraction, the levels where the monotonicity check failed"),
    Column("recommendation", "", "the best verified design (as in verified), its sentence and "
                                 "reduction_vs_no_absorber (-)"),
    Column("baseline", "", "the baseline's verification and ratio_to_recommendation (-); null without --baseline"),
    Column("no_absorber", "", "the structure without IES: D_1 and tip_m (m) per level"),
    Column("notes", "", "what the design neglects"),
))
DESIGN_KEYS = DESIGN_JSON.names


@dataclass(frozen=True)
class Sphere:
    """One design: clearance g (m), sphere radius (m) and material name (`sim.model.materials`)."""

    clearance: float
    radius: float
    material: str

    @property
    def mass(self) -> float:
        """m_a (kg) from the radius and the material's density."""
        from sim.model.materials import material, sphere_mass

        return sphere_mass(self.radius, material(self.material))

    @property
    def k_H(self) -> float:
        """k_H (N/m^1.5) of Eq. 8 against the host's steel wall."""
        from sim.model.materials import hertz_constant, material

        return hertz_constant(self.radius, material(self.material))

    def cavity(self) -> float:
        """The cavity's width 2R + 2g (m)."""
        return 2.0 * (self.radius + self.clearance)

    def label(self) -> str:
        return f"g {self.clearance * 1e3:.3f} mm, {self.material} R {self.radius * 1e3:.2f} mm"

    def describe(self) -> dict[str, Any]:
        return {"clearance_m": self.clearance, "radius_m": self.radius, "material": self.material,
                "mass_kg": self.mass, "k_H_N_per_m1p5": self.k_H, "cavity_m": self.cavity()}


@dataclass(frozen=True)
class DesignProblem:
    """What `ies design` is asked: the operating base amplitudes a_base (m), the design grid, the uncertainty box, the
    objective, how many screened candidates to verify, the repetitions and the stepped sine of a verification run."""

    excitation: tuple[float, ...]
    clearances: tuple[float, ...]
    radii: tuple[float, ...]
    materials: tuple[str, ...] = ("brass",)
    D: tuple[float, float] = D_INTERVAL
    clearance_tolerance: tuple[float, float] = CLEARANCE_TOLERANCE
    k_H_factor: tuple[float, float] = K_H_FACTOR
    objective: str = "mean"
    candidates: int = 5
    repetitions: int = 3
    restitution: float = RESTITUTION
    block_width: float = BLOCK_WIDTH
    min_wall: float = MIN_WALL
    modal_file: str | None = None
    baseline: Sphere | None = None
    seed: int = 2024
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
        if self.objective not in OBJECTIVES:
            raise StudyError(f"--objective must be one of {', '.join(OBJECTIVES)}, got {self.objective!r}")
        for name, (lo, hi) in (("--damping", self.D), ("--clearance-tolerance", self.clearance_tolerance),
                               ("--k-H-factor", self.k_H_factor)):
            if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
                raise StudyError(f"{name}: give an interval LOW:HIGH with LOW <= HIGH, got {lo:g}:{hi:g}")
        if not 0 < self.D[0] and self.D[1] < 1:
            raise StudyError(f"--damping: D_1 must lie in (0, 1), got {self.D[0]:g}:{self.D[1]:g}")
        if self.k_H_factor[0] <= 0:
            raise StudyError(f"--k-H-factor: the factor on Eq. 8's k_H must be > 0, got {self.k_H_factor[0]:g}")
        if min(self.clearances) + self.clearance_tolerance[0] <= 0:
            raise StudyError("--clearance-tolerance: the lower end makes the smallest clearance <= 0")
        if not 0 < self.restitution <= 1:
            raise StudyError(f"--restitution must lie in (0, 1], got {self.restitution:g}")
        if self.candidates < 1 or self.repetitions < 1:
            raise StudyError("--candidates and --reps must be >= 1")
        if self.baseline is not None and not self.fits(self.baseline):
            raise StudyError(f"--baseline: {self.baseline.label()} needs a {self.baseline.cavity() * 1e3:.2f} mm cavity;"
                             f" {self.room() * 1e3:.2f} mm fit between {self.min_wall * 1e3:g} mm walls")
        if not any(self.fits(s) for s in self.grid()):
            raise StudyError(f"no design fits: the cavity 2R + 2g must stay within {self.room() * 1e3:.2f} mm "
                             f"({self.block_width * 1e3:g} mm block, walls of {self.min_wall * 1e3:g} mm); "
                             f"the smallest design needs {min(s.cavity() for s in self.grid()) * 1e3:.2f} mm: "
                             "give smaller radii or clearances")

    def room(self) -> float:
        """The widest cavity (m) that leaves walls of min_wall."""
        return self.block_width - 2.0 * self.min_wall

    def fits(self, sphere: Sphere) -> bool:
        return sphere.cavity() <= self.room() * (1 + 1e-12)

    def grid(self) -> list[Sphere]:
        """Every design of the grid, material by material, radius by radius, clearance by clearance."""
        return [Sphere(g, R, m) for m in self.materials for R in self.radii for g in self.clearances]


_EXAMPLES = {"--excitation": "0.66um:6.6um:10", "--clearance": "0.3mm:1.2mm:10", "--radius": "5mm:8mm:4"}


# ---- the host ----------------------------------------------------------------------------------------------------

def host_model(problem: DesignProblem) -> Any:
    """The host's modal model (`sim.model.system.ModalModel`): the built-in rig or the problem's modal file."""
    from sim.common.errors import SimulationInputError
    from sim.hosts.modal_file import load_modal_model
    from sim.hosts.rig import seed_rig_model

    try:
        return seed_rig_model() if problem.modal_file is None else load_modal_model(problem.modal_file)
    except SimulationInputError as exc:
        raise StudyError(f"--model: {exc}") from None


def host_mode(model: Any) -> Any:
    """The slow flow's view of the host (`sim.reduced.slow_flow.HostMode`), refused with one line when the host lacks
    what the design needs (a first mode that moves the walls and is excited by the base)."""
    from sim.common.errors import SimulationInputError
    from sim.reduced.slow_flow import host_mode as mode_of

    try:
        return mode_of(model)
    except SimulationInputError as exc:
        raise StudyError(f"the host model cannot be designed for: {exc}") from None


def levels_of(model: Any, a_base: Sequence[float]) -> np.ndarray:
    """Excitation levels a_base / a_base* (-) of base amplitudes (m), a_base* of the paper's nominal D*, g* (Sect. 5.3)."""
    from sim.model.system import a_base_star

    return np.asarray(a_base, dtype=float) / a_base_star(model)


def no_absorber(model: Any, a_base: Sequence[float], D: float) -> np.ndarray:
    """Resonant tip amplitude (m) of the host alone at damping D (Sect. 5's a_noabs* with D* = D)."""
    from sim.model.system import Nominal, a_noabs_star

    return a_noabs_star(model, np.asarray(a_base, dtype=float), Nominal(D1=D))


def first_impacts(mode: Any, clearance: float) -> float:
    """The base amplitude (m) at which the host's linear resonant wall amplitude reaches `clearance` (Eq. 7, mode 1
    at resonance: |phi_c gamma| a_base / (2 D))."""
    return 2.0 * mode.D * clearance / mode.coupling


# ---- stage 1: screening ------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Screened:
    """The screening of the grid: per design (`designs`, grid order) the worst case over the uncertainty ends of the
    predicted resonant tip amplitude (m) at each operating level (`tip`, shape designs x levels), its regime there
    (`regime`), the base amplitude of the predicted switch to the almost periodic response (`switch`, m) and the
    design's worst case over the levels (`worst`, m; inf for designs that do not fit)."""

    designs: list[Sphere]
    tip: np.ndarray
    regime: np.ndarray
    switch: np.ndarray
    worst: np.ndarray
    seconds: float


def screen_designs(problem: DesignProblem, mode: Any) -> Screened:
    """Stage 1: one slow-flow screening per material, damping end and clearance-tolerance end (the clearances and
    levels of a material are one vectorised call)."""
    import time

    from sim.model.materials import material, sphere_mass
    from sim.reduced.slow_flow import screen

    started = time.perf_counter()
    a_base = np.asarray(problem.excitation, dtype=float)
    g = np.asarray(problem.clearances, dtype=float)
    R = np.asarray(problem.radii, dtype=float)
    designs, tips, regimes, switches = [], [], [], []
    for name in problem.materials:
        masses = sphere_mass(R, material(name))
        worst_tip, worst_regime, switch = None, None, None
        for D in sorted(set(problem.D)):
            host = dataclasses.replace(mode, D=float(D))
            for tol in sorted(set(problem.clearance_tolerance)):
                s = screen(host, g + tol, masses, a_base, problem.restitution)
                if worst_tip is None:
                    worst_tip, worst_regime, switch = s.tip.copy(), s.regime.copy(), s.switch_a_base.copy()
                else:
                    higher = s.tip > worst_tip
                    worst_tip[higher], worst_regime[higher] = s.tip[higher], s.regime[higher]
                    switch = np.maximum(switch, s.switch_a_base)
        # (clearance, radius, level) -> designs in grid order (radius outer, clearance inner)
        tips.append(worst_tip.transpose(1, 0, 2).reshape(-1, a_base.size))
        regimes.append(worst_regime.transpose(1, 0, 2).reshape(-1, a_base.size))
        switches.append(switch.T.reshape(-1))
        designs += [Sphere(float(gi), float(Ri), name) for Ri in R for gi in g]
    b = problem.baseline
    if b is not None and b not in designs:  # the baseline off the grid: screened too, as one more design
        one = dataclasses.replace(problem, clearances=(b.clearance,), radii=(b.radius,), materials=(b.material,),
                                  baseline=None)
        extra = screen_designs(one, mode)
        designs.append(b)
        tips.append(extra.tip)
        regimes.append(extra.regime)
        switches.append(extra.switch)
    tip, regime, switch = np.vstack(tips), np.vstack(regimes), np.concatenate(switches)
    worst = np.where([problem.fits(d) for d in designs], tip.max(axis=1), np.inf)
    return Screened(designs, tip, regime, switch, worst, time.perf_counter() - started)


def candidates(problem: DesignProblem, screened: Screened) -> list[Sphere]:
    """The designs to verify: the `problem.candidates` best screened designs that fit, the clearance neighbours of the
    best of them on the grid (same sphere), and the baseline, each once, best first."""
    order = [i for i in np.argsort(screened.worst, kind="stable") if np.isfinite(screened.worst[i])]
    chosen = [screened.designs[i] for i in order[: problem.candidates]]
    g = list(problem.clearances)
    if chosen and chosen[0].clearance in g:
        best = chosen[0]
        k = g.index(best.clearance)
        for j in (k - 1, k + 1):
            if 0 <= j < len(g):
                neighbour = Sphere(g[j], best.radius, best.material)
                if problem.fits(neighbour) and neighbour not in chosen:
                    chosen.append(neighbour)
    if problem.baseline is not None and problem.baseline not in chosen:
        chosen.append(problem.baseline)
    return chosen


# ---- stage 2: verification ---------------------------------------------------------------------------------------

def corners(problem: DesignProblem, sphere: Sphere) -> list[dict[str, float]]:
    """The uncertainty box of one design as task parameters (D, g, k_H, m_a in SI): its 8 corners, then the nominal
    point (D's midpoint, the clearance and k_H of the design) for the monotonicity check."""
    points = [{"D": D, "g": sphere.clearance + tol, "k_H": f * sphere.k_H, "m_a": sphere.mass}
              for D in problem.D for tol in problem.clearance_tolerance for f in problem.k_H_factor]
    nominal = {"D": 0.5 * sum(problem.D), "g": sphere.clearance + 0.5 * sum(problem.clearance_tolerance),
               "k_H": 0.5 * sum(problem.k_H_factor) * sphere.k_H, "m_a": sphere.mass}
    unique = {tuple(sorted(p.items())): p for p in points}
    return [*unique.values(), nominal]


@dataclass(frozen=True)
class Verified:
    """One verified design: per operating level the band (m) of the resonant tip amplitude over the corners (low,
    high; averaged over the repetitions), the nominal point's value, the fraction of runs in the almost periodic
    regime, whether the nominal point left the corners' band beyond the repetition noise (monotonicity check), and
    the worst case over the levels (m)."""

    sphere: Sphere
    low: np.ndarray
    high: np.ndarray
    nominal: np.ndarray
    apr: np.ndarray
    outside: np.ndarray
    runs: int

    @property
    def worst(self) -> float:
        """The worst case (m): the corners' and the nominal point's highest value over the levels."""
        return float(np.max(np.maximum(self.high, self.nominal)))


def verification_model(problem: DesignProblem) -> Any:
    """The study model that simulates one run of a design (`uq.models.IESModel`; the sphere mass m_a per task)."""
    from uq.models import IESModel

    return IESModel(protocol=dict(problem.protocol), modal_file=problem.modal_file)


def verify(problem: DesignProblem, spheres: Sequence[Sphere], model: Any, folder: Any, *, jobs: int | None,
           scheduler: str | None, progress: bool, client: Any = None) -> list[Verified]:
    """Stage 2: every corner and nominal point of every design at every level and repetition, through the study
    runner (`uq.runner.run_tasks`: cached in `folder`/tasks, resumable)."""
    from uq.runner import ResultStore, Task, run_tasks

    rig = model.rig
    levels = levels_of(rig, problem.excitation)
    amplitude = "mean" if problem.objective == "mean" else "max"
    boxes = {s: corners(problem, s) for s in spheres}
    tasks = [Task.make(p, L, rep) for s in spheres for p in boxes[s] for L in levels
             for rep in range(problem.repetitions)]
    results, _ = run_tasks(model, tasks, problem.seed, ResultStore(folder), jobs=jobs, scheduler=scheduler,
                           progress=progress, client=client)
    from sim.model.system import a_noabs_star

    out = []
    for s in spheres:
        value = np.empty((len(boxes[s]), levels.size))
        se = np.zeros_like(value)
        apr = np.zeros(levels.size)
        for i, p in enumerate(boxes[s]):
            for k, (L, a_base) in enumerate(zip(levels, problem.excitation)):
                runs = [results[Task.make(p, L, rep)] for rep in range(problem.repetitions)]
                scale = a_noabs_star(rig, a_base)  # the run's amplitudes are normalised by a_noabs* (Sect. 5)
                metres = np.array([r["outputs"].get(amplitude, math.nan) if not r.get("error") else math.nan
                                   for r in runs]) * scale
                value[i, k] = metres.mean()
                se[i, k] = metres.std(ddof=1) / math.sqrt(len(runs)) if len(runs) > 1 else 0.0
                apr[k] += sum(r["outputs"].get("apr", 0.0) for r in runs if not r.get("error"))
        low, high = value[:-1].min(axis=0), value[:-1].max(axis=0)
        nominal = value[-1]
        outside = (nominal > high + 2.0 * se[-1]) | (nominal < low - 2.0 * se[-1])
        out.append(Verified(s, low, high, nominal, apr / (len(boxes[s]) * problem.repetitions), outside,
                            len(boxes[s]) * levels.size * problem.repetitions))
    return out


# ---- the whole design --------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class DesignResult:
    """A finished design: the problem, the screening, the verified designs (best first), the recommendation (the best
    verified design), the baseline's verification (if asked), and the folder of its files."""

    problem: DesignProblem
    screened: Screened
    verified: list[Verified]
    folder: Any
    levels: np.ndarray
    no_absorber: np.ndarray
    files: list[Any]

    @property
    def recommendation(self) -> Verified:
        return self.verified[0]

    @property
    def baseline(self) -> Verified | None:
        return next((v for v in self.verified if v.sphere == self.problem.baseline), None)

    def sentence(self) -> str:
        """The recommendation in words and units."""
        best, p = self.recommendation, self.problem
        s = best.sphere
        lo, hi = min(p.excitation), max(p.excitation)
        ratio = float(np.max(self.no_absorber)) / best.worst
        return (f"clearance {s.clearance * 1e3:.2f} mm, {s.material} sphere of radius {s.radius * 1e3:.2f} mm "
                f"({s.mass * 1e3:.1f} g): worst case {best.worst * 1e3:.3g} mm over {_um(lo)}-{_um(hi)} um, "
                f"{ratio:.1f}x below the structure without IES ({float(np.max(self.no_absorber)) * 1e3:.3g} mm)")


def _um(a: float) -> str:
    return f"{a * 1e6:.3g}"


def run_design(problem: DesignProblem, out: Any, *, jobs: int | None = 1, scheduler: str | None = None,
               resume: bool = False, progress: bool = True, figures: bool = True, client: Any = None) -> DesignResult:
    """Screen, verify and write a design into the folder `out` (design.csv, design.json, design-levels.csv, the
    figures): checks everything before any simulation; `resume` continues an interrupted design."""
    from pathlib import Path

    from uq.runner import dask_client, prepare_output

    problem.check()
    model = verification_model(problem)
    mode = host_mode(host_model(problem))
    g_min = min(problem.clearances) + problem.clearance_tolerance[0]
    start = first_impacts(dataclasses.replace(mode, D=min(problem.D)), g_min)
    if max(problem.excitation) < start:
        raise StudyError(f"--excitation: the structure never reaches the clearance over {_um(min(problem.excitation))}-"
                         f"{_um(max(problem.excitation))} um (no impacts, the IES does nothing); impacts begin at "
                         f"a_base = {_um(start)} um for g = {g_min * 1e3:.3g} mm: raise the excitation or lower the "
                         "clearance")
    screened = screen_designs(problem, mode)
    spheres = candidates(problem, screened)
    with dask_client(scheduler, client) as connected:
        model = model.with_rig()
        folder = prepare_output(Path(out), resume=resume, study=("design", design_key(problem, model)))
        model.warm_up()
        verified = verify(problem, spheres, model, folder, jobs=jobs, scheduler=None, progress=progress,
                          client=connected)
    verified.sort(key=lambda v: v.worst)
    rig = model.rig
    result = DesignResult(problem, screened, verified, folder, levels_of(rig, problem.excitation),
                          no_absorber(rig, problem.excitation, min(problem.D)), [])
    result.files.extend(write_design(result, mode))
    if figures:
        from uq.design_figures import plot_design_curves, plot_design_map

        for suffix in ("png", "pdf"):
            result.files.append(plot_design_map(result, folder / f"design-map.{suffix}"))
            result.files.append(plot_design_curves(result, folder / f"design-curves.{suffix}"))
    return result


def design_key(problem: DesignProblem, model: Any) -> str:
    """SHA-256 of the problem and the model's settings: `--resume` continues only the same design."""
    import hashlib
    import json

    from uq.runner import describe_model

    text = json.dumps({"problem": dataclasses.asdict(problem), "model": describe_model(model)}, sort_keys=True,
                      default=str)
    return hashlib.sha256(text.encode()).hexdigest()


DESIGN_CSV = OutputFile("design.csv", "ies design", "One row per evaluated design (verified first, best first; then the "
                        "screened ones).", (
    Column("status", "-", "verified, baseline (verified) or screened"),
    Column("material", "-", "sphere material (sim.model.materials)"),
    Column("clearance_m", "m", "clearance g"),
    Column("radius_m", "m", "sphere radius R"),
    Column("mass_kg", "kg", "sphere mass m_a from R and the density"),
    Column("k_H_N_per_m1p5", "N/m^1.5", "Eq. 8's k_H against the host's steel wall"),
    Column("cavity_m", "m", "cavity width 2R + 2g"),
    Column("fits", "-", "1 if the cavity leaves walls of the minimum thickness"),
    Column("predicted_worst_m", "m", "slow-flow worst case over levels and the D, tolerance ends"),
    Column("predicted_switch_m", "m", "slow-flow base amplitude of the switch to the almost periodic response"),
    Column("worst_m", "m", "verified worst case over levels, uncertainty corners and the nominal point (empty if screened)"),
    Column("worst_level_m", "m", "base amplitude a_base where the verified worst case occurs"),
    Column("regimes", "-", ("per operating level: A (almost periodic in most runs), S (strongly modulated), L (no impacts "
                      "predicted); verified designs from the runs, screened ones from the slow flow")),
))
DESIGN_LEVELS_CSV = OutputFile("design-levels.csv", "ies design", "One row per verified design and operating level.", (
    Column("material", "-", "sphere material"),
    Column("clearance_m", "m", "clearance g"),
    Column("radius_m", "m", "sphere radius R"),
    Column("a_base_m", "m", "operating base amplitude"),
    Column("level", "-", "a_base / a_base* (a_base* of the paper's nominal D*, g*)"),
    Column("low_m", "m", "lowest resonant tip amplitude over the uncertainty corners (mean of the repetitions)"),
    Column("high_m", "m", "highest resonant tip amplitude over the uncertainty corners"),
    Column("nominal_m", "m", "resonant tip amplitude at the box's centre"),
    Column("outside", "-", "1 if the centre left the corners' band beyond 2 standard errors (monotonicity check failed)"),
    Column("apr_fraction", "-", "fraction of runs in the almost periodic regime"),
    Column("predicted_m", "m", "slow-flow prediction (worst over the D and tolerance ends)"),
    Column("no_absorber_m", "m", "the structure without IES at the lower end of D"),
))


def _regime_letters(values: Sequence[Any]) -> str:
    return "".join({"APR": "A", "SMR": "S", "linear": "L"}.get(str(v), "?") for v in values)


def write_design(result: DesignResult, mode: Any) -> list[Any]:
    """design.csv, design-levels.csv and design.json (all written atomically)."""
    from sim.common.files import dumps, write_csv, write_text

    p, s = result.problem, result.screened
    verified = {v.sphere: v for v in result.verified}
    index = {d: i for i, d in enumerate(s.designs)}
    rows = []
    for d in [*(v.sphere for v in result.verified), *(d for d in s.designs if d not in verified)]:
        v, i = verified.get(d), index.get(d)
        status = ("baseline" if d == p.baseline else "verified") if v else "screened"
        regimes = (_regime_letters("APR" if f > 0.5 else "SMR" for f in v.apr) if v
                   else _regime_letters(s.regime[i]))
        worst_at = p.excitation[int(np.argmax(np.maximum(v.high, v.nominal)))] if v else None
        rows.append([status, d.material, d.clearance, d.radius, d.mass, d.k_H, d.cavity(), int(p.fits(d)),
                     s.worst[i] if i is not None and np.isfinite(s.worst[i]) else None,
                     s.switch[i] if i is not None else None, v.worst if v else None, worst_at, regimes])
    level_rows = []
    for v in result.verified:
        i = index.get(v.sphere)
        for k, a_base in enumerate(p.excitation):
            level_rows.append([v.sphere.material, v.sphere.clearance, v.sphere.radius, a_base, result.levels[k],
                               v.low[k], v.high[k], v.nominal[k], int(v.outside[k]), v.apr[k],
                               s.tip[i, k] if i is not None else None, result.no_absorber[k]])
    folder = result.folder
    files = [write_csv(folder / "design.csv", DESIGN_CSV.names, rows),
             write_csv(folder / "design-levels.csv", DESIGN_LEVELS_CSV.names, level_rows)]

    def verified_data(v: Verified) -> dict[str, Any]:
        return {**v.sphere.describe(), "worst_m": v.worst, "runs": v.runs, "low_m": v.low, "high_m": v.high,
                "nominal_m": v.nominal, "apr_fraction": v.apr, "monotonicity_failed_at_m":
                [a for a, o in zip(p.excitation, v.outside) if o]}

    best = result.recommendation
    data = {
        "settings": {**{k: v for k, v in dataclasses.asdict(p).items() if k != "baseline"},
                     "baseline": p.baseline and dataclasses.asdict(p.baseline)},
        "host": {"source": p.modal_file or "built-in rig", "omega_1_rad_per_s": mode.omega, "D_1": mode.D,
                 "phi_c": mode.phi_c, "phi_tip": mode.phi_tip, "participation": mode.participation,
                 "levels": result.levels},
        "screening": {"designs": len(s.designs), "fitting": int(np.isfinite(s.worst).sum()), "seconds": s.seconds,
                      "restitution": p.restitution},
        "verified": [verified_data(v) for v in result.verified],
        "recommendation": {**verified_data(best), "sentence": result.sentence(),
                           "reduction_vs_no_absorber": float(np.max(result.no_absorber)) / best.worst},
        "baseline": (None if result.baseline is None else
                     {**verified_data(result.baseline), "ratio_to_recommendation": result.baseline.worst / best.worst}),
        "no_absorber": {"D_1": min(p.D), "tip_m": result.no_absorber},
        "notes": ["the host's modes are taken as they are: the change of the host's mass by the cavity is neglected",
                  "k_H from Eq. 8 (sphere on the host's flat steel wall), scaled by the k_H factor interval",
                  "dry friction is not modelled in the design (it would break the similarity law)"],
    }
    files.append(write_text(folder / "design.json", dumps(data) + "\n"))
    files.append(write_design_netcdf(result, data))
    return files


def write_design_netcdf(result: DesignResult, data: Mapping[str, Any]) -> Any:
    """results.nc of a design (`uq.netcdf` conventions): the verified designs x operating levels (band, centre, APR
    fraction, slow-flow prediction) and every screened design's variables and predicted worst case, with units."""
    from pathlib import Path

    import xarray as xr

    from sim.common.files import atomic_path, dumps
    from uq.netcdf import ENGINE

    p, s = result.problem, result.screened
    v = result.verified
    index = {d: i for i, d in enumerate(s.designs)}
    nan_row = np.full(len(p.excitation), np.nan)

    def design_coords(spheres: Sequence[Sphere], dim: str) -> dict[str, Any]:
        return {f"{dim}_clearance": (dim, [x.clearance for x in spheres], {"units": "m", "long_name": "clearance g"}),
                f"{dim}_radius": (dim, [x.radius for x in spheres], {"units": "m", "long_name": "sphere radius R"}),
                f"{dim}_material": (dim, [x.material for x in spheres], {"long_name": "sphere material"}),
                f"{dim}_mass": (dim, [x.mass for x in spheres], {"units": "kg", "long_name": "sphere mass m_a"})}

    metres = {"units": "m"}
    ds = xr.Dataset(
        {"low": (("design", "level"), [x.low for x in v], {**metres, "long_name": "lowest resonant tip amplitude "
                                                                                "over the uncertainty corners"}),
         "high": (("design", "level"), [x.high for x in v], {**metres, "long_name": "highest resonant tip amplitude "
                                                                                  "over the uncertainty corners"}),
         "nominal": (("design", "level"), [x.nominal for x in v], {**metres, "long_name": "resonant tip amplitude at "
                                                                                        "the box's centre"}),
         "apr_fraction": (("design", "level"), [x.apr for x in v], {"units": "1", "long_name": "fraction of runs in "
                                                                                              "the APR regime"}),
         "predicted": (("design", "level"), [s.tip[index[x.sphere]] if x.sphere in index else nan_row for x in v],
                       {**metres, "long_name": "slow-flow resonant tip amplitude (worst over the D, tolerance ends)"}),
         "worst": ("design", [x.worst for x in v], {**metres, "long_name": "verified worst case"}),
         "no_absorber": ("level", result.no_absorber, {**metres, "long_name": "resonant tip amplitude without IES"}),
         "screened_worst": ("screened", np.where(np.isfinite(s.worst), s.worst, np.nan),
                            {**metres, "long_name": "slow-flow worst case (NaN: the cavity does not fit)"})},
        coords={"level": ("level", result.levels, {"units": "1", "long_name": "excitation level a_base/a_base*"}),
                "a_base": ("level", np.asarray(p.excitation), {**metres, "long_name": "operating base amplitude"}),
                **design_coords([x.sphere for x in v], "design"), **design_coords(s.designs, "screened")},
        attrs={"Conventions": "CF-1.10", "title": "ies-workbench design", "kind": "design",
               "recommendation": data["recommendation"]["sentence"], "settings": dumps(data["settings"])})
    path = Path(result.folder) / "results.nc"
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp, engine=ENGINE)
    return path


def design_table(result: DesignResult) -> str:
    """The printed table of the verified designs (best first), ending with the recommendation in words."""
    p = result.problem
    lines = [f"screened {len(result.screened.designs)} designs in {result.screened.seconds:.2f} s "
             f"({int(np.isfinite(result.screened.worst).sum())} fit the cavity); verified {len(result.verified)} by "
             f"{sum(v.runs for v in result.verified)} runs",
             f"{'design':<38} {'predicted':>10} {'worst':>9} {'regimes':>12}",
             f"{'':<38} {'mm':>10} {'mm':>9}"]
    index = {d: i for i, d in enumerate(result.screened.designs)}
    for v in result.verified:
        i = index.get(v.sphere)
        predicted = f"{result.screened.worst[i] * 1e3:.3g}" if i is not None and np.isfinite(result.screened.worst[i]) else "-"
        mark = " (baseline)" if v.sphere == p.baseline else ""
        lines.append(f"{v.sphere.label() + mark:<38} {predicted:>10} {v.worst * 1e3:>9.3g} "
                     f"{_regime_letters('APR' if f > 0.5 else 'SMR' for f in v.apr):>12}")
    failed = [v.sphere.label() for v in result.verified if v.outside.any()]
    if failed:
        lines.append(f"monotonicity check failed (the box's centre left the corners' band) for: {'; '.join(failed)}; "
                     "the worst case includes the centre")
    lines.append(f"no IES: {float(np.max(result.no_absorber)) * 1e3:.3g} mm at {_um(max(p.excitation))} um (D_1 = "
                 f"{min(p.D):g})")
    if result.baseline is not None and result.baseline is not result.recommendation:
        lines.append(f"baseline: {result.baseline.sphere.label()}, worst case {result.baseline.worst * 1e3:.3g} mm; "
                     f"the recommendation's is {result.baseline.worst / result.recommendation.worst:.2f}x lower")
    lines.append("the host's modes are taken as they are (the cavity's change of the host's mass is neglected)")
    lines.append("recommendation: " + result.sentence())
    return "\n".join(lines)


# ---- reading ranges with units -----------------------------------------------------------------------------------

def _quantities() -> dict[str, Any]:
    from sim.common.units import Quantity

    length = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6}
    return {"excitation": Quantity("base amplitude a_base", "m", {**length, "nm": 1e-9}, (1e-10, 1e-2), "2um"),
            "acceleration": Quantity("base acceleration", "m/s2", {"m/s2": 1.0, "m/s^2": 1.0}, (1e-4, 1e4), "1m/s2"),
            "clearance": Quantity("clearance g", "m", length, (1e-6, 1e-2), "0.58mm"),
            "radius": Quantity("sphere radius R", "m", length, (0.5e-3, 0.1), "7.92mm")}


def parse_range(text: str, kind: str, *, count: int, omega: float | None = None) -> tuple[float, ...]:
    """`START:STOP[:COUNT]` or one value, each a number with its unit (`0.2mm:1.2mm`, `2um:8um:7`, `7.92mm`) or, for
    the excitation, base accelerations (`0.5m/s2:2m/s2`, turned into amplitudes a / omega^2 at the resonance omega);
    returns the COUNT (default `count`) equispaced values in SI. One line (StudyError) for a malformed, empty,
    reversed, unitless or implausible range."""
    from sim.common.errors import SimulationInputError
    from sim.common.units import implausible, parse_quantity

    quantities = _quantities()
    option = f"--{kind}"
    parts = [t.strip() for t in str(text).split(":")]
    if len(parts) > 3 or not all(parts[:2]):
        raise StudyError(f"{option} {text!r}: give START:STOP[:COUNT] or one value, with units, e.g. "
                         f"{_EXAMPLES.get(option, '1mm')}")
    n = count if len(parts) < 3 else _count(parts[2], option)
    accelerating = kind == "excitation" and any(u in parts[0] for u in ("m/s2", "m/s^2"))
    quantity = quantities["acceleration" if accelerating else kind]
    values = []
    for part in parts[:2]:
        if not any(ch.isalpha() for ch in part):
            raise StudyError(f"{option} {text!r}: {part!r} has no unit; write it with one, e.g. "
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


def _count(text: str, option: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise StudyError(f"{option}: COUNT {text!r} must be a whole number >= 1") from None
    if n < 1:
        raise StudyError(f"{option}: COUNT must be >= 1 (an empty range), got {n}")
    return n


def parse_interval(text: str, what: str, quantity: str | None = None) -> tuple[float, float]:
    """`LOW:HIGH` (plain numbers, or lengths with units for the clearance tolerance) -> (low, high)."""
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


def parse_baseline(text: str, radii: Sequence[float], materials: Sequence[str]) -> Sphere:
    """`G[,R[,MATERIAL]]` -> a Sphere; R and the material default to the first of the grid's."""
    from sim.common.errors import SimulationInputError
    from sim.model.materials import material

    parts = [t.strip() for t in str(text).split(",")]
    if not 1 <= len(parts) <= 3 or not parts[0]:
        raise StudyError(f"--baseline {text!r}: give G[,R[,MATERIAL]], e.g. 0.58mm,7.92mm,brass")
    g = parse_range(parts[0], "clearance", count=1)[0]
    R = parse_range(parts[1], "radius", count=1)[0] if len(parts) > 1 and parts[1] else radii[0]
    name = parts[2] if len(parts) > 2 else materials[0]
    try:
        material(name)
    except SimulationInputError as exc:
        raise StudyError(f"--baseline: {exc}") from None
    return Sphere(g, R, name.lower())


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


# ---- a design's settings: options of `ies design` or keys of a design study file -------------------------------

#: setting (the option `--NAME` with - for _, the key of a design study's [design] table) -> default
DESIGN_SETTINGS: dict[str, Any] = {
    "excitation": None, "clearance": "0.3mm:1.2mm:10", "radius": "7.92mm", "material": "brass", "model": None,
    "objective": "mean", "damping": None, "clearance_tolerance": None, "k_H_factor": None, "calibration": None,
    "candidates": 5, "reps": 3, "restitution": None, "baseline": None, "block_width": None, "min_wall": None,
    "output": "ies-out/design"}


@dataclass(frozen=True)
class DesignFile:
    """What a design study file (`[study] kind = "design"`) holds: its [design] settings (and [study] output), the
    stepped sine of its [excitation] table over `PROTOCOL`, and its [cluster] table (`uq.cluster`) or None."""

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
        from uq.cluster import parse_cluster_table

        cluster = parse_cluster_table(data["cluster"])
    return DesignFile(settings, {**PROTOCOL, **protocol_of(data.get("excitation", {}), f"{path}: [excitation]")},
                      cluster)


def problem_of(settings: Mapping[str, Any], protocol: Mapping[str, Any] = PROTOCOL) -> DesignProblem:
    """The checked `DesignProblem` of a design's settings (`DESIGN_SETTINGS` keys; ranges and lengths as text with
    units) and stepped sine; one line (StudyError) for anything wrong."""
    value = {**DESIGN_SETTINGS, **settings}
    if value["excitation"] is None:
        raise StudyError("--excitation is required: the operating base amplitudes, e.g. --excitation 0.66um:6.6um:10")
    problem = DesignProblem(excitation=(), clearances=(), radii=(), modal_file=value["model"], protocol=dict(protocol))
    mode = host_mode(host_model(problem))
    materials = tuple(m.strip().lower() for m in str(value["material"]).split(",") if m.strip())
    radii = parse_range(value["radius"], "radius", count=4)
    fields: dict[str, Any] = dict(
        excitation=parse_range(value["excitation"], "excitation", count=10, omega=mode.omega),
        clearances=parse_range(value["clearance"], "clearance", count=10), radii=radii, materials=materials,
        objective=value["objective"], candidates=int(value["candidates"]), repetitions=int(value["reps"]))
    for name, key, quantity in (("damping", "D", None), ("clearance_tolerance", "clearance_tolerance", "clearance"),
                                ("k_H_factor", "k_H_factor", None)):
        if value[name] is not None:
            fields[key] = parse_interval(value[name], "--" + name.replace("_", "-"), quantity)
    for name in ("block_width", "min_wall"):
        if value[name] is not None:
            fields[name] = parse_range(value[name], "radius", count=1)[0]
    if value["calibration"] is not None:
        if value["k_H_factor"] is not None:
            raise StudyError("give --calibration or --k-H-factor, not both: the calibration sets the factor's upper end")
        from uq.space import K_H_STAR, calibrated_k_H

        ratio = calibrated_k_H(value["calibration"]) / K_H_STAR
        if ratio < 1.0:
            raise StudyError(f"--calibration: k_H / k_H* = {ratio:.3f} < 1; a crater should stiffen the contact")
        fields["k_H_factor"] = (1.0, ratio)
    if value["restitution"] is not None:
        fields["restitution"] = float(value["restitution"])
    if value["baseline"] is not None:
        fields["baseline"] = parse_baseline(value["baseline"], radii, materials)
    problem = dataclasses.replace(problem, **fields)
    problem.check()
    return problem
