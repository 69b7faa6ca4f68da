"""The free buoy's heave response against WecOptTool on the same Capytaine dataset (slow).

WecOptTool pins an older Capytaine than parapend needs, so it lives in its own virtual
environment (``python benchmarks/wecopttool_free_buoy.py --setup``); without it the test is
skipped. It runs ``benchmarks/wecopttool_free_buoy.py --json``: a BEM of the default
cylinder written with ``save_dataset_as_netcdf``, read by :func:`parapend.hydro.bem.load`
and by WecOptTool (``read_netcdf``, ``change_bem_convention``), the free response ``Z/a``
of each compared (docs/buoy.md, "Bring your own dataset").
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "benchmarks" / "wecopttool_free_buoy.py"


def _venv() -> Path:
    env = os.environ.get("PARAPEND_WOT_VENV")
    return Path(env) if env else Path.home() / ".cache" / "parapend" / "wot-venv"


def _python(venv: Path) -> Path:
    return venv / ("Scripts/python.exe" if os.name == "nt" else "bin/python")


@pytest.mark.slow
def test_free_response_against_wecopttool(tmp_path):
    if not SCRIPT.is_file():
        pytest.skip(f"{SCRIPT} is not in this checkout")
    venv = _venv()
    if not _python(venv).is_file():
        pytest.skip(f"no WecOptTool virtual environment at {venv} (create it with "
                    "`python benchmarks/wecopttool_free_buoy.py --setup`; WecOptTool pins "
                    "capytaine 2.3.1 and cannot share parapend's environment)")
    env = dict(os.environ, PARAPEND_CACHE=str(tmp_path / "cache"))
    run = subprocess.run([sys.executable, str(SCRIPT), "--json", "--venv", str(venv)],
                         capture_output=True, text=True, env=env, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    r = json.loads(run.stdout.strip().splitlines()[-1])
    assert len(r["omega"]) == 30
    # both use exp(+i w t) after the convention change: the same division of the same
    # numbers, to round-off, except where WecOptTool floors a negative BEM damping at
    # 1e-6 N s/m (parapend uses max(B, 0)): a change of 1e-6 N s/m in B
    assert r["max_rel_diff_unfloored"] < 1e-12
    assert r["max_rel_diff"] < 1e-6
    # the test is sensitive to the convention: left unconjugated the excitation differs
    # by much more than any tolerance here
    assert r["max_rel_diff_unconjugated"] > 0.5
    # WecOptTool's pseudo-spectral solver, regular wave near resonance, no PTO
    assert r["ps_status"] == 0, r["ps_message"]
    assert r["ps_rel_diff"] < 1e-8
