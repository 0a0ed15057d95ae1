"""``main(argv)``: report source files without a copyright notice; 0 when there are none."""

from __future__ import annotations

import argparse
import os
import re
import sys

_NOTICE = re.compile(r"copyright", re.IGNORECASE)
_HEAD_LINES = 30  # a notice belongs at the top of the file
_EXTENSIONS = (".py", ".cpp", ".hpp", ".c", ".h")


def _files(paths: list[str]) -> list[str]:
    found: list[str] = []
    for path in paths:
        if os.path.isfile(path):
            found.append(path)
            continue
        for folder, subfolders, names in os.walk(path):
            subfolders[:] = sorted(d for d in subfolders if not d.startswith("."))
            found += [os.path.join(folder, n) for n in sorted(names) if n.endswith(_EXTENSIONS)]
    return found


def has_notice(text: str) -> bool:
    """An empty file needs none; otherwise a 'Copyright' line among the first lines."""
    if not text.strip():
        return True
    return any(_NOTICE.search(line) for line in text.splitlines()[:_HEAD_LINES])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Check source files for a copyright notice.")
    parser.add_argument("paths", nargs="*", default=[os.curdir])
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    files = _files(args.paths)
    missing = []
    for path in files:
        try:
            with open(path, encoding="utf-8", errors="replace") as handle:
                text = handle.read()
        except OSError:
            continue
        if not has_notice(text):
            missing.append(path)
            print(f"{path}: could not find copyright notice")
    print(f"{len(missing)} errors, checked {len(files)} files" if missing else "No problems found")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
