"""``python -m bench NAME [args]`` runs ``bench.NAME.main(args)``; no NAME runs the summary.

``tests/run.py --bench NAME`` calls this inside the private network
namespace, so benchmarks that use DDS stay on loopback.
"""

from __future__ import annotations

import importlib
import pkgutil
import sys
from pathlib import Path


def available() -> list[str]:
    return sorted(m.name for m in pkgutil.iter_modules([str(Path(__file__).parent)]))


def main(argv: list[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    names = [n for n in available() if not n.startswith("_")]
    if not args:
        args = ["summary"]  # `make bench`: every benchmark, short settings, one table
    if not args or args[0] in ("-h", "--help") or args[0] not in names:
        print(f"usage: python -m bench NAME [args]; NAME is one of: {', '.join(names)}")
        return 0 if args[:1] in (["-h"], ["--help"]) else 2
    module = importlib.import_module(f"bench.{args[0]}")
    result = module.main(args[1:])
    return int(result or 0)


if __name__ == "__main__":
    raise SystemExit(main())
