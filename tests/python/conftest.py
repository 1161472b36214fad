"""Fixtures of the Python package's tests: the test data, a work directory and the CLI, from
the environment ctest sets (tests/python/CMakeLists.txt); run by hand:
CADMORPH_CLI=build/cli/cadmorph PYTHONPATH=build/python python3 -m pytest -q tests/python
"""
import os
import pathlib
import sys

import pytest

HERE = pathlib.Path(__file__).resolve().parent
# the test code shared with the CLI tests (tests/helpers: pygem_prm.py)
sys.path.insert(0, str(HERE.parent / "helpers"))


@pytest.fixture(scope="session")
def data() -> pathlib.Path:
    """tests/data."""
    return pathlib.Path(os.environ.get("CADMORPH_TEST_DATA", HERE.parent / "data"))


@pytest.fixture(scope="session")
def cli() -> str:
    """The cadmorph program of this build (CADMORPH_CLI); the cross-checks need it."""
    path = os.environ.get("CADMORPH_CLI")
    if not path or not os.access(path, os.X_OK):
        pytest.fail("CADMORPH_CLI must name the built cadmorph program, got %r" % path)
    return path


@pytest.fixture
def work(tmp_path_factory, request) -> pathlib.Path:
    """A fresh work directory for one test."""
    root = os.environ.get("CADMORPH_TEST_WORK")
    if not root:
        return tmp_path_factory.mktemp(request.node.name[:40])
    d = pathlib.Path(root) / request.node.name.replace("/", "_")[:80]
    d.mkdir(parents=True, exist_ok=True)
    for f in d.iterdir():
        if f.is_file():
            f.unlink()
    return d
