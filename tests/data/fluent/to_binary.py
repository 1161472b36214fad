#!/usr/bin/python3
"""Binary variants of an ASCII Fluent mesh: node sections become 3010 (double) or 2010
(single precision), face sections 3013/2013 and mixed cell sections 3012/2012; every other
section is copied as it is.

The layout follows the Fluent file-format documentation (the user's guide, appendix "Case
and Data File Formats", "Formatting Conventions in Binary and Formatted Files"): the section
index is preceded by 20 (single precision) or 30 (double precision), the header stays text
in hexadecimal, the data follows the '(' that opens it, and the section ends with
")" "End of Binary Section <index>)". Integers are 32-bit, numbers little-endian. A mixed face
is its type (3, 4; 5 then the count for a polygon), its nodes, c0 and c1.

usage: to_binary.py IN.msh OUT.msh [single|double]"""
import re
import struct
import sys


def sections(text):
    """(start, end) of each top-level section, strings honoured."""
    i, n, out = 0, len(text), []
    while i < n:
        if text[i].isspace():
            i += 1
            continue
        assert text[i] == "(", "not a section at %d" % i
        depth, j = 0, i
        while True:
            c = text[j]
            if c == '"':
                j = text.index('"', j + 1)
            elif c == "(":
                depth += 1
            elif c == ")":
                depth -= 1
                if depth == 0:
                    break
            j += 1
        out.append((i, j + 1))
        i = j + 1
    return out


HEAD = re.compile(r"\(\s*(\d+)\s*\(([0-9a-fA-F\s]*)\)\s*\(")


def convert(text, precision="double"):
    pre = "30" if precision == "double" else "20"
    real = "<d" if precision == "double" else "<f"
    out, last = [], 0
    for a, b in sections(text):
        out.append(text[last:a].encode())
        last = b
        sec = text[a:b]
        m = HEAD.match(sec)
        if not m or m.group(1) not in ("10", "12", "13"):
            out.append(sec.encode())
            continue
        idx, hdr = m.group(1), m.group(2)
        h = [int(x, 16) for x in hdr.split()]
        body = sec[m.end():]
        body = body[:body.index(")")]  # the data list: numbers only
        if idx == "10":
            data = b"".join(struct.pack(real, float(x)) for x in body.split())
        elif idx == "12":
            data = b"".join(struct.pack("<i", int(x, 16)) for x in body.split())
        else:
            etype, data = h[4], b""
            for line in body.strip().splitlines():
                v = [int(x, 16) for x in line.split()]
                if etype == 0:  # "count nodes c0 c1" as OpenFOAM writes it: type-first in binary
                    n = v[0]
                    v = ([n] if n in (3, 4) else [5, n]) + v[1:]
                data += struct.pack("<%di" % len(v), *v)
        key = pre + idx
        out.append(("(%s (%s)(" % (key, hdr.strip())).encode() + data + ("\n)End of Binary Section   %s)" % key).encode())
    out.append(text[last:].encode())
    return b"".join(out)


if __name__ == "__main__":
    with open(sys.argv[1]) as f:
        text = f.read()
    with open(sys.argv[2], "wb") as f:
        f.write(convert(text, sys.argv[3] if len(sys.argv) > 3 else "double"))
