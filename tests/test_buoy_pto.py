"""The buoy's power take-off: the electrical optimum (parapend.hydro.pto, coupled_optimum with
an efficiency, ``parapend buoy --efficiency``).

Independent sources: finite differences (derivatives), parapend.pto.optimize_pto (the
uncoupled collocation solver, exact kink by slacks) on the free buoy's heave, the ideal
optimum (eta = 1, and the bound ``e(p) <= eta_g p``), the torque sampled in the time domain
(``sample``, no FFT) for the electrical power and its split, and the energy balance.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_buoy_kernel import toy_hydro

import parapend
from parapend.cli import main
from parapend.errors import ParameterError
from parapend.hydro.coupled import CoupledProblem, Pendulum, Wave, free_excitation, scales
from parapend.hydro.optimum import BALANCE_TOL, _Torque, coupled_optimum
from parapend.hydro.pto import ElectricalProblem, efficiency_pair, electrical_power

# a buoy like the default design (M = 402 kg, resonance near 1.74 s) without BEM
HYDRO = toy_hydro(radius=0.5, top=12.0)
PEND = Pendulum(80.0, 0.3, 7.2, 1.0)
WAVE = Wave.regular(0.2, 1.8)


def _electrical(hessian, coupled=True, width=0.05, n=6):
    sc = scales(HYDRO, PEND, WAVE, coupled=coupled)
    base = CoupledProblem(free_excitation(sc), sc.beta_nd, n, sc.gamma, hessian=hessian)
    tq = _Torque(base, HYDRO, PEND, WAVE, coupled)
    return ElectricalProblem(base, tq.gk, (0.9, 0.7), width), tq


@pytest.mark.parametrize("hessian", ["dense", "operator"])
def test_derivatives_match_finite_differences(hessian):
    pr, tq = _electrical(hessian)
    x = np.random.default_rng(0).normal(size=13) * 0.3
    # the torque is the inverse dynamics of the existing (dense-Jacobian) torque
    assert np.max(np.abs(pr.state(x)["tau"] - tq(x)[0])) <= 1e-12 * np.max(np.abs(tq(x)[0]))
    _, g, h = pr.evaluate(x)
    h = h if hessian == "dense" else h.dense()
    e, eye = 1e-6, np.eye(13)
    gf = np.array([(pr.power(x + e * eye[i]) - pr.power(x - e * eye[i])) / (2 * e)
                   for i in range(13)])
    hf = np.array([(pr.evaluate(x + e * eye[i])[1] - pr.evaluate(x - e * eye[i])[1]) / (2 * e)
                   for i in range(13)])
    assert np.max(np.abs(g - gf)) <= 1e-7 * np.max(np.abs(g))
    assert np.max(np.abs(h - hf)) <= 1e-6 * np.max(np.abs(h))


def test_electrical_power_of_samples():
    """The kink integrated on the piecewise-linear interpolant: exact for a sine."""
    t = 2 * np.pi * np.arange(64) / 64
    p = 1.0 + 2.0 * np.sin(t)
    e, pos, neg = electrical_power(p, (0.9, 0.8))
    # int max(1 + 2 sin, 0) / 2 pi, closed form (zero where sin = -1/2)
    a = np.arcsin(0.5)
    pos_exact = ((np.pi + 2 * a) + 4 * np.cos(a)) / (2 * np.pi)
    assert pos == pytest.approx(pos_exact, rel=2e-3)
    assert pos - neg == pytest.approx(1.0, rel=1e-12)
    assert e == pytest.approx(0.9 * pos - neg / 0.8, rel=1e-12)


def _sampled(r, eta, m=20000):
    """Electrical, generated and motoring power from the torque sampled by ``sample``."""
    t = r.period * np.arange(m) / m
    s = r.sample(t)
    p = -s["tau"] * s["theta_dot"]
    pos, neg = np.mean(np.maximum(p, 0)), np.mean(np.maximum(-p, 0))
    return eta[0] * pos - neg / eta[1], pos, neg, np.mean(p)


def test_coupled_electrical_optimum_invariants():
    eta = (0.9, 0.8)
    r = coupled_optimum(HYDRO, PEND, WAVE, harmonics=6, starts=4, efficiency=eta)
    assert r.success, r.status
    assert r.efficiency == eta and "electrical optimum" in r.status
    assert r.energy_balance_residual <= BALANCE_TOL
    # electrical <= eta_g ideal optimum (e(p) <= eta_g p), <= the motion's own mechanical
    assert 0 < r.electrical_power <= eta[0] * r.ideal_power
    assert r.electrical_power <= r.power
    assert r.generated_power - r.motoring_power == pytest.approx(r.power, rel=1e-9)
    # the same numbers from the motion sampled in the time domain (no FFT)
    e, pos, neg, mech = _sampled(r, eta)
    assert mech == pytest.approx(r.power, rel=1e-9)
    assert e == pytest.approx(r.electrical_power, rel=1e-6)
    assert pos == pytest.approx(r.generated_power, rel=1e-6)
    # the ideal optimum itself is a worse motion for the electrical power
    ideal = coupled_optimum(HYDRO, PEND, WAVE, harmonics=6, starts=4)
    assert ideal.power == pytest.approx(r.ideal_power, rel=1e-12)
    assert _sampled(ideal, eta)[0] < r.electrical_power
    # efficiency 1 both ways is the ideal problem
    one = coupled_optimum(HYDRO, PEND, WAVE, harmonics=6, starts=4, efficiency=1.0)
    assert one.power == ideal.power and one.electrical_power is None


def test_mass_to_zero_tends_to_one_way_electrical():
    eta = (0.9, 0.9)
    rel = []
    for m in (0.1, 0.001):
        p = Pendulum(m, 0.3, 0.09 * m, m / 80)
        c = coupled_optimum(HYDRO, p, WAVE, harmonics=6, starts=4, efficiency=eta)
        o = coupled_optimum(HYDRO, p, WAVE, harmonics=6, one_way=True, efficiency=eta)
        assert c.success and o.success, (c.status, o.status)
        rel.append(abs(c.electrical_power - o.electrical_power) / o.electrical_power)
    # the reaction's effect is proportional to m / M
    assert rel[1] < 0.02 * rel[0] and rel[1] < 1e-4


@pytest.mark.slow
def test_one_way_electrical_is_optimize_pto():
    """One-way (the free buoy's heave fed to the pendulum) against the uncoupled
    collocation solver with the exact kink (parapend.pto.optimize_pto)."""
    eta = 0.9
    r = coupled_optimum(HYDRO, PEND, WAVE, one_way=True, harmonics=32, efficiency=eta)
    sc = scales(HYDRO, PEND, WAVE, coupled=False)
    q1 = sc.q_spec[1]  # q = Re(q1 e^{is}) = |q1| sin(s + arg q1 + pi/2)
    o = parapend.pto.optimize_pto(efficiency=eta, harmonics=24, omega=sc.omega_nd,
                                  fourier=[(1, abs(q1), np.angle(q1) + np.pi / 2)],
                                  gamma=sc.gamma)
    assert r.success and o.success, (r.status, o.status)
    assert r.electrical_power == pytest.approx(o.electrical_power * sc.power_unit, rel=1e-4)
    assert r.power == pytest.approx(o.power * sc.power_unit, rel=1e-3)


@pytest.mark.parametrize("value, match", [
    (0.0, "numbers in"), (1.5, "numbers in"), ("0.9,x", "ETA_G"), ("0.9,0.8,0.7", "ETA_G"),
    (float("nan"), "numbers in"), ([0.9, -1], "numbers in")])
def test_bad_efficiency(value, match):
    with pytest.raises(ParameterError, match=match):
        efficiency_pair(value)


@pytest.mark.slow
def test_one_way_efficiency_and_torque_limit_is_optimize_pto():
    """Both at once, one-way, against the uncoupled collocation (exact kink, torque bound)."""
    from parapend.hydro.optimum import TORQUE_SLACK

    sc = scales(HYDRO, PEND, WAVE, coupled=False)
    q1 = sc.q_spec[1]
    free = coupled_optimum(HYDRO, PEND, WAVE, one_way=True, harmonics=12, efficiency=0.9)
    lim = 0.8 * free.peak_torque()
    r = coupled_optimum(HYDRO, PEND, WAVE, one_way=True, harmonics=24, efficiency=0.9,
                        torque_limit=lim)
    o = parapend.pto.optimize_pto(torque_limit=lim / sc.torque_unit, efficiency=0.9,
                                  harmonics=24, omega=sc.omega_nd, gamma=sc.gamma,
                                  fourier=[(1, abs(q1), np.angle(q1) + np.pi / 2)])
    assert r.success and o.success, (r.status, o.status)
    assert r.electrical_power == pytest.approx(o.electrical_power * sc.power_unit, rel=1e-4)
    assert r.peak_torque() <= lim * (1 + TORQUE_SLACK)


@pytest.mark.parametrize("argv, match", [
    (["--efficiency", "0"], "efficiency: expected numbers in (0, 1]"),
    (["--efficiency", "0.9,1.2"], "efficiency"),
    (["--efficiency", "high"], "efficiency: expected ETA_G"),
    (["--efficiency", "0.9", "--torque-limit", "-1"], "torque-limit"),
])
def test_cli_bad_efficiency(argv, match, capsys, tmp_path):
    before = set(tmp_path.iterdir())
    assert main(["buoy", *argv, "--save", str(tmp_path / "x.nc")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err, err
    assert match in err, err
    assert set(tmp_path.iterdir()) == before


@pytest.mark.slow
def test_cli_efficiency_json(capsys, sphere_nc):
    from test_buoy_cli import PEND as CLI_PEND
    from test_buoy_cli import PERIOD

    nc = sphere_nc
    assert main(["buoy", "--hydro", nc, "--wave-period", str(PERIOD), *CLI_PEND,
                 "--efficiency", "0.9,0.8", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["efficiency"] == [0.9, 0.8]
    assert out["success"], out["status"]
    assert out["power_w"] == out["electrical_power_w"]  # the headline: electrical
    assert out["pto_loss_w"] == pytest.approx(out["mechanical_power_w"]
                                              - out["electrical_power_w"],
                                              rel=1e-12)
    assert 0 < out["electrical_power_w"] <= 0.9 * out["ideal_power_w"]
    assert out["generated_power_w"] - out["motoring_power_w"] == pytest.approx(
        out["mechanical_power_w"], rel=1e-9)


@pytest.mark.slow
def test_default_design_with_efficiency():
    """The numbers of docs/buoy.md (default design, --efficiency 0.9), with the invariants:
    electrical <= eta_g x ideal, the ideal motion through the same take-off far below, and
    the energy balance."""
    r = parapend.buoy(efficiency=0.9)
    assert r.success, r.status
    from parapend.cli.buoy import _text_result

    text = "\n".join(_text_result(r))
    assert "electrical power (maximized)" in text and "take-off losses" in text
    assert r.electrical_power_w == pytest.approx(28.10, rel=2e-3)
    assert r.mechanical_power_w == pytest.approx(31.23, rel=2e-3)
    assert r.power_w == r.electrical_power_w
    assert r.ideal_power_w == pytest.approx(38.35, rel=2e-3)
    assert r.electrical_power_w <= 0.9 * r.ideal_power_w
    assert r.energy_balance_residual <= BALANCE_TOL
    ideal = parapend.buoy()
    p = ideal.samples(20000)["power"][:-1]
    # the ideal optimum is the copy of {theta(t), theta(t + T/2) + pi} (equal power) with
    # the smaller peak torque; through the take-off its image would give -16.2 W
    assert ideal.peak_torque_nm < ideal.solution.evidence["image_peak_torque"]
    assert electrical_power(p, (0.9, 0.9))[0] == pytest.approx(-25.569704, rel=1e-6)
    assert electrical_power(p, (0.9, 0.9))[0] < 0.5 * r.electrical_power_w
    assert r.one_way_electrical_power_w == pytest.approx(177.7, rel=2e-3)


def test_one_way_torque_limit_is_optimize_pto():
    """The augmented Lagrangian one-way (the free buoy's heave) against the uncoupled
    time-domain solver with the same limit (parapend.pto.optimize_pto: Hermite intervals
    and an interior point, an independent method)."""
    from parapend.hydro.optimum import TORQUE_SLACK

    sc = scales(HYDRO, PEND, WAVE, coupled=False)
    q1 = sc.q_spec[1]
    ideal = coupled_optimum(HYDRO, PEND, WAVE, one_way=True, harmonics=12)
    lim = 0.7 * ideal.peak_torque()
    r = coupled_optimum(HYDRO, PEND, WAVE, one_way=True, harmonics=12, torque_limit=lim)
    o = parapend.pto.optimize_pto(torque_limit=lim / sc.torque_unit, harmonics=24,
                                  omega=sc.omega_nd, gamma=sc.gamma,
                                  fourier=[(1, abs(q1), np.angle(q1) + np.pi / 2)])
    assert r.success and o.success, (r.status, o.status)
    assert "augmented Lagrangian" in r.status
    assert r.power == pytest.approx(o.power * sc.power_unit, rel=1e-4)
    assert r.power <= o.power * sc.power_unit * (1 + 1e-9)  # N harmonics: a lower bound
    assert r.peak_torque() <= lim * (1 + TORQUE_SLACK)
    assert r.energy_balance_residual <= BALANCE_TOL


@pytest.mark.slow
def test_torque_limit_on_an_irregular_record():
    """A 5-wave record under a limit at 0.8 of the ideal peak: the power falls a little,
    the peak holds between the grid points, the balance closes."""
    from parapend.hydro.optimum import TORQUE_SLACK

    h = toy_hydro(radius=2.0, top=6.0)
    p = Pendulum(2000.0, 1.0, 2500.0, 50.0)
    rec = Wave.from_spectrum(hs=2.0, tp=8.0, repeat_period=40.0, seed=0)
    ideal = coupled_optimum(h, p, rec, winding=5)
    lim = 0.8 * ideal.peak_torque()
    r = coupled_optimum(h, p, rec, winding=5, torque_limit=lim)
    assert r.success, r.status
    assert r.power <= ideal.power
    assert r.power >= 0.99 * ideal.power
    assert r.peak_torque() <= lim * (1 + TORQUE_SLACK)
    assert r.energy_balance_residual <= BALANCE_TOL


@pytest.mark.slow
def test_default_design_with_a_torque_limit():
    """The torque-limit table of docs/buoy.md (default design, 254.95 N m)."""
    from parapend.hydro.optimum import TORQUE_SLACK

    r = parapend.buoy(torque_limit=254.95)
    assert r.success, r.status
    # the local optimum from the ideal motion (peak 297.05 N m); from its half-period image
    # (peak 318.71 N m, the same ideal power) the limit gave another, 37.7476 W, on the
    # former per-call grid
    assert r.power_w == pytest.approx(38.322487, rel=1e-6)
    ideal = parapend.buoy()
    assert r.power_w <= ideal.power_w
    assert ideal.peak_torque_nm == pytest.approx(297.0503, rel=1e-6)
    assert 254.9 <= r.peak_torque_nm <= 254.95 * (1 + TORQUE_SLACK)
    assert r.energy_balance_residual <= BALANCE_TOL


def test_no_electrical_power_is_no_power():
    """A design whose best motion loses energy through the take-off: status no_power, the
    message names the efficiency (the CLI's one line)."""
    from test_buoy_kernel import HYDRO as HEAVY_BUOY

    from parapend.hydro.result import _result, _solve

    p = Pendulum(500.0, 1.0, 600.0, 60.0)
    wave = Wave.regular(1.5, 6.0)
    sol, _, notes = _solve(HEAVY_BUOY, p, wave, winding=1, harmonics=6, torque_limit=None,
                           efficiency=(0.9, 0.8), one_way=False)
    assert sol.power > 0 >= sol.electrical_power
    r = _result(HEAVY_BUOY, None, p, wave, {"kind": "regular"}, sol, None,
                torque_limit=None, efficiency=(0.9, 0.8), winding=1, notes=notes)
    assert r.status == "no_power" and not r.success
    assert r.message.startswith("no electrical power")


@pytest.mark.slow
def test_no_power_design_agrees_with_optimize_pto():
    """A design that cannot generate through an unequal take-off (0.69 generating, 0.96
    motoring): the one-way electrical optimum is negative and equals optimize_pto's
    (status no_power there)."""
    p = Pendulum(44.4, 0.46, 1.5 * 44.4 * 0.46**2, 2.04)
    wave = Wave.regular(0.2, 2.28)
    r = coupled_optimum(HYDRO, p, wave, one_way=True, harmonics=12, efficiency=(0.69, 0.96))
    sc = scales(HYDRO, p, wave, coupled=False)
    q1 = sc.q_spec[1]
    o = parapend.pto.optimize_pto(efficiency_generating=0.69, efficiency_motoring=0.96,
                                  harmonics=24, omega=sc.omega_nd, gamma=sc.gamma,
                                  fourier=[(1, abs(q1), np.angle(q1) + np.pi / 2)])
    assert o.status == "no_power"
    assert r.electrical_power < 0 < r.ideal_power
    assert r.electrical_power == pytest.approx(o.electrical_power * sc.power_unit, rel=1e-4)


@pytest.mark.slow
def test_invariants_over_random_designs():
    """Seeded random designs and take-offs: electrical <= eta_g x ideal, <= mechanical,
    generated - motoring = mechanical, and the energy balance, success or not."""
    rng = np.random.default_rng(5)
    for _ in range(6):
        m, length = rng.uniform(5, 150), rng.uniform(0.15, 0.5)
        p = Pendulum(m, length, rng.uniform(1, 2) * m * length**2, rng.uniform(0.1, 3))
        eta = (rng.uniform(0.6, 1), rng.uniform(0.6, 1))
        r = coupled_optimum(HYDRO, p, Wave.regular(0.2, rng.uniform(1.5, 2.4)),
                            harmonics=6, starts=4, efficiency=eta)
        assert r.electrical_power <= eta[0] * r.ideal_power + 1e-9 * abs(r.ideal_power)
        assert r.electrical_power <= r.power + 1e-12
        assert r.generated_power - r.motoring_power == pytest.approx(r.power, rel=1e-9,
                                                                     abs=1e-12)
        assert r.energy_balance_residual <= BALANCE_TOL


def _record_problem(waves, n):
    """The electrical problem of the toy record buoy (the docs' 5-wave test buoy) on a
    ``waves``-wave record with ``n`` harmonics, from its ideal optimum."""
    from parapend.optimal.fourier import _pad

    h = toy_hydro(radius=2.0, top=6.0)
    p = Pendulum(2000.0, 1.0, 2500.0, 50.0)
    rec = Wave.from_spectrum(hs=2.0, tp=8.0, repeat_period=8.0 * waves, seed=0)
    ideal = coupled_optimum(h, p, rec, winding=waves, harmonics=n)
    sc = scales(h, p, rec, coupled=True)

    def make(hessian):
        base = CoupledProblem(free_excitation(sc), sc.beta_nd, n, sc.gamma, winding=waves,
                              hessian=hessian)
        return ElectricalProblem(base, _Torque(base, h, p, rec, True).gk, (0.9, 0.9), 0.0)

    x0 = _pad(np.asarray(ideal.theta_coefficients["x"]), n)
    return make, x0, (h, p, rec, sc)


def test_record_preconditioned_krylov_is_a_dense_local_maximum():
    """A 2-wave record at N = 32: the preconditioned matrix-free continuation (trust-krylov
    on the Fourier coefficients scaled by the Hessian's estimated diagonal) ends its last
    width at first order, and the dense method of a regular wave (the dense Hessian,
    trust-exact) confirms it: its Hessian is negative definite there and trust-exact from
    it gains nothing. (From the ideal optimum the two continuations can end on different
    local maxima of this non-concave problem: 0.00819 preconditioned, 0.00745 dense.)"""
    from parapend.hydro.pto import maximize

    make, x0, _ = _record_problem(2, 32)
    widths = (1e-1, 3e-2, 1e-2, 3e-3, 1e-3)
    pr = make("operator")
    xo, exo, runs = maximize(pr, x0, widths)
    # |g| <= gtol, or the value settled at its rounding before
    assert runs[-1][2] in ("converged", "settled"), runs
    s = runs[-1][0]
    dense = make("dense")
    dense.width = s
    val, g, h = dense.evaluate(xo)
    assert np.max(np.linalg.eigvalsh(h)) < 0
    # first order, scale-free: the gain a full Newton step predicts is negligible (5e-13 of
    # the value when measured)
    assert 0.5 * g @ np.linalg.solve(-h, g) <= 1e-11 * abs(val)
    p0 = float(np.max(np.abs(dense.state(xo)["p"])))  # maximize's widths are relative
    xd, exd, runs_d = maximize(dense, xo, (s / p0,))
    assert dense.power(xd) == pytest.approx(val, rel=1e-9)
    assert exd == pytest.approx(exo, rel=1e-9)


@pytest.mark.slow
def test_record_electrical_optimum_second_methods():
    """A 2-wave record with its default harmonics: the electrical power of the returned
    motion sampled in the time domain (no FFT, a finer grid) is the reported one, the
    energy balance closes, electrical <= mechanical and <= eta_g x ideal."""
    h = toy_hydro(radius=2.0, top=6.0)
    p = Pendulum(2000.0, 1.0, 2500.0, 50.0)
    rec = Wave.from_spectrum(hs=2.0, tp=8.0, repeat_period=16.0, seed=0)
    eta = (0.9, 0.9)
    r = coupled_optimum(h, p, rec, winding=2, efficiency=eta)
    assert r.energy_balance_residual <= BALANCE_TOL
    assert 0 < r.electrical_power <= r.power
    assert r.electrical_power <= eta[0] * r.ideal_power
    e, pos, neg, mech = _sampled(r, eta)
    assert mech == pytest.approx(r.power, rel=1e-9)
    assert e == pytest.approx(r.electrical_power, rel=1e-6)
    assert pos == pytest.approx(r.generated_power, rel=1e-6)


class _StaleNumpy:
    """numpy whose ``empty`` returns arrays holding ``fill`` (stale heap contents)."""

    def __init__(self, fill):
        self.fill = fill

    def __getattr__(self, name):
        return getattr(np, name)

    def empty(self, shape, dtype=float, order="C"):
        a = np.empty(shape, dtype=dtype, order=order)
        a[...] = self.fill
        return a


def test_record_krylov_does_not_read_stale_workspace(monkeypatch):
    """SciPy's trlib wrapper allocates trlib's workspace with ``np.empty`` and trlib reads
    parts of it unwritten: the continuation on a record gives the same bits whatever that
    memory held (here: zeros, 1e300, NaN, -3), as the solve allocates it zeroed.
    (Without it: two different optima in the last 10 bits from these four fills.)"""
    from scipy.optimize._trlib import _trlib

    from parapend.hydro.pto import maximize

    make, x0, _ = _record_problem(2, 32)
    out = []
    for fill in (0.0, 1e300, np.nan, -3.0):
        monkeypatch.setattr(_trlib, "np", _StaleNumpy(fill))
        x, ex, _ = maximize(make("operator"), x0, (1e-1, 3e-2, 1e-2))
        out.append((x.tobytes(), ex))
    monkeypatch.undo()
    assert all(o == out[0] for o in out[1:])
    assert np.isfinite(out[0][1])
