"""The numba kernels of `sim` and their on-disk cache.

numba caches a compiled function in a cache folder (sim/__pycache__ in the source tree) and keys it on its
own source file alone (modification time and size). The integrators' kernels call and inline kernels of
other files: the period loop of `sim.integration.exact` embeds `sim.integration.collocation`, `sim.integration.dopri5` and `sim.integration.flight`. After an
edit of a callee file, numba would still load the caller's machine code with the old callee compiled in.

`kernel` is ``numba.njit(cache=True)`` with one addition: when it compiles the first kernel of a process it
compares a fingerprint of the sources of all KERNEL_MODULES (SHA-256 of their contents) with the one stored
in numba's cache folder for them (`Dispatcher.stats.cache_path`) and, if they differ, deletes the cached
kernels of these modules before anything is loaded; numba then compiles them afresh and the new fingerprint
is stored. So any edit of any kernel file invalidates every kernel that could embed it.

Why this design and not kernels that never call another file's kernels: the state layout, the free-flight
transitions and the closing functions are written once (`sim.integration.flight`) and shared by the exact integrator,
its two contact methods and, with the energy bookkeeping and the new contact laws to come, by more kernels.
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

Where the cache folder cannot be written to (a read-only install: numba then uses its user cache folder;
NUMBA_CACHE_DIR if set), nothing is deleted and numba itself decides (an install brings new files with new
modification times, which numba's own key already catches). A process that was started before an edit and
compiles a kernel after it still writes machine code for the sources it imported; restart such processes.
"""
from __future__ import annotations

import hashlib
import os
import sys
from pathlib import Path
from typing import Callable

import numba

#: Modules of `sim` (file stems) whose numba kernels are compiled with `kernel`; they may embed each other.
KERNEL_MODULES = ("jit", "flight", "dopri5", "collocation", "exact", "ode3")
#: Name of the file in the cache folder that holds the fingerprint the cached kernels were compiled from.
FINGERPRINT_FILE = "sim-kernels.sha256"

_SOURCE_DIR = Path(__file__).resolve().parent
#: Sources inlined into the kernels without kernels (cached files) of their own: the contact laws.
FINGERPRINT_FILES = (_SOURCE_DIR.parent / "model" / "contact_law.py",)
_checked_folders: set[str] = set()
#: The message `kernel` writes (once) when numba refuses the `_nrt` option.
NRT_FALLBACK_NOTICE = ("numba {version} does not take the option _nrt: the kernels of sim are compiled with "
                       "reference counts (correct, somewhat slower)\n")
_fallback_said = False


def fingerprint() -> str:
    """SHA-256 (hex) of the names and contents of the source files of KERNEL_MODULES and FINGERPRINT_FILES."""
    digest = hashlib.sha256()
    for stem in KERNEL_MODULES:
        digest.update(stem.encode() + b"\0")
        digest.update((_SOURCE_DIR / f"{stem}.py").read_bytes())
    for path in FINGERPRINT_FILES:
        digest.update(path.name.encode() + b"\0")
        digest.update(path.read_bytes())
    return digest.hexdigest()


def nrt_option_supported() -> bool:
    """True if the installed numba knows the private `_nrt` option (a kernel without reference counts)."""
    try:
        from numba.core.cpu import CPUTargetOptions
    except ImportError:
        return False
    return hasattr(CPUTargetOptions, "_nrt")


def discard_stale_kernels(cache_folder: str | os.PathLike) -> bool:
    """Delete the cached kernels of KERNEL_MODULES in `cache_folder` if they were compiled from other sources.

    Returns True if the folder's fingerprint did not match (kernels deleted, new fingerprint written). A folder
    that cannot be read or written is left alone (numba cannot cache there either).
    """
    folder = Path(cache_folder)
    stamp = folder / FINGERPRINT_FILE
    current = fingerprint()
    try:
        if stamp.read_text() == current:
            return False
    except OSError:
        pass  # no fingerprint yet: whatever is cached there is of unknown origin
    try:
        folder.mkdir(parents=True, exist_ok=True)
        for stem in KERNEL_MODULES:
            for path in [*folder.glob(f"{stem}.*.nbi"), *folder.glob(f"{stem}.*.nbc")]:
                path.unlink(missing_ok=True)
        partial = folder / f"{FINGERPRINT_FILE}.{os.getpid()}.tmp"
        partial.write_text(current)
        os.replace(partial, stamp)  # atomic: concurrent processes read either fingerprint, never half of one
    except OSError:
        return False
    return True


def kernel(function: Callable | None = None, *, refcounts: bool | None = None, **options) -> Callable:
    """``numba.njit(cache=True, **options)`` whose cache is discarded when any kernel source changed.

    Use as ``@kernel`` or ``@kernel(inline="always", fastmath=...)``. The check runs once per process and
    cache folder, before the first kernel of that folder is compiled or loaded (numba loads lazily, at the
    first call, so checking at decoration time is early enough).

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
        dispatcher = numba.njit(cache=True, **options)(py_function)
        folder = dispatcher.stats.cache_path
        if folder not in _checked_folders:
            _checked_folders.add(folder)
            discard_stale_kernels(folder)
        return dispatcher

    return decorate if function is None else decorate(function)
