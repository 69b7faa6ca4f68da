"""``parapend simulate | basins | rotations``: the uncontrolled pendulum of paper Eq. 1.

``phi'' + gamma phi' + (1 + p cos(omega t)) sin(phi) = 0``, ``phi`` from the hanging
position. A thin shell over :mod:`parapend.dynamics` (motion, basins, continuation); the
defaults are the paper's coexistence case gamma = 0.1, p = 0.8, omega = 2.1 (Section 1).
"""

from __future__ import annotations

import math
import re

from .. import limits
from ..commands import basins_json  # noqa: F401  (its former home)
from . import _output
from . import pto as _pto
from ._common import (
    FIGURE_SUFFIXES,
    SAVE_GRID,
    SAVE_TABLE,
    _check_output,
    _finite_float,
    _fmt,
    _int,
    _Progress,
    _run,
    _table,
    add_output_options,
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
    g.add_argument("--gamma", type=_finite_float("gamma"),
                   help=f"damping gamma in [0, {limits.DYN_MAX_GAMMA:g}] (default 0.1)")
    g.add_argument("--p", type=_finite_float("p"),
                   help=f"excitation strength p, |p| <= {limits.DYN_MAX_P:g} (default 0.8)")
    if omega:
        lo, hi = limits.DYN_OMEGA_RANGE
        g.add_argument("--omega", type=_finite_float("omega"),
                       help=f"forcing frequency in [{lo:g}, {hi:g}], units sqrt(g/l) "
                            "(default 2.1)")


def add_parsers(sub) -> None:
    """Add simulate, basins and rotations to the subcommand parser."""
    p = sub.add_parser("simulate", help="one motion of the uncontrolled pendulum (Eq. 1)",
                       description="Simulate paper Eq. 1 from (phi0, dphi0) at t = 0 (DOP853, "
                                   "rtol 1e-11): time history, phase portrait (Fig. 1 right) "
                                   "and the classification of the final motion on the "
                                   "Poincare section t = m 2 pi/omega.")
    p._negative_number_matcher = _RANGE_OR_NUMBER
    _add_model(p)
    p.add_argument("--phi0", type=_finite_float("phi0"),
                   help=f"initial angle from the hanging position, rad, |phi0| <= "
                        f"{limits.SIM_MAX_PHI0:g} (default 0.5)")
    p.add_argument("--dphi0", type=_finite_float("dphi0"),
                   help=f"initial angular rate, |dphi0| <= {limits.SIM_MAX_DPHI0:g} (default 0)")
    p.add_argument("--periods", type=_int,
                   help=f"forcing periods, 1 to {limits.SIM_MAX_PERIODS}, with periods x 2 pi/"
                        f"omega x (sqrt(1 + |p|) + |dphi0|) <= {limits.SIM_MAX_WORK:g} "
                        "(default 200)")
    p.add_argument("--points-per-period", type=_int,
                   help="output samples per forcing period, 2 to 1024 (default 64)")
    _pto.add_unit_options(p, damping=False, excitation=False, adds="time in s, energy in J")
    add_output_options(p, plot="the time history and phase portrait",
                       save="the time series (time, phi, phi_dot, energy; in SI with --length "
                            "and --mass) and the scalars")

    p = sub.add_parser("basins", help="basins of attraction of Eq. 1 (Fig. 2 right)",
                       description="Basins of attraction of paper Eq. 1 on an N x N grid of "
                                   "initial conditions at t = 0 (compiled RK4 kernel, 128 "
                                   "steps per period by default, early termination by "
                                   "capture). Every map reports how many of its labels are "
                                   "uncertain: a seeded sample of points is re-run with "
                                   "twice the steps and from 1e-6 away, and the share of "
                                   "labels that change is given with a 95 % interval.")
    p._negative_number_matcher = _RANGE_OR_NUMBER
    _add_model(p)
    p.add_argument("--resolution", type=_int,
                   help=f"grid points per axis N, 2 to {limits.BASIN_MAX_RESOLUTION} "
                        "(default 200)")
    p.add_argument("--phi-range", type=_numbers("phi-range", 2),
                   metavar="LOW:HIGH",
                   help="initial phi range, ends included (default the circle [-pi, pi))")
    p.add_argument("--dphi-range", type=_numbers("dphi-range", 2),
                   metavar="LOW:HIGH", help="initial dphi range, ends included (default -3:3)")
    p.add_argument("--periods", type=_int,
                   help=f"period budget per point, 1 to {limits.BASIN_MAX_PERIODS}, with "
                        f"integrated points x periods <= {limits.BASIN_MAX_WORK:g} (half "
                        "the grid on the default symmetric grid; default 300)")
    lo_s, hi_s = limits.BASIN_STEPS_RANGE
    p.add_argument("--steps-per-period", type=_int,
                   help=f"RK4 steps per forcing period, {lo_s} to {hi_s}; the work bound "
                        "counts periods x steps/128 (default 128)")
    lo_a, hi_a = limits.BASIN_ACCURACY_RANGE
    p.add_argument("--accuracy-sample", type=_int,
                   help=f"points re-run to estimate the uncertain labels, {lo_a} to {hi_a} "
                        "(at most the integrated points; default 1000)")
    p.add_argument("--accuracy-seed", type=_int,
                   help="seed of the accuracy sample (default 0)")
    p.add_argument("--split-phases", action="store_true",
                   help="one basin per phase of a period-k attractor (the paper's four "
                        "attractors of Fig. 2 right)")
    p.add_argument("--engine", choices=["numba", "numpy"],
                   help="compiled kernel (default) or the vectorized NumPy engine")
    add_output_options(p, plot="the basin image", save="the basin Dataset", table=False)

    p = sub.add_parser("rotations",
                       help="existence and stability of the period-1 rotation (Fig. 2 left)",
                       description="Curves J (birth, fold), G (stability lost) and E "
                                   "(stability regained) of the period-1 rotation of paper "
                                   "Eq. 1 by continuation in p with Floquet multipliers: "
                                   "for one omega, or for FROM:TO:N the (omega, p) map.")
    p._negative_number_matcher = _RANGE_OR_NUMBER
    p.add_argument("--gamma", type=_finite_float("gamma"),
                   help=f"damping gamma in [0, {limits.DYN_MAX_GAMMA:g}] (default 0.1)")
    lo, hi = limits.ROT_OMEGA_RANGE
    p.add_argument("--omega", type=_omega_arg, metavar="W|FROM:TO:N",
                   help=f"one frequency, or N (1 to {limits.ROT_MAX_OMEGAS}) from FROM to TO, "
                        f"each in [{lo:g}, {hi:g}] (default 2.1)")
    p.add_argument("--p-max", type=_finite_float("p-max"),
                   help=f"largest p followed, in (0, {limits.ROT_MAX_P:g}] (default 3, the "
                        "paper's range)")
    p.add_argument("--time-limit", type=_finite_float("time-limit"),
                   metavar="S",
                   help=f"seconds of continuation, in (0, {limits.ROT_MAX_TIME_LIMIT:g}]; past "
                        "them the branches stop where they are and the output says how far "
                        f"p was followed (default {limits.ROT_TIME_LIMIT:g})")
    add_output_options(p, plot="J, G, E and the stability regions", save="J, G, E against omega")


# --- simulate ------------------------------------------------------------------------------
def _cmd_simulate(a) -> dict | str:
    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    _check_output(a.save, "--save", SAVE_TABLE)
    from ._common import _Ticker

    with _Ticker("simulate"):
        rec = _run(a)
    m = rec.source
    units = rec.physical_units
    if a.save:
        _output.save_result(rec, a.save)
    if a.plot:
        _output.save_plot(rec, a.plot)
    if a.json:
        return rec.to_dict()
    c = m.classification
    rows = [["gamma, p, omega", f"{_fmt(m.gamma)}, {_fmt(m.p)}, {_fmt(m.omega)}"],
            ["initial (phi, dphi)", f"({_fmt(m.phi0)}, {_fmt(m.dphi0)})"],
            ["periods simulated", str(m.periods)],
            ["final motion", c.name],
            ["kind, period, winding", f"{c.kind}, {c.period}, {c.winding}"],
            ["net turns of phi", str(rec.turns)]]
    for j, (x, y) in enumerate(zip(c.phi, c.dphi)):
        rows.append([f"Poincare point {j + 1}", f"({_fmt(x)}, {_fmt(y)})"])
    if not m.success:
        rows.append(["status", f"{m.status}: {m.message}"])
    if units is not None:
        rows.append(["forcing period, duration (s)",
                     f"{rec.forcing_period_s:.6g} ({rec.forcing_frequency_hz:.6g} Hz), "
                     f"{rec.duration_s:.6g}"])
        rows.append(["final energy (J)", f"{rec.final_energy_j:.6g}"])
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


def _cmd_basins(a) -> dict | str:
    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    _check_output(a.save, "--save", SAVE_GRID)
    bar = _Progress("basins")
    with _PromptInterrupt("basins"):
        rec = _run(a, progress=bar)
    bar(1, 1)
    ds = rec.dataset
    n = ds.sizes["phi"]
    periods, steps = ds.attrs["periods"], ds.attrs["steps_per_period"]
    if a.save:
        _output.save_result(rec, a.save)
    if a.plot:
        _output.save_plot(rec, a.plot)
    out = rec.to_dict()
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
def _cmd_rotations(a) -> dict | str:
    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    _check_output(a.save, "--save", SAVE_TABLE)
    single = not isinstance(a.omega, tuple)
    if single:
        from ._common import _Ticker

        with _Ticker("rotations"):
            rec = _run(a)
        r = rec.source
    else:
        rec = _run(a, progress=_Progress("rotations"))
    ds = rec.dataset
    oms = ds["omega"].values
    if a.save:
        _output.save_result(rec, a.save)
    if a.plot:
        _output.save_plot(rec, a.plot)
    if single:
        if a.json:
            return rec.to_dict()
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
        return rec.to_dict()
    rows = [[_fmt(w), _fmt(j), _fmt(g), _fmt(e), _fmt(r_)] for w, j, g, e, r_ in
            zip(*(ds[k].values for k in ("omega", "p_J", "p_G", "p_E", "p_reached")))]
    note = ("" if ds.attrs["status"] == "ok" else
            f"\ntime limit ({_fmt(a.time_limit)} s) reached: each branch was followed up to "
            "p_reached only (nan: not computed)")
    return (f"period-1 rotation of {EQ1}, gamma = {_fmt(a.gamma)}, p <= {_fmt(a.p_max)}\n"
            + _table(rows, ["omega", "p_J", "p_G", "p_E", "p_reached"]) + "\nnan: not found "
            "for p <= p_reached (or no rotation found by shooting)" + note)


COMMANDS = {"simulate": _cmd_simulate, "basins": _cmd_basins, "rotations": _cmd_rotations}
