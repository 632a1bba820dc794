"""The numba kernels of `sim` and their on-disk cache.

numba keys a cached kernel on its own source file alone. The integrators' kernels call and inline kernels of
other files: the period loop of `sim.integration.exact` embeds `sim.integration.collocation`,
`sim.integration.dopri5` and `sim.integration.flight`, and every integrator inlines the contact laws. After an edit
of a callee file numba would still load the caller's machine code with the old callee compiled in.

`kernel` is ``numba.njit`` with its cache in the workbench's kernel cache (`sim.common.kernel_cache`: a per-user
folder, never the installed package) under the group ``sim``, in the folder of the simulator's code version
(`sim.common.kernel_cache.code_version`, the hash `ies --version` prints), its machine code stamped with a
fingerprint of the sources of all KERNEL_MODULES and FINGERPRINT_FILES (SHA-256 of their contents): any edit of any
kernel file compiles every kernel that could embed it afresh, an edit elsewhere in the simulator finds the machine
code of the same kernel sources again (the new folder starts from it), and so do the same sources wherever they are
installed (a reinstall compiles nothing).

Why this design and not kernels that never call another file's kernels: the state layout, the free-flight
transitions and the closing functions are written once (`sim.integration.flight`) and shared by the exact integrator,
its two contact methods and, with the energy bookkeeping and the contact laws, by more kernels.
One fingerprint over a handful of files costs a fraction of a millisecond per process.

Reference counts. numba counts the references to every array a kernel is handed or slices (an atomic
increment and decrement per array, per call). In the exact integrator's period loop, where small kernels are
called per contact step and per Newton iteration with a dozen arrays each, that was 80k atomic operations per
100 periods and 12 % of a stepped-sine point (tests/benchmarks/test_energy_speed.py). `kernel(refcounts=False)`
compiles a kernel without them (numba's `_nrt` option; the kernels it calls inherit it). That is safe when the
kernel, and everything it calls without counts, allocates no array, copies no slices into arrays
(`sim.integration.flight.copy_into` instead) and returns no array to a counting caller: every array it touches is then owned
by its Python caller for the whole call (numba unboxes the arrays of a kernel without counts with no runtime record
at all, so even a counting kernel further down counts nothing on them). numba refuses to compile an allocation
without counts, so a breach of the first rule is an error, not a leak; a kernel that must allocate says
`refcounts=True`. numba's cache keys a kernel on its signature alone, so a kernel that hands arrays back
(`sim.integration.collocation._step_table`) must only ever be called from kernels without counts.

`_nrt` is a private option of numba (tested with the versions pyproject.toml allows, 0.59 to 0.68). A numba that
does not know it (`nrt_option_supported`) would refuse every such kernel at its first call; `kernel` then compiles
it with reference counts (correct, some percent slower in the exact integrator) and says so once per process.

The contact laws (`sim.model.contact_law`) are compiled inlined into the kernels, per law: their file is part of
the fingerprint (`FINGERPRINT_FILES`).
"""
from __future__ import annotations

import functools
import sys
from pathlib import Path
from typing import Callable

import numba

from sim.common.kernel_cache import cache_in_folder, code_version, sources_hash, version_folder

#: Modules of `sim` (file stems) whose numba kernels are compiled with `kernel`; they may embed each other.
KERNEL_MODULES = ("jit", "flight", "dopri5", "collocation", "exact", "ode3")
#: the group of these kernels in the kernel cache (`sim.common.kernel_cache`)
CACHE_GROUP = "sim"

_SOURCE_DIR = Path(__file__).resolve().parent
#: Sources inlined into the kernels without kernels (cached files) of their own: the contact laws.
FINGERPRINT_FILES = (_SOURCE_DIR.parent / "model" / "contact_law.py",)
#: The message `kernel` writes (once) when numba refuses the `_nrt` option.
NRT_FALLBACK_NOTICE = ("numba {version} does not take the option _nrt: the kernels of sim are compiled with "
                       "reference counts (correct, somewhat slower)\n")
_fallback_said = False


@functools.lru_cache(maxsize=None)
def fingerprint() -> str:
    """SHA-256 (hex) of the names and contents of the source files of KERNEL_MODULES and FINGERPRINT_FILES."""
    return sources_hash([*(_SOURCE_DIR / f"{stem}.py" for stem in KERNEL_MODULES), *FINGERPRINT_FILES])


@functools.lru_cache(maxsize=None)
def simulator_version() -> str:
    """The simulator's code version when its kernels were first decorated in this process (the folder they live in)."""
    return code_version()


def cache_folder() -> Path | None:
    """The folder of the simulator's kernels in the kernel cache: its code version's, the machine code stamped with the
    kernels' fingerprint (None where no folder can be written)."""
    return version_folder(CACHE_GROUP, simulator_version(), fingerprint())


def nrt_option_supported() -> bool:
    """True if the installed numba knows the private `_nrt` option (a kernel without reference counts)."""
    try:
        from numba.core.cpu import CPUTargetOptions
    except ImportError:
        return False
    return hasattr(CPUTargetOptions, "_nrt")


def kernel(function: Callable | None = None, *, refcounts: bool | None = None, **options) -> Callable:
    """``numba.njit(**options)`` cached in the kernel cache's folder of the current kernel sources (`cache_folder`).

    Use as ``@kernel`` or ``@kernel(inline="always", fastmath=...)``.

    refcounts: False compiles the kernel, and every kernel it calls that does not say otherwise, without
    numba's reference counts (see the module docstring: such kernels may not allocate, copy slices or hand
    arrays back); True keeps them for a kernel that allocates and may be called from one without; None
    (default): numba's default, inherited from the calling kernel. A numba without the option
    (`nrt_option_supported`) compiles every kernel with counts, and this says so once per process on stderr.
    """
    global _fallback_said
    if refcounts is not None:
        if nrt_option_supported():
            options["_nrt"] = refcounts
        elif not _fallback_said:
            _fallback_said = True
            sys.stderr.write(NRT_FALLBACK_NOTICE.format(version=numba.__version__))

    def decorate(py_function: Callable) -> Callable:
        return cache_in_folder(numba.njit(**options)(py_function), CACHE_GROUP, simulator_version(), fingerprint())

    return decorate if function is None else decorate(function)
