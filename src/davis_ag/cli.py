"""The ``davis-ag`` command line: one sub-command per module in :mod:`davis_ag.commands`."""

from __future__ import annotations

import argparse
import importlib
import sys

from davis_ag.errors import UserError
from davis_ag.provenance import code_version

# Each name is a module of davis_ag.commands defining HELP, DESCRIPTION, add_arguments(parser),
# run(args) and maybe FORMATTER_CLASS (the package's docstring says what each is); add_command alone
# makes the sub-parsers from them, so that every command's is made the same way.
COMMANDS = ["generate", "validate", "train", "evaluate", "compare", "preview", "demo", "reproduce", "stats", "plot",
            "view", "export", "transfer"]


class OneLineParser(argparse.ArgumentParser):
    """Reports bad arguments as one line on stderr, exit status 2, like a :class:`UserError`.

    Sub-command parsers are made of the same class (argparse's default).
    """

    def error(self, message: str):  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    """Build the top-level parser with every sub-command registered."""
    parser = OneLineParser(prog="davis-ag", description=__doc__)
    parser.add_argument("--version", action="version", version=f"davis-ag {code_version()}")
    subparsers = parser.add_subparsers(dest="command", required=True)
    for name in COMMANDS:
        add_command(subparsers, name)
    return parser


def add_command(subparsers: argparse._SubParsersAction, name: str) -> argparse.ArgumentParser:
    """Add the sub-command ``name``, its parser made from its module in :mod:`davis_ag.commands`.

    Args:
        subparsers: what the parser's ``add_subparsers()`` returned.
        name: the command, the name of its module (one of :data:`COMMANDS`).

    Returns:
        The sub-command's parser, its ``func`` default the module's ``run``.
    """
    module = importlib.import_module(f"davis_ag.commands.{name}")
    parser = subparsers.add_parser(name, help=module.HELP, description=module.DESCRIPTION,
                                   formatter_class=getattr(module, "FORMATTER_CLASS", argparse.HelpFormatter))
    module.add_arguments(parser)
    parser.set_defaults(func=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; a :class:`UserError` becomes one line on stderr and exit code 2, an
    operating-system failure (``OSError``: disk full, folder removed) one line and exit code 1."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except UserError as error:
        print(f"davis-ag {args.command}: error: {error}", file=sys.stderr)
        return 2
    except OSError as error:  # the machine, not the code: a full disk, a folder gone, a lost mount
        where = f"{error.filename}: " if error.filename else ""
        print(f"davis-ag {args.command}: error: {where}{error.strerror or error}; nothing finished was "
              "lost: free the space or fix the path and run the same command again", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"davis-ag {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
