"""The scripts in ``docs/`` that regenerate README's and docs' figures: each still starts and says how it is used.

They are not run here (each is a measurement of minutes); a script that no longer imports against the package, or
lost its command line, would leave a figure that no command written next to it can regenerate."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"
SCRIPTS = sorted(DOCS.glob("*.py"))


def test_there_are_scripts_to_check():
    assert len(SCRIPTS) >= 10 and (DOCS / "eval_boxes.py") in SCRIPTS


@pytest.mark.parametrize("script", SCRIPTS, ids=[s.name for s in SCRIPTS])
def test_a_docs_script_imports_and_prints_its_usage(script, tmp_path):
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    done = subprocess.run([sys.executable, str(script), "--help"], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.startswith("usage:") and not done.stderr
    assert not any(tmp_path.iterdir())  # --help writes nothing
