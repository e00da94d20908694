"""The exceptions the command line turns into a one-line message, each class with its exit status.

docs/errors.md lists the classes and their exit statuses: bad input 2, a failure of the machine 1,
a stop asked for by a signal 128 + the signal's number.
"""

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any


class UserError(Exception):
    """Bad input or an unusable environment: the message says what, where and how to fix it.

    The command line prints it as a single line and exits with status 2, never with a traceback.
    """


class MachineError(UserError):
    """The machine failed the run (a full disk, a folder gone), not its input: one line naming
    what was kept and where, exit status 1."""


class Stopped(KeyboardInterrupt):
    """SIGTERM (or SIGINT) asked the run to stop: raised in the main thread by the command line's
    handler, so every ``finally`` and ``with`` unwinds (locks released, temporaries removed,
    worker processes ended) before the one line that says what was kept. A KeyboardInterrupt, so
    code that stops cleanly on Ctrl-C (Stable-Baselines3, the worker pool) does so on SIGTERM too.

    Args:
        signal_number: The signal that asked.
    """

    def __init__(self, signal_number: int) -> None:
        super().__init__(signal_number)
        self.signal_number = signal_number


#: Stops asked for while held (:func:`stops_held`): the signal number of the first, or None.
_held: dict[str, Any] = {"depth": 0, "pending": None}


def stop(signal_number: int) -> None:
    """Raise :class:`Stopped` for a signal, or, inside :func:`stops_held`, as soon as it ends.

    The command line's SIGTERM/SIGINT handler calls this (``davis_ag.cli``)."""
    if _held["depth"]:
        _held["pending"] = _held["pending"] or signal_number
        return
    raise Stopped(signal_number)


@contextmanager
def stops_held() -> Iterator[None]:
    """Defer a stop while a step that must not be cut in half runs (spawning worker processes:
    a child whose start is cut short prints a traceback); the stop takes effect at its end."""
    _held["depth"] += 1
    try:
        yield
    finally:
        _held["depth"] -= 1
        pending = _held["pending"]
        if not _held["depth"] and pending is not None:
            _held["pending"] = None
            raise Stopped(pending)


def yaml_problem(error: Exception) -> str:
    """A YAML parser's error in a few words, with its line and column: PyYAML's own text spans
    several lines (the context, the faulty line, a caret)."""
    mark = getattr(error, "problem_mark", None)
    where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
    problem = getattr(error, "problem", None) or "not valid YAML"
    return f"not valid YAML{where}: {problem}"
