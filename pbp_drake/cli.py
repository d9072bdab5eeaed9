"""The `pbp-drake` command line. Its subcommands live in `pbp_drake.commands`, but `draw`
(`pbp_drake.draw`) and `bench` (the package `pbp_drake_bench`)."""

import argparse
import errno
import os
import sys

from pbp_drake import __version__
from pbp_drake.cli_types import EXIT_INTERRUPTED, EXIT_USAGE
from pbp_drake.commands.driver_sim import add_driver_sim_command
from pbp_drake.commands.run import add_run_command
from pbp_drake.commands.study import add_study_commands
from pbp_drake.commands.teach import add_teach_command
from pbp_drake.draw import build_parser as build_draw_parser
from pbp_drake.draw import main as draw_main
from pbp_drake.scenarios import ScenarioError


def main(argv=None):
    """Runs the command line `argv` (default: sys.argv[1:]); returns the exit code."""
    try:
        code = _main(argv)
        sys.stdout.flush()  # a closed pipe (`| head`) shows here, not at the last flush
        return code
    except BrokenPipeError:
        # As the Python docs recommend (signal module, "Note on SIGPIPE"): the interpreter's
        # last flush goes to devnull.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 1
    except OSError as error:
        if error.errno != errno.ENAMETOOLONG:
            raise
        # A path given, or a scenario's, that no file system takes: pathlib's `exists` and
        # `is_dir` raise this where a missing file reads as False.
        print(f"pbp-drake: {error.filename}: the name is too long (a file or folder name is at "
              "most 255 bytes, a path 4,096)", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        # Ctrl-C is how a person ends a run: a word, not a traceback (128 + SIGINT).
        print("\npbp-drake: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


def build_parser():
    """The argument parser of `pbp-drake`; `bench` and `draw` are stubs that take the rest
    of the line (their parsers: `tool_parsers()`)."""
    parser = argparse.ArgumentParser(
        prog="pbp-drake",
        description="Policy Blending with Primitives (PBP): shared control on Drake.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    commands = parser.add_subparsers(dest="command", required=True)

    add_run_command(commands)
    add_study_commands(commands)
    add_driver_sim_command(commands)
    add_teach_command(commands)
    for name, help_text in [("bench", "time the DMP bank against the DMP libraries people "
                                      "use (pbp-drake bench --help)"),
                            ("draw", "write a scenario's system diagram as SVG "
                                     "(pbp-drake draw --help)")]:
        tool = commands.add_parser(name, help=help_text, add_help=False)
        tool.add_argument("arguments", nargs=argparse.REMAINDER)
    return parser


def tool_parsers():
    """The parsers of the subcommands that parse their own line: {"bench": ..., "draw": ...}."""
    from pbp_drake_bench.main import build_parser as build_bench_parser  # the harness: on use
    return {"bench": build_bench_parser(), "draw": build_draw_parser()}


def _main(argv):
    parser = build_parser()
    argv = sys.argv[1:] if argv is None else list(argv)
    # Before argparse, which would take their options (e.g. --help) for its own.
    if argv and argv[0] == "bench":
        from pbp_drake_bench.main import main as bench_main  # the harness: on use
        return bench_main(argv[1:])
    if argv and argv[0] == "draw":
        return draw_main(argv[1:])
    args = parser.parse_args(argv)
    try:
        return args.handler(args)
    except ScenarioError as error:
        print(f"pbp-drake: {error}", file=sys.stderr)
        return EXIT_USAGE
