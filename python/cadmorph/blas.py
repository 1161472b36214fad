"""blas_info(): which OpenBLAS kernels and threads the library's dense calls run on here.

The cadmorph program restarts itself with the OpenBLAS core its CPU deserves and one OpenBLAS
thread at load (include/cadmorph/blas.h says why). A Python process cannot: OpenBLAS chose its
kernels and started its threads when the interpreter first loaded it (NumPy loads it too).
So a process that wants the CLI's kernels, and the CLI's bits on the methods whose sparse
factorisations call BLAS (femwarp, lbwarp, mls, dmffd), starts Python with them:

    OPENBLAS_CORETYPE=SkylakeX OPENBLAS_NUM_THREADS=1 python3 script.py

`blas_info().advice` gives that line for this machine ("" when nothing is to gain).
"""
import os
from dataclasses import dataclass

from ._capi import ffi, lib


@dataclass(frozen=True)
class BlasInfo:
    """OpenBLAS as this process runs it (cm_blas_info).

    Attributes:
        config: openblas_get_config(), e.g. "OpenBLAS 0.3.21 DYNAMIC_ARCH ...".
        core: the kernels OpenBLAS runs now ("Prescott", "Haswell", "SkylakeX", ...).
        better_core: the core the CPU supports when OpenBLAS chose weaker kernels, else "".
        coretype_set: OPENBLAS_CORETYPE was set when OpenBLAS loaded.
        threads_now: OpenBLAS's thread count now.
        threads: the threads a dense factorisation asks for (all cores by default).
        advice: the environment to start Python with for the CLI's kernels and threads, or ""
            when this process already has them.
    """

    config: str
    core: str
    better_core: str
    coretype_set: bool
    threads_now: int
    threads: int
    advice: str


def blas_info() -> BlasInfo:
    """What OpenBLAS runs on in this process, and how to start Python to run as the CLI does
    (see the module's docstring). Report `core` with every dense timing."""
    s = ffi.new("cm_blas_summary *")
    lib.cm_blas_info(ffi.NULL, s)
    better = lib.cm_blas_action_core(s.action)
    better = ffi.string(better).decode() if better != ffi.NULL else ""
    env = []
    if better:
        env.append("OPENBLAS_CORETYPE=" + better)
    if os.environ.get("OPENBLAS_NUM_THREADS") != "1":
        env.append("OPENBLAS_NUM_THREADS=1")
    return BlasInfo(config=ffi.string(s.config).decode(), core=ffi.string(s.core).decode(),
                    better_core=better, coretype_set=bool(s.coretype_set),
                    threads_now=int(s.threads_now), threads=int(s.threads),
                    advice=" ".join(env))
