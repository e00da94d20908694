"""Atomic file writes, output paths proven writable before long work, and rescued results.

Atomic writes: a temporary sibling file, flushed to disk, then renamed over the target.

A reader, or a run that was killed midway, sees the old file or the new one, never half of one.
The temporary file is always ``.NAME.tmp`` beside the target, so a run can recognise and clear
what a killed run left.
"""

from __future__ import annotations

import errno
import json
import os
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

from davis_ag.errors import MachineError, UserError


def temporary_sibling(path: Path) -> Path:
    """The temporary file a write of ``path`` goes through."""
    return path.with_name(f".{path.name}.tmp")


@contextmanager
def atomic_output(path: str | os.PathLike[str], mode: str = "wb") -> Iterator[IO[Any]]:
    """Open a temporary sibling of ``path`` for writing; on success it replaces ``path``.

    Args:
        path: The file to write; its folder is created if missing.
        mode: ``"wb"`` or ``"w"``.

    Yields:
        The open file. If the body raises, the temporary file is removed and ``path`` is untouched.
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = temporary_sibling(target)
    try:
        with open(tmp, mode) as handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp, target)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically; returns the path."""
    with atomic_output(path, "wb") as handle:
        handle.write(data)
    return Path(path)


def write_text_atomic(path: str | os.PathLike[str], text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically; returns the path."""
    return write_bytes_atomic(path, text.encode("utf-8"))


def write_json_atomic(path: str | os.PathLike[str], data: Any, indent: int = 1) -> Path:
    """Write ``data`` as JSON (with a final newline) to ``path`` atomically; returns the path."""
    return write_text_atomic(path, json.dumps(data, indent=indent) + "\n")


def save_figure_atomic(figure: Any, path: str | os.PathLike[str], dpi: float | None = None) -> Path:
    """Save a matplotlib figure atomically, in the format the path's suffix names (PNG when none).

    Args:
        figure: A matplotlib ``Figure``.
        path: The file to write.
        dpi: Dots per inch; ``None`` keeps the figure's own.

    Returns:
        The path.

    Raises:
        UserError: when the file cannot be written (a folder in the way, no permission).
    """
    out = Path(path)
    fmt = out.suffix.lstrip(".").lower() or "png"
    try:
        with atomic_output(out, "wb") as handle:
            figure.savefig(handle, format=fmt, **({} if dpi is None else {"dpi": dpi}))
    except OSError as error:
        kind = MachineError if is_machine_failure(error) else UserError
        raise kind(
            f"{out}: cannot write the figure ({error.strerror or error}); free the space or choose another output path"
        ) from None
    return out


#: errno values that mean the machine failed the write (space, quota, the device), not the path.
MACHINE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EIO, errno.EROFS, errno.ENODEV, errno.ESTALE})


def is_machine_failure(error: OSError) -> bool:
    """Whether an ``OSError`` is the machine's (a full disk, a failing device), exit status 1."""
    return error.errno in MACHINE_ERRNOS


def read_page(path: str | os.PathLike[str], flag: str) -> str:
    """The text of a page a command rewrites (a Markdown page with measured sections).

    Raises:
        UserError: one line when it cannot be read or is not UTF-8 text.
    """
    try:
        return Path(path).read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise UserError(f"{flag} {path}: not UTF-8 text, so not a page of ours to rewrite; give another") from None
    except OSError as error:
        raise UserError(f"{flag} {path}: cannot read it ({error.strerror or error})") from None


def write_marked_section(doc: str | os.PathLike[str], marker: str, text: str) -> None:
    """Replace what lies between ``<!-- MARKER:start -->`` and ``<!-- MARKER:end -->`` in a file.

    This is how measured numbers reach Markdown pages: the code that measured them writes them
    between markers, and the rest of the page stays as written.

    Raises:
        UserError: when the file lacks either marker.
    """
    doc = Path(doc)
    content = read_page(doc, "page")
    start, end = f"<!-- {marker}:start -->", f"<!-- {marker}:end -->"
    if start not in content or end not in content:
        raise UserError(f"{doc} has no {start} ... {end} section to write into")
    head, rest = content.split(start, 1)
    _, tail = rest.split(end, 1)
    write_text_atomic(doc, f"{head}{start}\n{text}\n{end}{tail}")


# ---------------------------------------------------------------------------------------------
# Proving an output path writable, and keeping a result whose final write failed


#: Name prefix of the short-lived file that proves a folder writable (others must ignore it).
PROBE_PREFIX = ".davis_ag-write-test-"


def _nearest_existing(path: Path) -> Path:
    """``path`` or its nearest ancestor that exists."""
    for candidate in (path, *path.parents):
        if os.path.lexists(candidate):
            return candidate
    return Path(path.anchor or "/")


def _try_create_file_in(folder: Path) -> str | None:
    """Create and remove a temporary file in ``folder``; None when that worked, else the reason.

    ``os.access`` cannot answer this: as root it says yes to ``/proc`` and to read-only mounts.
    """
    try:
        handle, name = tempfile.mkstemp(prefix=PROBE_PREFIX, dir=folder)
    except OSError as error:
        return error.strerror or type(error).__name__
    os.close(handle)
    os.unlink(name)
    return None


def prove_writable_folder(path: str | os.PathLike[str], flag: str = "--out") -> Path:
    """Check that a folder can be written (made if missing) before any long work, creating nothing.

    A temporary file is created and removed in the folder, or in its nearest existing ancestor
    when it does not exist yet (the folder itself is made later, by the work).

    Args:
        path: The folder.
        flag: The option the path came from, for the message.

    Returns:
        The absolute path.

    Raises:
        UserError: when the path is a file, lies under a file, or cannot be written.
    """
    target = Path(path).expanduser().absolute()
    existing = _nearest_existing(target)
    if not existing.is_dir():
        what = "is a file" if existing == target else f"lies under {existing}, which is a file"
        raise UserError(f"{flag} {target} {what}: choose a folder")
    reason = _try_create_file_in(existing)
    if reason:
        raise UserError(f"{flag} {target}: cannot write in {existing} ({reason}): choose a writable folder")
    return target


def prove_writable_file(path: str | os.PathLike[str], flag: str = "--out") -> Path:
    """Check that a file can be written before any long work, creating nothing that stays.

    Args:
        path: The file.
        flag: The option the path came from, for the message.

    Returns:
        The absolute path.

    Raises:
        UserError: when the path is a folder, lies under a file, or its folder cannot be written.
    """
    target = Path(path).expanduser().absolute()
    if target.is_dir():
        raise UserError(f"{flag} {target} is a folder: give a file name, e.g. {target / 'out'}")
    existing = _nearest_existing(target.parent)
    if not existing.is_dir():
        raise UserError(f"{flag} {target} lies under {existing}, which is a file: choose another path")
    reason = _try_create_file_in(existing)
    if reason:
        raise UserError(f"{flag} {target}: cannot write in {existing} ({reason}): choose a writable path")
    return target


def rescue_folder() -> Path:
    """Where results are kept when their own path cannot be written: a fresh folder in the
    user's cache (``$XDG_CACHE_HOME`` or ``~/.cache``), else the system's temporary folder."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    for base in (
        Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "davis-ag" / "rescued",
        Path(tempfile.gettempdir()),
    ):
        try:
            base.mkdir(parents=True, exist_ok=True)
            return Path(tempfile.mkdtemp(prefix=f"davis-ag-{stamp}-", dir=base))
        except OSError:
            continue
    raise UserError("no folder is writable: neither ~/.cache nor the temporary folder")


def write_or_rescue(
    path: str | os.PathLike[str], write: Callable[[Path], object], what: str, survivor: Callable[[], str] | None = None
) -> Path:
    """Write a result that took long to make; when its path fails, keep it elsewhere and say so.

    Args:
        path: Where the result should go.
        write: Writes the result to the path it is given (atomically, ideally).
        what: What the result is, for the message (e.g. "the trained model").
        survivor: When neither place takes it, what survives of the work and how to go on (e.g.
            a training run's last checkpoint); by default, that the result is lost.

    Returns:
        ``path`` when written there.

    Raises:
        MachineError: naming the failure and the file the result was kept in instead.
    """
    target = Path(path)
    try:
        write(target)
        return target
    except OSError as error:
        reason = error.strerror or str(error)
    kept = rescue_folder() / target.name
    try:
        write(kept)
    except OSError as error:
        left = survivor() if survivor is not None else f"{what} is lost; free space and run again"
        raise MachineError(
            f"cannot write {what} to {target} ({reason}) nor to {kept} ({error.strerror or error}): {left}"
        ) from None
    raise MachineError(f"cannot write {what} to {target} ({reason}); it was kept in {kept}: move it where you want it")
