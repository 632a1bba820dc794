"""Where the workbench's compiled numba kernels live: one per-user cache folder, keyed by the code.

numba caches machine code beside the sources by default (``__pycache__``). In an installed workbench that is
site-packages: a read-only (system or shared) install cannot cache at all, and the files numba leaves there
survive ``pip uninstall`` (they are not in the install's record), so that a later editable install is shadowed by
the leftover package folders. Here every kernel's machine code goes to

    ROOT / GROUP-HASH /

instead, where ROOT is, in this order, the folder named by the environment variable IES_CACHE_DIR (the workbench's
own setting), ``$NUMBA_CACHE_DIR/ies-workbench`` where NUMBA_CACHE_DIR is set, or the platform's per-user cache
folder (``platformdirs.user_cache_dir``: ``$XDG_CACHE_HOME/ies-workbench``, by default
``~/.cache/ies-workbench`` on Linux). GROUP is a set of kernels that may embed each other (``sim``: the
integrators; ``scans``, ``bem_contact``: their own kernels), HASH the SHA-256 of the group's sources: for ``sim``
the simulator's code version (`code_version`, every source of the package: the hash `ies --version` prints and every
study task's key holds), for the others their kernels' files. A kernel is found again when the sources are the same,
wherever they are installed: a reinstall of the same code compiles nothing, and an edit of any source of the group
gets a new folder (numba's own key follows one file only). The kernels themselves are stamped with the hash of the
sources they are compiled from (for ``sim`` the kernel files alone, `sim.integration.jit.fingerprint`): a new folder
of a version whose kernel sources an existing folder was compiled from gets that folder's machine code (hard links,
`KERNEL_STAMP`), so an edit of the simulator outside its kernels compiles nothing either. Nothing is ever written
into the installed package. Where ROOT cannot be written, the system's temporary folder is used (said once on
stderr); where neither can, the kernels are compiled in every process.

A folder not used for PRUNE_AFTER_DAYS days is deleted when another folder of its group is made (an older
version of the code); `ies cache` shows the folders and their sizes and empties them (`clear`).

numba's cache machinery is used as it is (``numba.core.caching``: the index and data files, their atomic writes,
the key on signature, CPU and bytecode); only its locator, which says where the files go and what the source's
stamp is, is ours.
"""
from __future__ import annotations

import functools
import hashlib
import inspect
import os
import re
import shutil
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterable

#: the workbench's setting for the cache folder (an environment variable, as numba's NUMBA_CACHE_DIR)
SETTING = "IES_CACHE_DIR"
APP_NAME = "ies-workbench"
#: a version folder is GROUP-HASH16
_VERSION_FOLDER = re.compile(r"^(?P<group>[a-z_]+)-(?P<hash>[0-9a-f]{16})$")
#: file in a version folder whose modification time says when a process last used it
LAST_USED = "last-used"
#: file in a version folder holding the hash its kernels are stamped with (the sources they are compiled from)
KERNEL_STAMP = "kernel-sources"
PRUNE_AFTER_DAYS = 30.0
#: files numba and this module write into a version folder (anything else there is left alone by `clear`)
_OURS = re.compile(r"(\.nbi|\.nbc|\.tmp\.[0-9a-f]+)$|^(" + LAST_USED + "|" + KERNEL_STAMP + ")$|^tmp")
#: the simulator's package: every source file in it is part of its code version
_SIM_DIR = Path(__file__).resolve().parents[1]


def code_version() -> str:
    """The simulator's code version: the first 16 hex digits of the SHA-256 of every source file of `sim` (its path in
    the package and its content), read now. The one name of the simulator's code: `ies --version` prints it, `ies
    cache` and the kernel folder (``sim-VERSION``) carry it, and every study task's key holds it (`uq.problem.models`)."""
    digest = hashlib.sha256()
    for path in sorted(_SIM_DIR.rglob("*.py")):
        digest.update(path.relative_to(_SIM_DIR).as_posix().encode() + b"\0")
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def cache_root() -> tuple[Path, str]:
    """The kernel cache folder and what chose it (IES_CACHE_DIR, NUMBA_CACHE_DIR or the per-user default)."""
    if os.environ.get(SETTING):
        return Path(os.environ[SETTING]).expanduser(), SETTING
    if os.environ.get("NUMBA_CACHE_DIR"):
        return Path(os.environ["NUMBA_CACHE_DIR"]).expanduser() / APP_NAME, "NUMBA_CACHE_DIR"
    import platformdirs

    return Path(platformdirs.user_cache_dir(APP_NAME, appauthor=False)), "the per-user cache folder"


def _fallback_root() -> Path:
    """The system's temporary folder, per user (used where the chosen root cannot be written)."""
    user = os.getuid() if hasattr(os, "getuid") else os.environ.get("USERNAME", "user")
    return Path(tempfile.gettempdir()) / f"{APP_NAME}-{user}"


def sources_hash(paths: Iterable[Path]) -> str:
    """SHA-256 (hex) of the names and contents of `paths`, in the order given."""
    digest = hashlib.sha256()
    for path in paths:
        digest.update(Path(path).name.encode() + b"\0")
        digest.update(Path(path).read_bytes())
    return digest.hexdigest()


def _writable(folder: Path) -> bool:
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


def _touch(path: Path) -> None:
    try:
        if not path.exists() or time.time() - path.stat().st_mtime > 3600.0:
            path.touch()
    except OSError:
        pass


def _prune(root: Path, group: str, keep: str) -> None:
    """Delete the folders of `group` in `root` other than `keep` that no process used for PRUNE_AFTER_DAYS."""
    cutoff = time.time() - PRUNE_AFTER_DAYS * 86400.0
    for folder in root.glob(f"{group}-*"):
        match = _VERSION_FOLDER.match(folder.name)
        if not match or match["group"] != group or folder.name == keep:
            continue
        if _last_used(folder) < cutoff:
            _remove_version_folder(folder)


def _last_used(folder: Path) -> float:
    """When a process last used the version folder (its LAST_USED mark, else the folder's own time), epoch s."""
    try:
        return (folder / LAST_USED).stat().st_mtime
    except OSError:
        return folder.stat().st_mtime


def folder_name(group: str, code_hash: str) -> str:
    """The name of `group`'s version folder for sources with SHA-256 `code_hash`."""
    return f"{group}-{code_hash[:16]}"


_said_fallback = False


@functools.lru_cache(maxsize=None)
def version_folder(group: str, code_hash: str, stamp: str | None = None) -> Path | None:
    """The folder of `group`'s kernels for the code with hash `code_hash` (hex; its first 16 digits name it), made if
    needed (and marked as used); None where neither the cache root nor the temporary fallback can be written.
    stamp: the hash of the sources the kernels are compiled from, when it is not `code_hash` (the simulator's kernel
    files): a new folder gets the machine code of the latest folder of the group with the same stamp (`_seed`)."""
    global _said_fallback
    name = folder_name(group, code_hash)
    root, _ = cache_root()
    for candidate in (root, _fallback_root()):
        folder = candidate / name
        new = not folder.exists()
        if _writable(folder):
            if candidate != root and not _said_fallback:
                _said_fallback = True
                sys.stderr.write(f"ies: the kernel cache folder {root} cannot be written; using {candidate} (set "
                                 f"{SETTING} to a writable folder)\n")
            _touch(folder / LAST_USED)
            if stamp is not None and not (folder / KERNEL_STAMP).exists():
                _seed(folder, group, stamp)
            if new:
                _prune(candidate, group, name)
            return folder
    if not _said_fallback:
        _said_fallback = True
        sys.stderr.write(f"ies: no kernel cache folder can be written ({root}, {_fallback_root()}): the kernels are "
                         f"compiled in every process (set {SETTING} to a writable folder)\n")
    return None


def _seed(folder: Path, group: str, stamp: str) -> None:
    """Give the new version folder `folder` the machine code of the most recently used folder of `group` beside it
    whose kernels carry `stamp` (hard links, copies across file systems), then mark it with the stamp; numba checks
    the stamp of every index it loads, so a wrong file is never used, only compiled again."""
    others = [p for p in folder.parent.glob(f"{group}-*") if p != folder and _VERSION_FOLDER.match(p.name)]
    for other in sorted(others, key=_last_used, reverse=True):
        try:
            if _stamp_of(other) != stamp[:16]:
                continue
            for path in other.iterdir():
                if path.suffix in (".nbi", ".nbc") and not (folder / path.name).exists():
                    try:
                        os.link(path, folder / path.name)
                    except OSError:
                        shutil.copy2(path, folder / path.name)
        except OSError:
            continue  # pruned or cleared meanwhile: compiled as if new
        break
    try:
        (folder / KERNEL_STAMP).write_text(stamp + "\n")
    except OSError:
        pass


def _stamp_of(folder: Path) -> str:
    """The first 16 digits of the stamp a version folder's kernels carry: its KERNEL_STAMP file, else the hash in its
    name (a folder named by its kernels' sources, as every folder was before the simulator's were named by its code
    version)."""
    try:
        return (folder / KERNEL_STAMP).read_text().strip()[:16]
    except FileNotFoundError:
        return folder.name.rsplit("-", 1)[-1]


@functools.lru_cache(maxsize=None)
def _cache_class(folder: str, stamp: str) -> type:
    """numba's FunctionCache with a locator that puts the files into `folder`, stamped with the code's hash."""
    from numba.core.caching import CompileResultCacheImpl, FunctionCache, _CacheLocator

    class Locator(_CacheLocator):
        def __init__(self, py_func: Callable, py_file: str) -> None:
            self._lineno = py_func.__code__.co_firstlineno

        def get_cache_path(self) -> str:
            return folder

        def get_source_stamp(self) -> str:
            return stamp

        def get_disambiguator(self) -> str:
            return str(self._lineno)

        @classmethod
        def from_function(cls, py_func: Callable, py_file: str) -> "Locator":
            return cls(py_func, py_file)

    class Impl(CompileResultCacheImpl):
        _locator_classes = [Locator]

    class KernelCache(FunctionCache):
        _impl_class = Impl

    return KernelCache


def cache_in_folder(dispatcher, group: str, code_hash: str, stamp: str | None = None):
    """Give a numba dispatcher (compiled without ``cache=True``) its on-disk cache in `group`'s version folder for
    `code_hash`, stamped with `stamp` (the hash of the kernels' sources; default `code_hash`); without a writable
    folder it stays uncached. Returns the dispatcher."""
    folder = version_folder(group, code_hash, stamp)
    if folder is not None:
        dispatcher._cache = _cache_class(str(folder), stamp or code_hash)(dispatcher.py_func)
    return dispatcher


def cached_njit(function: Callable | None = None, **options) -> Callable:
    """``numba.njit(**options)`` with its machine code in the kernel cache: group = the function's top-level
    package, key = the SHA-256 of its source file. For kernels that embed no other file's kernels (those of
    `sim.integration` use `sim.integration.jit.kernel`, whose key covers all their files)."""
    import numba

    def decorate(py_function: Callable) -> Callable:
        source = Path(inspect.getfile(py_function))
        group = py_function.__module__.split(".")[0]
        return cache_in_folder(numba.njit(**options)(py_function), group, _file_hash(str(source)))

    return decorate if function is None else decorate(function)


@functools.lru_cache(maxsize=None)
def _file_hash(path: str) -> str:
    return sources_hash([Path(path)])


# ---- what `ies cache` shows and clears ----------------------------------------------------------------------

@dataclass(frozen=True)
class VersionFolder:
    """One code version's kernels in the cache: its folder, group, size (bytes), files and last use (s since the
    epoch)."""

    path: Path
    group: str
    size: int
    files: int
    last_used: float


def version_folders(root: Path | None = None) -> list[VersionFolder]:
    """The version folders in `root` (default: `cache_root`), most recently used first."""
    root = cache_root()[0] if root is None else root
    found = []
    if not root.is_dir():
        return found
    for folder in root.iterdir():
        match = _VERSION_FOLDER.match(folder.name)
        if not (match and folder.is_dir()):
            continue
        files = [path for path in folder.iterdir() if path.is_file()]
        found.append(VersionFolder(folder, match["group"], sum(path.stat().st_size for path in files), len(files),
                                   _last_used(folder)))
    return sorted(found, key=lambda entry: -entry.last_used)


def disk_size(entries: Iterable[VersionFolder]) -> int:
    """Bytes the version folders `entries` take on disk: a file shared by several (a hard link of `_seed`) once."""
    seen: dict[tuple[int, int], int] = {}
    for entry in entries:
        for path in entry.path.iterdir():
            try:
                stat = path.stat()
            except OSError:
                continue
            if path.is_file():
                seen[(stat.st_dev, stat.st_ino)] = stat.st_size
    return sum(seen.values())


def _remove_version_folder(folder: Path) -> int:
    """Delete the files numba and this module wrote in `folder`, then the folder if empty; returns bytes freed."""
    freed = 0
    try:
        for path in folder.iterdir():
            if path.is_file() and _OURS.search(path.name):
                size = path.stat().st_size
                path.unlink(missing_ok=True)
                freed += size
        folder.rmdir()
    except OSError:
        pass  # in use by another process, or a file that is not ours: left
    return freed


def clear(root: Path | None = None) -> tuple[int, int]:
    """Delete the version folders in `root` (default: `cache_root`); returns (folders, bytes) removed. Only the files
    numba and this module write are deleted; a folder holding anything else stays."""
    removed = freed = 0
    for entry in version_folders(root):
        freed += _remove_version_folder(entry.path)
        removed += not entry.path.exists()
    version_folder.cache_clear()
    return removed, freed
