"""``parapend simulate | basins | rotations``: the uncontrolled pendulum of paper Eq. 1.

``phi'' + gamma phi' + (1 + p cos(omega t)) sin(phi) = 0``, ``phi`` from the hanging
position. A thin shell over :mod:`parapend.dynamics` (motion, basins, continuation); the
defaults are the paper's coexistence case gamma = 0.1, p = 0.8, omega = 2.1 (Section 1).
"""

from __future__ import annotations

import math
import re

import numpy as np

from .. import limits
from ..errors import ParameterError, check_int, check_range
from . import _output
from ._common import (
    FIGURE_SUFFIXES,
    _check_output,
    _finite_float,
    _fmt,
    _int,
    _Progress,
    _table,
)

EQ1 = "paper Eq. 1: phi'' + gamma phi' + (1 + p cos(omega t)) sin(phi) = 0, phi from hanging"

# a value such as -3:3 or -1.5:2:10 is a range, not an option
_RANGE_OR_NUMBER = re.compile(
    r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?(:[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)*$"
    r"|^-(inf|infinity|nan)$", re.IGNORECASE)


def _numbers(name, count):
    """Parser of ``a:b`` (count 2) or ``a:b:n`` (count 3) values."""
    import argparse

    def conv(text):
        parts = text.split(":")
        if len(parts) != count:
            form = "LOW:HIGH" if count == 2 else "FROM:TO:N"
            raise argparse.ArgumentTypeError(f"expected {form}, got {text!r:.40}")
        try:
            vals = [float(x) for x in parts]
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected numbers, got {text!r:.40}") from None
        if not all(math.isfinite(v) for v in vals):
            raise argparse.ArgumentTypeError(f"expected finite numbers, got {text!r:.40}")
        return tuple(vals)

    conv.__name__ = name
    return conv


def _omega_arg(text):
    """``W`` or ``FROM:TO:N``."""
    import argparse

    if ":" in text:
        return _numbers("omega", 3)(text)
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number or FROM:TO:N, got "
                                         f"{text!r:.40}") from None
    if not math.isfinite(x):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r:.40}")
    return x


def _add_model(p, omega=True):
    g = p.add_argument_group("Eq. 1 parameters (defaults: the paper's coexistence case)")
    g.add_argument("--gamma", type=_finite_float("gamma"), default=0.1,
                   help=f"damping gamma in [0, {limits.DYN_MAX_GAMMA:g}] (default 0.1)")
    g.add_argument("--p", type=_finite_float("p"), default=0.8,
                   help=f"excitation strength p, |p| <= {limits.DYN_MAX_P:g} (default 0.8)")
    if omega:
        lo, hi = limits.DYN_OMEGA_RANGE
        g.add_argument("--omega", type=_finite_float("omega"), default=2.1,
                       help=f"forcing frequency in [{lo:g}, {hi:g}], units sqrt(g/l) "
                            "(default 2.1)")


def _check_model(a, omega=True):
    check_range("gamma", a.gamma, 0.0, limits.DYN_MAX_GAMMA)
    check_range("p", a.p, 0.0, limits.DYN_MAX_P, absolute=True)
    if omega:
        check_range("omega", a.omega, *limits.DYN_OMEGA_RANGE)


def add_parsers(sub) -> None:
    """Add simulate, basins and rotations to the subcommand parser."""
    p = sub.add_parser("simulate", help="one motion of the uncontrolled pendulum (Eq. 1)",
                       description="Simulate paper Eq. 1 from (phi0, dphi0) at t = 0 (DOP853, "
                                   "rtol 1e-11): time history, phase portrait (Fig. 1 right) "
                                   "and the classification of the final motion on the "
                                   "Poincare section t = m 2 pi/omega.")
    p._negative_number_matcher = _RANGE_OR_NUMBER
    _add_model(p)
    p.add_argument("--phi0", type=_finite_float("phi0"), default=0.5,
                   help=f"initial angle from the hanging position, rad, |phi0| <= "
                        f"{limits.SIM_MAX_PHI0:g} (default 0.5)")
    p.add_argument("--dphi0", type=_finite_float("dphi0"), default=0.0,
                   help=f"initial angular rate, |dphi0| <= {limits.SIM_MAX_DPHI0:g} (default 0)")
    p.add_argument("--periods", type=_int, default=200,
                   help=f"forcing periods, 1 to {limits.SIM_MAX_PERIODS}, with periods x 2 pi/"
                        f"omega x (sqrt(1 + |p|) + |dphi0|) <= {limits.SIM_MAX_WORK:g} "
                        "(default 200)")
    p.add_argument("--points-per-period", type=_int, default=64,
                   help="output samples per forcing period, 2 to 1024 (default 64)")
    p.add_argument("--plot", metavar="PNG",
                   help="draw the time history and phase portrait (PNG, SVG or PDF)")
    p.add_argument("--save", metavar="CSV", help="write the time series: t,phi,dphi,energy")
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("basins", help="basins of attraction of Eq. 1 (Fig. 2 right)",
                       description="Basins of attraction of paper Eq. 1 on an N x N grid of "
                                   "initial conditions at t = 0 (compiled RK4 kernel, 128 "
                                   "steps per period by default, early termination by "
                                   "capture). Every map reports how many of its labels are "
                                   "uncertain: a seeded sample of points is re-run with "
                                   "twice the steps and from 1e-6 away, and the share of "
                                   "labels that change is given with a 95 %% interval.")
    p._negative_number_matcher = _RANGE_OR_NUMBER
    _add_model(p)
    p.add_argument("--resolution", type=_int, default=200,
                   help=f"grid points per axis N, 2 to {limits.BASIN_MAX_RESOLUTION} "
                        "(default 200)")
    p.add_argument("--phi-range", type=_numbers("phi-range", 2), default=None,
                   metavar="LOW:HIGH",
                   help="initial phi range, ends included (default the circle [-pi, pi))")
    p.add_argument("--dphi-range", type=_numbers("dphi-range", 2), default=(-3.0, 3.0),
                   metavar="LOW:HIGH", help="initial dphi range, ends included (default -3:3)")
    p.add_argument("--periods", type=_int, default=300,
                   help=f"period budget per point, 1 to {limits.BASIN_MAX_PERIODS}, with "
                        f"integrated points x periods <= {limits.BASIN_MAX_WORK:g} (half "
                        "the grid on the default symmetric grid; default 300)")
    lo_s, hi_s = limits.BASIN_STEPS_RANGE
    p.add_argument("--steps-per-period", type=_int, default=128,
                   help=f"RK4 steps per forcing period, {lo_s} to {hi_s}; the work bound "
                        "counts periods x steps/128 (default 128)")
    lo_a, hi_a = limits.BASIN_ACCURACY_RANGE
    p.add_argument("--accuracy-sample", type=_int, default=1000,
                   help=f"points re-run to estimate the uncertain labels, {lo_a} to {hi_a} "
                        "(at most the integrated points; default 1000)")
    p.add_argument("--accuracy-seed", type=_int, default=0,
                   help="seed of the accuracy sample (default 0)")
    p.add_argument("--split-phases", action="store_true",
                   help="one basin per phase of a period-k attractor (the paper's four "
                        "attractors of Fig. 2 right)")
    p.add_argument("--engine", choices=["numba", "numpy"], default="numba",
                   help="compiled kernel (default) or the vectorized NumPy engine")
    p.add_argument("--plot", metavar="PNG", help="draw the basin image (PNG, SVG or PDF)")
    p.add_argument("--save", metavar="NC", help="write the basin Dataset as NetCDF (.nc)")
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("rotations",
                       help="existence and stability of the period-1 rotation (Fig. 2 left)",
                       description="Curves J (birth, fold), G (stability lost) and E "
                                   "(stability regained) of the period-1 rotation of paper "
                                   "Eq. 1 by continuation in p with Floquet multipliers: "
                                   "for one omega, or for FROM:TO:N the (omega, p) map.")
    p._negative_number_matcher = _RANGE_OR_NUMBER
    p.add_argument("--gamma", type=_finite_float("gamma"), default=0.1,
                   help=f"damping gamma in [0, {limits.DYN_MAX_GAMMA:g}] (default 0.1)")
    lo, hi = limits.ROT_OMEGA_RANGE
    p.add_argument("--omega", type=_omega_arg, default=2.1, metavar="W|FROM:TO:N",
                   help=f"one frequency, or N (1 to {limits.ROT_MAX_OMEGAS}) from FROM to TO, "
                        f"each in [{lo:g}, {hi:g}] (default 2.1)")
    p.add_argument("--p-max", type=_finite_float("p-max"), default=3.0,
                   help=f"largest p followed, in (0, {limits.ROT_MAX_P:g}] (default 3, the "
                        "paper's range)")
    p.add_argument("--time-limit", type=_finite_float("time-limit"),
                   default=limits.ROT_TIME_LIMIT, metavar="S",
                   help=f"seconds of continuation, in (0, {limits.ROT_MAX_TIME_LIMIT:g}]; past "
                        "them the branches stop where they are and the output says how far "
                        f"p was followed (default {limits.ROT_TIME_LIMIT:g})")
    p.add_argument("--plot", metavar="PNG",
                   help="draw J, G, E and the stability regions (PNG, SVG or PDF)")
    p.add_argument("--save", metavar="NC", help="write J, G, E against omega as NetCDF (.nc)")
    p.add_argument("--json", action="store_true", help="print one JSON object")


# --- simulate ------------------------------------------------------------------------------
def _cmd_simulate(a) -> dict | str:
    from ..dynamics.motion import simulate

    _check_model(a)
    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    _check_output(a.save, "--save", (".csv",))
    check_range("phi0", a.phi0, 0.0, limits.SIM_MAX_PHI0, absolute=True)
    check_range("dphi0", a.dphi0, 0.0, limits.SIM_MAX_DPHI0, absolute=True)
    periods = check_int("periods", a.periods, 1, limits.SIM_MAX_PERIODS)
    work = periods * 2 * math.pi / a.omega * (math.sqrt(1 + abs(a.p)) + abs(a.dphi0))
    if work > limits.SIM_MAX_WORK:
        raise ParameterError(f"periods: expected periods x 2 pi/omega x (sqrt(1 + |p|) + "
                             f"|dphi0|) <= {limits.SIM_MAX_WORK:g}, got {work:.4g}")
    check_int("points-per-period", a.points_per_period, 2, 1024)
    from ._common import _Ticker

    with _Ticker("simulate"):
        m = simulate(a.gamma, a.p, a.omega, a.phi0, a.dphi0, periods,
                     points_per_period=a.points_per_period)
    if a.save:
        _output.write_columns(a.save, {"t": m.t, "phi": m.phi, "dphi": m.dphi,
                                       "energy": m.energy})
    if a.plot:
        from ..dynamics.figures import plot_motion

        _output.plot(lambda mm, path: plot_motion(mm, path=path), m, a.plot)
    if a.json:
        return m.to_dict()
    c = m.classification
    rows = [["gamma, p, omega", f"{_fmt(m.gamma)}, {_fmt(m.p)}, {_fmt(m.omega)}"],
            ["initial (phi, dphi)", f"({_fmt(m.phi0)}, {_fmt(m.dphi0)})"],
            ["periods simulated", str(m.periods)],
            ["final motion", c.name],
            ["kind, period, winding", f"{c.kind}, {c.period}, {c.winding}"],
            ["net turns of phi", str(m.to_dict()["turns"])]]
    for j, (x, y) in enumerate(zip(c.phi, c.dphi)):
        rows.append([f"Poincare point {j + 1}", f"({_fmt(x)}, {_fmt(y)})"])
    if not m.success:
        rows.append(["status", f"{m.status}: {m.message}"])
    return (f"one motion of {EQ1}\n" + _table(rows, ["quantity", "value"])
            + "\nPoincare section t = m 2 pi/omega; phi wrapped to [-pi, pi).")


# --- basins --------------------------------------------------------------------------------
class _PromptInterrupt:
    """Answer a Ctrl-C within ``grace`` seconds even while compiled code holds the
    interpreter (the first compile of the basin kernel spends 30 s or more inside LLVM, where
    Python cannot deliver ``KeyboardInterrupt``: a Ctrl-C waited 15 s there).

    ``signal.set_wakeup_fd`` makes the C-level handler write a byte at once; a daemon thread
    (which runs while LLVM, called through ctypes, has released the GIL) waits for it, and if
    the main thread has not ended the command ``grace`` seconds later, prints the command's
    one line and ends the process with exit code 130 (nothing is half-written then: output
    files are written after the computation, atomically). Only in the main thread on POSIX.
    """

    def __init__(self, name: str, grace: float = 1.5):
        self.name, self.grace = name, grace
        self.done = False
        self.fds = None

    def __enter__(self):
        import os
        import signal
        import threading

        if os.name != "posix" or threading.current_thread() is not threading.main_thread():
            return self
        try:
            r, w = os.pipe()
            os.set_blocking(w, False)
            self.old_fd = signal.set_wakeup_fd(w, warn_on_full_buffer=False)
        except (OSError, ValueError):
            return self
        self.fds = (r, w)
        threading.Thread(target=self._watch, daemon=True).start()
        return self

    def _watch(self):
        import os
        import signal
        import sys
        import time

        while True:
            try:
                data = os.read(self.fds[0], 64)
            except OSError:
                data = b""
            if not data:          # the write end was closed: the command has ended
                os.close(self.fds[0])
                return
            if signal.SIGINT in data:
                time.sleep(self.grace)
                if not self.done:
                    try:
                        print(f"parapend {self.name}: interrupted", file=sys.__stderr__,
                              flush=True)
                    finally:
                        os._exit(130)

    def __exit__(self, *exc):
        import os
        import signal

        self.done = True
        if self.fds is not None:
            try:
                signal.set_wakeup_fd(self.old_fd)
            except (OSError, ValueError):
                pass
            os.close(self.fds[1])     # the watcher sees the end of the pipe and closes it
        return False


# --- basins --------------------------------------------------------------------------------
def basins_json(ds) -> dict:
    """The JSON object of ``parapend basins`` from a basin Dataset."""
    import json

    frac = ds["basin_fraction"].values
    err = (ds["basin_fraction_error"].values if "basin_fraction_error" in ds
           else np.full(frac.shape, np.nan))
    atts = []
    for c in range(ds.sizes["code"]):
        if c == 0 and frac[0] == 0:
            continue
        pp = ds["poincare_phi"].values[c]
        pd = ds["poincare_dphi"].values[c]
        ok = np.isfinite(pp)
        atts.append({"code": c, "name": str(ds["name"].values[c]),
                     "kind": str(ds["kind"].values[c]),
                     "period": int(ds["period"].values[c]),
                     "winding": int(ds["winding"].values[c]),
                     "direction": str(ds["direction"].values[c]),
                     "basin_fraction": float(frac[c]),
                     "basin_fraction_error": float(err[c]),
                     "poincare_phi": [float(x) for x in pp[ok]],
                     "poincare_dphi": [float(x) for x in pd[ok]]})
    keys = ("gamma", "p", "omega", "t0", "periods", "steps_per_period", "tol",
            "capture_radius", "engine", "workers", "elapsed_s", "convention")
    out = {k: ds.attrs[k] for k in keys if k in ds.attrs}
    out.update(resolution=[int(ds.sizes["phi"]), int(ds.sizes["dphi"])],
               phi_range=[float(ds["phi"].values[0]), float(ds["phi"].values[-1])],
               dphi_range=[float(ds["dphi"].values[0]), float(ds["dphi"].values[-1])],
               attractors=atts, stats=json.loads(ds.attrs.get("stats", "{}")),
               accuracy=json.loads(ds.attrs.get("accuracy", "{}")),
               mirror_symmetric=bool(ds.attrs.get("mirror_symmetric", 0)))
    return out


def _cmd_basins(a) -> dict | str:
    from ..dynamics.basins import basin_map

    _check_model(a)
    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    _check_output(a.save, "--save", (".nc",))
    n = check_int("resolution", a.resolution, 2, limits.BASIN_MAX_RESOLUTION)
    periods = check_int("periods", a.periods, 1, limits.BASIN_MAX_PERIODS)
    steps = check_int("steps-per-period", a.steps_per_period, *limits.BASIN_STEPS_RANGE)
    sample = check_int("accuracy-sample", a.accuracy_sample, *limits.BASIN_ACCURACY_RANGE)
    seed = check_int("accuracy-seed", a.accuracy_seed, 0, 2**63 - 1)
    # the default grid (whole circle, dphi range symmetric about 0) integrates half its
    # columns (symmetry of Eq. 1); the bound is on the trajectories actually integrated,
    # the accuracy check's included (twice at double steps and once: 3 units per point)
    sym = a.phi_range is None and a.dphi_range[0] == -a.dphi_range[1]
    points = n * (n // 2 + 1) if sym else n * n
    work = (points + 3 * min(sample, points)) * periods * steps / 128
    if work > limits.BASIN_MAX_WORK:
        raise ParameterError(f"periods: expected integrated points x periods x steps/128 <= "
                             f"{limits.BASIN_MAX_WORK:g} (1000 x 1000 at 300 periods), got "
                             f"{work:.3g} ({n} x {n}{', half by symmetry' if sym else ''}, "
                             f"{periods} periods, {steps} steps, accuracy sample included)")
    for name, rng, cap in (("phi-range", a.phi_range, 1e3), ("dphi-range", a.dphi_range, 1e3)):
        if rng is not None:
            if rng[1] <= rng[0]:
                raise ParameterError(f"{name}: expected LOW < HIGH, got {rng[0]:g}:{rng[1]:g}")
            if max(abs(rng[0]), abs(rng[1])) > cap:
                raise ParameterError(f"{name}: expected values within +-{cap:g}, got "
                                     f"{rng[0]:g}:{rng[1]:g}")
    bar = _Progress("basins")
    with _PromptInterrupt("basins"):
        ds = basin_map(a.gamma, a.p, a.omega, n_phi=n, n_dphi=n, dphi_range=a.dphi_range,
                       phi_range=a.phi_range, periods=periods, steps_per_period=steps,
                       split_phases=a.split_phases, engine=a.engine, progress=bar,
                       accuracy_sample=sample, accuracy_seed=seed)
    bar(1, 1)
    if a.save:
        _output.write_dataset(ds, a.save)
    if a.plot:
        from ..dynamics.figures import plot_basins

        _output.plot(lambda d, path: plot_basins(d, path=path), ds, a.plot)
    out = basins_json(ds)
    if a.json:
        return out
    rows = [[str(t["code"]), t["name"], t["kind"], str(t["period"]), str(t["winding"]),
             f"{100 * t['basin_fraction']:.2f}", f"{100 * t['basin_fraction_error']:.2f}",
             "; ".join(f"({x:.4f}, {y:.4f})" for x, y in zip(t["poincare_phi"],
                                                             t["poincare_dphi"]))]
            for t in out["attractors"]]
    head = (f"basins of {EQ1}\ngamma = {_fmt(a.gamma)}, p = {_fmt(a.p)}, omega = "
            f"{_fmt(a.omega)}; {n} x {n} initial conditions at t = 0, budget {periods} "
            f"periods, {steps} RK4 steps per period; {ds.attrs['elapsed_s']:.1f} s "
            f"({ds.attrs['engine']})\n")
    acc = out["accuracy"]
    lo, hi = acc["mislabel_interval"]
    tail = (f"\nuncertain labels: {100 * acc['mislabel_fraction']:.2f} % (95 % interval "
            f"{100 * lo:.2f} to {100 * hi:.2f} %): of {acc['sample']} sampled points, "
            f"{acc['changed_refined']} change label at {acc['refined_steps_per_period']} steps "
            f"per period, {acc['changed_perturbed']} from {acc['perturbation']:g} away; "
            "+- %: 95 % bound on the shift of a basin's share when they are recomputed"
            + ("\nthe map is mirror-symmetric by construction ((phi, phi') -> (-phi, -phi'): "
               "half the grid integrated)" if out["mirror_symmetric"] else ""))
    return head + _table(rows, ["code", "attractor", "kind", "period", "winding",
                                "basin %", "+- %", "Poincare points (phi, dphi)"]) + tail


# --- rotations -----------------------------------------------------------------------------
def _omegas(a) -> np.ndarray:
    lo, hi = limits.ROT_OMEGA_RANGE
    if isinstance(a.omega, tuple):
        w0, w1, n = a.omega
        if n != int(n):
            raise ParameterError(f"omega: expected an integer N in FROM:TO:N, got {n:g}")
        n = check_int("omega", int(n), 1, limits.ROT_MAX_OMEGAS)
        check_range("omega", w0, lo, hi)
        check_range("omega", w1, lo, hi)
        if n > 1 and w1 <= w0:
            raise ParameterError(f"omega: expected FROM < TO, got {w0:g}:{w1:g}")
        return np.linspace(w0, w1, n)
    return np.array([check_range("omega", a.omega, lo, hi)])


def _cmd_rotations(a) -> dict | str:
    from ..dynamics.continuation import rotation_boundaries, rotation_boundaries_at

    check_range("gamma", a.gamma, 0.0, limits.DYN_MAX_GAMMA)
    if not 0 < a.p_max <= limits.ROT_MAX_P:
        raise ParameterError(f"p-max: expected a number in (0, {limits.ROT_MAX_P:g}], got "
                             f"{a.p_max:g}")
    if not 0 < a.time_limit <= limits.ROT_MAX_TIME_LIMIT:
        raise ParameterError(f"time-limit: expected seconds in (0, "
                             f"{limits.ROT_MAX_TIME_LIMIT:g}], got {a.time_limit:g}")
    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    _check_output(a.save, "--save", (".nc",))
    oms = _omegas(a)
    single = not isinstance(a.omega, tuple)
    if single:
        from ._common import _Ticker

        with _Ticker("rotations"):
            r = rotation_boundaries_at(a.gamma, float(oms[0]), p_max=a.p_max,
                                       time_limit=a.time_limit)
        import xarray as xr

        ds = xr.Dataset({k: ("omega", np.array([v])) for k, v in
                         (("p_J", r.lowest_J), ("p_G", r.lowest_G), ("p_E", r.lowest_E),
                          ("p_start", r.p_start), ("p_reached", r.p_reached))},
                        coords={"omega": oms},
                        attrs={"gamma": a.gamma, "p_max": float(a.p_max),
                               "convention": "paper Eq. 1 (p, omega)", "status": r.status})
    else:
        bar = _Progress("rotations")
        ds = rotation_boundaries(a.gamma, oms, p_max=a.p_max, progress=bar,
                                 time_limit=a.time_limit)
    if a.save:
        _output.write_dataset(ds, a.save)
    if a.plot:
        from ..dynamics.figures import plot_rotation_boundaries

        _output.plot(lambda d, path: plot_rotation_boundaries(d, path=path), ds, a.plot)
    if single:
        if a.json:
            return r.to_dict()
        rows = [["J (birth, fold)", ", ".join(_fmt(x) for x in r.p_J) or "-"],
                ["G (stability lost, period doubling)", ", ".join(_fmt(x) for x in r.p_G)
                 or "-"],
                ["E (stability regained)", ", ".join(_fmt(x) for x in r.p_E) or "-"]]
        note = ("" if r.success else f"\n{r.status}: {r.message}")
        return (f"period-1 rotation of {EQ1}\ngamma = {_fmt(a.gamma)}, omega = "
                f"{_fmt(float(oms[0]))}, p in [0, {_fmt(a.p_max)}]\n"
                + _table(rows, ["boundary", "p"])
                + "\nstable for J < p < G and above E (Floquet multipliers inside the unit "
                  "circle)" + note)
    if a.json:
        return {"gamma": a.gamma, "p_max": a.p_max,
                "omega": [float(x) for x in ds["omega"].values],
                **{k: [None if math.isnan(x) else float(x) for x in ds[k].values]
                   for k in ("p_J", "p_G", "p_E", "p_start", "p_reached")},
                "convention": ds.attrs["convention"], "status": ds.attrs["status"],
                "success": ds.attrs["status"] == "ok"}
    rows = [[_fmt(w), _fmt(j), _fmt(g), _fmt(e), _fmt(r_)] for w, j, g, e, r_ in
            zip(*(ds[k].values for k in ("omega", "p_J", "p_G", "p_E", "p_reached")))]
    note = ("" if ds.attrs["status"] == "ok" else
            f"\ntime limit ({_fmt(a.time_limit)} s) reached: each branch was followed up to "
            "p_reached only (nan: not computed)")
    return (f"period-1 rotation of {EQ1}, gamma = {_fmt(a.gamma)}, p <= {_fmt(a.p_max)}\n"
            + _table(rows, ["omega", "p_J", "p_G", "p_E", "p_reached"]) + "\nnan: not found "
            "for p <= p_reached (or no rotation found by shooting)" + note)


COMMANDS = {"simulate": _cmd_simulate, "basins": _cmd_basins, "rotations": _cmd_rotations}
