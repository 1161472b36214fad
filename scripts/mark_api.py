#!/usr/bin/python3
"""Puts CM_API in front of every public function declaration of include/cadmorph/*.h that
lacks it (idempotent). Run after adding functions to a public header:
  python3 scripts/mark_api.py include/cadmorph/*.h
"""
import re
import sys

DECL = re.compile(r"^(?!typedef\b|CM_API\b|static\b|extern\b|return\b|#)"
                  r"((?:const\s+|unsigned\s+|struct\s+|enum\s+)*[A-Za-z_]\w*[\s\*]+\**cm_\w+\s*\()")

for path in sys.argv[1:]:
    text = open(path).read().split("\n")
    out = [("CM_API " + l) if DECL.match(l) else l for l in text]
    if out != text:
        open(path, "w").write("\n".join(out))
        print("marked %d in %s" % (sum(a != b for a, b in zip(out, text)), path))
