#!/usr/bin/env python3
"""Checks the module layering of docs/DESIGN.md against the compiled objects.

From the object files of each module (nm: the global symbols each object defines and the ones
it needs), it fails on
  - a call from one module into another that the "may use" column of DESIGN.md's module table
    does not allow, and
  - a circle of files inside a module (object A needs a symbol of B and B one of A, directly or
    through others), except the circles DESIGN.md names under "Intended circles".
Weak symbols (inline functions, template instances that C++ emits in every object) are not
calls between files and are ignored.

usage: check_layering.py DESIGN.md MODULE=PATH[;PATH...] ...
  PATH: a static library or a directory searched for *.o (an executable's objects).
"""
import os
import re
import subprocess
import sys
from collections import defaultdict

STRONG = set("TDBRGSC")  # defined, not weak (W, V, u: inline/template/unique)


def parse_design(path):
    """Module name -> set of modules it may use; list of intended circles (sets of file names)."""
    text = open(path, encoding="utf-8").read()
    rows = []
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if not line.lstrip().startswith("|") or len(cells) < 3:
            continue
        folder = re.match(r"`([^`]+)`", cells[0])
        if folder:
            rows.append((folder.group(1).rstrip("/").split("/")[-1], cells[2]))
    names = {name for name, _ in rows}
    allowed = {}
    for name, uses in rows:
        words = set(re.findall(r"[A-Za-z_]+", uses))
        allowed[name] = {w for w in words if w in names and w != name}
    circles = []
    m = re.search(r"^#+\s*Intended circles\s*$(.*?)(?=^#+\s|\Z)", text, re.M | re.S)
    if m:
        # one bullet ("- ...", continued on the lines below it) names the files of one circle
        for bullet in re.split(r"^\s*[-*]\s", m.group(1), flags=re.M)[1:]:
            files = set(os.path.basename(f) for f in re.findall(r"`([^`]+\.(?:c|cpp))`", bullet))
            if len(files) > 1:
                circles.append(files)
    return allowed, circles


def nm(paths, *flags):
    """(object name, symbol type, symbol) for every symbol nm lists with these flags."""
    out = subprocess.run(["nm", "-A", "-P", *flags, *paths], check=True, capture_output=True,
                         text=True).stdout
    for line in out.splitlines():
        # archive.a[member.o]: sym T value size   |   file.o: sym U
        head, _, rest = line.partition(": ")
        parts = rest.split()
        if len(parts) < 2:
            continue
        obj = head[head.rfind("[") + 1:-1] if head.endswith("]") else os.path.basename(head)
        yield obj, parts[1], parts[0]


def objects_of(spec):
    paths = []
    for p in spec.split(";"):
        if os.path.isdir(p):
            for top, _, names in os.walk(p):
                paths += [os.path.join(top, n) for n in sorted(names) if n.endswith(".o")]
        elif p:
            paths.append(p)
    return paths


def strip_suffix(obj):
    for s in (".o", ".obj"):
        if obj.endswith(s):
            obj = obj[: -len(s)]
    return obj  # rbf_schwarz.c


def cycles(graph):
    """Strongly connected components with more than one node (Tarjan, iterative)."""
    index, low, on, stack, out, counter = {}, {}, set(), [], [], [0]
    for start in graph:
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = counter[0]; counter[0] += 1
        stack.append(start); on.add(start)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]; counter[0] += 1
                    stack.append(w); on.add(w)
                    work.append((w, iter(sorted(graph.get(w, ())))))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = set()
                    while True:
                        w = stack.pop(); on.discard(w); comp.add(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(comp)
    return out


def main():
    if len(sys.argv) < 3:
        print(__doc__, file=sys.stderr)
        return 1
    allowed, intended = parse_design(sys.argv[1])
    modules = {}
    for arg in sys.argv[2:]:
        name, _, spec = arg.partition("=")
        modules.setdefault(name, []).extend(objects_of(spec))
    owner = {}            # symbol -> (module, object)
    needs = defaultdict(set)  # (module, object) -> symbols
    errors = []
    for mod, paths in modules.items():
        if mod not in allowed:
            errors.append(f"module '{mod}' has no row in DESIGN.md's module table")
            continue
        if not paths:
            errors.append(f"module '{mod}': no object files found")
            continue
        for obj, kind, sym in nm(paths, "--defined-only", "-g"):
            if kind in STRONG:
                owner[sym] = (mod, strip_suffix(obj))
        for obj, kind, sym in nm(paths, "--undefined-only"):
            needs[(mod, strip_suffix(obj))].add(sym)
    calls = defaultdict(set)  # (from module, to module) -> example
    files = defaultdict(lambda: defaultdict(set))  # module -> object -> objects it needs
    for (mod, obj), syms in needs.items():
        for sym in syms:
            if sym not in owner:
                continue  # a library outside the project
            tmod, tobj = owner[sym]
            if tmod != mod:
                calls[(mod, tmod)].add(f"{obj} -> {sym} ({tobj})")
            elif tobj != obj:
                files[mod][obj].add(tobj)
    for (a, b), ex in sorted(calls.items()):
        if b not in allowed.get(a, ()):
            errors.append(f"{a} uses {b}, which DESIGN.md does not allow: " +
                          "; ".join(sorted(ex)[:3]) + (" ..." if len(ex) > 3 else ""))
    for mod, graph in sorted(files.items()):
        for comp in cycles(graph):
            if not any(comp <= set(i) for i in intended):
                errors.append(f"{mod}: a circle of files: {', '.join(sorted(comp))}")
    for e in errors:
        print("check_layering: " + e)
    n_calls = sum(len(v) for v in calls.values())
    print(f"check_layering: {len(modules)} modules, {len(owner)} symbols, {n_calls} calls "
          f"between modules, {len(errors)} problems")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
