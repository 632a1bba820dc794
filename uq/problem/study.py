"""Study files: a TOML description of an uncertainty study, validated with one-line errors.

Layout (every table and key is optional except where noted; SI units)::

    [study]
    name = "fig7"
    kind = "interval"            # a kind of `uq.methods.METHODS`: "interval", "sobol" or "response" (required)
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

    [impactor]                   # optional, model "ies": the sphere (`sim.model.sphere`; default the paper's: R =
    radius = "5 mm"              # 7.92 mm brass, 17.7 g); k_H's nominal value is its k_H* (Eq. 8 with both bodies'
    material = "steel"           # E and nu), "1.25 k_H*" its multiples; mass = "4 g" (hollow or weighed);
    wall_material = "aluminium"  # default: the host's [host] wall_material, else steel

    [variant]                    # optional, model "ies": modelling choices the paper leaves open
    sphere_mass_factor = 1.537   # (uq/studies/fidelity/README.md): the sphere's effective mass in x over m_a (rolling: 1.4 on a
    higher_mode_damping = 0.001  # flat floor, 1.537 on the groove's edges); the damping ratio of modes 5..N

    [parameters.D]               # listed parameters are varied; unlisted ones stay nominal. Missing keys default
    nominal = 0.00085            # to Table 2 (model "ies"), D to the host's D_1* and damping interval
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
    levels = [5.3, 6.7, 7.4]     # a_base / a_base* (Sect. 5.3; D* the host's nominal D_1, g* below)
    g_star = "0.58 mm"           # the nominal clearance g* of a_base* (default the paper's 0.58 mm)
    eta = { start = 0.95, stop = 1.01, n = 25 }   # Omega / omega_1*
    repetition = "leg"           # "leg" or "run": what counts as one repetition sample (sim.stepped_sine.protocol)
    start = "base-velocity"      # initial conditions of each run: "rest" or "base-velocity" (sim.stepped_sine.protocol)
    perturbation = 5e-4          # half-width of the random relative frequency offset of each run (sim.stepped_sine.protocol)
    perturb = "start"            # what it perturbs: "start" (each run's first wait) or "each-point"
    wait = 3.0                   # s
    hold = 5.0                   # s
    sequence = "up-down-up"
    integrator = "exact"

    [interval]                   # the method's own table, named after the kind: [interval], [sobol] or
    designs = ["individual"]     # [response]; its keys are the method's settings (`uq.methods`; every key with
                                 # its default and meaning: uq/OUTPUTS.md, "Study files")

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
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Mapping

from sim.model.parameters import PARAMETERS
from uq.errors import StudyError
from uq.problem.cluster_settings import ClusterSettings, parse_cluster_table
from uq.problem.models import ResponseModel, make_model
from uq.problem.space import K_H_STAR, Parameter, ParameterSpace, resolve_k_H, resolve_value

#: the tables every study may have; the method's own table is named after its kind (`Method.kind`)
COMMON_TABLES = {
    "study": {"name", "kind", "model", "modal_model", "seed", "repetitions", "output", "outputs", "contact_law"},
    "variant": {"sphere_mass_factor", "higher_mode_damping"},
    "impactor": {"radius", "material", "mass", "wall_material"},
    "parameters": None,  # one sub-table per parameter
    "excitation": {"levels", "eta", "wait", "hold", "sequence", "integrator", "perturbation", "perturb", "repetition",
                   "start", "dt_scale", "g_star"},
    "cluster": None,  # checked by uq.problem.cluster_settings.parse_cluster_table
}
_PARAM_KEYS = {"nominal", "min", "max", "best_estimate"}


@dataclass(frozen=True)
class Context:
    """What a method's settings are read against: the study's kind, parameter space, the folder that relative paths
    in the file start from, the file read (for warnings), and whether values of implausible magnitude are allowed
    (--allow-implausible, `check_plausible`)."""

    kind: str
    space: ParameterSpace
    base_dir: Path = Path(".")
    source: str = ""
    allow_implausible: bool = False


@dataclass(frozen=True)
class Setting:
    """One key of a method's study-file table, and its command-line option if a user may give it there.

    key: the key in the table (``[KIND] KEY``) and in study.json; default: its value when neither gives it (a
    default computed from other settings is set in `Method.finish`); read(value, context): the checked
    value, or a one-line `StudyError` naming ``[KIND] KEY``; option, metavar, parse, help: the option of `ies KIND`
    (parse: argparse's type; None: the study file only); identity: part of the study's identity, so that
    ``--resume`` continues a folder only with the same value (False for analysis settings and sample sizes whose
    samples are nested: a study grown with --resume reuses its runs).
    """

    key: str
    default: Any
    read: Callable[[Any, Context], Any]
    help: str
    option: str | None = None
    metavar: str | None = None
    parse: Callable[[str], Any] | None = None
    identity: bool = True



@dataclass(frozen=True, kw_only=True)
class Study:
    """A resolved, validated study (see the module docstring for the file layout); built with named fields.

    method: the method that runs it (a `uq.problem.method.Method` of `uq.methods.METHODS`), settings: its checked
    settings (`Method.settings`),
    table: the method's table as the file gave it (the command line's options are read over it, `with_settings`)."""

    name: str
    kind: str
    model: str
    space: ParameterSpace
    levels: tuple[float, ...]
    repetitions: int
    seed: int
    output: Path
    method: Any
    settings: Mapping[str, Any] = field(default_factory=dict)
    table: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)
    protocol: Mapping[str, Any] = field(default_factory=dict)
    source: str = ""
    modal_model: Path | None = None
    variant: Mapping[str, float] = field(default_factory=dict)
    outputs: tuple[str, ...] = ()
    contact_law: str = "hertz"
    impactor: Mapping[str, Any] = field(default_factory=dict)
    g_star: float | None = None
    #: where the study runs ([cluster], uq.engine.cluster); not part of its results, so left out of to_dict and the key
    cluster: ClusterSettings | None = None
    #: whether it was read with --allow-implausible (values of implausible magnitude computed as given)
    allow_implausible: bool = field(default=False, compare=False)

    def make_model(self) -> ResponseModel:
        """The study's response model (`uq.problem.models.make_model`)."""
        return make_model(self.model, protocol=self.protocol, parameters=tuple(self.space.names),
                          modal_model=self.modal_model, variant=self.variant, outputs=self.outputs,
                          contact_law=self.contact_law, impactor=self.impactor, g_star=self.g_star)

    def context(self) -> Context:
        """What its method's settings are read against (`Context`)."""
        return Context(self.kind, self.space, Path(self.source).parent if self.source else Path("."), self.source,
                       self.allow_implausible)

    def to_dict(self) -> dict:
        """The resolved study as plain data (study.json's "study", results.nc's attribute): the common keys and the
        method's settings under its kind (`Method.describe`)."""
        return {**self.common_dict(), **self.method.describe(self.settings)}

    def identity(self) -> dict:
        """What defines the study's runs, for `--resume`: the resolved study without its output folder and file, and
        of the method's settings those that are part of its identity (`Method.identity`)."""
        common = {k: v for k, v in self.common_dict().items() if k not in ("output", "source")}
        return {**common, **self.method.identity(self.settings)}

    def common_dict(self) -> dict:
        """The resolved study without its method's settings, as plain data."""
        return {
            "name": self.name, "kind": self.kind, "model": self.model,
            "modal_model": None if self.modal_model is None else str(self.modal_model), "seed": self.seed,
            "repetitions": self.repetitions, "output": str(self.output), "source": self.source,
            "levels": list(self.levels), "protocol": dict(self.protocol), "parameters": self.space.to_dict(),
            "variant": dict(self.variant), "outputs": list(self.outputs), "contact_law": self.contact_law,
            **({"impactor": dict(self.impactor)} if self.impactor else {}),  # the paper's sphere: keys as before
            **({"g_star_m": self.g_star} if self.g_star is not None else {}),
        }


def with_calibration(study: Study, k_H_cal: float) -> Study:
    """The study with k_H's upper bound at a calibrated k_H (N/m^1.5; `ies calibrate`), as the paper does with its BEM
    result 1.52 k_H* (Sect. 4.1): the best estimate stays (1.25 k_H* by default) unless the calibration falls below
    it, then it is the midpoint of k_H's lower bound and the calibrated value (and a setting that fixes k_H at its
    best estimate, the residual band of Fig. 8, follows it). A calibrated k_H below k_H* (Eq. 8) is refused with one
    line: a crater stiffens the contact."""
    from uq.problem.space import K_H_BEST_ESTIMATE, K_H_STAR

    k_H_star = study.space.extras.get("k_H_star", K_H_STAR)
    if k_H_cal < k_H_star:
        raise StudyError(f"the calibrated k_H = {k_H_cal:.4g} N/m^1.5 is below k_H* = {k_H_star:.4g}; a crater should "
                         "stiffen the contact: check the calibration or use --no-calibration")
    space = study.space
    k = space["k_H"]
    best = space.extras.get("k_H_best_estimate", K_H_BEST_ESTIMATE)
    if best > k_H_cal:
        best = 0.5 * (k.min + k_H_cal)
    params = tuple(replace(p, max=max(k_H_cal, p.min)) if p.name == "k_H" else p for p in space.parameters)
    new_space = ParameterSpace(params, {**space.extras, "k_H_best_estimate": best, "k_H_calibrated": k_H_cal})
    settings = dict(study.settings)
    fix = settings.get("fix")
    if isinstance(fix, Mapping) and "k_H" in fix:
        settings["fix"] = {**fix, "k_H": best}
    return replace(study, space=new_space, settings=settings)


def read_study(path: str | Path, methods: Mapping[str, Any], elsewhere: Mapping[str, str] | None = None, *,
               allow_implausible: bool = False) -> Study:
    """Read and validate a study file against the methods of a registry (`uq.methods.load_study` passes its own);
    errors are one-line `StudyError`s naming the file. `elsewhere`: kinds that another command runs (kind ->
    that command), refused with its name; allow_implausible: compute with values of implausible magnitude
    (`check_plausible`) instead of refusing them."""
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
        return parse_study(data, methods, base_dir=path.parent, source=str(path), elsewhere=elsewhere,
                           allow_implausible=allow_implausible)
    except StudyError as exc:
        raise StudyError(f"{path}: {exc}") from None


def check_number(where: str, value: Any, *, integer: bool = False, positive: bool = True,
                 minimum: float | None = None, maximum: float | None = None) -> float:
    """`value` of a study file's key `where` ("[table] key") checked: a finite number (an integer with `integer`),
    positive unless `positive` is False, within [minimum, maximum] where given; else a one-line StudyError."""
    ok = isinstance(value, int) if integer else isinstance(value, (int, float))
    if isinstance(value, bool) or not ok or not math.isfinite(value):
        kind = "an integer" if integer else "a number"
        raise StudyError(f"{where} must be {kind}, got {value!r}")
    if positive and value <= 0:
        raise StudyError(f"{where} must be positive, got {value!r}")
    if minimum is not None and value < minimum or maximum is not None and value > maximum:
        bounds = (f"between {minimum:g} and {maximum:g}" if minimum is not None and maximum is not None
                  else f">= {minimum:g}" if minimum is not None else f"<= {maximum:g}")
        raise StudyError(f"{where} must be {bounds}, got {value!r}")
    return value


def numeric(key: str, default: float, help: str, *, integer: bool = False, positive: bool = True,
            minimum: float | None = None, maximum: float | None = None, **option: Any) -> Setting:
    """A setting whose value is a number checked by `check_number` (the error names ``[KIND] KEY``); `option`: the
    Setting's option, metavar, parse and identity."""
    def read(value: Any, context: Context) -> float:
        checked = check_number(f"[{context.kind}] {key}", value, integer=integer, positive=positive, minimum=minimum,
                               maximum=maximum)
        return int(checked) if integer else float(checked)

    return Setting(key, default, read, help, **option)


def _number(table: str, key: str, value: Any, *, integer: bool = False, positive: bool = True) -> float:
    return check_number(f"[{table}] {key}", value, integer=integer, positive=positive)


def kinds_of(methods: Mapping[str, Any]) -> dict[str, list[Any]]:
    """kind -> its methods, in registry order (the first is the kind's default)."""
    kinds: dict[str, list[Any]] = {}
    for method in methods.values():
        kinds.setdefault(method.kind, []).append(method)
    return kinds


def parse_study(data: Mapping[str, Any], methods: Mapping[str, Any], *, base_dir: Path = Path("."),
                source: str = "", elsewhere: Mapping[str, str] | None = None, allow_implausible: bool = False) -> Study:
    """Validate the parsed TOML of a study (see `read_study`)."""
    kinds = kinds_of(methods)
    elsewhere = dict(elsewhere or {})
    known_tables = {**COMMON_TABLES, **{kind: None for kind in kinds}}
    for table in data:
        if table not in known_tables and table not in elsewhere:
            raise StudyError(f"unknown table [{table}]; known: {', '.join('[' + t + ']' for t in known_tables)}")
        if not isinstance(data[table], Mapping):
            raise StudyError(f"'{table}' must be a table ([{table}])")
        allowed = COMMON_TABLES.get(table)
        if allowed is not None:
            for key in data[table]:
                if key not in allowed:
                    raise StudyError(f"unknown key '{key}' in [{table}]; known: {', '.join(sorted(allowed))}")
    head = data.get("study", {})
    every_kind = ", ".join([*kinds, *elsewhere])
    if "kind" not in head:
        raise StudyError(f"[study] kind is missing: say what the study computes, one of {every_kind} "
                         "(e.g. kind = \"interval\")")
    kind = head["kind"]
    if kind in elsewhere:
        raise StudyError(f"this is a {kind} study: run it with `{elsewhere[kind]} FILE`")
    if kind not in kinds:
        raise StudyError(f"[study] kind must be one of {every_kind}, got {kind!r}")
    for table in data:
        if table in kinds and table != kind:
            raise StudyError(f"[{table}] applies to kind = \"{table}\" only; this is a{'n' if kind[0] in 'aeiou' else ''} "
                             f"{kind} study: remove the table or change the kind")
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
    impactor = _parse_impactor(data.get("impactor", {}))
    exc = dict(data.get("excitation", {}))
    g_star = _parse_g_star(exc.pop("g_star", None), allow_implausible)
    if (impactor or g_star is not None) and model_spec != "ies":
        raise StudyError("[impactor] and [excitation] g_star only apply to model = \"ies\" (the simulator)")
    table = data.get("parameters")
    names = table or {}
    if model_spec == "ies":
        by_key = {row.study_key: name for name, row in PARAMETERS.items()}
        names = {by_key.get(key, key): spec for key, spec in names.items()}
    host_model = make_model(model_spec, parameters=tuple(names), modal_model=modal_model, variant=variant,
                            impactor=impactor, g_star=g_star)
    space = _parse_parameters(table, model_spec, base_dir, host_model, allow_implausible)

    levels_raw = exc.pop("levels", [1.0] if model_spec != "ies" else None)
    if levels_raw is None:
        raise StudyError("[excitation] levels is missing: give a_base / a_base* values, e.g. levels = [5.3, 6.7, 7.4]")
    if not isinstance(levels_raw, list) or not levels_raw:
        raise StudyError(f"[excitation] levels must be a non-empty list of numbers, got {levels_raw!r}")
    levels = tuple(float(_number("excitation", "levels", v)) for v in levels_raw)
    if len(set(levels)) != len(levels):
        raise StudyError("[excitation] levels lists a value twice")
    protocol = _parse_protocol(exc)

    table = data.get(kind, {})
    context = Context(kind, space, base_dir, source, allow_implausible)
    method, settings = method_settings(kinds[kind], table, context)
    if method.models is not None and model_spec not in method.models:
        raise StudyError(f"a{'n' if kind[0] in 'aeiou' else ''} {kind} study runs the simulator: model = \"ies\"")
    outputs = head.get("outputs", [])
    if not isinstance(outputs, list) or not all(isinstance(o, str) for o in outputs) or len(set(outputs)) != len(outputs):
        raise StudyError(f"[study] outputs must be a list of distinct output names, e.g. [\"mean\", \"restitution\"], got {outputs!r}")
    contact_law = _parse_contact_law(head, space)
    cluster = parse_cluster_table(data["cluster"]) if "cluster" in data else None
    study = Study(name=name, kind=kind, method=method, settings=settings, table=dict(table), model=model_spec,
                  space=space, levels=levels, repetitions=reps, seed=seed, output=output, protocol=protocol,
                  source=source, modal_model=modal_model, variant=variant, outputs=tuple(outputs),
                  contact_law=contact_law, impactor=impactor, g_star=g_star, cluster=cluster,
                  allow_implausible=allow_implausible)
    for _, one in method.substudies(study):
        _parse_contact_law({"contact_law": contact_law}, one.space)  # every value of a series in range
    model = study.make_model()  # unknown model -> one line now
    from sim.model.contact_law import DEFAULT_LAW

    if modal_model is not None or variant or contact_law != DEFAULT_LAW or impactor:
        model.check()  # an unreadable modal file -> one line now
    if "friction" in space.names:  # every mu of the study: >= 0, and > 0 needs ode3 and the floor values
        k_t = space["k_t"].min if "k_t" in space.names else model.optional_parameter("k_t").nominal
        series = [one.space["friction"].nominal for _, one in method.substudies(study)]
        for mu in (space["friction"].min, space["friction"].max, *series):
            model.check_physics({"friction": mu, "k_t": k_t})
    return study


def method_settings(candidates: list[Any], table: Mapping[str, Any], context: Context,
                    given: Mapping[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
    """The method of a kind's table and its checked settings: the table's ``method`` key chooses among the kind's
    `candidates` (the first by default; `given`'s ``method``, from the command line, wins, and then the table's keys
    of the kind's other methods are dropped); every setting from `given` (the command line's options), else the
    table, else its default; one line (StudyError) for an unknown key, a key of another method or a bad value."""
    given = dict(given or {})
    kind = context.kind
    names = [m.name for m in candidates]
    chosen = given.pop("method", None)
    table = dict(table)
    from_file = table.pop("method", names[0])
    name = chosen or from_file
    if name not in names:
        where = "--method" if chosen else f"[{kind}] method"
        raise StudyError(f"{where} must be one of {', '.join(names)}, got {name!r}")
    method = candidates[names.index(name)]
    own = {s.key for s in method.settings}
    if chosen and chosen != from_file:  # the command line switched the method: the file's keys of the other go
        table = {k: v for k, v in table.items() if k in own}
    ignored = {k: table.pop(k) for k in list(table) if k in method.superseded}  # a file of an earlier release
    others: dict[str, list[str]] = {}
    for m in candidates:
        if m is not method:
            for s in m.settings:
                if s.key not in own:
                    others.setdefault(s.key, []).append(m.name)
    for source, keys in (("table", table), ("options", given)):
        misplaced = sorted(k for k in keys if k in others)
        if misplaced:
            if source == "options":
                options = [next(s.option for m in candidates for s in m.settings if s.key == k) for k in misplaced]
                raise StudyError(f"{', '.join(o or k for o, k in zip(options, misplaced))} appl"
                                 f"{'ies' if len(misplaced) == 1 else 'y'} to method "
                                 f"{' or '.join(others[misplaced[0]])} only, not {method.name}")
            raise StudyError(f"[{kind}] {', '.join(misplaced)} only appl{'ies' if len(misplaced) == 1 else 'y'} to "
                             + " or ".join(f"method = \"{m}\"" for m in others[misplaced[0]]))
        unknown = sorted(k for k in keys if k not in own)
        if unknown:
            raise StudyError(f"unknown key '{unknown[0]}' in [{kind}]; known: {', '.join(sorted(own | {'method'}))}")
    values: dict[str, Any] = {}
    for s in method.settings:
        if s.key in given:
            values[s.key] = s.read(given[s.key], context)
        elif s.key in table:
            values[s.key] = s.read(table[s.key], context)
        else:
            values[s.key] = s.default
    values = method.finish(values, context)
    for key, value in ignored.items():
        instead = method.superseded[key]
        where = f"{context.source}: " if context.source else ""
        sys.stderr.write(f"warning: {where}[{kind}] {key} = {value!r} is not a setting of method = \"{method.name}\" "
                         f"(an earlier release ignored it too) and is ignored: its setting is {instead}, here "
                         f"{instead} = {values[instead]!r}; remove {key} or write {instead} = N\n")
    return method, values


def with_settings(study: Study, methods: Mapping[str, Any], given: Mapping[str, Any]) -> Study:
    """The study with settings given on the command line (key -> value, ``method`` to switch among the kind's
    methods), read over the file's table as the file's own keys are (one-line StudyError)."""
    given = {k: v for k, v in given.items() if v is not None}
    if not given:
        return study
    method, settings = method_settings(kinds_of(methods)[study.kind], study.table, study.context(), given)
    return replace(study, method=method, settings=settings)

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


def _parse_impactor(table: Any) -> dict[str, Any]:
    """The [impactor] table (`sim.model.sphere.sphere_of`'s arguments, SI): radius and mass as numbers (m, kg) or with
    their unit ("5 mm", "4 g"), material and wall_material as names or "E=...GPa,nu=...[,density=...]"; checked by
    building the sphere (one StudyError line)."""
    from sim.common.errors import SimulationInputError
    from sim.common.units import MASS, RADIUS, parse_quantity
    from sim.model.sphere import sphere_of

    out: dict[str, Any] = {}
    try:
        for key, quantity in (("radius", RADIUS), ("mass", MASS)):
            if key in table:
                out[key] = parse_quantity(table[key], quantity)
        for key in ("material", "wall_material"):
            if key in table:
                if not isinstance(table[key], str):
                    raise StudyError(f"[impactor] {key} must be a name like \"steel\" or \"E=200GPa,nu=0.29"
                                     f"{',density=7850kg/m3' if key == 'material' else ''}\", got {table[key]!r}")
                out[key if key == "material" else "wall"] = table[key]
        sphere_of(**out)
    except SimulationInputError as exc:
        raise StudyError(f"[impactor] {exc}") from None
    return out


def _parse_g_star(value: Any, allow_implausible: bool = False) -> float | None:
    """[excitation] g_star: the nominal clearance g* (m, or with its unit) of the levels, None when not given; an
    implausible magnitude refused unless `allow_implausible` (`check_plausible`)."""
    if value is None:
        return None
    from sim.common.errors import SimulationInputError

    try:
        g_star = PARAMETERS["g"].check(PARAMETERS["g"].parse(value))
    except SimulationInputError as exc:
        raise StudyError(f"[excitation] g_star: {exc}") from None
    check_plausible("[excitation] g_star", "g", g_star, value, allow_implausible)
    return g_star


def _parse_parameters(table: Mapping[str, Any] | None, model_spec: str, base_dir: Path,
                      model: ResponseModel | None = None, allow_implausible: bool = False) -> ParameterSpace:
    """The parameter space of [parameters.KEY] tables against `model`'s default space (for the simulator: Table 2 for
    its host and sphere); for the simulator KEY is a row's study key in `sim.model.parameters.PARAMETERS` (its name in
    the space, CSV columns and messages is the row's name); a value of implausible magnitude is refused unless
    `allow_implausible` (`check_plausible`)."""
    if table is not None and model_spec == "ies":
        by_key = {row.study_key: name for name, row in PARAMETERS.items()}
        table = {by_key.get(key, key): spec for key, spec in table.items()}
    model = make_model(model_spec, parameters=tuple(table or {})) if model is None else model
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
    k_H_star = extras.get("k_H_star", K_H_STAR)  # "1.25 k_H*" of the study's sphere
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
            values[key] = resolve_value(p.name, spec.get(key, fallback), base_dir=base_dir, k_H_star=k_H_star)
            if key in spec:
                check_plausible(f"[parameters.{PARAMETERS[p.name].study_key if p.name in PARAMETERS else p.name}] {key}",
                                p.name, values[key], spec[key], allow_implausible)
        if "best_estimate" in spec:
            if p.name != "k_H":
                raise StudyError(f"[parameters.{p.name}] best_estimate is only defined for k_H")
            extras["k_H_best_estimate"] = resolve_k_H(spec["best_estimate"], base_dir=base_dir, k_H_star=k_H_star)
            if not extras["k_H_best_estimate"] > 0:
                raise StudyError("[parameters.k_H] best_estimate must be positive")
        params.append(Parameter(p.name, values["nominal"], values["min"], values["max"], p.unit, p.label,
                                p.upper_limit, p.positive))
    return ParameterSpace(tuple(params), extras)


def check_plausible(where: str, name: str, value: object, raw: object, allow: bool) -> None:
    """A study file's value `raw` of the parameter `name` at `where` ("[parameters.g] max"), read as `value` (SI),
    refused with one line (StudyError) when its magnitude is implausible for its quantity (a unit slip: 0.612 for
    0.612 mm, 0.085 for 0.085 %), naming the reading that would make it plausible, unless `allow`
    (`sim.model.parameters.check_plausible`, as on the command line)."""
    from sim.common.errors import SimulationInputError
    from sim.model.parameters import Typed, check_plausible as check

    if isinstance(value, (int, float)) and not isinstance(value, bool):
        try:
            check({name: Typed(value, str(raw))}, allow=allow, where=lambda row, v: f"{where} = {raw!r}")
        except SimulationInputError as exc:
            raise StudyError(str(exc)) from None


def _check_param_table(name: str, spec: Any) -> Mapping[str, Any]:
    if not isinstance(spec, Mapping):
        raise StudyError(f"[parameters.{name}] must be a table with nominal, min, max")
    for key in spec:
        if key not in _PARAM_KEYS:
            raise StudyError(f"unknown key '{key}' in [parameters.{name}]; known: {', '.join(sorted(_PARAM_KEYS))}")
    return spec


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
