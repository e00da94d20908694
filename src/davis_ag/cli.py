"""The ``davis-ag`` command line: one sub-command per module in :mod:`davis_ag.commands`."""

from __future__ import annotations

import argparse
import importlib
import os
import re
import signal
import sys
from typing import Any, NoReturn

from davis_ag.errors import MachineError, Stopped, UserError, stop
from davis_ag.provenance import code_version

# Each name is a module of davis_ag.commands defining HELP, DESCRIPTION, add_arguments(parser),
# run(args) and maybe FORMATTER_CLASS (the package's docstring says what each is); add_command alone
# makes the sub-parsers from them, so that every command's is made the same way.
COMMANDS = [
    "generate",
    "validate",
    "verify",
    "train",
    "evaluate",
    "compare",
    "preview",
    "demo",
    "reproduce",
    "stats",
    "plot",
    "view",
    "export",
    "transfer",
    "robots",
    "reach",
    "bench",
    "scene-stats",
]


#: What a stopped command keeps, for its last line (every command resumes by being run again).
KEPT_WHEN_STOPPED = {
    "generate": "finished scenes are kept and a scene in progress resumes from its views",
    "demo": "finished scenes are kept",
    "reproduce": "finished stages, scenes and training checkpoints are kept",
    "train": "the last checkpoint and the best snapshot so far are kept beside --out",
    "evaluate": "nothing half-written was left",
    "export": "the files already exported are kept",
    "transfer": "finished stages are kept",
    "verify": "the dataset was only read (run it again with a new --keep folder)",
}


class OneLineParser(argparse.ArgumentParser):
    """Reports bad arguments as one line on stderr, exit status 2, like a :class:`UserError`.

    Sub-command parsers are made of the same class (argparse's default).
    """

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    """Build the top-level parser with every sub-command registered."""
    parser = OneLineParser(prog="davis-ag", description=plain_text(__doc__))
    parser.add_argument("--version", action="version", version=f"davis-ag {code_version()}")
    subparsers = parser.add_subparsers(dest="command", required=True)
    for name in COMMANDS:
        add_command(subparsers, name)
    return parser


def plain_text(docstring: str | None) -> str | None:
    """A docstring as help text: Sphinx markup (````code````, ``:mod:`name```` and friends) as plain text.

    The command modules' docstrings are both their API documentation and their ``--help``; only
    the first may carry markup.
    """
    if docstring is None:
        return None
    text = re.sub(r":(?:mod|func|class|meth|data|attr|exc):`~?([^`]+)`", r"\1", docstring)
    return text.replace("``", "")


def add_command(subparsers: argparse._SubParsersAction, name: str) -> argparse.ArgumentParser:
    """Add the sub-command ``name``, its parser made from its module in :mod:`davis_ag.commands`.

    Args:
        subparsers: what the parser's ``add_subparsers()`` returned.
        name: the command, the name of its module with ``_`` for ``-`` (one of :data:`COMMANDS`).

    Returns:
        The sub-command's parser, its ``func`` default the module's ``run``.
    """
    module = importlib.import_module(f"davis_ag.commands.{name.replace('-', '_')}")
    parser = subparsers.add_parser(
        name,
        help=plain_text(module.HELP),
        description=plain_text(module.DESCRIPTION),
        formatter_class=getattr(module, "FORMATTER_CLASS", argparse.HelpFormatter),
    )
    module.add_arguments(parser)
    parser.set_defaults(func=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line: each failure class becomes one line on stderr and its exit status
    (docs/errors.md): a :class:`UserError` 2, a :class:`MachineError` or an operating-system failure
    (``OSError``: disk full, folder removed) 1, SIGINT 130 and SIGTERM 143."""
    args = build_parser().parse_args(argv)
    previous = _stop_on_signals()
    try:
        return int(args.func(args) or 0)
    except MachineError as error:
        print(f"davis-ag {args.command}: error: {error}", file=sys.stderr)
        return 1
    except UserError as error:
        print(f"davis-ag {args.command}: error: {error}", file=sys.stderr)
        return 2
    except BrokenPipeError as error:
        if _stdout_closed():  # the reader of our output went away (``| head``): stop as Unix tools do
            return 128 + signal.SIGPIPE
        print(f"davis-ag {args.command}: error: {error}", file=sys.stderr)
        return 1
    except OSError as error:  # the machine, not the code: a full disk, a folder gone, a lost mount
        where = f"{error.filename}: " if error.filename else ""
        print(
            f"davis-ag {args.command}: error: {where}{error.strerror or error}; nothing finished was "
            "lost: free the space or fix the path and run the same command again",
            file=sys.stderr,
        )
        return 1
    except KeyboardInterrupt as error:
        number = error.signal_number if isinstance(error, Stopped) else signal.SIGINT
        kept = KEPT_WHEN_STOPPED.get(args.command, "nothing half-written was left")
        print(
            f"davis-ag {args.command}: stopped by {signal.Signals(number).name}; {kept}: run the same "
            "command again to resume",
            file=sys.stderr,
        )
        return 128 + int(number)
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


def _stdout_closed() -> bool:
    """Whether standard output is a pipe whose reader has gone (poll reports an error on it); if
    so, point it at the null device, so the interpreter's last flush at exit stays quiet."""
    import select

    try:
        fd = sys.stdout.fileno()
        poller = select.poll()
        poller.register(fd, select.POLLOUT)
        closed = any(events & select.POLLERR for _, events in poller.poll(0))
    except (AttributeError, OSError, ValueError):  # no poll (Windows), or stdout not a file
        return False
    if closed:
        os.dup2(os.open(os.devnull, os.O_WRONLY), fd)
    return closed


def _stop_on_signals() -> dict[int, Any]:
    """Turn SIGTERM and SIGINT into :class:`Stopped` in the main thread, so a stopped command
    unwinds (locks, temporaries, worker processes) and says what it kept; returns the handlers
    it replaced. A second signal while unwinding is ignored, so the cleanup is not cut short."""

    def on_signal(number: int, frame: Any) -> None:
        for each in (signal.SIGTERM, signal.SIGINT):
            signal.signal(each, signal.SIG_IGN)
        stop(number)  # raises Stopped, at once or when a step that must not be cut (stops_held) ends

    previous: dict[int, Any] = {}
    for number in (signal.SIGTERM, signal.SIGINT):
        try:
            previous[number] = signal.signal(number, on_signal)
        except ValueError:  # not the main thread (main() called from a thread): leave them
            break
    return previous


if __name__ == "__main__":
    sys.exit(main())
