"""``davis-ag view DIR``: a local web page to drive through a scene with the keyboard, using the
paper's actions (arrows or W/S/A/D, R/F up and down, Q/E rotate), boxes, masks, depth and organ
classes toggled with B, M, Z and O, the current position shown on the map (click it to jump).

The server listens on 127.0.0.1 only and serves nothing outside the dataset's scene folders.
Stop it with Ctrl-C.
"""

from __future__ import annotations

import argparse

from davis_ag.commands import arguments

HELP = "drive through a scene in the browser (local web page)"
DESCRIPTION = __doc__
FORMATTER_CLASS = argparse.RawDescriptionHelpFormatter


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``view``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument("dataset", type=arguments.path, metavar="DIR", help="dataset root, group or scene folder")
    parser.add_argument(
        "--port", type=arguments.whole, default=8765, help="TCP port on 127.0.0.1 (default 8765; 0 = any free port)"
    )
    parser.add_argument("--scene", default=None, metavar="ID", help="scene to open first (default: the first)")


def run(args: argparse.Namespace) -> int:
    """Serve until interrupted."""
    from urllib.parse import quote

    from davis_ag.data.reader import open_dataset
    from davis_ag.figures.viewer_server import server_url, start_server

    if args.scene:  # refused at start, not as a blank page in the browser
        args.scene = open_dataset(args.dataset).scene(args.scene).id
    server = start_server(args.dataset, args.port)
    url = server_url(server) + (f"#scene={quote(args.scene, safe='')}" if args.scene else "")
    print(f"viewing {args.dataset} at {url}  (open it in a browser; Ctrl-C stops)", flush=True)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        print("stopped")
    finally:
        server.server_close()
    return 0
