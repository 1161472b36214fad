"""A study's progress line on a terminal (docs/DESIGN.md, "Studies in batches"), without timing.

Usage: check_progress_tty.py VARIANTS -- CADMORPH study ARGS...

Runs the command twice: with stderr on a pseudo-terminal, then on a pipe. On the terminal the
line is redrawn in place (carriage return, erase to the end of the line); every "study k/n
variants" it shows has n = VARIANTS and k never falling, never above n, and every inner
stage's percentage lies in 0..100; its end, "study 100.0%", is drawn and then erased, and
each warning starts on an erased line, so no message is glued to a half line. On the pipe
there is no progress at all (no carriage return). Both runs exit alike. Which draws come
between the first and the last depends on the machine's speed (a redraw waits 0.1 s), so
none of them is required. Exit 77 (skipped) where no pseudo-terminal can be opened.
"""
import os
import pty
import re
import subprocess
import sys

ERASE = "\x1b[K"


def run_on_pty(cmd):
    """(exit code, stderr text) of cmd with stderr on a pseudo-terminal."""
    try:
        master, slave = pty.openpty()
    except OSError as e:  # a machine without /dev/ptmx: skipped (ctest SKIP_RETURN_CODE)
        print("no pseudo-terminal here: %s" % e)
        sys.exit(77)
    proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                            stderr=slave)
    os.close(slave)
    chunks = []
    while True:
        try:
            data = os.read(master, 65536)
        except OSError:  # EIO: every writer has closed the terminal
            break
        if not data:
            break
        chunks.append(data)
    os.close(master)
    return proc.wait(), b"".join(chunks).decode("utf-8", "replace")


def fail(msg):
    """Report msg and exit 1."""
    print("FAIL:", msg)
    sys.exit(1)


def main():
    """Check the command of sys.argv on a pseudo-terminal and on a pipe."""
    args = sys.argv[1:]
    if len(args) < 3 or args[1] != "--":
        print(__doc__)
        sys.exit(2)
    variants, cmd = int(args[0]), args[2:]
    rc, text = run_on_pty(cmd)
    # the terminal turns "\n" into "\r\n": only the carriage returns before drawing count
    draws = [d for d in text.replace("\r\n", "\n").split("\r") if d.startswith(ERASE)]
    lines = [d[len(ERASE):] for d in draws]
    study = [s for s in lines if s.startswith("study ")]
    print("%d draws, %d of the study line; first %r, last %r" %
          (len(lines), len(study), study[0] if study else None, lines[-1] if lines else None))
    if "study 100.0%\r" + ERASE not in text:
        fail("the study's end is not drawn and erased")
    done = -1
    for s in study:
        m = re.match(r"study (\d+)/(\d+) variants", s)
        if not m:
            continue
        k, n = int(m.group(1)), int(m.group(2))
        if n != variants or k > n or k < done:
            fail("%r after %d variants done" % (s, done))
        done = k
        for p in re.findall(r"\(([a-z ]+) (\d+)%\)", s):
            if not 0 <= int(p[1]) <= 100:
                fail("inner stage out of range: %r" % s)
    for m in re.finditer("warning: ", text):
        if not text[:m.start()].endswith("\r" + ERASE):
            fail("a warning glued to the progress line: %r" %
                 text[max(0, m.start() - 60):m.start() + 20])
    # bytes: text mode would turn a carriage return into a newline
    piped = subprocess.run(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE)
    if b"\r" in piped.stderr:
        fail("progress drawn on a pipe: %r" % piped.stderr[:200])
    if piped.returncode != rc:
        fail("exit %d on the terminal, %d on a pipe" % (rc, piped.returncode))
    print("exit %d both ways; no progress on the pipe" % rc)


if __name__ == "__main__":
    main()
