"""``python -m bench NAME [args]`` runs ``bench.NAME.main(args)``; no NAME runs the summary.

``tests/run.py --bench NAME`` calls this inside the private network
namespace, so benchmarks that use DDS stay on loopback. Whatever happens in
the benchmark (an exception, a timeout, a child hung in its teardown), every
process it started is found by the run's mark at the end (``bench._reaper``),
killed and named, and the run exits non-zero.
"""

from __future__ import annotations

import importlib
import os
import pkgutil
import sys
import traceback
from pathlib import Path

from bench._reaper import MARK, end_leftovers, mark_this_run


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
    # The outermost run marks its processes (summary's benchmarks inherit its mark).
    own_mark = MARK not in os.environ
    mark = mark_this_run("bench") if own_mark else os.environ[MARK]
    try:
        module = importlib.import_module(f"bench.{args[0]}")
        result = int(module.main(args[1:]) or 0)
    except Exception:  # a benchmark that cannot finish says why, and fails
        traceback.print_exc()
        print(f"bench {args[0]}: FAILED (exception above)", flush=True)
        result = 1
    if own_mark:
        left = end_leftovers(mark)
        if left:
            print(f"bench {args[0]}: FAILED, processes left running (killed now):", flush=True)
            print("\n".join(f"  {line}" for line in left), flush=True)
            result = result or 1
    return result


if __name__ == "__main__":
    raise SystemExit(main())
