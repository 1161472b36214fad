"""Shared by the tests of the package: STEP models as Geometry objects, a model numbered
otherwise, the bore's files made by the CLI, and the CLI's own runs."""
import json
import os
import pathlib
import re
import subprocess
import sys
from typing import List

import numpy as np

import cadmorph


def read_step(path):
    """cadmorph.read_step of a path (millimetre)."""
    return cadmorph.read_step(str(path))


def reversed_shell(src, dst):
    """src with the faces of its closed shell listed the other way round: the same model,
    numbered otherwise (OpenCASCADE numbers faces in the shell's order)."""
    text = src.read_text()
    m = re.search(r"CLOSED_SHELL\('',\(([^)]*)\)\)", text)
    ids = m.group(1).split(",")
    dst.write_text(text[:m.start(1)] + ",".join(reversed(ids)) + text[m.end(1):])


def run(cli: str, *args) -> str:
    """Runs the CLI; its stdout (an AssertionError with stderr if it fails)."""
    r = subprocess.run([cli] + [str(a) for a in args], capture_output=True, text=True)
    assert r.returncode == 0, "%s %s: exit %d\n%s" % (cli, " ".join(map(str, args)),
                                                      r.returncode, r.stderr)
    return r.stdout


def bore(cli: str, work: pathlib.Path, ts: List[float], scale: float = 0.5) -> List[pathlib.Path]:
    """The built-in bore model G(t) for each t as STEP, and the hex mesh of G(0) at scale
    (M0.vtu), in work: [M0.vtu, G(t0).step, ...]."""
    mesh = work / ("bore_M0_%g.vtu" % scale)
    run(cli, "model", "bore", 0, work / "bore_0.step", "--hex-mesh", mesh, "--scale", scale)
    out = [mesh]
    for t in ts:
        p = work / ("bore_%g.step" % t)
        run(cli, "model", "bore", t, p)
        out.append(p)
    return out


class CtrlC:
    """Ctrl-C from a timer thread after `delay` seconds (_thread.interrupt_main: SIGINT's
    KeyboardInterrupt), and a progress callable that records every report with its time:
    `after()` lists the reports recorded once the signal was sent. A call that stops at
    its next progress point records none: the KeyboardInterrupt is raised in the callback
    of that point before the callable runs (at most one, if the signal lands inside it)."""

    def __init__(self, delay: float = 0.3) -> None:
        import threading
        import time
        import _thread
        self.reports = []
        self.sent = None
        self._time = time.perf_counter

        def fire():
            self.sent = self._time()
            _thread.interrupt_main()

        self.timer = threading.Timer(delay, fire)

    def __call__(self, stage: str, done: float, total: float) -> None:
        self.reports.append((self._time(), stage, done, total))

    def __enter__(self) -> "CtrlC":
        self.timer.start()
        return self

    def __exit__(self, *exc) -> None:
        # a call that ended first must not leave the signal to hit the test runner
        self.timer.cancel()
        self.timer.join()

    def after(self) -> list:
        """(stage, done, total) of the reports made after the signal was sent."""
        return [r[1:] for r in self.reports if self.sent is not None and r[0] >= self.sent]


def child_env() -> dict:
    """The environment of a child Python that runs OpenBLAS as the CLI does: the cadmorph
    program starts it with OPENBLAS_NUM_THREADS=1 (include/cadmorph/blas.h), and the sparse
    methods' (CHOLMOD's) sums depend on OpenBLAS's thread count."""
    env = dict(os.environ)
    env["OPENBLAS_NUM_THREADS"] = "1"
    env["PYTHONPATH"] = os.pathsep.join(p for p in [os.path.dirname(os.path.dirname(
        cadmorph.__file__)), env.get("PYTHONPATH", "")] if p)
    return env


def in_child(*args) -> None:
    """Runs this file's main() in a child Python with child_env()."""
    r = subprocess.run([sys.executable, __file__] + [str(a) for a in args], env=child_env(),
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def two_threads(m0, g0, targets, repeats: int = 4) -> dict:
    """One Morpher per target in its own thread (threads=1 each), each applied `repeats`
    times, while this thread counts loop turns: whether each result equals the serial one,
    how long both threads were in their loops at once, and how many turns this thread made
    meanwhile (none if the calls held the GIL)."""
    import threading
    import time
    mesh = cadmorph.read_mesh(m0)
    jobs = [(read_step(g0), read_step(g)) for g in targets]
    serial = [cadmorph.Morpher(a, mesh, threads=1, progress=False).apply(b) for a, b in jobs]
    results, window = [None] * len(jobs), [None] * len(jobs)
    ready = threading.Barrier(len(jobs) + 1)

    def work(k):
        a, b = jobs[k]
        m = cadmorph.Morpher(a, mesh, threads=1, progress=False)
        ready.wait()
        t0 = time.perf_counter()
        for _ in range(repeats):
            results[k] = m.apply(b)
        window[k] = (t0, time.perf_counter())

    threads = [threading.Thread(target=work, args=(k,)) for k in range(len(jobs))]
    for t in threads:
        t.start()
    ready.wait()
    ticks = []
    while any(t.is_alive() for t in threads):
        ticks.append(time.perf_counter())
    for t in threads:
        t.join()
    lo, hi = max(w[0] for w in window), min(w[1] for w in window)
    return {"equal": [bool(np.array_equal(r, s)) for r, s in zip(results, serial)],
            "overlap": hi - lo, "ticks": sum(lo < x < hi for x in ticks),
            "calls": [w[1] - w[0] for w in window]}


def main(argv: List[str]) -> None:
    """morph OUT.npy G0 G1 M0 OPTIONS_JSON: Morpher(G0, M0, **options).apply(G1);
    warp OUT.npy M0 NODES.npy D.npy OPTIONS_JSON: Warp(M0, nodes, **options).apply(D);
    threads OUT.json M0 G0 TARGET...: two_threads."""
    kind, out = argv[0], argv[1]
    if kind == "morph":
        g0, g1, m0, options = argv[2:6]
        m = cadmorph.Morpher(read_step(g0), cadmorph.read_mesh(m0), **json.loads(options))
        np.save(out, m.apply(read_step(g1)))
    elif kind == "warp":
        m0, nodes, D, options = argv[2:6]
        w = cadmorph.Warp(cadmorph.read_mesh(m0), np.load(nodes), **json.loads(options))
        np.save(out, w.apply(np.load(D)))
    elif kind == "threads":
        with open(out, "w") as f:
            json.dump(two_threads(argv[2], argv[3], argv[4:]), f)
    else:
        raise SystemExit("unknown command %r" % kind)


if __name__ == "__main__":
    main(sys.argv[1:])
