"""The frame the deform/detect CLI test scripts share: the cadmorph binary and a work
directory from argv (CADMORPH DATA_DIR WORK_DIR), check() that counts failures, run() of one
cadmorph command, and finish() that reports and exits."""
import os
import subprocess
import sys


class CliCase:
    def __init__(self, name, command):
        self.cad, self.command = sys.argv[1], command
        self.work = os.path.join(sys.argv[3], name)
        os.makedirs(self.work, exist_ok=True)
        os.chdir(self.work)
        self.fails = 0

    def check(self, cond, what):
        if not cond:
            self.fails += 1
            print("FAILED:", what)

    def run(self, *args):
        p = subprocess.run([self.cad, self.command, *args], capture_output=True, text=True)
        return p.returncode, p.stdout, p.stderr

    def finish(self):
        print("%d passed, %d failed" % (1 if self.fails == 0 else 0, self.fails))
        sys.exit(1 if self.fails else 0)
