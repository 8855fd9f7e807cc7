"""docs/python_cell_size_study.py runs (short sweep, Agg backend) and writes its study and figure."""

import os
import subprocess
import sys

import numpy as np

from conftest import SOURCE_DIR


def test_cell_size_study_example_runs(tmp_path):
    out = tmp_path / "study"
    env = dict(os.environ, MPLBACKEND="Agg")
    run = subprocess.run([sys.executable, str(SOURCE_DIR / "docs" / "python_cell_size_study.py"), "--small",
                          "--out", str(out)], env=env, capture_output=True, text=True, timeout=240)
    assert run.returncode == 0, run.stderr
    assert "fastest cell size" in run.stdout
    figure = out / "cell_size.png"
    assert figure.exists() and figure.stat().st_size > 10_000
    table = np.genfromtxt(out / "study.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    assert len(table) == 3 and set(np.round(table["cell_factor"], 6)) == {0.5, 1.0, 2.0}
