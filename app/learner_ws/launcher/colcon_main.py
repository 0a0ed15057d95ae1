"""colcon's own entry point, run by path in a workspace: ``colcon_main.py WORKSPACE WORDS...``.

A dashboard served to other machines runs colcon contained (app.containment.contain
runs a script by path, in its own process): this is that script. It has a
folder of its own because the folder of a script run by path comes first on
``sys.path``, and app/learner_ws holds a ``build`` module.
"""

from __future__ import annotations

import os
import sys

if sys.path and os.path.realpath(sys.path[0]) == os.path.dirname(os.path.realpath(__file__)):
    del sys.path[0]


def main() -> object:
    if len(sys.argv) < 2:
        print("usage: colcon_main.py WORKSPACE [colcon words]", file=sys.stderr)
        return 2
    os.chdir(sys.argv[1])
    sys.argv = ["colcon", *sys.argv[2:]]
    from colcon_core.command import main as colcon

    return colcon()  # an int, or the exception that ended the build (sys.exit prints it)


if __name__ == "__main__":
    sys.exit(main())  # type: ignore[arg-type]
