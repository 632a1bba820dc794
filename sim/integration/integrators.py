"""Integrators of the coupled system by name (Sect. 3.2), imported lazily, and their warm-up.

Every entry follows the contract of `sim.model.system`:
``run_step(y, n_periods, Omega, a_base, sys, record=None) -> (amplitudes, impacts)``.

The kernels are numba functions cached on disk (``cache=True``, in ``__pycache__`` beside the sources). The
first run on a machine compiles them, which takes minutes; `warm_up` does it before a command's progress bar
starts (so that the bar's rate and ETA measure simulation only) and says so while it happens.
"""
from __future__ import annotations

import contextlib
import functools
import importlib
import io
import os
import subprocess
import sys as _sys
import threading
import time
from pathlib import Path
from typing import Callable, Iterable, Iterator, TextIO

import numpy as np

from sim.common.errors import SimulationInputError
from sim.model.system import Impactor, ModalModel, SystemArrays, system_arrays

RunStep = Callable[[np.ndarray, int, float, float, SystemArrays, "np.ndarray | None"], tuple[np.ndarray, np.ndarray]]

#: name -> (module, function). "ode3" is the paper's reference; "exact" is the fast free-flight integrator.
REGISTRY: dict[str, tuple[str, str]] = {
    "ode3": ("sim.integration.ode3", "run_step"),
    "exact": ("sim.integration.exact", "run_step"),
}
#: integrators that accept ``dt_scale`` (a multiple of the paper's dt = 2 pi/(15 omega_9))
_ACCEPTS_DT_SCALE = {"ode3"}


def available() -> list[str]:
    """Names of the registered integrators."""
    return list(REGISTRY)


def get_integrator(name: str, *, dt_scale: float | None = None) -> RunStep:
    """The `run_step` function registered under `name`, with ``dt_scale`` bound if given (ode3 only)."""
    if name not in REGISTRY:
        raise SimulationInputError(f"unknown integrator {name!r}; available: {', '.join(available())}")
    module_name, attribute = REGISTRY[name]
    run_step = getattr(importlib.import_module(module_name), attribute)
    if dt_scale is None or dt_scale == 1.0:
        return run_step
    if name not in _ACCEPTS_DT_SCALE:
        raise SimulationInputError(f"dt_scale applies only to {', '.join(sorted(_ACCEPTS_DT_SCALE))}, not to {name!r}")
    return functools.partial(run_step, dt_scale=float(dt_scale))


#: how long compiling the kernels of one integrator takes with a cold cache (`warm_up`), measured on the 2-core
#: development machine while other work shared the cores (load average 6-8): "exact" 101 s in a fresh install
#: (up to 390 s under heavier load), "ode3" 32 s
COMPILE_MINUTES = {"exact": 2, "ode3": 1}
#: seconds after which `warm_up` says that it is compiling: loading the cached kernels of "exact" takes 1-3 s
#: (2.5-3 s measured with the machine's 2 cores shared by four engineers), compiling them minutes
NOTICE_AFTER_S = 5.0


def _run_tiny_system(run_step: RunStep, *, law: str = "hertz") -> None:
    """Short runs of a tiny impacting system (2 modes, the sphere sent into a wall) in every form a stepped-sine
    run calls the integrator (`sim.stepped_sine.protocol.run_sweep`): without the energy ledger (lead-in, wait)
    and with it (hold), with the contact law `law` (a name of `sim.model.contact_law.LAWS`; a law that takes r_cont
    with r_cont = 0.9). numba compiles one specialisation per form and law, so each kernel a worker will call is
    compiled (or loaded) here, in the parent."""
    from sim.integration.energy import Ledger
    from sim.model.contact_law import contact_law_of, law_named

    model = ModalModel(frequencies_hz=np.array([100.0, 20000.0]), damping_ratios=np.array([0.01, 0.01]),
                       phi_wall_left=np.array([1.0, 0.5]), phi_wall_right=np.array([1.0, 0.5]),
                       phi_tip=np.array([1.0, 0.5]), participation=np.array([1.0, 0.3]), source="warm-up",
                       beam_mass=1.0)
    contact = contact_law_of(law, 0.9 if law_named(law).takes_r_cont else None)
    sys = system_arrays(model, Impactor(contact_law=contact))
    for ledger in (None, Ledger()):
        y = np.zeros(2 * model.n_modes + 2)
        y[-1] = 0.5  # m/s: the sphere meets a wall within the first period
        if ledger is None:
            run_step(y, 3, 2.0 * np.pi * 100.0, 1e-5, sys, None)
        else:
            run_step(y, 3, 2.0 * np.pi * 100.0, 1e-5, sys, None, ledger=ledger)


@contextlib.contextmanager
def _announced(what: str, minutes: float, stream: TextIO) -> Iterator[None]:
    """Say, once NOTICE_AFTER_S have passed, that `what` is being compiled (about `minutes` min), and when done how
    long it took; silent when it is quick (the kernels came from the cache)."""
    def say_so() -> None:
        stream.write(f"compiling {what} (first run only, about {minutes:g} min) ...\n")
        stream.flush()

    notice = threading.Timer(NOTICE_AFTER_S, say_so)
    started = time.perf_counter()
    notice.start()
    try:
        yield
    finally:
        notice.cancel()
    elapsed = time.perf_counter() - started
    if elapsed > NOTICE_AFTER_S:
        stream.write(f"kernels compiled in {elapsed:.0f} s; later runs load them from the cache\n")


def warm_up(name: str, *, law: str = "hertz", stream: TextIO | None = None) -> float:
    """Compile (or load from numba's on-disk cache) the kernels of the integrator `name` in this process by one
    short run of a tiny system, before any timed or progress-reported work. When that takes longer than
    NOTICE_AFTER_S (a cold cache), one line ``compiling ... kernels (first run only, about N min) ...`` goes to
    `stream` (stderr) while it happens, and one line with the time when it is done. Returns the seconds spent
    (0 when this process has warmed the integrator with this law before). law: the run's contact law (its name in
    `sim.model.contact_law.LAWS`; the kernels are compiled per law)."""
    if (name, law) in _WARM:
        return 0.0
    run_step = get_integrator(name)
    started = time.perf_counter()
    with _announced(f"the {name} integrator's kernels", COMPILE_MINUTES.get(name, 2), stream or _sys.stderr):
        _run_tiny_system(run_step, law=law)
    _WARM.add((name, law))
    return time.perf_counter() - started


#: what a compiling child process runs: warm the integrator argv[1] for each law argv[2:]
_CHILD = "import sys; from sim.integration.integrators import warm_up; [warm_up(sys.argv[1], law=law) for law in sys.argv[2:]]"


def warm_up_all(pairs: Iterable[tuple[str, str]], *, stream: TextIO | None = None) -> float:
    """`warm_up` every (integrator, law) of `pairs` in this process. With several integrators to warm and several
    cores, their kernels are first compiled in parallel, one child process per integrator (into numba's on-disk
    cache, so this process then only loads them): a first run's compilation then takes about as long as its
    slowest integrator's instead of the sum. Returns the seconds spent."""
    pending = [pair for pair in dict.fromkeys(pairs) if pair not in _WARM]
    if not pending:
        return 0.0
    stream = stream or _sys.stderr
    started = time.perf_counter()
    laws: dict[str, list[str]] = {}
    for name, law in pending:
        laws.setdefault(name, []).append(law)
    with _announced(f"the kernels of {', '.join(laws)}", max(COMPILE_MINUTES.get(n, 2) for n in laws), stream):
        if len(laws) > 1 and (os.cpu_count() or 1) > 1:
            for name in laws:
                get_integrator(name)  # imports the kernels: a stale cache is discarded here, once (`sim.integration.jit`)
            root = str(Path(__file__).resolve().parents[2])
            env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, (root, os.environ.get("PYTHONPATH"))))}
            children = [subprocess.Popen([_sys.executable, "-c", _CHILD, name, *names], env=env,
                                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                        for name, names in laws.items()]
            for child in children:  # a child that fails leaves the work to this process, which reports any error
                child.wait()
        for name, law in pending:
            warm_up(name, law=law, stream=io.StringIO())
    return time.perf_counter() - started


#: integrators warmed up in this process (the kernels' argument types do not depend on dt_scale)
_WARM: set[tuple[str, str]] = set()
