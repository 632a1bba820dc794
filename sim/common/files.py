"""The one way every stage writes a file: atomically, with the permissions a user expects.

A file is written to a new temporary file beside its target and renamed onto it (`os.replace`) only when
the writing succeeded, so a reader never sees half a file and a failure leaves the old file (or nothing).
The temporary file is created with mode 0666 and the process umask applied by the kernel (0644 under the
usual umask 022), as `open()` would; `tempfile.mkstemp` would give 0600. No fsync: the files are results,
not a database; an interrupted write leaves a hidden ``.NAME.*`` temporary file at worst.

It lives in `sim` because `sim` stands alone (it imports no other stage): scans, bem_contact and uq may
all import it without a cycle, while scans and sim must never import uq (the pipeline's arrows,
tests/test_architecture.py). JSON for machines (`dumps`: numpy values and NaN made plain), CSV tables (`write_csv`) and
matplotlib figures (`save_figure`, `plot_to`, Agg back end) are written through it too.
"""
from __future__ import annotations

import csv
import errno
import io
import json
import math
import os
import secrets
import signal
import sys
import tempfile
import threading
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator, Sequence, TypeVar

import numpy as np

#: mode of a new file before the umask is applied (what `open(path, "w")` uses)
NEW_FILE_MODE = 0o666
#: errno values of a machine that cannot take a file (read-only or full disk, quota, too large, I/O): exit code 3
RESOURCE_ERRNOS = (errno.EROFS, errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO)

T = TypeVar("T")


def read_text(path: str | os.PathLike, kind: str, fmt: str, hint: str = "") -> str:
    """The UTF-8 text of a user's input file, without the byte-order mark spreadsheets write; a missing file, a
    folder or a binary file is one line (SimulationInputError) naming the file, its `kind` (e.g. "modal file"), the
    format `fmt` and a `hint`."""
    from sim.common.errors import SimulationInputError

    path = Path(path)
    try:
        return path.read_bytes().decode("utf-8-sig")
    except FileNotFoundError:
        raise SimulationInputError(f"{kind} {path} not found{hint}") from None
    except IsADirectoryError:
        raise SimulationInputError(f"{path} is a folder, not a {kind}") from None
    except UnicodeDecodeError:
        raise SimulationInputError(f"{path}: not a text (UTF-8 {fmt}) file") from None


#: whether `interrupts_held` holds Ctrl-C back now (in the main thread; nested holds are one)
_holding = False


@contextmanager
def interrupts_held() -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) back while the block runs, and deliver it when the block ends: as KeyboardInterrupt
    under Python's default handler (or to whatever handler was there). Every writer runs its writing inside one, so
    that an interrupt never fires inside a file's writer (HDF5, matplotlib, ...), where it leaves a library in a state
    that can end the interpreter with a fatal error at exit instead of one line. Outside the main thread (where
    signals cannot be handled) and inside another hold it does nothing."""
    global _holding
    if _holding or threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: caught.append(signum))
    _holding = True
    try:
        yield
    finally:
        _holding = False
        signal.signal(signal.SIGINT, previous)
        if caught:
            if callable(previous):
                previous(signal.SIGINT, None)  # Python's default handler raises KeyboardInterrupt
            elif previous == signal.SIG_DFL:
                os.kill(os.getpid(), signal.SIGINT)


@contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a new empty temporary file beside `path` for the caller to write (by its name); on success it
    is renamed onto `path`, on any exception it is removed and `path` is left untouched. Ctrl-C is held back
    while the file is written and renamed (`interrupts_held`): a file is whole or absent, and an interrupt
    arrives between files.

    Raises FileNotFoundError (folder missing) or IsADirectoryError (`path` is a folder) with a one-line
    message before anything is created.
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise FileNotFoundError(errno.ENOENT, f"cannot write {target}: folder {folder} does not exist; create it or "
                                   "choose another path")
    if target.is_dir():
        raise IsADirectoryError(errno.EISDIR, f"cannot write {target}: it is a folder; give a file name")
    with interrupts_held():
        try:
            tmp = _new_temporary_file(folder, target)
        except OSError as exc:
            raise _naming(exc, target) from None
        try:
            yield tmp
            os.replace(tmp, target)
        except OSError as exc:
            tmp.unlink(missing_ok=True)
            raise _naming(exc, target) from None  # the user's file, not the hidden temporary one
        except BaseException:
            tmp.unlink(missing_ok=True)
            raise


def _naming(exc: OSError, target: Path) -> OSError:
    """The same error (type, errno, reason) naming `target` instead of a temporary file."""
    if exc.errno is None:
        return exc
    return type(exc)(exc.errno, exc.strerror or os.strerror(exc.errno), str(target))


def check_writable(path: str | os.PathLike, option: str, *, folder: bool = False) -> None:
    """Prove before any work that a file can be written at `path` (a file, or with `folder` a folder that
    exists): a temporary file is created in its folder and removed again. A missing folder or a folder in
    place of the file is one SimulationInputError line (exit 2); a read-only or full disk one
    ResourceFailure line (exit 3), both naming `option` (e.g. "--plot") and saying nothing was computed."""
    from sim.common.errors import ResourceFailure, SimulationInputError

    target = Path(path)
    where = target if folder else (target.parent if str(target.parent) else Path("."))
    if not where.is_dir():
        raise SimulationInputError(f"{option} {path}: folder {where} does not exist; create it or choose another path "
                                   "(nothing was computed)")
    if not folder and target.is_dir():
        raise SimulationInputError(f"{option} {path} is a folder; give a file name (nothing was computed)")
    try:
        _new_temporary_file(where, target if not folder else where / "probe").unlink()
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        if exc.errno in RESOURCE_ERRNOS:
            raise ResourceFailure(f"cannot write {option} {path} ({reason}); choose another folder (nothing was "
                                  "computed)") from None
        raise SimulationInputError(f"cannot write {option} {path} ({reason}); choose another folder (nothing was "
                                   "computed)") from None


def write_or_fallback(write: Callable[[Path], T], folder: str | os.PathLike, what: str) -> T:
    """`write(folder)` for results that took long to compute; if the disk refuses them (read-only, full:
    RESOURCE_ERRNOS), `write` into a new folder ``ies-WHAT-*`` in the system's temporary folder and raise one
    ResourceFailure line naming it, so that nothing computed is lost."""
    from sim.common.errors import ResourceFailure

    try:
        return write(Path(folder))
    except OSError as exc:
        if exc.errno not in RESOURCE_ERRNOS:
            raise
        failed = f"cannot write {exc.filename or folder} ({exc.strerror or exc})"
    spare = Path(tempfile.mkdtemp(prefix=f"ies-{what}-"))
    try:
        write(spare)
    except OSError as again:
        raise ResourceFailure(f"{failed}, nor into the fallback {spare} ({again.strerror or again}); the results "
                              "are lost: free space or choose another --out") from None
    raise ResourceFailure(f"{failed}; the results were written to {spare} instead")


def _new_temporary_file(folder: Path, target: Path) -> Path:
    """A new empty file `.STEM.RANDOM.SUFFIX` in `folder`, created exclusively with NEW_FILE_MODE & ~umask."""
    while True:
        tmp = folder / f".{target.stem}.{secrets.token_hex(4)}{target.suffix}"
        try:
            os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, NEW_FILE_MODE))
        except FileExistsError:
            continue
        return tmp


def write_bytes(path: str | os.PathLike, data: bytes) -> Path:
    """Write `data` to `path` atomically; returns the path."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)


def write_text(path: str | os.PathLike, text: str) -> Path:
    """Write `text` (UTF-8) to `path` atomically; returns the path."""
    return write_bytes(path, text.encode("utf-8"))


def to_jsonable(obj: Any) -> Any:
    """Convert numpy scalars/arrays (and NaN/inf, which JSON lacks, to None) into plain JSON values."""
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        value = float(obj)
        return value if math.isfinite(value) else None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def dumps(obj: Any) -> str:
    """One JSON object as indented text (numpy values made plain, NaN written as null)."""
    return json.dumps(to_jsonable(obj), indent=2, allow_nan=False)


def csv_value(value: Any) -> str:
    """A table cell: numpy integers and booleans as integers, finite floats by repr (exact round trip),
    NaN and inf as "nan", anything else by str."""
    if isinstance(value, (np.integer, np.bool_)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return repr(float(value)) if math.isfinite(value) else "nan"
    return str(value)


def write_csv(path: str | os.PathLike, header: Sequence[str], rows: Iterable[Sequence[Any]], comment: str = "") -> Path:
    """A CSV table (optional `# comment` lines first, one header line, `csv_value` cells, "\\n" line ends) written
    atomically; returns the path."""
    buffer = io.StringIO()
    buffer.writelines(f"# {line}\n" for line in comment.splitlines())
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    writer.writerows([csv_value(v) for v in row] for row in rows)
    return write_text(path, buffer.getvalue())


def write_json(path: str | os.PathLike, data: Any) -> Path:
    """One JSON object (`dumps`) and a line end, written atomically; returns the path."""
    return write_text(path, dumps(data) + "\n")


def read_rows(path: str | os.PathLike) -> list[dict[str, str]]:
    """The rows of a CSV table as `write_csv` writes it, each a dict by column (cells as text). A file cut short (no
    line end after its last row, a row with fewer cells than the header) or damaged (a row with more) is one line
    (SimulationInputError) naming the file and the line, instead of a row whose missing cells read as None."""
    from sim.common.errors import SimulationInputError

    path = Path(path)
    text = path.read_text(encoding="utf-8")
    if not text:
        raise SimulationInputError(f"{path} is empty (cut short?); rerun the command that wrote it")
    reader = csv.DictReader(io.StringIO(text))
    rows = []
    for row in reader:
        if None in row or None in row.values():
            cells = sum(1 for key, value in row.items() if key is not None and value is not None) + len(row.get(None, ()))
            raise SimulationInputError(f"{path}: line {reader.line_num} has {cells} cells but the header names "
                                       f"{len(reader.fieldnames or ())} columns (cut short or damaged); rerun the command "
                                       "that wrote it")
        rows.append(row)
    if not text.endswith("\n"):
        raise SimulationInputError(f"{path}: line {reader.line_num} ends without a line end (the file was cut short); "
                                   "rerun the command that wrote it")
    return rows


def report_written(paths: Iterable[str | os.PathLike], *, json_mode: bool = False) -> None:
    """One confirmation line ``wrote PATH`` per file a command wrote: on stdout after a text report, on stderr
    when stdout carries one JSON object (`json_mode`)."""
    stream = sys.stderr if json_mode else sys.stdout
    for path in paths:
        stream.write(f"wrote {path}\n")


def save_figure(fig: Any, path: str | os.PathLike) -> Path:
    """Save a matplotlib figure atomically (format from the file suffix, e.g. .png, .pdf; 150 dpi)."""
    target = Path(path)
    with atomic_path(target) as tmp:
        fig.savefig(tmp, format=target.suffix.lstrip(".") or "png", dpi=150, bbox_inches="tight")
    return target


def pyplot() -> Any:
    """matplotlib.pyplot on the Agg back end (files only, no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


@contextmanager
def plot_to(path: str | os.PathLike, figsize: tuple[float, float] = (6.0, 4.0)) -> Iterator[tuple[Any, Any]]:
    """Yield (figure, axes) of a new matplotlib figure (Agg back end, constrained layout: titles, labels and
    legends outside the axes get their room); on success it is saved atomically to `path` (format from the
    suffix), and it is always closed."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=figsize, layout="constrained")
    try:
        yield fig, ax
        save_figure(fig, path)
    finally:
        plt.close(fig)
