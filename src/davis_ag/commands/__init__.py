"""Stage 16, commands: one module per ``davis-ag`` sub-command. :func:`davis_ag.cli.add_command` makes each command's
parser from its module, which defines:

- ``HELP``: the command's line in ``davis-ag --help``;
- ``DESCRIPTION``: the text at the top of ``davis-ag COMMAND --help``;
- ``FORMATTER_CLASS`` (optional): an ``argparse`` formatter class, where the description is laid
  out by hand (``argparse.RawDescriptionHelpFormatter``); argparse's default re-wraps it;
- ``add_arguments(parser)``: adds the command's arguments to ``parser``, the parser made for it;
- ``run(args)``: runs the command on the parsed ``argparse.Namespace`` and returns its exit code.
"""
