"""Fixtures of the chaintube module's tests: the repository's samples copied into a temporary
folder (with the scenes they reference), and the `chaintube` command line built beside the
module (CHAINTUBE_CLI, set by ctest)."""
import os
import shutil
from pathlib import Path

import pytest

SOURCE = Path(os.environ.get("CHAINTUBE_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SAMPLES = SOURCE / "samples"


def copy_samples(folder, *names):
    """Copies samples/<name>.ctproj and samples/scenes into `folder`; returns the project paths."""
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copytree(SAMPLES / "scenes", folder / "scenes", dirs_exist_ok=True)
    projects = []
    for name in names:
        shutil.copy(SAMPLES / f"{name}.ctproj", folder / f"{name}.ctproj")
        projects.append(folder / f"{name}.ctproj")
    return projects


@pytest.fixture
def rig_project(tmp_path):
    """samples/test-rig.ctproj in a temporary folder of its own."""
    return copy_samples(tmp_path / "projects", "test-rig")[0]


@pytest.fixture
def motion_project(tmp_path):
    """samples/motion-rig.ctproj in a temporary folder of its own."""
    return copy_samples(tmp_path / "projects", "motion-rig")[0]


@pytest.fixture(scope="package")
def cli():
    """The `chaintube` executable of the same build as the module."""
    path = Path(os.environ.get("CHAINTUBE_CLI", SOURCE / "build/exporters/chaintube"))
    assert path.is_file(), f"the chaintube CLI is not built: {path}"
    return path
