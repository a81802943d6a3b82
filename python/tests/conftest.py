"""Shared fixtures: where the repository and the build tree are (set by the ctest that runs
pytest; derived from this file's place otherwise)."""

import os
import pathlib

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("FACET_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
BINARY_DIR = pathlib.Path(os.environ.get("FACET_BINARY_DIR", SOURCE_DIR / "build"))
CORNELL = SOURCE_DIR / "scenes" / "cornell-box" / "scene.xml"
FACET_CLI = BINARY_DIR / "bin" / "facet"


@pytest.fixture
def cornell():
    return CORNELL


@pytest.fixture
def facet_cli():
    assert FACET_CLI.exists(), f"{FACET_CLI} is missing: build the facet command first"
    return FACET_CLI


@pytest.fixture
def cli_env():
    """The environment of a facet command the tests start: this one without LD_PRELOAD. The
    sanitizer build preloads AddressSanitizer's shared runtime into the interpreter
    (python/CMakeLists.txt); the command links its own, and ASan refuses two in one process."""
    return {k: v for k, v in os.environ.items() if k != "LD_PRELOAD"}
