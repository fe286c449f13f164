"""The ``zmpwalk`` command.

Exit status: 0 success; 2 bad input or usage (one line, ``zmpwalk: error: ...``); 3 the walk failed
(``simulate``, ``report``, ``demo``: a criterion of the verdict failed, each printed with its figure;
``plan``: the ZMP leaves the support polygon, unless ``--allow-outside``).

Each command is a module of this package with its parser (``add_parser``) and what it does (``run``); the options
several commands share are declared once in :mod:`zmpwalk.cli.options`. A command imports what walks, simulates or
renders when it runs, so ``zmpwalk --help`` and ``zmpwalk --version`` start fast.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from types import ModuleType

from zmpwalk.cli import export, hyperbolic, plan, report, robot, scenarios, simulate, sweep, tables, tune
from zmpwalk.cli.hyperbolic import paper_example
from zmpwalk.cli.options import EXIT_ERROR, EXIT_FAILED, Parser, UsageError
from zmpwalk.errors import ZmpwalkError

__all__ = ["EXIT_ERROR", "EXIT_FAILED", "main", "paper_example"]

# In the order ``zmpwalk --help`` lists them.
_COMMANDS: tuple[ModuleType, ...] = (scenarios, plan, hyperbolic, simulate, report, tables, sweep, tune, robot, export)


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("zmpwalk")
    except PackageNotFoundError:  # run from a source tree that was not installed
        return "unknown"


def _parser() -> argparse.ArgumentParser:
    """The ``zmpwalk`` parser with every command's."""
    parser = Parser(
        prog="zmpwalk",
        description="Online ZMP walking patterns for biped humanoids (HUBO polynomial pattern).",
        epilog="example: zmpwalk plan --scenario fig28 --rate 1000 --out fig28.csv",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    commands = parser.add_subparsers(dest="command", parser_class=Parser)
    for module in _COMMANDS:
        module.add_parser(commands)
    return parser


def _run(args: argparse.Namespace) -> int:
    """Run the command the arguments name; its exit status."""
    for module in _COMMANDS:
        if args.command in module.NAMES:
            return int(module.run(args))
    raise UsageError(f"unknown command {args.command!r}")  # pragma: no cover


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``zmpwalk`` command; returns the exit status."""
    try:
        parser = _parser()
        args = parser.parse_args(argv)
        if args.command is None:  # zmpwalk alone: the commands and what they do
            parser.print_help()
            return 0
        return _run(args)
    except (ZmpwalkError, UsageError) as error:
        print(f"zmpwalk: error: {error}", file=sys.stderr)
        return EXIT_ERROR
    except OSError as error:  # an output folder or file the system refuses (full disk, permissions)
        where = f"{error.filename}: " if error.filename else ""
        print(f"zmpwalk: error: {where}cannot be written: {error.strerror or error}", file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        return 130
