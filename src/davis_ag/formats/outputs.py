"""The output rule: where a command may write, and how, so that no run loses or replaces data.

Every command that writes (``train``, ``evaluate``, ``export``; ``generate`` through its runner)
claims its output with :func:`claim_output` before any long work:

- **Nothing inside a dataset but the generator's files.** An output that lies in a dataset root
  (a folder with ``dataset.json`` or ``splits.json``) or a scene folder (``annotations.json`` or
  ``scene.json``) is refused: a results file named ``annotations.json`` would replace a scene's
  labels. Only ``generate`` writes there, under its own lock.
- **Nothing replaced without ``--force``.** An existing output (a model, results, a chart, an
  export) is refused in one line naming it, unless the user asked to replace it.
- **One run per output.** The output is locked (:class:`OutputLock`, ``fcntl.flock``) for the
  whole run: a second run on it stops at once with the first one's PID, instead of the two
  racing on the same temporary files. The kernel drops the lock when its holder dies.
- **Temporaries cleaned.** What a killed run left beside the output (``.NAME.tmp`` from
  :mod:`davis_ag.atomic_files`, an export's hidden working folders) is removed under the lock.
"""

from __future__ import annotations

import fcntl
import os
import shutil
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from davis_ag.atomic_files import (
    prove_writable_file,
    prove_writable_folder,
    temporary_sibling,
)
from davis_ag.errors import UserError
from davis_ag.formats.layout import (
    ANNOTATIONS,
    DATASET_FILE,
    LOCK_FILE,
    SCENE_METADATA,
    SPLITS_FILE,
)

#: Files that mark a folder as a dataset root, and those that mark a scene folder.
DATASET_MARKS = (DATASET_FILE, SPLITS_FILE)
SCENE_MARKS = (ANNOTATIONS, SCENE_METADATA)


class OutputLock:
    """An exclusive, non-blocking ``flock`` on a lock file holding the owner's PID.

    Args:
        path: The lock file (its folder must exist).
        doing: What the holder does to the output, for the message ("generated", "written").
        flag: The option that named the output, for the message.
    """

    def __init__(self, path: Path, doing: str = "written", flag: str = "--out", remove: bool = True) -> None:
        self.path, self.doing, self.flag, self.remove = Path(path), doing, flag, remove
        self._fd: int | None = None

    def target(self) -> Path:
        """The output the lock guards: its folder, or the file ``.NAME.lock`` stands for."""
        name = self.path.name
        if name == LOCK_FILE:
            return self.path.parent
        return self.path.with_name(name[1:].removesuffix(".lock"))

    def __enter__(self) -> OutputLock:
        while True:
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "unknown"
                os.close(fd)
                raise UserError(
                    f"{self.target()} is being {self.doing} by another davis-ag run (PID {holder}): "
                    f"wait for it to end or choose another {self.flag}"
                ) from None
            except OSError as error:
                os.close(fd)
                raise UserError(
                    f"cannot lock {self.path} ({error.strerror}): use a local folder for {self.flag}"
                ) from None
            if self._still_linked(fd):
                break
            os.close(fd)  # its holder removed the file as it ended: lock the one there now
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        self._fd = fd
        return self

    def _still_linked(self, fd: int) -> bool:
        """Whether the locked file is still the one at :attr:`path` (a removed lock file locks nothing)."""
        try:
            return os.path.samestat(os.fstat(fd), os.stat(self.path))
        except FileNotFoundError:
            return False

    def __exit__(self, *exc: object) -> None:
        if self._fd is not None:
            if self.remove:  # removed while held: a run that opened it meanwhile sees it unlinked and retries
                self.path.unlink(missing_ok=True)
            os.close(self._fd)  # closing the only descriptor releases the flock
            self._fd = None


def file_lock_path(path: Path) -> Path:
    """The lock file of a single-file output: ``.NAME.lock`` beside it."""
    return path.with_name(f".{path.name}.lock")


def dataset_holding(path: str | os.PathLike[str]) -> Path | None:
    """The dataset root or scene folder ``path`` lies in (or is), else None.

    A folder counts when it holds a file of :data:`DATASET_MARKS` or :data:`SCENE_MARKS`. The path
    is read both as written with its ``..`` collapsed and with its links followed: a path through
    a folder that does not exist yet (``out/new/../DATA/x``) ends in the dataset once the folders
    are made, which the file system cannot tell while ``new`` is missing.
    """
    target = Path(path).expanduser().absolute()
    for candidate in dict.fromkeys((Path(os.path.normpath(target)), Path(os.path.realpath(target)))):
        for folder in (candidate, *candidate.parents):
            try:
                if any((folder / mark).is_file() for mark in DATASET_MARKS + SCENE_MARKS):
                    return folder
            except OSError:  # an unreadable ancestor says nothing either way
                continue
    return None


def check_outside_datasets(path: str | os.PathLike[str], flag: str = "--out") -> Path:
    """Refuse an output path inside a dataset (only ``generate`` writes there).

    Returns:
        The absolute path.

    Raises:
        UserError: naming the dataset folder.
    """
    target = Path(path).expanduser().absolute()
    holder = dataset_holding(target)
    if holder is not None:
        kind = "a scene folder" if any((holder / m).is_file() for m in SCENE_MARKS) else "a dataset"
        raise UserError(
            f"{flag} {target} lies in {holder}, which is {kind}: only davis-ag generate writes "
            "there; choose a path outside the dataset"
        )
    return target


def resolved(path: str | os.PathLike[str]) -> Path:
    """A path as the file system will take it: absolute, links followed, ``..`` collapsed (also
    through folders not made yet), so two spellings of one file compare equal."""
    return Path(os.path.realpath(Path(path).expanduser().absolute()))


def _check_distinct(outputs: Sequence[tuple[Path, str]], reads: Sequence[tuple[Path, str]]) -> None:
    """Refuse an output that is one of the run's inputs, or two outputs that are one file."""
    seen: dict[Path, str] = {}
    for path, flag in outputs:
        real = resolved(path)
        for read, read_flag in reads:
            if resolved(read) == real:
                raise UserError(
                    f"{flag} {path} is {read_flag} {read}, which this run reads: choose another path for the output"
                )
        if real in seen:
            raise UserError(f"{flag} {path} and {seen[real]} name the same file: give each output its own path")
        seen[real] = f"{flag} {path}"


def _exists(path: Path, ignore: Sequence[str]) -> bool:
    """Whether an output is already there: a file, or a folder holding anything but ``ignore``."""
    if path.is_dir():
        return any(p.name not in ignore for p in path.iterdir())
    return os.path.lexists(path)


@contextmanager
def claim_output(
    path: str | os.PathLike[str],
    *,
    force: bool = False,
    flag: str = "--out",
    folder: bool = False,
    also: Sequence[tuple[Path, str]] = (),
    temporaries: Sequence[str] = (),
    reads: Sequence[tuple[Path, str]] = (),
) -> Iterator[Path]:
    """Claim an output for one run by :mod:`the output rule <davis_ag.formats.outputs>`.

    Args:
        path: The output (a file, or with ``folder`` a folder).
        force: Replace an existing output instead of refusing.
        flag: The option that named it, for the messages.
        folder: The output is a folder (an export), locked by its ``.davis_ag.lock``.
        also: Further files the run writes, ``(path, flag)``: checked like ``path``, their
            temporaries cleaned (e.g. evaluate's chart).
        temporaries: Glob patterns, relative to a folder output, of what a killed run leaves
            (hidden working folders and files); removed under the lock.
        reads: The run's input files, ``(path, flag)``: no output may be one of them, however
            spelt (``..``, links), even with ``force``.

    Yields:
        The absolute path, locked for the run.

    Raises:
        UserError: for a path inside a dataset, an unwritable path, an output that is an input
            or another output, an existing output without ``force``, or another run holding the
            output.
    """
    target = Path(path).expanduser().absolute()
    files = [(target, flag), *[(Path(p).expanduser().absolute(), f) for p, f in also]]
    _check_distinct(files, reads)
    for each, each_flag in files:
        check_outside_datasets(each, each_flag)
        if folder and each == target:
            prove_writable_folder(each, each_flag)
        else:
            prove_writable_file(each, each_flag)
    if folder:
        target.mkdir(parents=True, exist_ok=True)
        lock = OutputLock(target / LOCK_FILE, "written", flag)
    else:
        target.parent.mkdir(parents=True, exist_ok=True)
        lock = OutputLock(file_lock_path(target), "written", flag)
    with lock:
        for each, _ in files:
            temporary_sibling(each).unlink(missing_ok=True)
        for pattern in temporaries if folder else ():
            for left in target.glob(pattern):
                if left.is_dir() and not left.is_symlink():
                    shutil.rmtree(left, ignore_errors=True)
                else:
                    left.unlink(missing_ok=True)
        if not force:
            for each, each_flag in files:
                if _exists(each, (LOCK_FILE,)):
                    raise UserError(
                        f"{each_flag} {each} already exists: give --force to replace it, or choose another path"
                    )
        yield target
