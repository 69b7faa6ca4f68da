"""``parapend reproduce``: files, key numbers, determinism, and the page in a real browser."""

import json
import os
import shutil
import subprocess

import pytest

from parapend.cli import main
from parapend.report import reproduce


@pytest.fixture(scope="module")
def report_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    reproduce(out)
    return out


def test_files_written(report_dir):
    figs = {p.name for p in (report_dir / "figures").iterdir()}
    for key in ("fig1", "fig2a", "fig2b", "fig4", "fig5", "fig6", "fig7", "fig8", "fig9",
                "fig10"):
        assert f"{key}.png" in figs and f"{key}.svg" in figs
        assert (report_dir / "figures" / f"{key}.png").stat().st_size > 10_000
    assert {p.name for p in (report_dir / "tables").iterdir()} >= {
        "table1.csv", "table2.csv", "table3.csv", "scalars.csv"}
    assert (report_dir / "report.html").read_text().count("data:image/png;base64,") == 10


def test_key_numbers(report_dir):
    r = json.loads((report_dir / "results.json").read_text())
    t1 = {row["quantity"]: row for row in r["tables"]["table1"]}
    assert t1["best uniform rotation"]["parapend"] == pytest.approx(0.27, abs=1e-14)
    assert t1["Fourier series, N = 24"]["parapend"] >= 0.3424
    assert round(t1["piecewise-constant limit"]["parapend"], 4) == 0.3438
    t2 = {row["quantity"]: row for row in r["tables"]["table2"]}
    assert t2["Fourier series, N = 30"]["parapend"] >= 0.3763
    for row in r["tables"]["table3"]:
        assert round(row["parapend"], 4) == 0.3438
    sc = {row["quantity"][:24]: row for row in r["tables"]["scalars"]}
    assert round(sc["damping threshold gamma*"]["parapend"], 4) == 0.0856
    # Fig. 4: nondecreasing in N and below the limit for every chosen (delta, omega)
    for case in r["figures"]["fig4"]:
        p = case["power"]
        assert all(b >= a - 1e-14 for a, b in zip(p, p[1:])) and p[-1] < case["limit_power"]
    # Fig. 5: BVP power rises towards the limit as epsilon falls
    p5 = [row["power"] for row in r["figures"]["fig5"]]
    assert all(b > a for a, b in zip(p5, p5[1:])) and p5[-1] < 0.3437746770785
    # Fig. 9: distinct optima of equal power through (0.5, 2 pi); Fig. 10: uniform rotation
    f9 = r["figures"]["fig9"]
    assert len(f9["power"]) >= 3 and max(f9["power"]) - min(f9["power"]) < 1e-6
    assert all(abs(v - 2 * 3.141592653589793) < 1e-3 for v in f9["theta_at_half_period"])
    # Fig. 1: the recorded initial conditions reach the attractors they are named after, and
    # the rotation's Floquet multipliers obey Liouville's formula
    f1 = r["figures"]["fig1"]
    assert all(k == v for k, v in f1["reached"].items())
    assert f1["rotation_floquet_product"] == pytest.approx(f1["liouville_exp_minus_gamma_T"],
                                                           rel=1e-8)
    # Fig. 2: both paper cases lie between J and G (stable rotation); basins sum to one
    f2 = r["figures"]["fig2a"]
    i = f2["omega"].index(1.8)
    assert f2["p_J"][i] < 0.5 < f2["p_G"][i]
    assert sum(r["figures"]["fig2b"]["basin_fraction"]) == pytest.approx(1.0)
    dev = [row["max_deviation_from_uniform"] for row in r["figures"]["fig10"]]
    assert all(b < a for a, b in zip(dev, dev[1:])) and dev[-1] < 1e-3


def test_values_are_computed_not_copied(monkeypatch):
    """Change the case: every 'parapend' value follows, the 'paper' column does not."""
    from parapend import paper

    monkeypatch.setattr(paper, "PAPER_CASE", {"delta": -0.4, "omega": 1.8})
    t = paper.tables()
    rows = {r["quantity"]: r for r in t["table1"]}
    assert rows["best uniform rotation"]["parapend"] == pytest.approx(0.36, abs=1e-14)
    assert rows["best uniform rotation"]["paper"] == 0.27
    lim = rows["piecewise-constant limit"]["parapend"]
    assert lim == pytest.approx(2 * 1.8 * 0.4 / 3.141592653589793)


def test_deterministic(report_dir, tmp_path):
    main(["reproduce", "--out", str(tmp_path)])
    assert (tmp_path / "results.json").read_bytes() == (report_dir / "results.json").read_bytes()


def _chromium():
    for name in ("chromium", "chromium-browser"):
        path = shutil.which(name)
        if path:
            return path
    if os.geteuid() == 0 and shutil.which("apt-get"):
        env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
        subprocess.run(["apt-get", "update", "-qq"], env=env, capture_output=True, timeout=600)
        subprocess.run(["apt-get", "install", "-y", "-qq", "chromium"], env=env,
                       capture_output=True, timeout=900)
    return shutil.which("chromium")


def test_report_renders_in_headless_chromium(report_dir, tmp_path):
    """Load report.html in Debian's Chromium and check every image decoded with a size."""
    exe = _chromium()
    if exe is None:
        pytest.skip("chromium is not installed and could not be installed with apt-get")
    probe = tmp_path / "probe.html"
    page = (report_dir / "report.html").read_text()
    script = ("<script>window.addEventListener('load',()=>{const s=[...document.images].map("
              "i=>i.complete&&i.naturalWidth>0&&i.naturalHeight>0&&i.width>0);"
              "document.title='IMAGES:'+s.length+':'+s.filter(x=>x).length;});</script>")
    probe.write_text(page.replace("</body>", script + "</body>"))
    flags = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
             "--disable-background-networking", "--disable-component-update", "--disable-sync",
             f"--user-data-dir={tmp_path / 'profile'}"]
    dom = subprocess.run([exe, *flags, "--virtual-time-budget=5000", "--dump-dom",
                          probe.as_uri()], capture_output=True, text=True, timeout=120)
    assert "<title>IMAGES:10:10</title>" in dom.stdout
    shot = tmp_path / "shot.png"
    subprocess.run([exe, *flags, f"--screenshot={shot}", "--window-size=1100,3000",
                    (report_dir / "report.html").as_uri()], capture_output=True, timeout=120)
    assert shot.exists() and shot.stat().st_size > 10_000
