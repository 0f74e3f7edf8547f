"""The module installs into a virtual environment (cmake --install --component python) and imports
from there without the build tree on the path."""

import os
import pathlib
import subprocess
import sys

from conftest import SOURCE


def test_installs_into_a_virtual_environment(tmp_path):
    build = pathlib.Path(os.environ.get("TALUS_BUILD_DIR", SOURCE / "build"))
    venv = tmp_path / "venv"
    # NumPy comes from the system's site-packages (Debian's python3-numpy).
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", venv], check=True)
    subprocess.run(["cmake", "--install", build, "--component", "python", "--prefix", venv],
                   check=True, capture_output=True)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    done = subprocess.run(
        [venv / "bin" / "python", "-c",
         "import talus; s = talus.Scene.load(%r); print(talus.__file__, s.total_rocks)"
         % str(SOURCE / "cases" / "ramp40" / "scene.toml")],
        check=True, capture_output=True, text=True, env=env, cwd=tmp_path)
    where, rocks = done.stdout.split()
    assert pathlib.Path(where).is_relative_to(venv)
    assert rocks == "1000"


def test_type_stubs_name_every_public_member():
    """_core.pyi (for type checkers and editors) lists exactly what the compiled core offers."""
    import ast
    import talus
    from talus import _core
    stub = ast.parse((SOURCE / "python" / "talus" / "_core.pyi").read_text())
    classes = {node.name: node for node in stub.body if isinstance(node, ast.ClassDef)}
    for name in ("Scene", "Event", "Calibration", "InputError"):
        assert name in classes, name
    for name in ("Scene", "Event", "Calibration"):
        stubbed = set()
        for node in classes[name].body:
            if isinstance(node, ast.FunctionDef):
                stubbed.add(node.name)
            elif isinstance(node, ast.AnnAssign):
                stubbed.add(node.target.id)
        offered = {m for m in dir(getattr(_core, name)) if not m.startswith("_")}
        assert stubbed == offered, (name, stubbed ^ offered)
    assert talus.__version__ == _core.__version__
