"""Receding-horizon control (``parapend.control.mpc``): the horizon problem's gradient, the
saved series re-integrated by an independent integrator, the terminal value, the CLI."""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from parapend.api import build_excitation
from parapend.cli import main
from parapend.control.mpc import horizon_problem, mpc_run

GAMMA = 0.01


def test_gradient_is_the_exact_derivative_of_the_horizon_objective():
    """The adjoint gradient against central differences, with and without an efficiency
    and a terminal value (the objective is smooth away from the efficiency's kink)."""
    rng = np.random.default_rng(1)
    n, dt = 24, 0.2
    qn = 0.3 * np.sin(1.8 * 0.5 * dt / 4 * np.arange(2 * n * 4 + 1))
    for eff, kappa in ((None, None), ((0.9, 0.8), 0.5), (None, 0.0)):
        p = horizon_problem(n, dt, gamma=GAMMA, efficiency=eff, terminal_weight=kappa)
        u = 0.5 * rng.normal(size=n)
        x0 = (2.0, 1.3)
        _, g = p.fun(u, x0, qn)
        e = 1e-6
        fd = [(p.fun(u + e * np.eye(n)[i], x0, qn)[0] - p.fun(u - e * np.eye(n)[i], x0, qn)[0])
              / (2 * e) for i in range(n)]
        np.testing.assert_allclose(g, fd, atol=1e-7)


def test_objective_is_the_work_of_the_held_torque_plus_the_terminal_energy():
    """f(u) = -(work) - kappa E_N, the work recomputed from an independent DOP853
    integration of the held torques."""
    n, dt, steps = 10, 0.25, 8
    exc = build_excitation(omega=1.8, delta=-0.3)
    t = 0.5 * dt / steps * np.arange(2 * n * steps + 1)
    p = horizon_problem(n, dt, gamma=GAMMA, steps=steps, terminal_weight=1.0)
    u = np.linspace(-0.5, 0.7, n)
    f, _ = p.fun(u, (math.pi - 1.0, 0.5), exc.q(t))
    y = np.array([math.pi - 1.0, 0.5])
    work = 0.0
    for j in range(n):
        s = solve_ivp(lambda tt, z, uj=u[j]: [z[1], (1 + exc.q(tt)) * math.sin(z[0])
                                              - GAMMA * z[1] + uj],
                      (j * dt, (j + 1) * dt), y, method="DOP853", rtol=1e-12, atol=1e-12)
        y1 = s.y[:, -1]
        work += -u[j] * (y1[0] - y[0])
        y = y1
    energy = 0.5 * y[1] ** 2 + math.cos(y[0])
    assert f == pytest.approx(-work - energy, abs=1e-8)


def _read(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["t", "theta", "theta_dot", "torque", "q"]
    return {k: np.array([float(r[i]) for r in rows[1:]]) for i, k in enumerate(rows[0])}


@pytest.fixture(scope="module")
def mpc_saved(tmp_path_factory):
    path = tmp_path_factory.mktemp("mpc") / "run.csv"
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = main(["track", "--gamma", str(GAMMA), "--torque-limit", "1", "--irregular",
                     "--controller", "mpc", "--horizon", "1", "--update-interval", "0.25",
                     "--periods", "20", "--save", str(path), "--json"])
    assert code == 0
    r = json.loads(out.getvalue())
    # the record the plant saw (the same seed gives the same sea as track --irregular)
    from parapend.control.track import design_sea

    rng = np.random.default_rng(0)
    exc = build_excitation(omega=1.8, delta=-0.3)
    sea, info = design_sea(1.8, math.sqrt(float(np.mean(exc.q_uniform(1024) ** 2))),
                           int(rng.integers(0, 2**63 - 1)))
    assert info == r["sea"]
    return path, r, sea.q


def test_saved_mpc_series_reintegrates_and_gives_the_reported_power(mpc_saved):
    """Each saved interval integrated again by DOP853 (rtol 1e-10) from its saved state with
    its saved torque held reproduces the next saved state; the power recomputed from the
    re-integrated angles is the reported one."""
    path, r, q = mpc_saved
    s = _read(path)
    assert s["t"].size == 20 * 64 + 1
    assert s["theta"][0] == pytest.approx(math.pi) and s["theta_dot"][0] == 0.0
    assert math.isnan(s["torque"][-1]) and np.all(np.abs(s["torque"][:-1]) <= 1.0)
    np.testing.assert_allclose(s["q"], q(s["t"]), atol=1e-12)
    t, th, om, tq = s["t"], s["theta"], s["theta_dot"], s["torque"][:-1]
    h = t[1] - t[0]
    t0 = t[:-1]

    def f(x, y):
        a, b = y[:t0.size], y[t0.size:]
        return np.concatenate((b, (1 + q(t0 + x)) * np.sin(a) - GAMMA * b + tq))

    sol = solve_ivp(f, (0.0, h), np.concatenate((th[:-1], om[:-1])), method="DOP853",
                    rtol=1e-10, atol=1e-10)
    th1, om1 = sol.y[:t0.size, -1], sol.y[t0.size:, -1]
    assert np.max(np.abs(th1 - th[1:])) < 1e-8
    assert np.max(np.abs(om1 - om[1:])) < 1e-7
    p = -tq * (th1 - th[:-1]) / h
    last = 10 * 64
    assert np.mean(p[-last:]) == pytest.approx(r["mean_power"], abs=1e-8)
    assert np.mean(p[10 * 64:]) == pytest.approx(r["run_power"], abs=1e-8)
    # the check can fail: a 10 % wrong damping is seen (on the last period)
    k = t0.size - 64
    bad = solve_ivp(lambda x, y: np.concatenate((y[64:], (1 + q(t0[k:] + x)) * np.sin(y[:64])
                                                 - 1.1 * GAMMA * y[64:] + tq[k:])),
                    (0.0, h), np.concatenate((th[k:-1], om[k:-1])), method="DOP853",
                    rtol=1e-10, atol=1e-10)
    assert np.max(np.abs(bad.y[:64, -1] - th[k + 1:])) > 1e-8


def test_mpc_harvests_from_rest_in_the_irregular_sea(mpc_saved):
    _, r, _ = mpc_saved
    assert r["success"] and r["catch_period"] is not None
    assert r["mean_power"] > 0 and r["run_power"] > 0
    assert r["peak_torque"] <= 1.0
    assert r["solves"] > 0 and r["controller"] == "mpc"


def test_terminal_value_keeps_the_energy_at_the_horizon_end():
    """Without the terminal value one horizon solve drains the pendulum at its end (the
    stored energy counts for nothing); with it the horizon ends with more energy."""
    exc = build_excitation(omega=1.8, delta=-0.3)
    n, dt = 32, exc.period / 32
    qn = exc.q(0.5 * dt / 4 * np.arange(2 * n * 4 + 1))
    ends = []
    for kappa in (0.0, 1.0):
        p = horizon_problem(n, dt, gamma=GAMMA, terminal_weight=kappa, torque_limit=1.0)
        res = p.solve((0.3, 1.8), qn, np.zeros(n))
        p.fun(res.x, (0.3, 1.8), qn)
        ends.append(0.5 * p.v[-1] ** 2 + math.cos(p.th[-1]))
    assert ends[1] > ends[0] + 0.5


def test_mpc_run_bad_input_is_a_parameter_error():
    from parapend.errors import ParameterError

    exc = build_excitation(omega=1.8, delta=-0.3)
    with pytest.raises(ParameterError, match="horizon"):
        mpc_run(exc, gamma=GAMMA, horizon=0.01, update_interval=0.1, dt=0.1, t_end=10)
    with pytest.raises(ParameterError, match="t_end"):
        mpc_run(exc, gamma=GAMMA, horizon=1, update_interval=0.1, dt=0.1)


@pytest.mark.parametrize("args,word", [
    (["--controller", "mpc", "--runs", "2"], "runs"),
    (["--controller", "mpc", "--noise-theta", "0.1"], "noise-theta"),
    (["--horizon", "3"], "horizon"),
    (["--controller", "mpc", "--horizon", "1", "--update-interval", "2"], "update-interval"),
    (["--controller", "mpc", "--plot", "x.png"], "plot")])
def test_cli_errors_are_one_line(args, word, capsys):
    assert main(["track", *args]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and word in err


@pytest.mark.slow
def test_perfect_forecast_harvests_most_of_the_noncausal_optimum():
    """The README's sea state on a 10-wave record: after 4 peak periods of warm-up, the MPC
    with a perfect forecast of one peak period over a whole repeat against ``sea``'s
    periodic optimum on the same record (docs/control.md)."""
    from parapend.irregular import sea

    s = sea(seed=0, repeat_period=80.0)
    exc = s.excitation
    tp = exc.period / 10
    r = mpc_run(exc, gamma=0.01, horizon=tp, update_interval=tp / 8, dt=tp / 32,
                t_end=exc.period + 4 * tp, average_from=4 * tp)
    assert r.success and r.catch_time is not None
    assert r.mean_power > 0
    assert r.mean_power / s.power > 0.5
    assert r.mean_power < s.limit_power
