"""The ``tservo`` command.

Each command group lives in its own module with a ``register(subparsers)`` function that adds its
sub-commands and sets ``func`` on them.  Errors in user input (InputError) print one line,
``tservo: error: <field>: <problem>``, and exit with status 2; nothing is written.
"""
from __future__ import annotations

import argparse
import importlib
import os
import sys

from .errors import InputError

# Modules that add commands (each has register(subparsers)).
COMMAND_MODULES = ["cli_chain", "cli_kin", "cli_track", "cli_ik"]


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, exit 2 (argparse prints usage first)
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="tservo", description="tensor-servo model and tools")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in COMMAND_MODULES:
        mod = importlib.import_module(f".{name}", __package__)
        mod.register(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        rc = args.func(args)
    except InputError as e:
        print(f"tservo: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("tservo: interrupted", file=sys.stderr)
        return 130
    except Exception as e:  # not a user error: still one line unless debugging
        if os.environ.get("TSERVO_DEBUG"):
            raise
        print(f"tservo: internal error: {type(e).__name__}: {e} (set TSERVO_DEBUG=1 for a traceback)",
              file=sys.stderr)
        return 1
    return int(rc or 0)


if __name__ == "__main__":
    sys.exit(main())
