#!/usr/bin/env python3
"""Checks which shared libraries an executable loads, as ldd reports them.

The link-graph check proves what the build links; this proves what a built
host tool pulls in at run time, the way an engineer installing it sees it:
e.g. rover-eval must load no middleware (iceoryx), no HTTP server, no
systemd, no camera or GPIO library and no OpenGL.

usage: check_shared_libraries.py EXECUTABLE --forbid PATTERN [PATTERN ...]
Patterns match library file names by case-insensitive substring. Exit 0 when
none matches, 1 listing every match, 2 when ldd cannot read the executable.
"""

import argparse
import subprocess
import sys


def loaded_libraries(executable):
    """The library names ldd lists for `executable` (first column)."""
    result = subprocess.run(["ldd", executable], capture_output=True, text=True, check=False)
    if result.returncode != 0:
        raise RuntimeError(f"ldd {executable}: {result.stderr.strip() or 'failed'}")
    return [line.split()[0] for line in result.stdout.splitlines() if line.strip()]


def main():
    """Parses the arguments, reports forbidden libraries, returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("executable")
    parser.add_argument("--forbid", nargs="+", required=True, metavar="PATTERN")
    args = parser.parse_args()
    try:
        libraries = loaded_libraries(args.executable)
    except (OSError, RuntimeError) as error:
        print(f"check_shared_libraries: {error}", file=sys.stderr)
        return 2
    found = [(lib, p) for lib in libraries for p in args.forbid if p.lower() in lib.lower()]
    for lib, pattern in found:
        print(f"{args.executable}: loads {lib} (forbidden: '{pattern}')")
    if not found:
        print(f"{args.executable}: {len(libraries)} shared libraries, none of {args.forbid}")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
