"""Study files: a TOML description of an uncertainty study, validated with one-line errors.

Layout (every table and key is optional except where noted; SI units)::

    [study]
    name = "fig7"
    kind = "interval"            # "interval", "sobol" or "response" (required)
    model = "ies"                # "ies" (the simulator), "ishigami", or "package.module:function"
    modal_model = "rig.toml"     # optional, model "ies": a modal-model file (`ies modes --save`), relative to
                                 # this file, instead of the built-in rig
    seed = 1                     # random stream of the repetitions (Sect. 5.1: perturbed frequencies)
    repetitions = 5
    output = "results/fig7"      # default output folder (`--out` overrides), relative to the cwd
    outputs = ["mean", "max"]    # model "ies": the outputs the bands / indices are computed for (default
                                 # mean, max; also "restitution", "significant_impacts_per_period", ... of
                                 # sim.stepped_sine.measures.SCATTERING_MEASURES, at the resonant mean's eta)
    contact_law = "hertz"        # model "ies": "hertz" (Eq. 4) or "hertz-damped" (Eq. 10, r_cont,diss from
                                 # [parameters.r_cont], default 0.99; a table there implies "hertz-damped")

    [variant]                    # optional, model "ies": modelling choices the paper leaves open
    sphere_mass_factor = 1.537   # (uq/studies/fidelity/README.md): the sphere's effective mass in x over m_a (rolling: 1.4 on a
    higher_mode_damping = 0.001  # flat floor, 1.537 on the groove's edges); the damping ratio of modes 5..N

    [parameters.D]               # listed parameters are varied; unlisted ones stay nominal.
    nominal = 0.00085            # missing keys default to Table 2 (model "ies")
    min = 0.00075
    max = 0.00090
    [parameters.k_H]             # N/m^1.5, or "1.52 k_H*", or "calibrated:calib.json"
    max = "1.52 k_H*"
    best_estimate = "1.25 k_H*"  # the value k_H is fixed at in the residual band (Fig. 8)
    [parameters.r_cont]          # model "ies", optional: r_cont,diss of Eq. 10 in (0, 1] (fixed: nominal only)
    nominal = 0.99
    [parameters.friction]        # model "ies", optional: mu of dry friction at the floor (Appendix C; ode3 only),
    nominal = 0.07               # with [parameters.k_t] (N/m, or "22kN/mm") the tangential stiffness

    [excitation]                 # passed to the stepped-sine protocol (sim.stepped_sine.protocol.SteppedSine)
    levels = [5.3, 6.7, 7.4]     # a_base / a_base* (Sect. 5.3; nominal D*, g*)
    eta = { start = 0.95, stop = 1.01, n = 25 }   # Omega / omega_1*
    repetition = "leg"           # "leg" or "run": what counts as one repetition sample (sim.stepped_sine.protocol)
    start = "base-velocity"      # initial conditions of each run: "rest" or "base-velocity" (sim.stepped_sine.protocol)
    perturbation = 5e-4          # half-width of the random relative frequency offset of each run (sim.stepped_sine.protocol)
    perturb = "start"            # what it perturbs: "start" (each run's first wait) or "each-point"
    wait = 3.0                   # s
    hold = 5.0                   # s
    sequence = "up-down-up"
    integrator = "exact"

    [interval]
    designs = ["individual", "joint", "residual"]
    interior = 1                 # interior points per axis (individual) / in the box (joint, residual)
    z = 2.0                      # noise multiple below which a monotonicity violation is not flagged
    fix = { k_H = "best_estimate" }   # parameters held fixed in the residual band

    [sobol]
    method = "saltelli"          # "saltelli" (SALib's sampling, the reference) or "pce" (a polynomial-chaos
                                 # surrogate, uq.methods.surrogate: far fewer runs for a smooth response)
    n = 64                       # saltelli: base sample size (power of two); n (k + 2) points
    bootstrap = 200
    confidence = 0.95
    points = 32                  # pce: design points (scrambled Sobol'; default 3 per term, to a power of 2)
    degree = 2                   # pce: total degree of the polynomials (points >= C(k + degree, degree))
    max_misfit = 0.1             # pce: cross-validated error beyond the noise (share of the variance) above
                                 # which the response is flagged not smooth

    [response]                   # kind "response": the frequency responses and resonant levels of the nominal
    figures = ["fig5", "fig6"]   # point (the parameters' nominal values) at every level, as Figs. 5 and 6, and
                                 # "figD2", "figD3": impacts per period and r at the resonant eta (Appendix D),
                                 # "fig11", "figC1": the resonant mean of each value of `series` (Sect. 5.5,
                                 # Appendix C)
    series = { r_cont = [1.0, 0.99, 0.9] }   # optional: the whole study once per value of one listed
                                 # parameter (a response study each, in OUT/NAME=VALUE), as Fig. 11

    [cluster]                    # optional: run on a batch cluster (uq.engine.cluster; the --cluster-* options win)
    kind = "slurm"               # slurm (tested), pbs, sge, lsf, oar, moab, htcondor
    cores = 4                    # per job (a worker process each); memory = "8GB", walltime = "02:00:00",
    max_jobs = 10                # queue = "short", account = "proj1", directives = ["--qos=short"],
                                 # worker_timeout = 600 (s); unset values come from Dask's jobqueue.yaml

Unknown tables or keys, unknown parameters, min > max, non-positive bounds and the like are refused with
a `StudyError` whose one line names the file, the key and the fix.
"""
from __future__ import annotations

import math
import sys
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from sim.model.parameters import PARAMETERS
from uq.engine.cluster import ClusterSettings, parse_cluster_table
from uq.errors import StudyError
from uq.problem.models import ResponseModel, make_model
from uq.problem.space import Parameter, ParameterSpace, plausibility_warning, resolve_k_H, resolve_value

KINDS = ("interval", "sobol", "response")
DESIGNS = ("individual", "joint", "residual")
_KEYS = {
    "study": {"name", "kind", "model", "modal_model", "seed", "repetitions", "output", "outputs", "contact_law"},
    "variant": {"sphere_mass_factor", "higher_mode_damping"},
    "parameters": None,  # one sub-table per parameter
    "excitation": {"levels", "eta", "wait", "hold", "sequence", "integrator", "perturbation", "perturb", "repetition",
                   "start", "dt_scale"},
    "interval": {"designs", "interior", "z", "fix"},
    "sobol": {"n", "bootstrap", "confidence", "method", "points", "degree", "max_misfit"},
    "response": {"figures", "series"},
    "cluster": None,  # checked by uq.engine.cluster.parse_cluster_table
}
_PARAM_KEYS = {"nominal", "min", "max", "best_estimate"}


def _response_figure_names() -> tuple[str, ...]:
    """The figures a response study may draw: the response rows of `uq.outputs.paper_figures.PAPER_FIGURES` (imported here:
    it brings the figure code)."""
    from uq.outputs.paper_figures import response_figure_names

    return response_figure_names()


@dataclass(frozen=True, kw_only=True)
class Study:
    """A resolved, validated study (see the module docstring for the file layout); built with named fields."""

    name: str
    kind: str
    model: str
    space: ParameterSpace
    levels: tuple[float, ...]
    repetitions: int
    seed: int
    output: Path
    protocol: Mapping[str, Any] = field(default_factory=dict)
    designs: tuple[str, ...] = ("individual",)
    interior: int = 1
    z: float = 2.0
    fix: Mapping[str, float] = field(default_factory=dict)
    sobol_n: int = 64
    bootstrap: int = 200
    confidence: float = 0.95
    source: str = ""
    modal_model: Path | None = None
    figures: tuple[str, ...] = field(default_factory=lambda: _response_figure_names())
    variant: Mapping[str, float] = field(default_factory=dict)
    outputs: tuple[str, ...] = ()
    contact_law: str = "hertz"
    series: tuple[str, tuple[float, ...]] | None = None
    sobol_method: str = "saltelli"
    surrogate_points: int = 0
    surrogate_degree: int = 2
    max_misfit: float = 0.1
    #: where the study runs ([cluster], uq.engine.cluster); not part of its results, so left out of to_dict and the key
    cluster: ClusterSettings | None = None

    def make_model(self) -> ResponseModel:
        """The study's response model (`uq.problem.models.make_model`)."""
        return make_model(self.model, protocol=self.protocol, parameters=tuple(self.space.names),
                          modal_model=self.modal_model, variant=self.variant, outputs=self.outputs,
                          contact_law=self.contact_law)

    def to_dict(self) -> dict:
        """The resolved study as plain data (written to the results' metadata)."""
        return {
            "name": self.name, "kind": self.kind, "model": self.model,
            "modal_model": None if self.modal_model is None else str(self.modal_model), "seed": self.seed,
            "repetitions": self.repetitions, "output": str(self.output), "source": self.source,
            "levels": list(self.levels), "protocol": dict(self.protocol), "parameters": self.space.to_dict(),
            "interval": {"designs": list(self.designs), "interior": self.interior, "z": self.z, "fix": dict(self.fix)},
            "sobol": {"n": self.sobol_n, "bootstrap": self.bootstrap, "confidence": self.confidence,
                      **({"method": "pce", "points": self.surrogate_points, "degree": self.surrogate_degree,
                          "max_misfit": self.max_misfit} if self.sobol_method == "pce" else {})},
            "response": {"figures": list(self.figures)}, "variant": dict(self.variant),
            "outputs": list(self.outputs), "contact_law": self.contact_law,
            **({"series": {self.series[0]: list(self.series[1])}} if self.series else {}),
        }

    def series_studies(self) -> list[tuple[str, "Study"]]:
        """[(folder name NAME=VALUE, the study with that parameter fixed at VALUE)] of [response] series; [] without."""
        if not self.series:
            return []
        from dataclasses import replace

        name, values = self.series
        out = []
        for value in values:
            params = tuple(p.fixed_at(value) if p.name == name else p for p in self.space.parameters)
            space = ParameterSpace(params, self.space.extras)
            out.append((f"{name}={value:g}", replace(self, space=space, series=None, name=f"{self.name} {name}={value:g}")))
        return out


def with_calibration(study: Study, k_H_cal: float) -> Study:
    """The study with k_H's upper bound at a calibrated k_H (N/m^1.5; `ies calibrate`), as the paper does with its BEM
    result 1.52 k_H* (Sect. 4.1): the best estimate stays (1.25 k_H* by default) unless the calibration falls below
    it, then it is the midpoint of k_H's lower bound and the calibrated value. A calibrated k_H below k_H* (Eq. 8)
    is refused with one line: a crater stiffens the contact."""
    from dataclasses import replace

    from uq.problem.space import K_H_BEST_ESTIMATE, K_H_STAR

    if k_H_cal < K_H_STAR:
        raise StudyError(f"the calibrated k_H = {k_H_cal:.4g} N/m^1.5 is below k_H* = {K_H_STAR:.4g}; a crater should "
                         "stiffen the contact: check the calibration or use --no-calibration")
    space = study.space
    k = space["k_H"]
    best = space.extras.get("k_H_best_estimate", K_H_BEST_ESTIMATE)
    if best > k_H_cal:
        best = 0.5 * (k.min + k_H_cal)
    params = tuple(replace(p, max=max(k_H_cal, p.min)) if p.name == "k_H" else p for p in space.parameters)
    new_space = ParameterSpace(params, {**space.extras, "k_H_best_estimate": best, "k_H_calibrated": k_H_cal})
    fix = {**study.fix, "k_H": best} if "k_H" in study.fix else dict(study.fix)
    return replace(study, space=new_space, fix=fix)


def load_study(path: str | Path) -> Study:
    """Read and validate a study file; errors are one-line `StudyError`s naming the file."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise StudyError(f"study file {path} not found")
    except IsADirectoryError:
        raise StudyError(f"{path} is a folder; give a study .toml file")
    except tomllib.TOMLDecodeError as exc:
        raise StudyError(f"{path} is not valid TOML: {exc}")
    except UnicodeDecodeError:
        raise StudyError(f"{path} is not a text (TOML) file")
    try:
        return parse_study(data, base_dir=path.parent, source=str(path))
    except StudyError as exc:
        raise StudyError(f"{path}: {exc}") from None


def _number(table: str, key: str, value: Any, *, integer: bool = False, positive: bool = True) -> float:
    ok = isinstance(value, int) if integer else isinstance(value, (int, float))
    if isinstance(value, bool) or not ok or not math.isfinite(value):
        kind = "an integer" if integer else "a number"
        raise StudyError(f"[{table}] {key} must be {kind}, got {value!r}")
    if positive and value <= 0:
        raise StudyError(f"[{table}] {key} must be positive, got {value!r}")
    return value


def parse_study(data: Mapping[str, Any], *, base_dir: Path = Path("."), source: str = "") -> Study:
    """Validate the parsed TOML of a study (see `load_study`)."""
    for table in data:
        if table not in _KEYS:
            raise StudyError(f"unknown table [{table}]; known: {', '.join('[' + t + ']' for t in _KEYS)}")
        if not isinstance(data[table], Mapping):
            raise StudyError(f"'{table}' must be a table ([{table}])")
        allowed = _KEYS[table]
        if allowed is not None:
            for key in data[table]:
                if key not in allowed:
                    raise StudyError(f"unknown key '{key}' in [{table}]; known: {', '.join(sorted(allowed))}")
    head = data.get("study", {})
    kind = head.get("kind")
    if kind not in KINDS:
        raise StudyError(f"[study] kind must be one of {', '.join(KINDS)}, got {kind!r}")
    model_spec = head.get("model", "ies")
    if not isinstance(model_spec, str):
        raise StudyError(f"[study] model must be a string, got {model_spec!r}")
    name = str(head.get("name", Path(source).stem if source else kind))
    seed = int(_number("study", "seed", head.get("seed", 0), integer=True, positive=False))
    if seed < 0:
        raise StudyError(f"[study] seed must be >= 0, got {seed}")
    reps = int(_number("study", "repetitions", head.get("repetitions", 1), integer=True))
    output = Path(head.get("output", f"results/{name}"))
    modal_model = head.get("modal_model")
    if modal_model is not None:
        if model_spec != "ies":
            raise StudyError("[study] modal_model only applies to model = \"ies\" (the simulator)")
        if not isinstance(modal_model, str) or not modal_model:
            raise StudyError(f"[study] modal_model must be the path of a modal-model file (`ies modes --save`), got {modal_model!r}")
        modal_model = base_dir / modal_model

    variant = {key: float(_number("variant", key, value)) for key, value in data.get("variant", {}).items()}
    if variant and model_spec != "ies":
        raise StudyError("[variant] only applies to model = \"ies\" (the simulator)")
    if not 0 < variant.get("higher_mode_damping", 0.5) < 1:
        raise StudyError(f"[variant] higher_mode_damping must lie in (0, 1), got {variant['higher_mode_damping']}")

    space = _parse_parameters(data.get("parameters"), model_spec, base_dir, source)

    exc = dict(data.get("excitation", {}))
    levels_raw = exc.pop("levels", [1.0] if model_spec != "ies" else None)
    if levels_raw is None:
        raise StudyError("[excitation] levels is missing: give a_base / a_base* values, e.g. levels = [5.3, 6.7, 7.4]")
    if not isinstance(levels_raw, list) or not levels_raw:
        raise StudyError(f"[excitation] levels must be a non-empty list of numbers, got {levels_raw!r}")
    levels = tuple(float(_number("excitation", "levels", v)) for v in levels_raw)
    if len(set(levels)) != len(levels):
        raise StudyError("[excitation] levels lists a value twice")
    protocol = _parse_protocol(exc)

    iv = data.get("interval", {})
    designs = tuple(iv.get("designs", ["individual"]))
    for d in designs:
        if d not in DESIGNS:
            raise StudyError(f"[interval] unknown design '{d}'; known: {', '.join(DESIGNS)}")
    interior = int(_number("interval", "interior", iv.get("interior", 1), integer=True, positive=False))
    if interior < 0:
        raise StudyError(f"[interval] interior must be >= 0, got {interior}")
    z = float(_number("interval", "z", iv.get("z", 2.0), positive=False))
    fix = _parse_fix(iv.get("fix", {"k_H": "best_estimate"} if "k_H" in space.names else {}), space, base_dir, source)
    if "residual" in designs and not fix:
        raise StudyError("[interval] the residual design needs fixed parameters: fix = { k_H = \"best_estimate\" }")

    sb = data.get("sobol", {})
    sobol_n = int(_number("sobol", "n", sb.get("n", 64), integer=True))
    if sobol_n < 2 or sobol_n & (sobol_n - 1):
        raise StudyError(f"[sobol] n = {sobol_n} must be a power of two >= 2 (e.g. 64)")
    bootstrap = int(_number("sobol", "bootstrap", sb.get("bootstrap", 200), integer=True))
    confidence = float(_number("sobol", "confidence", sb.get("confidence", 0.95)))
    if not 0 < confidence < 1:
        raise StudyError(f"[sobol] confidence must lie in (0, 1), got {confidence}")
    if kind == "sobol" and not space.varied:
        raise StudyError("no parameter is varied; give at least one [parameters.NAME] with min < max")
    method, points, degree, max_misfit = _parse_surrogate(sb, kind, space)
    known = _response_figure_names()
    figures = data.get("response", {}).get("figures", list(known))
    if not isinstance(figures, list) or not figures or any(f not in known for f in figures):
        raise StudyError(f"[response] figures must be a list from {', '.join(known)}, got {figures!r}")
    if kind == "response" and model_spec != "ies":
        raise StudyError("a response study runs the simulator: model = \"ies\"")

    outputs = head.get("outputs", [])
    if not isinstance(outputs, list) or not all(isinstance(o, str) for o in outputs) or len(set(outputs)) != len(outputs):
        raise StudyError(f"[study] outputs must be a list of distinct output names, e.g. [\"mean\", \"restitution\"], got {outputs!r}")
    contact_law = _parse_contact_law(head, space)
    series = _parse_series(data.get("response", {}).get("series"), kind, space)
    cluster = parse_cluster_table(data["cluster"]) if "cluster" in data else None
    study = Study(name=name, kind=kind, model=model_spec, space=space, levels=levels, repetitions=reps, seed=seed,
                  output=output, protocol=protocol, designs=designs, interior=interior, z=z, fix=fix,
                  sobol_n=sobol_n, bootstrap=bootstrap, confidence=confidence, source=source,
                  modal_model=modal_model, figures=tuple(figures), variant=variant, outputs=tuple(outputs),
                  contact_law=contact_law, series=series, sobol_method=method,
                  surrogate_points=points, surrogate_degree=degree, max_misfit=max_misfit,
                  cluster=cluster)
    for _, one in study.series_studies():
        _parse_contact_law({"contact_law": contact_law}, one.space)  # every value in range
    model = study.make_model()  # unknown model -> one line now
    from sim.model.contact_law import DEFAULT_LAW

    if modal_model is not None or variant or contact_law != DEFAULT_LAW:
        model.check()  # an unreadable modal file -> one line now
    if "friction" in space.names:  # every mu of the study: >= 0, and > 0 needs ode3 and the floor values
        k_t = space["k_t"].min if "k_t" in space.names else model.optional_parameter("k_t").nominal
        for mu in (space["friction"].min, space["friction"].max, *(study.series[1] if study.series else ())):
            model.check_physics({"friction": mu, "k_t": k_t})
    return study


def _parse_surrogate(sb: Mapping[str, Any], kind: str, space: ParameterSpace) -> tuple[str, int, int, float]:
    """[sobol] method, points, degree, max_misfit (`uq.methods.surrogate`): (method, design points, degree, allowed misfit)."""
    from uq.methods.surrogate import MAX_MISFIT, METHODS

    method = sb.get("method", "saltelli")
    if method not in METHODS:
        raise StudyError(f"[sobol] method must be one of {', '.join(METHODS)}, got {method!r}")
    own = sorted({"points", "degree", "max_misfit"} & set(sb))
    if method != "pce" and own:
        raise StudyError(f"[sobol] {', '.join(own)} only appl{'ies' if len(own) == 1 else 'y'} to method = \"pce\"")
    degree = int(_number("sobol", "degree", sb.get("degree", 2), integer=True))
    points = int(_number("sobol", "points", sb["points"], integer=True)) if "points" in sb else 0
    max_misfit = float(_number("sobol", "max_misfit", sb.get("max_misfit", MAX_MISFIT)))
    if method == "pce":
        return surrogate_settings(kind, len(space.varied), points, degree) + (max_misfit,)
    return method, points, degree, max_misfit


def surrogate_settings(kind: str, k: int, points: int, degree: int) -> tuple[str, int, int]:
    """("pce", design points, degree) checked for a study of `kind` with `k` varied parameters (`points` 0: the
    default of `uq.methods.surrogate.default_points`); a one-line StudyError for a kind without a surrogate, too few
    points for the degree, or OpenTURNS missing."""
    from uq.methods.surrogate import check_design, default_points, openturns

    if kind != "sobol":
        raise StudyError(f"method \"pce\" (a surrogate of the Sobol' indices) applies to kind = \"sobol\" only; "
                         f"a{'n' if kind[0] in 'aeiou' else ''} {kind} study has no surrogate")
    points = points or default_points(k, degree)
    check_design(k, points, degree)
    openturns()
    return "pce", points, degree


def with_sobol_method(study: Study, method: str | None = None, points: int | None = None,
                      degree: int | None = None) -> Study:
    """The study with the command line's `--method`, `--points`, `--degree` (None: the study file's), checked as
    the study file's keys are (one-line StudyError)."""
    from dataclasses import replace

    from uq.methods.surrogate import METHODS

    method = method or study.sobol_method
    if method not in METHODS:
        raise StudyError(f"--method must be one of {', '.join(METHODS)}, got {method!r}")
    if method != "pce":
        if points is not None or degree is not None:
            raise StudyError("--points and --degree apply to --method pce only")
        return replace(study, sobol_method=method)
    keep = study.sobol_method == "pce"
    points = points if points is not None else (study.surrogate_points if keep else 0)
    degree = degree if degree is not None else study.surrogate_degree
    _, points, degree = surrogate_settings(study.kind, len(study.space.varied), points, degree)
    return replace(study, sobol_method="pce", surrogate_points=points, surrogate_degree=degree)


def _parse_series(table: Any, kind: str, space: ParameterSpace) -> tuple[str, tuple[float, ...]] | None:
    """[response] series = { NAME = [values] }: one listed parameter and its distinct values (kind "response")."""
    if table is None:
        return None
    if kind != "response":
        raise StudyError("[response] series only applies to kind = \"response\"")
    if not isinstance(table, Mapping) or len(table) != 1:
        raise StudyError(f"[response] series must name one parameter and its values, e.g. series = {{ r_cont = [1.0, 0.99] }}, "
                         f"got {table!r}")
    (name, values), = table.items()
    if name not in space.names:
        raise StudyError(f"[response] series: '{name}' is not a parameter of the study; list it as [parameters.{name}]")
    if not isinstance(values, list) or not values or len(set(values)) != len(values):
        raise StudyError(f"[response] series: {name} needs a list of distinct values, got {values!r}")
    return name, tuple(float(_number("response", f"series.{name}", v, positive=False)) for v in values)


def _parse_contact_law(head: Mapping[str, Any], space: ParameterSpace) -> str:
    """[study] contact_law (a law of `sim.model.contact_law.LAWS`: Eq. 4 "hertz" or Eq. 10 "hertz-damped");
    [parameters.r_cont] implies the damped law, and its values must lie in (0, 1]."""
    from sim.common.errors import SimulationInputError
    from sim.model.contact_law import DEFAULT_DAMPED_LAW, DEFAULT_LAW, LAWS, ContactLaw

    listed = "r_cont" in space.names
    law = head.get("contact_law", DEFAULT_DAMPED_LAW if listed else DEFAULT_LAW)
    if law not in LAWS:
        raise StudyError(f"[study] contact_law must be one of {', '.join(LAWS)}, got {law!r}")
    if listed:
        r = space["r_cont"]
        for value in (r.min, r.nominal, r.max):
            try:
                ContactLaw(law, value)
            except SimulationInputError as exc:
                raise StudyError(f"[parameters.r_cont] {exc}") from None
    return law


def _parse_parameters(table: Mapping[str, Any] | None, model_spec: str, base_dir: Path, source: str) -> ParameterSpace:
    """The parameter space of [parameters.KEY] tables; for the simulator KEY is a row's study key in
    `sim.model.parameters.PARAMETERS` (its name in the space, CSV columns and messages is the row's name)."""
    if table is not None and model_spec == "ies":
        by_key = {row.study_key: name for name, row in PARAMETERS.items()}
        table = {by_key.get(key, key): spec for key, spec in table.items()}
    model = make_model(model_spec, parameters=tuple(table or {}))
    default = model.default_space()
    if default is None:  # a user's function: every parameter must be given in full
        if not table:
            raise StudyError("a 'module:function' model needs its parameters: [parameters.NAME] with nominal, min, max")
        params = []
        for pname, spec in table.items():
            spec = _check_param_table(pname, spec)
            missing = {"nominal", "min", "max"} - set(spec)
            if missing:
                raise StudyError(f"[parameters.{pname}] needs {', '.join(sorted(missing))}")
            params.append(Parameter(pname, *(float(_number(f"parameters.{pname}", k, spec[k], positive=False))
                                             for k in ("nominal", "min", "max")), positive=False))
        return ParameterSpace(tuple(params))
    if table is None:
        return default
    optional = tuple(getattr(model, "optional_parameters", ()))
    for pname in table:
        if pname not in default.names and pname not in optional:
            raise StudyError(f"unknown parameter '{pname}' for model '{model_spec}'; known: "
                             f"{', '.join((*default.names, *optional))}")
    extras = dict(default.extras)
    params = []
    listed_optional = [model.optional_parameter(name) for name in optional if name in table]
    for p in (*default.parameters, *listed_optional):
        if p.name not in table:
            params.append(p.fixed_at(p.nominal))
            continue
        spec = _check_param_table(p.name, table[p.name])
        values = {}
        for key in ("nominal", "min", "max"):
            # an optional parameter's missing bound is its nominal value (a fixed value needs nominal only)
            fallback = spec.get("nominal", p.nominal) if p in listed_optional else getattr(p, key)
            values[key] = resolve_value(p.name, spec.get(key, fallback), base_dir=base_dir)
            _warn_implausible(source, f"[parameters.{p.name}] {key}", p.name, values[key])
        if "best_estimate" in spec:
            if p.name != "k_H":
                raise StudyError(f"[parameters.{p.name}] best_estimate is only defined for k_H")
            extras["k_H_best_estimate"] = resolve_k_H(spec["best_estimate"], base_dir=base_dir)
            if not extras["k_H_best_estimate"] > 0:
                raise StudyError("[parameters.k_H] best_estimate must be positive")
        params.append(Parameter(p.name, values["nominal"], values["min"], values["max"], p.unit, p.label,
                                p.upper_limit, p.positive))
    return ParameterSpace(tuple(params), extras)


def _warn_implausible(source: str, where: str, name: str, value: object) -> None:
    """One warning line on stderr when a value of g or k_H in study file `source` has an implausible magnitude
    (probably a unit slip)."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        warning = plausibility_warning(name, value)
        if warning:
            sys.stderr.write(f"warning: {source + ': ' if source else ''}{where}: {warning}\n")


def _check_param_table(name: str, spec: Any) -> Mapping[str, Any]:
    if not isinstance(spec, Mapping):
        raise StudyError(f"[parameters.{name}] must be a table with nominal, min, max")
    for key in spec:
        if key not in _PARAM_KEYS:
            raise StudyError(f"unknown key '{key}' in [parameters.{name}]; known: {', '.join(sorted(_PARAM_KEYS))}")
    return spec


def _parse_fix(fix: Any, space: ParameterSpace, base_dir: Path, source: str) -> dict[str, float]:
    if not isinstance(fix, Mapping):
        raise StudyError(f"[interval] fix must be a table like {{ k_H = \"best_estimate\" }}, got {fix!r}")
    out = {}
    for pname, raw in fix.items():
        if pname not in space.names:
            raise StudyError(f"[interval] fix: unknown parameter '{pname}'; known: {', '.join(space.names)}")
        if raw == "best_estimate":
            if f"{pname}_best_estimate" not in space.extras:
                raise StudyError(f"[interval] fix: '{pname}' has no best estimate; give a number")
            value = space.extras[f"{pname}_best_estimate"]
        elif pname in PARAMETERS and PARAMETERS[pname].quantity is not None:  # k_H, g, k_t: also with a unit
            value = resolve_value(pname, raw, base_dir=base_dir)
            _warn_implausible(source, f"[interval] fix.{pname}", pname, value)
        else:
            value = float(_number("interval", f"fix.{pname}", raw, positive=space[pname].positive))
        out[pname] = float(value)
    return out


def _parse_protocol(exc: Mapping[str, Any]) -> dict[str, Any]:
    """Protocol settings as given (SteppedSine fills in and validates the rest when the model is built)."""
    out: dict[str, Any] = {}
    for key in ("wait", "hold", "perturbation", "dt_scale"):
        if key in exc:
            out[key] = float(_number("excitation", key, exc[key]))
    for key in ("sequence", "integrator", "repetition", "start", "perturb"):
        if key in exc:
            if not isinstance(exc[key], str):
                raise StudyError(f"[excitation] {key} must be a string, got {exc[key]!r}")
            out[key] = exc[key]
    if "eta" in exc:
        eta = exc["eta"]
        if not isinstance(eta, Mapping) or set(eta) != {"start", "stop", "n"}:
            raise StudyError("[excitation] eta must be a table { start = 0.96, stop = 1.02, n = 31 } (Omega / omega_1)")
        out["eta_start"], out["eta_stop"] = (float(_number("excitation", f"eta.{k}", eta[k])) for k in ("start", "stop"))
        out["n_eta"] = int(_number("excitation", "eta.n", eta["n"], integer=True))
        if out["n_eta"] > 1 and not out["eta_start"] < out["eta_stop"]:
            raise StudyError(f"[excitation] eta: start {out['eta_start']} must be below stop {out['eta_stop']}")
    return out
