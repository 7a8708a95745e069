# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""Shared fixtures: where ../shared/data and the lumx CLI are, and how a test that needs them stops.

Real-world files are read in place from ../shared/data ($LUMX_SHARED_DIR overrides; CTest passes the
default as $LUMX_TEST_SHARED_DEFAULT). Without them a test is skipped with a message, except under CI
(CI=true), which always has them: there it fails, as the C++ tests do (tests/test_support.h).
"""
import json
import os
import subprocess
from pathlib import Path

import pytest

SOURCE_DIR = Path(os.environ.get("LUMX_TEST_SOURCE_DIR", Path(__file__).resolve().parents[2]))


def in_ci():
    return os.environ.get("CI", "") not in ("", "0", "false")


def missing(what):
    """Skips (or, under CI, fails) a test that needs something absent."""
    if in_ci():
        pytest.fail(f"{what} is missing, but CI always has it")
    pytest.skip(f"{what} is not present")


def shared_dir():
    env = os.environ.get("LUMX_SHARED_DIR") or os.environ.get("LUMX_TEST_SHARED_DEFAULT")
    return Path(env) if env else SOURCE_DIR.parent / "shared"


def shared_file(relative):
    path = shared_dir() / "data" / relative
    if not path.exists():
        missing(f"../shared/data/{relative} (real-world data is read in place there)")
    return path


def shared_photometry_files():
    root = shared_dir() / "data" / "photometry"
    if not root.is_dir():
        return []
    return sorted(p for p in root.rglob("*") if p.is_file() and p.suffix.lower() in (".ies", ".ldt"))


@pytest.fixture(scope="session")
def cli():
    """Runs the lumx CLI: cli(*args) -> CompletedProcess (text)."""
    path = os.environ.get("LUMX_TEST_CLI", "")
    if not path or not Path(path).exists():
        missing("the lumx CLI (build target lumx_cli; CTest passes its path as $LUMX_TEST_CLI)")

    def run(*args, check=True):
        r = subprocess.run([path, *map(str, args)], capture_output=True, text=True)
        if check and r.returncode != 0:
            raise AssertionError(f"lumx {' '.join(map(str, args))} failed ({r.returncode}):\n{r.stderr}")
        return r

    run.path = path
    # --json output, whatever the exit status (`lumx check` exits 1 on findings).
    run.json = lambda *args: json.loads(run(*args, "--json", check=False).stdout)
    return run
