"""Argument pieces the ros2 verb groups share: ros2cli's option types and texts.

Each group's verbs (``add_verbs`` in app/ros2cli/topic.py, param.py, lifecycle.py,
interfaces.py, bag.py, pkg.py; node, service and action in graph_verbs.py) take
the options of Jazzy's ros2cli, in its order, with its names, metavars and help
texts, so ``-h`` reads as the docs and the real tool show it (compared side by
side: bench/results/ros2cli_compare.md). The few options we do not offer are
still listed (the same ``-h``), named again at the end of the help ("Not
supported here"), and refused with argparse's usage error when typed, never
silently ignored: ``not_here``.
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, TypedDict

if TYPE_CHECKING:
    from typing_extensions import Unpack  # typing's own from Python 3.11

NOT_HERE = "not supported here"


class _NotHere(argparse.Action):
    """An option Jazzy's ros2 has and we do not: shown in -h, refused when used."""

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: object,
        option_string: str | None = None,
    ) -> None:
        raise argparse.ArgumentError(self, f"{NOT_HERE} (see the end of -h)")


class _NotHereOptions(TypedDict, total=False):
    help: str
    metavar: str
    dest: str


def not_here(
    p: argparse.ArgumentParser,
    *flags: str,
    flag: bool = False,
    group: argparse._MutuallyExclusiveGroup | None = None,
    **kw: Unpack[_NotHereOptions],
) -> None:
    """Add an option we do not offer (``flag``: it takes no value), and name it in the epilog.

    ``group``: the mutually exclusive group it belongs to (else the parser itself).
    """
    target = p if group is None else group
    target.add_argument(*flags, action=_NotHere, nargs=0 if flag else None, **kw)
    names: list[str] = p.__dict__.setdefault("_not_here", [])
    names.append("/".join(sorted(flags, key=len)))
    p.epilog = (
        f"Not supported here (Jazzy's ros2 has them): {', '.join(names)}. "
        "Using one gives a usage error."
    )


def positive_float(text: str) -> float:
    """ros2topic's float > 0 (argparse names this function in its error)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError("Expects a floating point number") from None
    if value <= 0.0:
        raise argparse.ArgumentTypeError("Value must be positive")
    return value


def positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value <= 0:
        raise argparse.ArgumentTypeError("value must be a positive integer")
    return value


def unsigned_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError("value must be non-negative integer")
    return value


def nonnegative_int(text: str) -> int:
    value = int(text)
    if value < 0:
        raise ValueError("Value must be positive or zero")
    return value


def spin_time(p: argparse.ArgumentParser) -> None:
    """--spin-time and -s: the options of ros2cli's own (direct) node."""
    p.add_argument(
        "--spin-time",
        type=float,
        default=None,
        help="Spin time in seconds to wait for discovery (only applies when not using an "
        "already running daemon)",
    )
    not_here(p, "-s", "--use-sim-time", flag=True, help="Enable ROS simulation time")


def strategy(p: argparse.ArgumentParser) -> None:
    """--spin-time, -s, --no-daemon (there is no daemon here: never spawned nor used)."""
    spin_time(p)
    p.add_argument(
        "--no-daemon",
        action="store_true",
        help="Do not spawn nor use an already running daemon",
    )


def node_listing_options(p: argparse.ArgumentParser) -> None:
    """`ros2 node list` and `ros2 lifecycle nodes` take the same options."""
    strategy(p)
    p.add_argument("-a", "--all", action="store_true", help="Display all nodes even hidden ones")
    p.add_argument(
        "-c",
        "--count-nodes",
        action="store_true",
        help="Only display the number of nodes discovered",
    )


def node_name_argument(
    p: argparse.ArgumentParser, optional: bool = False, help_text: str = ""
) -> None:
    p.add_argument(
        "node_name", nargs="?" if optional else None, help=help_text or "Name of the ROS node"
    )


def hidden_nodes_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--include-hidden-nodes", action="store_true", help="Consider hidden nodes as well"
    )


def timeout_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--timeout",
        metavar="N",
        type=int,
        default=1,
        help="Wait for N seconds until node becomes available (default 1 sec)",
    )


def command_options(group: str, p: argparse.ArgumentParser) -> None:
    """Options ros2 takes before the verb: `ros2 topic --include-hidden-topics type /x`."""
    noun = {"topic": "topics", "service": "services"}.get(group)
    if noun:
        p.add_argument(
            f"--include-hidden-{noun}",
            action="store_true",
            help=f"Consider hidden {noun} as well",
        )
