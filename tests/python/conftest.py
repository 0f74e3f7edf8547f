"""Shared set-up of the Python module's tests: where the sources, the talus program and the test
scenes are. CTest sets TALUS_SOURCE_DIR and TALUS_PROGRAM (tests/python/CMakeLists.txt)."""

import os
import pathlib
import subprocess

import pytest

SOURCE = pathlib.Path(os.environ.get("TALUS_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
PROGRAM = os.environ.get("TALUS_PROGRAM", str(SOURCE / "build" / "app" / "talus"))
TSCHAMUT = SOURCE / "cases" / "tschamut2014"


def run_talus(*args, check=True):
    """Runs the talus program; returns the completed process (stdout and stderr as text)."""
    done = subprocess.run([PROGRAM, *map(str, args)], capture_output=True, text=True)
    if check and done.returncode != 0:
        raise AssertionError(f"talus {' '.join(map(str, args))} failed: {done.stderr}")
    return done


@pytest.fixture
def small_ramp(tmp_path):
    """A scene of the ramp with 6 rocks, trajectories and every raster: a few seconds."""
    text = (SOURCE / "cases" / "ramp40" / "scene.toml").read_text()
    text = text.replace("rocks = 1000", "rocks = 6").replace("trajectories = false",
                                                              "trajectories = true")
    assert "rocks = 6" in text and "trajectories = true" in text
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return path


@pytest.fixture
def small_calibration(tmp_path):
    """The Tschamut calibration with 2 rocks per run, two free parameters and 4 evaluations."""
    path = tmp_path / "calibrate.toml"
    path.write_text(f"""
event = "{TSCHAMUT / 'calibrate_event.toml'}"
rocks = 2
seed = 1

[[parameters]]
category = "medium"
field = "mu_min"
lower = 0.1
upper = 1.2

[[parameters]]
category = "medium"
field = "kappa"
lower = 0.2
upper = 10

[objective]
weights = {{ runout = 1.0, deposit = 1.0 }}

[optimizer]
algorithm = "bobyqa"
max_evaluations = 4
initial_step = 0.15
seed = 1

[roughness]
enabled = false

[uncertainty]
enabled = false
""")
    return path
