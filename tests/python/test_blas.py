"""blas_info(): the OpenBLAS core and threads of this process, and the advice to start
Python as the CLI runs (a child process with the environment set, as a user would)."""
import json
import os
import subprocess
import sys

import cadmorph


def child_info(env_extra):
    env = {k: v for k, v in os.environ.items() if not k.startswith("OPENBLAS_")}
    env.update(env_extra)
    code = ("import cadmorph, dataclasses, json; "
            "print(json.dumps(dataclasses.asdict(cadmorph.blas_info())))")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, check=True).stdout
    return json.loads(out)


def test_info_of_this_process():
    info = cadmorph.blas_info()
    assert info.core and info.core.lower() in info.config.lower()
    assert info.threads_now >= 1 and info.threads >= 1


def test_the_advised_environment_needs_no_further_advice():
    first = child_info({})
    assert "OPENBLAS_NUM_THREADS=1" in first["advice"]
    env = dict(item.split("=", 1) for item in first["advice"].split())
    second = child_info(env)
    assert second["advice"] == ""
    assert second["threads_now"] == 1
    if first["better_core"]:
        assert second["core"].lower() == first["better_core"].lower()
