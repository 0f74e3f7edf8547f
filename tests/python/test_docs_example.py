"""The examples of docs/python.md run as they stand, from the source folder."""

import os
import re
import subprocess
import sys

from conftest import SOURCE


def test_the_documented_examples_run():
    text = (SOURCE / "docs" / "python.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 2
    done = subprocess.run([sys.executable, "-c", "\n".join(blocks)], cwd=SOURCE,
                          capture_output=True, text=True, env=dict(os.environ), timeout=600)
    assert done.returncode == 0, done.stderr
    assert "Metropolis:" in done.stdout and "run-out median" in done.stdout
