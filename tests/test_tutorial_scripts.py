"""Every tutorial's calls, run as a plain ``python script.py`` (no ``__main__`` guard, no
notebook kernel), work: the parallel functions, the figures and the files they write
(the acceptance; the documentation build runs the same cells in a Jupyter kernel)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

TUTORIALS = sorted((Path(__file__).resolve().parents[1] / "docs" / "tutorials").glob("*.md"))
_CELL = re.compile(r"^```\{code-cell\}[^\n]*\n(.*?)^```", re.M | re.S)


def script(page: Path) -> str:
    """The page's code cells in order, as one script: the cells a reader sees (those tagged
    ``remove-cell`` only set up the notebook's display) and a last expression of a cell
    dropped on the floor as a script does."""
    cells = []
    for body in _CELL.findall(page.read_text(encoding="utf-8")):
        lines = body.splitlines()
        tags = [ln for ln in lines if ln.startswith(":tags:")]
        if any("remove-cell" in t for t in tags):
            continue
        cells.append("\n".join(ln for ln in lines if not ln.startswith(":")))
    return "import matplotlib\nmatplotlib.use('Agg')\n\n" + "\n\n".join(cells) + "\n"


def test_the_script_of_a_page_keeps_its_cells():
    text = script(TUTORIALS[0])
    assert "get_ipython" not in text and "import parapend" in text


@pytest.mark.slow
@pytest.mark.parametrize("page", TUTORIALS, ids=[p.stem for p in TUTORIALS])
def test_a_tutorial_runs_as_a_plain_script(page, tmp_path):
    path = tmp_path / f"{page.stem.replace('-', '_')}.py"
    path.write_text(script(page), encoding="utf-8")
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONUNBUFFERED": "1"}
    proc = subprocess.run([sys.executable, str(path)], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
