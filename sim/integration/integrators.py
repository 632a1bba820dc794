"""The integrators of the coupled system (Sect. 3.2): one record each (`Integrator`: its kernels' module, imported
lazily, and its capabilities), and their warm-up.

Every entry follows the contract of `sim.model.system`:
``run_step(y, n_periods, Omega, a_base, sys, record=None) -> (amplitudes, impacts)``.

A record says what its integrator can do, so that no caller asks by name: whether it takes dry friction (Appendix C),
a step scale (``dt_scale``, a multiple of the paper's dt = 2 pi/(15 omega_9)), which contact laws it runs (None: every
registered law, `sim.model.contact_law.LAWS`) and how long its kernels take to compile. `Integrator.check` refuses a
system it cannot run with one line; the commands' options and help are built from the records. Adding an integrator
is writing its module and one `INTEGRATORS` row.

The kernels are numba functions cached on disk (`sim.integration.jit`: in the per-user kernel cache, one folder per
version of their sources). The first run of a version of the code on a machine compiles them, which takes about a
minute (each form of the kernels in a process of its own where there are cores: `compile_in_children`); `warm_up`
does it before a command's progress bar starts (so that the bar's rate and ETA measure simulation only) and says so
while it happens, with an estimate of how long: a small test compilation (`compile_probe_s`, about a second)
measures this machine's speed, the load average how many other processes share its cores with the compiling ones
(`compile_estimate_s`), and the reference times of COMPILE_S_QUIET scale with both; the line states the quiet
machine's figure beside it.
"""
from __future__ import annotations

import contextlib
import functools
import importlib
import os
import subprocess
import sys as _sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterable, Iterator, TextIO

import numpy as np

from sim.common.errors import SimulationInputError
from sim.model.system import Impactor, ModalModel, SystemArrays, system_arrays

RunStep = Callable[[np.ndarray, int, float, float, SystemArrays, "np.ndarray | None"], tuple[np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class Integrator:
    """One integrator: name (the --integrator value), module (its kernels, with ``run_step``), summary (one line of the
    help); friction: it takes dry friction (Appendix C); dt_scale: it takes a step scale; compile_s_quiet: how long
    compiling its kernels for one law takes with a cold cache on a quiet 2-core machine, s (what `warm_up`'s estimate
    scales); typical_cost: seconds one simulated second of the rig's stepped sine takes on one quiet core (from its
    SMR to its APR levels; the cost model measures it where it matters, `sim.stepped_sine.cost`, this sizes a run
    count refused before anything is measured); laws: the contact laws it runs (None: all)."""

    name: str
    module: str
    summary: str
    friction: bool = False
    dt_scale: bool = False
    compile_s_quiet: float = 80.0
    laws: tuple[str, ...] | None = None
    typical_cost: float = 0.02

    def run_step(self, *, dt_scale: float | None = None) -> RunStep:
        """Its `run_step`, with ``dt_scale`` bound if given (one line if it takes none)."""
        self.check_dt_scale(dt_scale)
        run_step = importlib.import_module(self.module).run_step
        if dt_scale is None or dt_scale == 1.0:
            return run_step
        return functools.partial(run_step, dt_scale=float(dt_scale))

    def check_dt_scale(self, dt_scale: float | None) -> None:
        """One line (SimulationInputError) if a step scale other than 1 is asked of an integrator that takes none."""
        if dt_scale is not None and dt_scale != 1.0 and not self.dt_scale:
            scaled = ", ".join(i.name for i in INTEGRATORS.values() if i.dt_scale)
            raise SimulationInputError(f"dt_scale applies only to {scaled}, not to {self.name!r}")

    def supports(self, law: str) -> bool:
        """Whether it runs the contact law `law` (a name of `sim.model.contact_law.LAWS`)."""
        return self.laws is None or law in self.laws

    def check(self, impactor: Impactor) -> None:
        """One line (SimulationInputError) if this integrator cannot run `impactor`: its contact law, dry friction."""
        law = impactor.contact_law.name
        if not self.supports(law):
            able = " or ".join(i.name for i in INTEGRATORS.values() if i.supports(law))
            raise SimulationInputError(f"the contact law {law!r} is not in the {self.name} integrator; choose {able} "
                                       "(--integrator, or [excitation] integrator in a study file)")
        if impactor.friction > 0 and not self.friction:
            able = " or ".join(i.name for i in INTEGRATORS.values() if i.friction)
            raise SimulationInputError(f"dry friction (mu = {impactor.friction:g}, Appendix C) is in the {able} "
                                       f"integrator only; choose it (--integrator {able.split(' or ')[0]}, or "
                                       f"[excitation] integrator = \"{able.split(' or ')[0]}\" in a study file)")


#: "ode3" is the paper's reference; "exact" is the fast free-flight integrator (the default).
INTEGRATORS: dict[str, Integrator] = {i.name: i for i in (
    Integrator("ode3", "sim.integration.ode3", "the paper's fixed step", friction=True, dt_scale=True,
               compile_s_quiet=25.0, typical_cost=0.025),
    Integrator("exact", "sim.integration.exact", "closed-form free flight, located contacts", compile_s_quiet=80.0,
               typical_cost=0.006),
)}
DEFAULT_INTEGRATOR = "exact"


def integrator_named(name: str) -> Integrator:
    """The record of the integrator `name`; one line naming the choices if there is none."""
    try:
        return INTEGRATORS[name]
    except KeyError:
        raise SimulationInputError(f"unknown integrator {name!r}; available: {', '.join(available())}") from None


def available() -> list[str]:
    """Names of the registered integrators."""
    return list(INTEGRATORS)


def get_integrator(name: str, *, dt_scale: float | None = None) -> RunStep:
    """The `run_step` function of the integrator `name`, with ``dt_scale`` bound if given (`Integrator.run_step`)."""
    return integrator_named(name).run_step(dt_scale=dt_scale)


#: seconds a cold compilation of one integrator's kernels with one contact law takes on a quiet 2-core machine, in
#: one process (`Integrator.compile_s_quiet`), and the share each further law adds (its own specialisations of the
#: entry kernels), measured by tests/benchmarks/test_cold_compile.py together with PROBE_S_QUIET
COMPILE_S_QUIET = {name: record.compile_s_quiet for name, record in INTEGRATORS.items()}
FURTHER_LAW_SHARE = 0.5
#: the forms numba compiles each kernel in: without the energy ledger (lead-in, wait) and with it (hold, Eq. 9's
#: terms); each has its own specialisations of the entry kernels, so they compile in parallel, and FORM_SHARE is the
#: share of COMPILE_S_QUIET one form alone takes (the kernels both call are compiled by each: 54 s of 84 s measured)
FORMS = ("plain", "ledger")
FORM_SHARE = 0.65
#: seconds `compile_probe_s` takes on the same quiet machine
PROBE_S_QUIET = 0.75
#: seconds after which `warm_up` says that it is compiling where it did not expect to (kernels it thought cached);
#: loading the cached kernels of "exact" takes 1-3 s
NOTICE_AFTER_S = 5.0


def _probe_kernel(y: np.ndarray, omega: np.ndarray, zeta: np.ndarray, force: np.ndarray, h: float, n: int) -> float:
    """A damped modal system with a Hertz-like wall, a few third-order Runge-Kutta steps: loops, array arithmetic and
    branches like the integrators', for `compile_probe_s` to compile."""
    m = omega.size
    k1, k2, k3, stage_y = np.empty_like(y), np.empty_like(y), np.empty_like(y), np.empty_like(y)
    peak = 0.0
    for step in range(n):
        for stage in range(3):
            source = y if stage == 0 else stage_y
            out = k1 if stage == 0 else (k2 if stage == 1 else k3)
            for j in range(m):
                q, v = source[j], source[m + j]
                out[j] = v
                out[m + j] = (force[j] * np.cos(step * h) - 2.0 * zeta[j] * omega[j] * v - omega[j] ** 2 * q
                              - 1e3 * max(q - 1.0, 0.0) ** 1.5)
            weight, slope = (0.5, k1) if stage == 0 else (0.75, k2)
            for i in range(y.size):
                stage_y[i] = y[i] + weight * h * slope[i]
        for i in range(y.size):
            y[i] += h * (2.0 * k1[i] + 3.0 * k2[i] + 4.0 * k3[i]) / 9.0
        peak = max(peak, abs(y[0]))
    return peak


def compile_probe_s() -> float:
    """Seconds this machine takes, now, to compile `_probe_kernel` afresh (never cached): its speed and load."""
    import numba

    started = time.perf_counter()
    numba.njit(_probe_kernel)(np.zeros(4), np.ones(2), np.full(2, 0.01), np.ones(2), 1e-3, 2)
    return time.perf_counter() - started


def compile_estimate_s(laws: dict[str, list[str]], *, probe_s: float | None = None, cores: int | None = None,
                       load: float | None = None) -> float:
    """Estimated seconds to compile the kernels of the integrators `laws` names, each for its list of contact laws,
    from COMPILE_S_QUIET scaled by this machine's speed against the quiet reference. With more than one core every
    (integrator, form) compiles in a process of its own (`compile_in_children`), each taking FORM_SHARE of its
    integrator's time, all at once. The machine's other work (`load`, the 1-minute load average; None: now) shares
    the cores: k processes of ours get cores / (load + k) of a core each, at most one. The test compilation that
    measures the speed (`compile_probe_s`, `probe_s`) ran as one such process, so its time is the quiet machine's
    speed times that share's slowdown, which is taken out before the children's own share is put in."""
    cores = cores or os.cpu_count() or 1
    others = _load() if load is None else max(0.0, load)
    share = lambda k: min(1.0, cores / (others + k))  # noqa: E731
    probe = compile_probe_s() if probe_s is None else probe_s
    speed = probe / PROBE_S_QUIET * share(1)  # the machine's own speed against the quiet reference
    # an integrator registered after this module was imported (a plug-in) counts as the slowest
    each = [COMPILE_S_QUIET.get(name, max(COMPILE_S_QUIET.values())) * (1.0 + FURTHER_LAW_SHARE * (len(names) - 1))
            for name, names in laws.items()]
    if cores == 1:
        return speed * sum(each) / share(1)
    jobs = [part * FORM_SHARE for part in each for _ in FORMS]
    k = len(jobs)
    return speed * max(max(jobs) / share(1), sum(jobs) / (k * share(k)))


def _load() -> float:
    """The 1-minute load average (0 where the system does not say)."""
    try:
        return float(os.getloadavg()[0])
    except (AttributeError, OSError):
        return 0.0


def cached(name: str) -> bool:
    """Whether the kernel cache holds the integrator `name`'s kernels for the present sources (`sim.integration.jit`;
    the laws share its files, so a law compiled for the first time is found out only by `warm_up`'s timer)."""
    from sim.integration import jit

    folder = jit.cache_folder()
    stem = INTEGRATORS[name].module.rsplit(".", 1)[-1]
    return folder is not None and any(folder.glob(f"{stem}.*.nbi"))


def _run_tiny_system(run_step: RunStep, *, law: str = "hertz", forms: Iterable[str] = FORMS) -> None:
    """Short runs of a tiny impacting system (2 modes, the sphere sent into a wall) in every form a stepped-sine
    run calls the integrator (`sim.stepped_sine.protocol.run_sweep`): without the energy ledger (lead-in, wait)
    and with it (hold), with the contact law `law` (a name of `sim.model.contact_law.LAWS`; a law that takes r_cont
    with r_cont = 0.9). numba compiles one specialisation per form and law, so each kernel a worker will call is
    compiled (or loaded) here, in the parent. forms: those of FORMS to run."""
    from sim.integration.energy import Ledger
    from sim.model.contact_law import contact_law_of, law_named

    model = ModalModel(frequencies_hz=np.array([100.0, 20000.0]), damping_ratios=np.array([0.01, 0.01]),
                       phi_wall_left=np.array([1.0, 0.5]), phi_wall_right=np.array([1.0, 0.5]),
                       phi_tip=np.array([1.0, 0.5]), participation=np.array([1.0, 0.3]), source="warm-up",
                       beam_mass=1.0)
    contact = contact_law_of(law, 0.9 if law_named(law).takes_r_cont else None)
    sys = system_arrays(model, Impactor(contact_law=contact))
    for form in forms:
        y = np.zeros(2 * model.n_modes + 2)
        y[-1] = 0.5  # m/s: the sphere meets a wall within the first period
        if form == "plain":
            run_step(y, 3, 2.0 * np.pi * 100.0, 1e-5, sys, None)
        else:
            run_step(y, 3, 2.0 * np.pi * 100.0, 1e-5, sys, None, ledger=Ledger())


def _notice(what: str, estimate_s: float, quiet_s: float, load: float, cores: int) -> str:
    return (f"compiling {what} (once per version of the code on this machine; about {_duration(estimate_s)} here, "
            f"estimated from a test compilation at load {load:.1f} on {cores} core(s); {_duration(quiet_s)} on a quiet "
            "machine) ...\n")


def _duration(seconds: float) -> str:
    return f"{seconds:.0f} s" if seconds < 300 else f"{seconds / 60:.0f} min"


@contextlib.contextmanager
def _announced(what: str, laws: dict[str, list[str]], cold: bool, stream: TextIO) -> Iterator[None]:
    """Say that `what` is being compiled and about how long it takes (`compile_estimate_s`): at once when the cache
    lacks the kernels, else once NOTICE_AFTER_S have passed; when done, how long it took. Silent when it is quick (the
    kernels came from the cache)."""
    load, cores = _load(), os.cpu_count() or 1

    def say_so(estimate_s: float, quiet_s: float) -> None:
        stream.write(_notice(what, estimate_s, quiet_s, load, cores))
        stream.flush()

    if cold:  # compiled in children where they can hand their kernels over (`warm_up_all`), else here
        used = None if _shared_cache() else 1
        say_so(compile_estimate_s(laws, cores=used, load=load),
               compile_estimate_s(laws, probe_s=PROBE_S_QUIET, cores=used, load=0.0))
    # unexpected (e.g. a law compiled for the first time): no test compilation while numba holds its lock; the quiet
    # machine's speed, in this process, at the present load
    quiet = compile_estimate_s(laws, probe_s=PROBE_S_QUIET, cores=1, load=0.0)
    expected = compile_estimate_s(laws, probe_s=PROBE_S_QUIET / min(1.0, cores / (load + 1.0)), cores=1, load=load)
    notice = threading.Timer(NOTICE_AFTER_S, say_so, args=(expected, quiet))
    started = time.perf_counter()
    if not cold:
        notice.start()
    try:
        yield
    finally:
        notice.cancel()
    elapsed = time.perf_counter() - started
    if cold or elapsed > NOTICE_AFTER_S:
        stream.write(f"kernels compiled in {elapsed:.0f} s; later runs load them from the cache (ies cache)\n")


def warm_up(name: str, *, law: str = "hertz", stream: TextIO | None = None) -> float:
    """Compile (or load from numba's on-disk cache) the kernels of the integrator `name` in this process by one
    short run of a tiny system, before any timed or progress-reported work. When the cache lacks the kernels (or a
    load takes longer than NOTICE_AFTER_S), one line ``compiling ... (once per version of the code on this machine;
    about N s here ...) ...`` goes to `stream` (stderr) while it happens, and one line with the time when it is done.
    Returns the
    seconds spent (0 when this process has warmed the integrator with this law before). law: the run's contact law
    (its name in `sim.model.contact_law.LAWS`; the kernels are compiled per law)."""
    return warm_up_all([(name, law)], stream=stream)


def warm_up_all(pairs: Iterable[tuple[str, str]], *, stream: TextIO | None = None) -> float:
    """`warm_up` every (integrator, law) of `pairs` in this process. Kernels the cache lacks are first compiled in
    parallel where there are several cores (`compile_in_children`), so that this process then only loads them: a
    first run's compilation takes about as long as its slowest form instead of the sum. Returns the seconds spent."""
    pending = [pair for pair in dict.fromkeys(pairs) if pair not in _WARM]
    if not pending:
        return 0.0
    laws: dict[str, list[str]] = {}
    for name, law in pending:
        laws.setdefault(name, []).append(law)
    runs = {name: get_integrator(name) for name in laws}  # refuses an unknown name; a stale cache is discarded here
    started = time.perf_counter()
    what = f"the {pending[0][0]} integrator's kernels" if len(laws) == 1 else f"the kernels of {', '.join(laws)}"
    cold = {name: names for name, names in laws.items() if not cached(name)}
    with _announced(what, laws, bool(cold), stream or _sys.stderr):
        if cold and (os.cpu_count() or 1) > 1 and _shared_cache():
            compile_in_children(cold)
        for name, law in pending:
            _run_tiny_system(runs[name], law=law)
            _WARM.add((name, law))
    return time.perf_counter() - started


def _shared_cache() -> bool:
    """Whether child processes can hand their kernels to this one: a kernel cache folder exists (not where no
    folder can be written, `sim.common.kernel_cache`; there the children would compile for nothing)."""
    from sim.integration import jit

    return jit.cache_folder() is not None


#: what a compiling child process runs: the integrator argv[1] in the form argv[2] (of FORMS) for each law argv[3:]
_CHILD = ("import sys; from sim.integration import integrators as i; "
          "[i._run_tiny_system(i.get_integrator(sys.argv[1]), law=law, forms=(sys.argv[2],)) for law in sys.argv[3:]]")


def compile_in_children(laws: dict[str, list[str]]) -> None:
    """Compile the kernels of each integrator of `laws` for its contact laws into the kernel cache, one child process
    per (integrator, form of FORMS), all at once, and wait for them. A child that fails leaves its work to the caller,
    which compiles what it does not find and reports any error; an interrupt stops the children."""
    root = str(Path(__file__).resolve().parents[2])
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, (root, os.environ.get("PYTHONPATH"))))}
    children = [subprocess.Popen([_sys.executable, "-c", _CHILD, name, form, *names], env=env,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                for name, names in laws.items() for form in FORMS]
    try:
        for child in children:
            child.wait()
    finally:
        for child in children:
            if child.poll() is None:
                child.kill()


#: integrators warmed up in this process (the kernels' argument types do not depend on dt_scale)
_WARM: set[tuple[str, str]] = set()
