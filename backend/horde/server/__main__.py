"""`python -m horde.server [--host H] [--port P] [--data DIR]`: the same as `horde serve`."""

from __future__ import annotations

import argparse

from horde.server.cli_serve import add_serve_arguments, serve


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m horde.server", description="Serve the Horde Lab API.")
    add_serve_arguments(parser)
    return serve(parser.parse_args(argv))


if __name__ == "__main__":
    raise SystemExit(main())
