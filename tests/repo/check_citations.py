#!/usr/bin/env python3
"""Fails on citations a reader of the repository cannot follow.

Sources, headers, CMake files and scripts must explain themselves by what is inside the
repository: docs/, a reference key of docs/references.md, a section of
benchmarks/RESULTS.md (docs/STYLE.md, "Comments"). This test fails on
  - an issue number ("issue 12", "issues #3"),
  - a numbered work session, in digits or in words ("6th session", "sixth session"),
  - a path into the steering repository ("../shared"),
  - a relative include that climbs out of its folder (#include "../x.h"),
and, in the installed headers (include/cadmorph/), on anything outside the installed tree: a
source file, a script, benchmarks/ or tests/ (docs/ is installed with them).
usage: check_citations.py ROOT
"""
import os
import re
import sys

ORDINALS = ("first second third fourth fifth sixth seventh eighth ninth tenth eleventh twelfth "
            "thirteenth fourteenth fifteenth sixteenth seventeenth eighteenth nineteenth "
            "twentieth").split()
RULES = [
    ("an issue number", re.compile(r"\bissues?\s*#?\s*[0-9]", re.I)),
    ("a numbered session",
     re.compile(r"\b(%s|[0-9]+(st|nd|rd|th))[- ]+session" % "|".join(ORDINALS), re.I)),
    ("a numbered session", re.compile(r"\bsession\s*#?\s*[0-9]", re.I)),
    ("a work log", re.compile(r"\bwork[- ]?logs?\b", re.I)),
    ("a path outside the repository", re.compile(r"\.\./+shared\b")),
    ("a relative include out of its folder", re.compile(r'#\s*include\s*"\.\./')),
]
INSTALLED_RULES = [
    ("a file that is not installed",
     re.compile(r"[A-Za-z0-9_./-]+\.(c|cpp|hxx|py|sh)\b|RESULTS\.md|\bbenchmarks/|\btests/")),
]
SOURCE_SUFFIXES = (".c", ".h", ".cpp", ".hxx", ".hpp", ".in", ".cmake", ".py", ".pyi", ".sh",
                   ".map")
SOURCE_NAMES = ("CMakeLists.txt", "Makefile", "run")
SKIP_DIRS = {".git", "__pycache__"}


def is_source(name):
    return name in SOURCE_NAMES or name.endswith(SOURCE_SUFFIXES)


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 1
    root = os.path.abspath(sys.argv[1])
    me = os.path.abspath(__file__)
    found = 0
    files = 0
    for top, dirs, names in os.walk(root):
        # a build tree (in or beside the sources) is not part of the repository
        dirs[:] = sorted(d for d in dirs if d not in SKIP_DIRS
                         and not os.path.exists(os.path.join(top, d, "CMakeCache.txt")))
        for name in sorted(names):
            path = os.path.join(top, name)
            if not is_source(name) or path == me:
                continue
            files += 1
            try:
                with open(path, encoding="utf-8", errors="replace") as f:
                    lines = f.readlines()
            except OSError as e:
                print(f"{path}: cannot read: {e}", file=sys.stderr)
                return 1
            rules = RULES
            if os.path.relpath(top, root) == os.path.join("include", "cadmorph"):
                rules = RULES + INSTALLED_RULES
            for no, line in enumerate(lines, 1):
                for what, rx in rules:
                    if rx.search(line):
                        found += 1
                        print(f"{os.path.relpath(path, root)}:{no}: cites {what}: {line.strip()[:160]}")
                        break
    print(f"check_citations: {files} files, {found} citations outside the repository")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
