"""Every plotting command renders, at cheap parameters, a figure a referee would accept.

Each command runs in-process through the ``parapend`` entry point; the figure is checked
(tests/figure_checks.py) at the moment it is saved, as it is written: axis labels with units,
no legend over the data, colour bars covering their data, no text over other text. The checks
themselves are tested on figures made to fail them.
"""

from __future__ import annotations

import contextlib
import io
import math

import figure_checks as fc
import matplotlib
import numpy as np
import pytest
import xarray as xr

matplotlib.use("Agg")

#: labels of non-dimensional quantities that need no unit (plain text, ``$`` removed)
UNITLESS = (r"\\tau = .*", r"period m", r"harmonics N", r"damping \\gamma")

#: (name, argv without --plot): the default run, about 25 s on one core
FAST = [
    ("simulate", ["simulate", "--phi0", "0", "--dphi0", "2.5", "--periods", "20"]),
    ("track", ["track", "--omega", "2", "--delta", "-0.2", "--periods", "20"]),
    ("optimize", ["optimize", "--harmonics", "8"]),
    ("optimize-pto", ["optimize", "--torque-limit", "2.5"]),
    ("optimize-efficiency", ["optimize", "--torque-limit", "0.8", "--efficiency", "0.8"]),
    ("basins", ["basins", "--resolution", "12", "--periods", "60"]),
    ("pto-curve", ["pto-curve", "--points", "3"]),
    ("damping-sweep", ["damping-sweep", "--points", "9", "--harmonics", "8"]),
    ("harmonics", ["harmonics", "--from", "2", "--to", "8"]),
    *[(f"figure {n}", ["figure", n]) for n in ("1", "2b", "4", "5", "6", "8", "9")],
]
#: more than a few seconds each. Figure 2a (a minute: the rotation band's continuation) is
#: drawn by the same ``paper_figure`` in the report, whose figures test_report_figures checks
SLOW = [
    ("rotations", ["rotations", "--omega", "1.0:1.2:3"]),
    *[(f"figure {n}", ["figure", n]) for n in ("7", "10")],
]
#: commands run with physical options: every unit must be SI (sea is always in SI)
SI = [("sea", ["sea", "--length", "1.5", "--mass", "20"])]


def _render(argv, tmp_path, monkeypatch, *, plot: str | None = "--plot", si: bool = False):
    """Run ``parapend argv`` and return, for each figure it saved, ``(problems, legend
    texts)``; problems from :func:`figure_checks.all_problems`."""
    from parapend import fileio
    from parapend.cli import main

    seen = []
    save = fileio.figure_bytes

    def checked(fig, *args, **kwargs):
        with fileio._figure_rc():  # as it is written: in the style the file is drawn with
            problems = fc.all_problems(fig, unitless=UNITLESS, si=si)
        legends = [t.get_text() for ax in fig.axes if ax.get_legend() is not None
                   for t in ax.get_legend().get_texts()]
        seen.append((problems, legends))
        return save(fig, *args, **kwargs)

    monkeypatch.setattr(fileio, "figure_bytes", checked)
    if plot is not None:
        argv = [*argv, plot, str(tmp_path / "figure.png")]
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        rc = main(argv)
    assert rc == 0, out.getvalue()
    assert seen, f"{argv}: no figure saved"
    return seen


def _assert_clean(seen, argv):
    problems = sorted({p for probs, _ in seen for p in probs})
    assert not problems, f"parapend {' '.join(argv)}:\n  " + "\n  ".join(problems)


#: the figures that take 3 to 4 s each run in the slow set (the default run's 5 minutes)
SLOW_FIGURES = ("figure 1", "figure 4", "figure 6", "track")


@pytest.mark.parametrize("argv", [pytest.param(a, marks=pytest.mark.slow)
                                  if n in SLOW_FIGURES else a for n, a in FAST],
                         ids=[n for n, _ in FAST])
def test_figure(argv, tmp_path, monkeypatch):
    _assert_clean(_render(argv, tmp_path, monkeypatch), argv)


@pytest.mark.slow
@pytest.mark.parametrize("argv", [a for _, a in SLOW], ids=[n for n, _ in SLOW])
def test_figure_slow(argv, tmp_path, monkeypatch):
    _assert_clean(_render(argv, tmp_path, monkeypatch), argv)


@pytest.mark.parametrize("argv", [a for _, a in SI], ids=[n for n, _ in SI])
@pytest.mark.slow
def test_figure_si_units(argv, tmp_path, monkeypatch):
    _assert_clean(_render(argv, tmp_path, monkeypatch, si=True), argv)


#: physical options of a 1 m, 10 kg pendulum at 0.9 Hz and 9 cm: every plot made with them
#: shows each dimensional axis in SI (its own label, or an SI scale beside it)
PHYSICAL = ["--length", "1", "--mass", "10", "--frequency", "0.9", "--amplitude", "0.09"]
SI_BESIDE = [
    ("optimize", ["optimize", "--harmonics", "8", *PHYSICAL]),
    ("optimize-pto", ["optimize", "--torque-limit", "2.5", "--gamma", "0.03", *PHYSICAL]),
    ("damping-sweep", ["damping-sweep", "--points", "5", "--harmonics", "8", *PHYSICAL]),
    ("harmonics", ["harmonics", "--from", "2", "--to", "6", *PHYSICAL]),
    ("pto-curve", ["pto-curve", "--points", "3", *PHYSICAL]),
    ("track", ["track", "--omega", "2", "--delta", "-0.2", "--periods", "20", "--length", "1",
               "--mass", "10"]),
    ("simulate", ["simulate", "--periods", "20", "--length", "1", "--mass", "10"]),
]


@pytest.mark.slow
@pytest.mark.parametrize("argv", [a for _, a in SI_BESIDE], ids=[n for n, _ in SI_BESIDE])
def test_physical_options_give_si_axes(argv, tmp_path, monkeypatch):
    from parapend import fileio

    found = []
    save = fileio.figure_bytes

    def checked(fig, *args, **kwargs):
        fc.render(fig)
        found.extend(fc.si_axis_problems(fig, unitless=UNITLESS))
        found.append("checked")
        return save(fig, *args, **kwargs)

    monkeypatch.setattr(fileio, "figure_bytes", checked)
    _render(argv, tmp_path, monkeypatch)  # the same figures without units: FAST checks them
    assert "checked" in found
    problems = [p for p in found if p != "checked"]
    assert not problems, f"parapend {' '.join(argv)}:\n  " + "\n  ".join(problems)


def test_si_check_catches_a_model_unit_alone():
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    ax.set_xlabel("time (s)")
    ax.set_ylabel("power $P$ ($mgl/t_0$)")
    assert len(fc.si_axis_problems(fig)) == 1
    ax.secondary_yaxis("right", functions=(lambda v: 2 * v, lambda v: v / 2)).set_ylabel(
        "power (W)")
    assert fc.si_axis_problems(fig) == []
    plt.close(fig)


@pytest.mark.slow
def test_report_figures(tmp_path, monkeypatch):
    """``parapend reproduce``: every figure of the report (PNG and SVG of each)."""
    argv = ["reproduce", "--out", str(tmp_path / "report")]
    seen = _render(argv, tmp_path, monkeypatch, plot=None)
    assert len(seen) >= 10
    _assert_clean(seen, argv)


def test_pto_legend_lists_only_what_is_drawn(tmp_path, monkeypatch):
    """Motoring is shaded, and named in the legend, only when some power is negative."""
    lossy = _render(["optimize", "--torque-limit", "0.8", "--efficiency", "0.8"], tmp_path,
                    monkeypatch)
    assert not any("motoring" in t for t in lossy[-1][1]), lossy[-1][1]
    ideal = _render(["optimize", "--torque-limit", "2.5"], tmp_path, monkeypatch)
    assert any("motoring" in t for t in ideal[-1][1]), ideal[-1][1]


# --- the rotation band --------------------------------------------------------------------

def _rotations_dataset():
    """J, G, E as `parapend rotations --omega 0.8:2.0:13` finds them at gamma = 0.1: no
    rotation at 0.8, E above p_max = 3 at 0.9, 1.0 and 2.0."""
    om = np.round(np.linspace(0.8, 2.0, 13), 10)
    pj = np.array([np.nan, .3085, .3032, .3032, .3075, .3152, .3255, .3378, .3516, .3667,
                   .3827, .3995, .4168])
    pg = np.array([np.nan, .3130, .3169, .3369, .3759, .4354, .5153, .6143, .7307, .8631,
                   1.0106, 1.1721, 1.3469])
    pe = np.array([np.nan, np.nan, np.nan, 2.0137, 2.0849, 2.1711, 2.2680, 2.3760, 2.4962,
                   2.6291, 2.7750, 2.9336, np.nan])
    return xr.Dataset({"p_J": ("omega", pj), "p_G": ("omega", pg), "p_E": ("omega", pe)},
                      coords={"omega": om}, attrs={"gamma": 0.1, "p_max": 3.0})


def test_rotation_band_joins_no_unrelated_points():
    """The G-E band's top edge never joins p_max (E not found) to a value of E by a slanted
    edge (the diagonal fill_between drew between omega = 1.0 and 1.1): a change of status
    is a vertical step halfway between two grid omegas."""
    from parapend.dynamics.figures import _unstable_band

    ds = _rotations_dataset()
    om, pg, pe = ds["omega"].values, ds["p_G"].values, ds["p_E"].values
    bands = _unstable_band(om, pg, pe, 3.0)
    assert len(bands) == 1
    x, y = bands[0]
    n = int(np.isfinite(pg).sum())
    assert np.allclose(x[:n], om[1:]) and np.allclose(y[:n], pg[1:])  # bottom edge is G
    top_x, top_y = x[n:][::-1], y[n:][::-1]

    def e_near(w, y):  # y is E at a grid omega within half a step of w (a flat extension)
        near = np.abs(om - w) <= 0.5 * (om[1] - om[0]) + 1e-12
        return any(math.isclose(y, v) for v in pe[near] if np.isfinite(v))

    for (x0, y0), (x1, y1) in zip(zip(top_x[:-1], top_y[:-1]), zip(top_x[1:], top_y[1:])):
        if x0 == x1:  # a step: only halfway between grid omegas
            assert not any(math.isclose(x0, w) for w in om)
            continue
        at_max = [math.isclose(y0, 3.0), math.isclose(y1, 3.0)]
        assert at_max[0] == at_max[1], f"slanted edge ({x0}, {y0}) - ({x1}, {y1})"
        if not at_max[0]:
            assert e_near(x0, y0) and e_near(x1, y1)


def test_rotation_figure_is_clean():
    from parapend.dynamics.figures import plot_rotation_boundaries

    fig = plot_rotation_boundaries(_rotations_dataset(),
                                   points={"Fig. 1": (2.1, 0.8), "Fig. 2": (1.8, 0.5)})
    assert not fc.all_problems(fig, unitless=UNITLESS)


# --- the checks catch what they are for -----------------------------------------------------

def _figure(size=(4, 3)):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=size)
    FigureCanvasAgg(fig)
    return fig


def test_checks_catch_missing_labels_and_units():
    fig = _figure()
    ax = fig.add_subplot()
    ax.plot([0, 1], [0, 1])
    ax.set_xlabel("time (s)")
    fc.render(fig)
    assert fc.label_problems(fig) == ["axes 0 (''): no y label"]
    ax.set_ylabel("power")
    assert "has no unit" in fc.label_problems(fig)[0]
    ax.set_ylabel("power (m g l / t0)")
    assert fc.label_problems(fig) == []
    assert "no SI unit" in fc.label_problems(fig, si=True)[0]
    ax.set_ylabel("power (W)")
    assert fc.label_problems(fig, si=True) == []


def test_checks_catch_a_legend_over_data():
    fig = _figure()
    ax = fig.add_subplot()
    t = np.linspace(0, 1, 50)
    ax.plot(t, np.full_like(t, 0.9), label="a line through the legend")
    ax.plot(t, t, label="diagonal")
    ax.set_ylim(0, 1)
    ax.legend(loc="upper left")
    fc.render(fig)
    assert fc.legend_problems(fig)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0))  # beside the axes
    fc.render(fig)
    assert fc.legend_problems(fig) == []


def test_checks_catch_a_clipped_colour_bar():
    fig = _figure()
    ax = fig.add_subplot()
    data = np.linspace(0, 71.8, 20).reshape(4, 5)
    im = ax.imshow(data, vmin=0, vmax=17.8)
    fig.colorbar(im, ax=ax)
    fc.render(fig)
    assert "do not cover" in fc.colorbar_problems(fig)[0]
    im.set_clim(0, 71.8)
    assert fc.colorbar_problems(fig) == []


def test_checks_catch_overlapping_text():
    fig = _figure()
    ax = fig.add_subplot()
    ax.plot([0, 1], [0, 1])
    ax.set_title("a title")
    ax.text(0.5, 1.02, "text on the title", transform=ax.transAxes, ha="center")
    fc.render(fig)
    assert any("title" in p for p in fc.text_problems(fig))
    ax.texts[0].remove()
    fc.render(fig)
    assert fc.text_problems(fig) == []
