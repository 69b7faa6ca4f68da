"""The plotting modules select Agg for files, but keep a Jupyter kernel's inline backend
(switching to Agg there hid every figure a notebook cell returned)."""

import os
import subprocess
import sys

import pytest

SCRIPT = ("import matplotlib, parapend.plotting, parapend.irregular, parapend.maps.figures;"
          "from parapend.style import use_agg; use_agg(); print(matplotlib.get_backend())")


def _backend(mplbackend):
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    if mplbackend is not None:
        env["MPLBACKEND"] = mplbackend
    out = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                         text=True, timeout=120, check=True)
    return out.stdout.strip().splitlines()[-1]


def test_agg_by_default():
    assert _backend(None).lower() == "agg"


def test_inline_backend_kept():
    pytest.importorskip("matplotlib_inline")
    inline = "module://matplotlib_inline.backend_inline"
    assert _backend(inline) == inline
