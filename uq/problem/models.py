"""Response models that a study evaluates: the IES simulator, Ishigami, or a user's Python function.

A model maps (parameter values, excitation level, repetition) to named scalar outputs:

* ``"ies"``: one stepped-sine run of the simulator (`sim.stepped_sine.protocol.run_sweep`, Sect. 5.1-5.3 of the
  seed paper) with D, g, k_H; outputs the run's resonant response levels ``mean`` and ``max``
  (largest per-frequency mean / max amplitude, normalised by the nominal a_noabs*, Sect. 5) and
  ``apr`` (1 where the resonant level is reached in the almost periodic regime, else 0).
* ``"ishigami"``: the Ishigami-Homma function of x1, x2, x3 (output ``value``), a reference for the
  Sobol' layer that runs through the whole study machinery.
* ``"package.module:function"``: ``function(params: dict, level: float, rep: int, seed: int)``
  returning a float (output ``value``), e.g. a surrogate of the response.

Each model also aggregates the runs of one (point, level) over the repetitions: ``aggregate(records)``
-> {output: (value, standard error, samples)}; the simulator does it exactly as `ies sweep` does.

Models are small picklable objects: they travel to joblib and Dask workers, and their ``version()``
(a hash of the code that computes the outputs: for the simulator its code version, which `ies --version` prints) is
part of every cached task's key.
"""
from __future__ import annotations

import functools
import hashlib
import importlib
import inspect
import math
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping, Protocol, runtime_checkable

from sim.stepped_sine.measures import SCATTERING_MEASURES
from uq.errors import StudyError
from uq.problem.space import Parameter, ParameterSpace, parameter_of, table2_space

if TYPE_CHECKING:
    from sim.model.parameters import SystemSettings
    from sim.model.sphere import Sphere
    from sim.model.system import Impactor, ModalModel
    from sim.stepped_sine.protocol import SteppedSine, SweepResult

_ROOT = Path(__file__).resolve().parents[2]


@runtime_checkable
class ResponseModel(Protocol):
    """What a study evaluates (`make_model`): a picklable callable from (parameter values, excitation level,
    repetition, seed) to named scalar outputs, with the aggregation of the runs of one (point, level).

    The runner may also use optional hooks when a model has them: ``with_rig()``, ``warm_up()``,
    ``resolved_protocol()``, ``describe()`` (`uq.engine.execution`, `uq.engine.runner`).
    """

    @property
    def name(self) -> str:
        """The study file's ``model`` key ("ies", "ishigami", "function")."""

    @property
    def parameters(self) -> tuple[str, ...]:
        """The inputs the model reads from a point (names of the parameter space)."""

    @property
    def outputs(self) -> tuple[str, ...]:
        """Every output a run returns."""

    @property
    def banded_outputs(self) -> tuple[str, ...]:
        """The outputs whose bands and indices a study computes."""

    def default_space(self) -> ParameterSpace | None:
        """The parameter space when the study lists none (None: the study must give every parameter)."""

    def version(self) -> str:
        """A hash of the code that computes the outputs (part of every cached task's key)."""

    def check(self) -> None:
        """Fail with one `StudyError` line before any task runs when the settings cannot work."""

    def aggregate(self, records: list[Mapping[str, Any]]) -> Mapping[str, Any]:
        """{output: (value, standard error, samples)} over the repetitions of one (point, level)."""

    def __call__(self, params: Mapping[str, float], level: float, rep: int, seed: int) -> Mapping[str, Any]:
        """One run: {output: value} (and, for the simulator, its "trace")."""


def _hash_files(paths: list[Path]) -> str:
    digest = hashlib.sha256()
    for path in sorted(paths):
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def _source_version(*relative_dirs_or_files: str) -> str:
    """Hash of the source files (read now, not cached: the code on disk may change between runs)."""
    paths: list[Path] = []
    for rel in relative_dirs_or_files:
        target = _ROOT / rel
        paths.extend(sorted(target.rglob("*.py")) if target.is_dir() else [target])
    return _hash_files(paths)


@dataclass(frozen=True)
class IESModel:
    """The simulator of the seed rig under a stepped-sine protocol (one task = one run at one level).

    protocol: keyword arguments of `sim.stepped_sine.protocol.SteppedSine` (eta grid, sequence, wait, hold, ...);
    n_modes: modes of the built-in rig model (9 as in the paper);
    modal_file: a modal-model file (`sim.hosts.modal_file`, e.g. from `ies modes --save`) used instead of the built-in
    rig; its SHA-256 is part of every task's key;
    rig: the modal model itself, built once by the controlling process (`with_rig`) and shipped to the
    workers: the eigen-solution's last bits depend on the BLAS thread count, which differs between the
    main process and joblib/Dask workers, and a chaotic response amplifies such bits;
    impactor: the study's [impactor] table (radius in m, material, mass in kg, wall_material; `sim.model.sphere`), the
    paper's sphere on the host's walls when empty; g_star: the nominal clearance g* (m) of the levels (Sect. 5.3; None:
    the paper's 0.58 mm). The amplitudes are normalised by the host's own D_1* (`sim.model.system.Nominal.of`).
    """

    protocol: Mapping[str, Any] = field(default_factory=dict)
    n_modes: int = 9
    name: str = "ies"
    modal_file: str | None = None
    variant: Mapping[str, float] = field(default_factory=dict)
    rig: "ModalModel | None" = field(default=None, compare=False, repr=False)
    banded_outputs: tuple[str, ...] = ("mean", "max")
    contact_law: str | None = None
    impactor: Mapping[str, Any] = field(default_factory=dict)
    g_star: float | None = None

    #: the resonant levels, the regime (1 = APR) and the scattering measures of `sim.stepped_sine.measures` at the resonant
    #: mean's eta (Sect. 5.5, Appendix D)
    outputs = ("mean", "max", "apr", *SCATTERING_MEASURES)

    @property
    def parameters(self) -> tuple[str, ...]:
        """Table 2's parameters (D, g, k_H): the table2 rows of `sim.model.parameters.PARAMETERS`."""
        from sim.model.parameters import table2_parameters

        return tuple(row.name for row in table2_parameters())

    @property
    def optional_parameters(self) -> tuple[str, ...]:
        """Parameters a study may add to Table 2's, the other rows of `PARAMETERS` (they enter a task's point, and so
        its key, only when listed): r_cont,diss of the damped contact law (Eq. 10; listing it implies contact_law =
        "hertz-damped"), the friction coefficient mu and tangential stiffness k_t (N/m) of dry friction at the floor
        (Appendix C; ode3), and any row added to the table."""
        from sim.model.parameters import optional_parameters

        return tuple(row.name for row in optional_parameters())

    def default_space(self) -> ParameterSpace:
        """Table 2's space for this host and sphere (`uq.problem.space.table2_space`): D around the host's D_1* over its
        damping interval, k_H around the sphere's k_H* (Eq. 8 on the host's walls)."""
        return table2_space(host=self._host(), sphere=self.sphere())

    def optional_parameter(self, name: str) -> Parameter:
        """The default of an optional parameter (`optional_parameters`), before the study's table fills it in: its row
        of `PARAMETERS` held at its nominal value (the sphere's mass for m_a)."""
        from sim.model.parameters import PARAMETERS

        row = PARAMETERS[name]
        p = parameter_of(row)
        sets_mass = row.feeds.field == "mass" and not row.feeds.scale and row.feeds.derive is None
        return p.fixed_at(self.sphere().mass) if sets_mass else p

    def sphere(self) -> "Sphere":
        """The study's sphere (`sim.model.sphere.Sphere`) of its [impactor] table, on the host's walls unless the
        table names them; one StudyError line for a bad value."""
        from sim.common.errors import SimulationInputError
        from sim.model.sphere import sphere_of

        try:
            return sphere_of(**dict(self.impactor), host_wall=self._host().wall_material)
        except SimulationInputError as exc:
            raise StudyError(f"[impactor] {exc}") from None

    def normalisation(self) -> dict[str, Any]:
        """What the outputs are normalised by (Sect. 5): `D_star` (the host's nominal D_1), `g_star_m`, the sentence
        saying so, and the study's sphere (`sim.model.sphere.Sphere.describe`)."""
        from sim.model.system import Nominal

        nominal = Nominal.of(self._host(), self.g_star)
        return {**nominal.describe(), "text": nominal.text(), "sphere": self.sphere().describe()}

    def _host(self) -> "ModalModel":
        """The host's modal model: the one this model carries, else built (`_rig`)."""
        return self.rig if self.rig is not None else self._rig()

    def version(self) -> str:
        """The simulator's code version (`sim.common.kernel_cache.code_version`: what `ies --version` prints and the
        kernel folder is named by); this file's own code, which turns a run into outputs, is in `describe`."""
        from sim.common.kernel_cache import code_version

        return code_version()

    def resolved_protocol(self) -> dict:
        """The protocol with every default filled in (for the study metadata)."""
        return _protocol_dict(self._stepped_sine())

    def _stepped_sine(self) -> "SteppedSine":
        from sim.stepped_sine.protocol import SteppedSine

        from sim.common.errors import SimulationInputError

        try:
            return SteppedSine(**dict(self.protocol))
        except (TypeError, SimulationInputError) as exc:
            raise StudyError(f"[excitation]: {exc}") from None

    def check(self) -> None:
        """Build the protocol, the integrator and the rig model once so that bad settings fail before any
        task runs (and before anything is written)."""
        from sim.common.errors import SimulationInputError
        from sim.integration.integrators import get_integrator
        from sim.model.system import check_resonant_mode

        protocol = self._stepped_sine()
        try:
            get_integrator(protocol.integrator, dt_scale=protocol.dt_scale)
        except SimulationInputError as exc:
            raise StudyError(f"[excitation]: {exc}") from None
        rig = self._rig()
        try:
            check_resonant_mode(rig)  # walls at a node of mode 1: refused before any task runs
        except SimulationInputError as exc:
            raise StudyError(f"[study] modal_model {rig.source}: {exc}") from None
        self.check_physics({})

    def check_physics(self, params: Mapping[str, float]) -> None:
        """The model and protocol can simulate a point with these optional parameters (`optional_parameters`): the
        checks of `sim.model.system.build_system` (Eq. 10 needs the model's beam mass, friction its phi_floor) and of
        the protocol's integrator (`sim.integration.integrators.Integrator.check`: its laws, friction), one line
        otherwise."""
        from sim.common.errors import SimulationInputError
        from sim.integration.integrators import integrator_named
        from sim.model.contact_law import law_named
        from sim.model.system import build_system

        from sim.model.parameters import table2_parameters

        point = {**{row.name: row.nominal for row in table2_parameters()}, **params}
        if not law_named(self._law_name()).takes_r_cont and point.get("friction", 0.0) == 0.0:
            return  # only Eq. 10 (the beam mass) and friction (the floor values) ask more of the model
        try:
            build_system(self._rig(), self._settings(point), integrator=integrator_named(self._stepped_sine().integrator))
        except SimulationInputError as exc:
            raise StudyError(f"[study] {exc}") from None

    def _rig(self) -> "ModalModel":
        from sim.common.errors import SimulationInputError
        from sim.hosts.variants import with_higher_mode_damping

        try:
            rig = _rig_model(self.n_modes) if self.modal_file is None else _file_model(self.modal_file)
        except SimulationInputError as exc:
            raise StudyError(f"[study] modal_model: {exc}") from None
        if "higher_mode_damping" in self.variant:
            try:
                rig = with_higher_mode_damping(rig, self.variant["higher_mode_damping"])
            except SimulationInputError as exc:
                raise StudyError(f"[variant] {exc}") from None
        return rig

    def _law_name(self) -> str:
        """The study's contact law (`sim.model.contact_law.LAWS`; None: its DEFAULT_LAW)."""
        from sim.model.contact_law import DEFAULT_LAW

        return self.contact_law if self.contact_law is not None else DEFAULT_LAW

    def _settings(self, params: Mapping[str, float]) -> "SystemSettings":
        """What this run's parameters feed (`sim.model.parameters.system_settings`): the sphere of Eqs. 3-6 with its
        mass scaled by [variant] sphere_mass_factor and the study's contact law, then every parameter of the point."""
        from sim.model.parameters import SystemSettings, system_settings

        sphere = self.sphere()
        base = replace(sphere.settings(SystemSettings(contact_law=self.contact_law)),
                       mass=sphere.mass * self.variant.get("sphere_mass_factor", 1.0))
        return system_settings(params, base)

    def simulated_system(self, params: Mapping[str, float]) -> tuple["ModalModel", "Impactor"]:
        """(modal model with this point's D, impactor) of a point of the study's space
        (`sim.model.system.build_system`, the builder `ies sweep` uses too)."""
        from sim.model.system import build_system

        return build_system(self._host(), self._settings(params))

    def stepped_sine(self) -> "SteppedSine":
        """The study's stepped-sine protocol (`sim.stepped_sine.protocol.SteppedSine`)."""
        return self._stepped_sine()

    def warm_up(self) -> None:
        """Compile the kernels this study's runs use, in this process (`sim.integration.integrators.warm_up_all`;
        minutes on a first run)."""
        from sim.integration.integrators import warm_up_all

        warm_up_all(self.kernel_variants())

    def seconds_per_run(self, levels: list[float], runs: int) -> dict[float, float] | None:
        """Estimated seconds of one run at each of `levels` on one core of this machine now
        (`sim.stepped_sine.cost.seconds_per_run`: a probe of the study's protocol at its nominal point, the kernels
        loaded by `warm_up`); None when `runs` runs cannot take long enough to be worth the probe."""
        from sim.stepped_sine.cost import seconds_per_run, simulated_seconds, worth_probing

        protocol = self._stepped_sine()
        model, impactor = self.simulated_system({})
        if not worth_probing(runs, simulated_seconds(protocol, float(model.omega[0]))):
            return None
        from sim.model.system import Nominal

        return seconds_per_run(model, impactor, levels, protocol, nominal=Nominal.of(model, self.g_star))

    def typical_seconds_per_run(self) -> float:
        """Seconds of one run at the integrator's typical cost on one quiet core (`Integrator.typical_cost`): a size
        before anything is compiled or measured."""
        from sim.integration.integrators import integrator_named
        from sim.stepped_sine.cost import simulated_seconds

        protocol = self._stepped_sine()
        return simulated_seconds(protocol, float(self._host().omega[0])) * integrator_named(protocol.integrator).typical_cost

    def kernel_variants(self) -> list[tuple[str, str]]:
        """(integrator, contact law) of every kernel specialisation this study's runs use: its law and, since
        r_cont = 1 runs it, the law's elastic counterpart."""
        from sim.model.contact_law import law_named

        law = law_named(self._law_name())
        integrator = self._stepped_sine().integrator
        return [(integrator, name) for name in dict.fromkeys((law.name, law.elastic or law.name))]

    def with_rig(self) -> "IESModel":
        """This model carrying the rig's modal model (built here, used unchanged by every worker)."""
        return self if self.rig is not None else replace(self, rig=self._rig())

    def describe(self) -> dict:
        """Settings that define a task's computation (part of its cache key; the built-in rig is covered by
        version, a modal file by its content, the code that turns a run into outputs, this file, by its hash)."""
        out = {"class": type(self).__name__, "protocol": dict(self.protocol), "n_modes": self.n_modes,
               "outputs_code": _source_version("uq/problem/models.py")}
        from sim.model.contact_law import DEFAULT_LAW

        if self._law_name() != DEFAULT_LAW:  # the default law is not in the key (keys from before the choice)
            out["contact_law"] = self.contact_law
        if self.variant:
            out["variant"] = dict(self.variant)
        if self.modal_file is not None:
            out["modal_model_sha256"] = hashlib.sha256(Path(self.modal_file).read_bytes()).hexdigest()
        if self.impactor:  # the paper's sphere is not in the key (keys from before the choice)
            out["impactor"] = dict(self.impactor)
        if self.g_star is not None:
            out["g_star"] = self.g_star
        return out

    def __call__(self, params: Mapping[str, float], level: float, rep: int, seed: int) -> dict[str, Any]:
        """One run: its own resonant levels (outputs) and the per-point measures (trace) for aggregation."""
        from sim.model.system import Nominal
        from sim.stepped_sine.protocol import aggregate_runs, run_sweep

        model, impactor = self.simulated_system(params)
        run = run_sweep(model, impactor, level, self._stepped_sine(), seed=seed, rep=rep,
                        nominal=Nominal.of(model, self.g_star))
        own = aggregate_runs([run])
        trace = {key: getattr(run, key).tolist() for key in _TRACE}
        trace["scattering"] = {name: values.tolist() for name, values in run.scattering.items()}
        trace.update(level=run.level, a_base=run.a_base, a_noabs=run.a_noabs, seed=run.seed, rep=run.rep)
        at = own.eta == own.eta_resonant_mean
        return {"mean": own.resonant_mean, "max": own.resonant_max, "apr": 1.0 if own.regime == "APR" else 0.0,
                **{name: float(own.scattering[name][at][0]) for name in SCATTERING_MEASURES}, "trace": trace}

    def sweep_result(self, records: list[Mapping[str, Any]]) -> "SweepResult | None":
        """The frequency response (`sim.stepped_sine.protocol.SweepResult`, Fig. 5) of the runs of one (point, level), rebuilt
        from their traces and aggregated exactly as `ies sweep` does (`sim.stepped_sine.protocol.aggregate_runs`); None
        without runs."""
        import numpy as np
        from sim.stepped_sine.protocol import SweepRun, aggregate_runs

        protocol = self._stepped_sine()
        runs = []
        for rec in records:
            t = rec["trace"]
            arrays = {key: np.asarray(t[key], dtype=int if key in ("leg", "hold_periods") else float) for key in _TRACE}
            scattering = {name: np.asarray(values, dtype=float) for name, values in t.get("scattering", {}).items()}
            runs.append(SweepRun(**arrays, level=t["level"], a_base=t["a_base"], a_noabs=t["a_noabs"], seed=t["seed"],
                                 rep=t["rep"], protocol=protocol, impactor=None, scattering=scattering))
        return aggregate_runs(runs) if runs else None

    def aggregate(self, records: list[Mapping[str, Any]]) -> dict[str, Any]:
        """Resonant levels over the repetitions of one (point, level), exactly as `sim.stepped_sine.protocol.aggregate_runs`
        (largest repetition-averaged mean / max over eta, Sect. 5.2-5.3), with the standard error of the
        repetition samples at that eta (`SweepResult.resonant_spread`; NaN for a single sample: no noise
        estimate): {output: (value, standard error, number of samples)} and "regime": the regime there."""
        import numpy as np

        res = self.sweep_result(records)
        if res is None:
            return {**{name: (float("nan"), float("nan"), 0) for name in self.outputs}, "regime": ""}
        n = int(res.n_samples)
        at = res.eta == res.eta_resonant_mean
        scattering = {}
        for name in SCATTERING_MEASURES:  # at the resonant mean's eta, standard error of its samples
            samples = res.scattering_samples[name][:, at][:, 0]
            samples = samples[np.isfinite(samples)]
            se = float(np.std(samples, ddof=1) / np.sqrt(samples.size)) if samples.size >= 2 else float("nan")
            scattering[name] = (float(res.scattering[name][at][0]), se, int(samples.size))
        return {"mean": (res.resonant_mean, res.resonant_spread("mean")[2], n),
                "max": (res.resonant_max, res.resonant_spread("max")[2], n),
                "apr": (1.0 if res.regime == "APR" else 0.0, 0.0, n), **scattering, "regime": res.regime}


_TRACE = ("eta", "eta_actual", "leg", "mean", "max", "min", "std", "impacts_per_period", "hold_periods")


def _protocol_dict(protocol: "SteppedSine") -> dict:
    out = asdict(protocol) if hasattr(protocol, "__dataclass_fields__") else dict(vars(protocol))
    return {k: (list(v) if isinstance(v, tuple) else v) for k, v in out.items()}


def mean_over_repetitions(outputs: tuple[str, ...], records: list[Mapping[str, Any]], *,
                          deterministic: bool = False) -> dict[str, tuple[float, float, int]]:
    """Plain repetition statistics of scalar outputs: {output: (mean, standard error, count)}; the standard error
    of a single value is NaN (unknown) unless the model is `deterministic` (then 0)."""
    import numpy as np

    out = {}
    for name in outputs:
        values = np.array([rec["outputs"].get(name, np.nan) for rec in records], dtype=float)
        values = values[np.isfinite(values)]
        n = values.size
        mean = float(values.mean()) if n else float("nan")
        se = float(values.std(ddof=1) / np.sqrt(n)) if n >= 2 else (0.0 if deterministic and n else float("nan"))
        out[name] = (mean, se, n)
    return out


@functools.lru_cache(maxsize=4)
def _rig_model(n_modes: int) -> "ModalModel":
    """The built-in rig with n_modes modes, through the one host resolver (`sim.hosts.sources.resolve_host`)."""
    from sim.hosts.sources import resolve_host

    return resolve_host({"n_modes": n_modes}).model


def _file_model(path: str) -> "ModalModel":
    """The host of a study's modal_model file, through the one host resolver: a modal-model file or a file kind a row
    of `sim.hosts.sources.HOST_SOURCES` reads."""
    from sim.hosts.sources import resolve_host

    return resolve_host({"model": path}).model


@dataclass(frozen=True)
class IshigamiModel:
    """Ishigami-Homma function f = sin x1 + a sin^2 x2 + b x3^4 sin x1 (a = 7, b = 0.1), x_i in [-pi, pi]."""

    a: float = 7.0
    b: float = 0.1
    name: str = "ishigami"

    parameters = ("x1", "x2", "x3")
    outputs = ("value",)
    banded_outputs = ("value",)

    def default_space(self) -> ParameterSpace:
        return ParameterSpace(tuple(Parameter(n, 0.0, -math.pi, math.pi, positive=False) for n in self.parameters))

    def version(self) -> str:
        return _source_version("uq/problem/models.py")

    def check(self) -> None:
        return None

    def aggregate(self, records: list[Mapping[str, Any]]) -> dict[str, tuple[float, float, int]]:
        return mean_over_repetitions(self.outputs, records, deterministic=True)

    def __call__(self, params: Mapping[str, float], level: float, rep: int, seed: int) -> dict[str, float]:
        x1, x2, x3 = (params[n] for n in self.parameters)
        return {"value": math.sin(x1) + self.a * math.sin(x2) ** 2 + self.b * x3**4 * math.sin(x1)}


@dataclass(frozen=True)
class FunctionModel:
    """A user's function ``module:function`` with the call signature (params, level, rep, seed)."""

    target: str
    parameters: tuple[str, ...] = ()
    name: str = "function"

    outputs = ("value",)
    banded_outputs = ("value",)

    def _function(self) -> Callable:
        module_name, _, attr = self.target.partition(":")
        try:
            module = importlib.import_module(module_name)
            return getattr(module, attr)
        except (ImportError, AttributeError) as exc:
            raise StudyError(f"model '{self.target}' cannot be imported ({exc}); give an importable 'module:function'")

    def default_space(self) -> ParameterSpace | None:
        return None

    def version(self) -> str:
        func = self._function()
        try:
            return _hash_files([Path(inspect.getfile(func))])
        except (TypeError, OSError):
            return "unversioned"

    def check(self) -> None:
        self._function()

    def aggregate(self, records: list[Mapping[str, Any]]) -> dict[str, tuple[float, float, int]]:
        return mean_over_repetitions(self.outputs, records)

    def __call__(self, params: Mapping[str, float], level: float, rep: int, seed: int) -> dict[str, float]:
        return {"value": float(self._function()(dict(params), level, rep, seed))}


def make_model(spec: str, *, protocol: Mapping[str, Any] | None = None, parameters: tuple[str, ...] = (),
               modal_model: str | Path | None = None, variant: Mapping[str, float] | None = None,
               outputs: tuple[str, ...] = (), contact_law: str | None = None, impactor: Mapping[str, Any] | None = None,
               g_star: float | None = None) -> ResponseModel:
    """The model named by a study's ``model`` key ("ies", "ishigami" or "module:function"); modal_model: a
    modal-model file replacing the built-in rig of "ies"; variant: the [variant] table of "ies"; outputs: the
    outputs of "ies" whose bands and indices the study computes (default: the resonant mean and max);
    contact_law: the normal contact law of "ies" (a name in `sim.model.contact_law.LAWS`; None: its default);
    impactor: the sphere of "ies" (`IESModel.impactor`); g_star: its nominal clearance g* (m) of the levels."""
    if spec == "ies":
        unknown = [name for name in outputs if name not in IESModel.outputs]
        if unknown:
            raise StudyError(f"[study] unknown output(s) {', '.join(unknown)}; known: {', '.join(IESModel.outputs)}")
        return IESModel(dict(protocol or {}), modal_file=None if modal_model is None else str(modal_model),
                        variant=dict(variant or {}), **({"banded_outputs": tuple(outputs)} if outputs else {}),
                        contact_law=contact_law, impactor=dict(impactor or {}), g_star=g_star)
    if impactor or g_star is not None:
        raise StudyError("[impactor] and [excitation] g_star only apply to model = \"ies\" (the simulator)")
    from sim.model.contact_law import DEFAULT_LAW

    if contact_law not in (None, DEFAULT_LAW):
        raise StudyError("[study] contact_law only applies to model = \"ies\" (the simulator)")
    if outputs:
        raise StudyError("[study] outputs only applies to model = \"ies\" (the simulator)")
    if spec == "ishigami":
        return IshigamiModel()
    if ":" in spec:
        return FunctionModel(spec, tuple(parameters))
    raise StudyError(f"unknown model '{spec}'; use \"ies\", \"ishigami\" or an importable \"module:function\"")
