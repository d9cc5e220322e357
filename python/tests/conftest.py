"""Shared fixtures: the repository root and the `bulge` command line the
bindings are checked against (BULGE_BIN, else target/debug/bulge)."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def root():
    return ROOT


@pytest.fixture(scope="module")
def cli():
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    exe = pathlib.Path(os.environ.get("BULGE_BIN", target / "debug" / "bulge"))
    if not exe.is_file():
        pytest.skip(f"no bulge binary at {exe}: build it with cargo build (or set BULGE_BIN)")

    def call(*args):
        return subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True)

    return call
