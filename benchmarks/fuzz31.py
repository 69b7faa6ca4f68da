"""Audit of the newest command surfaces (issue 31): ``horizon --device buoy``, the buoy's causal
column of ``power-matrix --device buoy --controller mpc --forecast ...``, and ``buoy
--controller mpc`` / ``buoy --dofs surge,heave,pitch`` (changes nothing; prints a table).

Each case runs alone, as ``timeout 150 prlimit --as=3000000000 python -m parapend ...`` (or a
tiny ``python -c`` for the Python API), from the checkout above ``benchmarks/`` with
``PYTHONPATH=src`` and one BEM cache for the whole run (``PARAPEND_CACHE``: a fresh directory,
seeded from ``~/.cache/parapend`` where it exists, so that the default bodies are not solved
again). The peak RSS is the largest single process's (``wait4``'s ``ru_maxrss``).

Verdict: ends within 2 minutes and 3 GB of address space with exit 0 and a result, or exit 2
and one line of stderr naming the parameter (``must``); never a traceback. Cases that must be
refused (bad input, options that do not apply, conflicts, unusable output paths) fail on exit
0; cases that must work fail on exit 2. Output paths under the fixtures' ``out/`` must exist
(non-empty) after exit 0 and must not exist after a refusal (no partial file that looks
complete). In a JSON result ``success`` true with a failed status, or a non-finite power
marked a success, fails.

Usage: ``nice python benchmarks/fuzz31.py [substring-of-case-id ...]`` -> the table on stdout
(all cases: about 15 minutes on the shared 2 cores). Kept out of the default test run.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # above benchmarks/
TMP = tempfile.mkdtemp(prefix="fuzz31-")
CACHE = os.path.join(TMP, "cache")
ENV = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "src"), PYTHONWARNINGS="default",
           PARAPEND_CACHE=CACHE)
CAP_S, CAP_AS = 150, 3_000_000_000
T = TMP
OUT = os.path.join(TMP, "out")

SETUP = r"""
import sys, os
sys.path.insert(0, ROOT)
from capytaine.io.xarray import save_dataset_as_netcdf
from tests.buoy_synthetic import toy_hydro
save_dataset_as_netcdf(os.path.join(TMP, "good.nc"), toy_hydro(radius=1.0).to_dataset())
"""


def fixtures():
    seed = os.path.expanduser("~/.cache/parapend/hydro")
    if os.path.isdir(seed):
        shutil.copytree(seed, os.path.join(CACHE, "hydro"))
    os.makedirs(OUT)
    code = f"ROOT={ROOT!r}; TMP={TMP!r}\n" + SETUP
    subprocess.run([sys.executable, "-c", code], env=ENV, check=True)
    os.mkdir(os.path.join(T, "adir"))
    os.mkfifo(os.path.join(T, "fifo.nc"))
    with open(os.path.join(T, "text.nc"), "w") as f:
        f.write("not a netcdf file\n")
    with open(os.path.join(T, "text.gdf"), "w") as f:
        f.write("not a mesh\n")
    with open(os.path.join(T, "afile"), "w") as f:
        f.write("a file, not a directory\n")
    open(os.path.join(T, "empty.nc"), "w").close()


# the small settings that finish: two waves of record, one horizon, one forecast, no warm-up
HB = ["horizon", "--device", "buoy"]
HSMALL = ["--repeat-period", "10", "--horizons", "0.5", "--forecasts", "perfect",
          "--warm-up", "0"]


def H(*a, small=True):
    return HB + (HSMALL if small else []) + list(a) + ["--json"]


# power matrix, the buoy's causal column: 2 x 2 bins, one realization, three waves
PMB = ["power-matrix", "--device", "buoy", "--hs", "0.5,1", "--te", "2.2,2.5",
       "--realizations", "1", "--waves", "3", "--workers", "1"]


def PM(*a):
    return PMB + list(a) + ["--json"]


def PMC(*a):  # with the causal column
    return PMB + ["--controller", "mpc"] + list(a) + ["--json"]


BMPC = ["buoy", "--controller", "mpc", "--hs", "0.5", "--tp", "2.5", "--repeat-period", "10"]


def BM(*a):
    return BMPC + list(a) + ["--json"]


def B(*a):
    return ["buoy", *a, "--json"]


def HULL(*a):
    return ["buoy", "--dofs", "surge,heave,pitch", *a, "--json"]


API = r"""
import sys, json
import parapend
from parapend.errors import ParameterError
try:
    r = {expr}
except ParameterError as e:
    print(f"ParameterError: {{e}}", file=sys.stderr); sys.exit(2)
out = {{}}
for k in ("status", "success", "power_w"):
    if hasattr(r, k):
        out[k] = getattr(r, k)
print(json.dumps(out, default=str))
"""

# (id, argv or ("api", expr), expect in {"refuse", "ok", "either"}, must, mustnot)
CASES = []


def case(cid, argv, expect="either", must=(), mustnot=()):
    CASES.append((cid, argv, expect, tuple(must), tuple(mustnot)))


def api_h(args):
    """``parapend.horizon(device="buoy", ...)`` on the small settings, ``args`` replacing
    them where it names one."""
    small = {"repeat_period": "10", "horizons": "'0.5'", "forecasts": "'perfect'",
             "warm_up": "0"}
    keep = ", ".join(f"{k}={v}" for k, v in small.items() if f"{k}=" not in args)
    return ("api", f"parapend.horizon(device='buoy', {keep}, {args})")


# ===== horizon --device buoy ===============================================================
case("horizon buoy: small run (2 waves, 1 horizon, perfect)", H(), "ok")
case("horizon buoy: small run, forecast ar", H("--forecasts", "ar"), "ok")
case("horizon buoy: small run, --controller plan", H("--controller", "plan"), "ok")
case("horizon buoy: small run --save .nc", H("--save", f"{OUT}/h1.nc"), "ok")
case("horizon buoy: small run --save .json", H("--save", f"{OUT}/h2.json"), "ok")
case("horizon buoy: small run --plot .png", H("--plot", f"{OUT}/h3.png"), "ok")
case("horizon buoy: --hydro good.nc (toy body)",
     H("--hydro", f"{T}/good.nc", "--damping-coefficient", "0"))
for v in ("nan", "inf", "-1", "0", "1e300", "abc"):
    case(f"horizon buoy --hs {v}", H("--hs", v), "refuse", must=["hs"])
for v in ("nan", "-1", "0", "1e6", "0.01"):
    case(f"horizon buoy --tp {v}", H("--tp", v), "refuse", must=["tp"])
for v in ("0", "21", "1.5", "-1", "abc", "1e30"):
    case(f"horizon buoy --records {v}", H("--records", v), "refuse", must=["records"])
for v in ("-1", "1.5", "abc", "9223372036854775807", "1e400"):
    case(f"horizon buoy --seed {v}", H("--seed", v), "refuse", must=["seed"])
case("horizon buoy --seed 12345", H("--seed", "12345"), "ok")
for v in ("", "0", "nan", "inf", "-0.5", "1e300", "0.5,abc", ",".join(["0.5"] * 17),
          "0.5,0.5"):
    case(f"horizon buoy --horizons '{v[:20]}'", HB + ["--repeat-period", "10", "--horizons", v,
                                                      "--forecasts", "perfect", "--json"],
         "either" if v == "0.5,0.5" else "refuse", must=["horizons"])
for v in ("none", "", "foo", "perfect,perfect", "perfect,,ar"):
    case(f"horizon buoy --forecasts '{v}'", HB + ["--repeat-period", "10", "--horizons", "0.5",
                                                  "--forecasts", v, "--json"],
         "either" if v == "perfect,,ar" else "refuse", must=["forecasts"])
for v in ("0", "nan", "-1", "2", "1e-9", "0.75"):
    case(f"horizon buoy --update-interval {v}", H("--update-interval", v), "refuse",
         must=["update-interval"])
for v in ("-1", "nan", "inf", "1e6"):
    case(f"horizon buoy --warm-up {v}", H("--warm-up", v), "refuse", must=["warm-up"])
for v in ("-1", "0", "nan", "1e300"):
    case(f"horizon buoy --torque-limit {v}", H("--torque-limit", v), "refuse",
         must=["torque-limit"])
case("horizon buoy --torque-limit-nm -5", H("--torque-limit-nm", "-5"), "refuse",
     must=["torque-limit-nm"])
case("horizon buoy --torque-limit 1 --torque-limit-nm 100",
     H("--torque-limit", "1", "--torque-limit-nm", "100"), "refuse", must=["torque-limit"])
case("horizon buoy --torque-limit 1 (run)", H("--torque-limit", "1"), "ok")
for v in ("0", "1.5", "nan", "-1"):
    case(f"horizon buoy --efficiency {v}", H("--efficiency", v), "refuse", must=["efficiency"])
case("horizon buoy --efficiency 0.9 (run)", H("--efficiency", "0.9"), "ok")
case("horizon buoy --planner plan --efficiency 0.9",
     H("--planner", "plan", "--efficiency", "0.9"), "refuse", must=["efficiency"])
case("horizon buoy --planner foo", H("--planner", "foo"), "refuse", must=["planner"])
case("horizon buoy --controller plan (renamed)", H("--controller", "plan"), "refuse",
     must=["--planner"])
for opt, v in (("--gamma", "0.1"), ("--gravity", "9.81"), ("--baselines", "tracker"),
               ("--speed-limit", "1"), ("--baselines", "none")):
    case(f"horizon buoy {opt} {v} (pendulum only)", H(opt, v), "refuse", must=[opt[2:]])
for opt, v in (("--mass", "0"), ("--mass", "nan"), ("--length", "-1"), ("--length", "1e300"),
               ("--inertia", "0"), ("--damping-coefficient", "-1"),
               ("--damping-coefficient", "nan")):
    case(f"horizon buoy {opt} {v}", H(opt, v), "refuse", must=[opt[2:]])
for opt, v in (("--spectrum", "foo"), ("--gamma-peak", "0"), ("--gamma-peak", "nan"),
               ("--cutoff", "0"), ("--cutoff", "nan"), ("--cutoff", "1e6")):
    case(f"horizon buoy {opt} {v}", H(opt, v), "refuse", must=[opt[2:]])
for v in ("0", "-1", "nan", "inf", "1"):
    case(f"horizon buoy --repeat-period {v}",
         HB + ["--repeat-period", v, "--horizons", "0.5", "--forecasts", "perfect", "--json"],
         "refuse", must=["repeat-period"])
case("horizon buoy --repeat-period 1e5 (refused: estimate)",
     HB + ["--repeat-period", "1e5", "--json"], "refuse", must=["repeat-period"])
case("horizon buoy --records 20 (refused: estimate)", HB + ["--records", "20", "--json"],
     "refuse", must=["records"])
for opt, v in (("--radius", "0"), ("--radius", "nan"), ("--draft", "1e300"),
               ("--body", "barge"), ("--body", "foo")):
    case(f"horizon buoy {opt} {v}", H(opt, v), "refuse", must=[opt[2:]])
case("horizon buoy --body sphere --hydro good.nc",
     H("--body", "sphere", "--hydro", f"{T}/good.nc"), "refuse", must=["body"])
case("horizon buoy --mesh x --hydro y", H("--mesh", f"{T}/text.gdf", "--hydro", f"{T}/good.nc"),
     "refuse", must=["hydro"])
for what, p in (("missing", f"{T}/none.nc"), ("directory", f"{T}/adir"),
                ("text", f"{T}/text.nc"), ("empty", f"{T}/empty.nc"), ("FIFO", f"{T}/fifo.nc"),
                ("/dev/zero", "/dev/zero")):
    case(f"horizon buoy --hydro <{what}>", H("--hydro", p), "refuse", must=["hydro"])
for what, p in (("missing", f"{T}/none.gdf"), ("directory", f"{T}/adir"),
                ("text", f"{T}/text.gdf")):
    case(f"horizon buoy --mesh <{what}>", H("--mesh", p), "refuse", must=["mesh"])
for what, p in (("no directory", "/nonexistent/x.nc"), ("/proc", "/proc/x.nc"),
                ("parent is a file", f"{T}/afile/x.nc"), ("bad suffix", f"{OUT}/x.txt"),
                ("a directory", f"{T}/adir")):
    case(f"horizon buoy --save <{what}>", H("--save", p), "refuse", must=["save"])
for what, p in (("no directory", "/nonexistent/x.png"), ("/proc", "/proc/x.png"),
                ("bad suffix", f"{OUT}/x.nc")):
    case(f"horizon buoy --plot <{what}>", H("--plot", p), "refuse", must=["plot"])
for v in ("0", "-1", "nan", "inf", "1e9", "abc"):
    case(f"horizon buoy --time-limit {v}", H("--time-limit", v),
         "either" if v == "1e9" else "refuse", must=["time-limit"])
case("horizon buoy --time-limit 0.001 --save (partial, marked)",
     H("--time-limit", "0.001", "--save", f"{OUT}/h_tl.nc"), "ok")
case("horizon buoy --repeat-period 1e5 --time-limit 20 (partial)",
     HB + ["--repeat-period", "1e5", "--horizons", "0.5", "--forecasts", "perfect",
           "--time-limit", "20", "--json"])
case("horizon buoy --repeat-period 900 --time-limit 20 (partial, within the limit)",
     HB + ["--repeat-period", "900", "--horizons", "0.5", "--forecasts", "perfect",
           "--time-limit", "20", "--json"])
case("horizon buoy: small run --records 2", H("--records", "2"), "ok")
case("horizon buoy --torque-limit-nm 50 (run)", H("--torque-limit-nm", "50"), "ok")
case("horizon buoy --seed 9223372036854775787 (the largest)",
     H("--seed", "9223372036854775787"), must=["seed"])
case("horizon buoy --seed 9223372036854775788", H("--seed", "9223372036854775788"), "refuse",
     must=["seed"])
case("horizon buoy --horizons 0.05 (below the default update interval)",
     H("--horizons", "0.05"), "refuse", must=["update-interval"])
case("horizon buoy --warm-up 100", H("--warm-up", "100"), must=["warm-up"])
case("horizon (pendulum) --planner plan", ["horizon", "--planner", "plan", "--json"],
     "refuse", must=["planner"])
case("horizon (pendulum) --body sphere", ["horizon", "--body", "sphere", "--json"], "refuse",
     must=["body"])
case("horizon (pendulum) --hydro good.nc", ["horizon", "--hydro", f"{T}/good.nc", "--json"],
     "refuse", must=["hydro"])
case("horizon --device foo", ["horizon", "--device", "foo"], "refuse", must=["device"])
# the Python API
for args, must in (("records='2'", "records"), ("records=True", "records"),
                   ("records=2.0", "records"), ("seed=1.5", "seed"), ("seed=True", "seed"),
                   ("hs='1'", "hs"), ("hs=None, tp=float('nan')", "tp"),
                   ("horizons=[0.5, 'a']", "horizons"), ("horizons=None", ""),
                   ("forecasts=5", "forecasts"), ("forecasts=['perfect', 5]", "forecasts"),
                   ("progress=5", "progress"), ("time_limit='abc'", "time-limit"),
                   ("controller=['coupled']", "controller"), ("controller=5", "controller"),
                   ("efficiency='abc'", "efficiency"), ("efficiency=(0.9, 0.8)", ""),
                   ("efficiency=(0.9, 0.8, 0.7)", "efficiency"),
                   ("torque_limit='x'", "torque-limit"), ("update_interval='x'", "update"),
                   ("warm_up='x'", "warm-up"), ("mesh=5", "mesh"), ("hydro=5", "hydro"),
                   ("body=5", "body"), ("radius='x'", "radius"), ("spectrum=5", "spectrum"),
                   ("mass=[80]", "mass"), ("inertia='x'", "inertia")):
    # records=2.0: an integral float is an integer (errors.check_int, everywhere)
    ok = args in ("horizons=None", "efficiency=(0.9, 0.8)", "records=2.0")
    case(f"api horizon(device='buoy', {args})", api_h(args), "ok" if ok else "refuse",
         must=[must] if must else [])
case("api horizon(device=5)", ("api", "parapend.horizon(device=5)"), "refuse",
     must=["device"])
case("api horizon(device=None)", ("api", "parapend.horizon(device=None)"), "refuse",
     must=["device"])
case("api horizon(device='buoy', gamma=0.1)",
     ("api", "parapend.horizon(device='buoy', gamma=0.1)"), "refuse", must=["gamma"])

# ===== buoy --controller mpc ===============================================================
case("buoy mpc: short record (10 s)", BM(), "ok")
case("buoy mpc: short record --forecast ar", BM("--forecast", "ar"), "ok")
case("buoy mpc: --save .nc", BM("--save", f"{OUT}/b1.nc"), "ok")
case("buoy mpc: --plot dir (refused by name: no figures of a run)",
     BM("--plot", f"{OUT}/bplot"), "refuse", must=["plot"])
for v in ("0", "nan", "-1", "100", "abc"):
    case(f"buoy mpc --horizon {v}", BM("--horizon", v), "refuse", must=["horizon"])
for v in ("0", "nan", "-1", "2", "1e-9"):
    case(f"buoy mpc --update-interval {v}", BM("--update-interval", v), "refuse",
         must=["update-interval"])
for v in ("foo", "perfect,ar", ""):
    case(f"buoy mpc --forecast '{v}'", BM("--forecast", v), "refuse", must=["forecast"])
case("buoy --forecast ar (no --controller mpc)", B("--forecast", "ar"), "refuse",
     must=["forecast"])
case("buoy --controller foo", B("--controller", "foo"), "refuse", must=["controller"])
case("buoy --controller mpc (regular wave)", B("--controller", "mpc"))
case("buoy mpc --wave-period 1:3:5", BM("--wave-period", "1:3:5"), "refuse",
     must=["wave-period"])
case("buoy mpc --optimize-design mass", BM("--optimize-design", "mass"), "refuse")
# the optimum the run is measured against takes them (mpc_command)
case("buoy mpc --winding 2", BM("--winding", "2"), must=["winding"])
case("buoy mpc --harmonics 10", BM("--harmonics", "10"), must=["harmonics"])
case("buoy mpc --copper-loss 0.1", BM("--copper-loss", "0.1"), "refuse", must=["copper-loss"])
case("buoy mpc --torque-limit 50 (run)", BM("--torque-limit", "50"))
for v in ("0", "nan", "-1"):
    case(f"buoy mpc --torque-limit {v}", BM("--torque-limit", v), "refuse",
         must=["torque-limit"])
case("buoy mpc --efficiency 0.9 (run)", BM("--efficiency", "0.9"))
for v in ("0", "nan", "1.5"):
    case(f"buoy mpc --efficiency {v}", BM("--efficiency", v), "refuse", must=["efficiency"])
for v in ("0", "-1", "nan", "abc"):
    case(f"buoy mpc --time-limit {v}", BM("--time-limit", v), "refuse", must=["time-limit"])
case("buoy mpc --time-limit 0.001 --save (partial)",
     BM("--time-limit", "0.001", "--save", f"{OUT}/b_tl.nc"))
case("buoy mpc --repeat-period 1e5 (refused: estimate)",
     ["buoy", "--controller", "mpc", "--hs", "0.5", "--tp", "2.5", "--repeat-period", "1e5",
      "--json"], "refuse", must=["repeat-period"])
for what, p in (("no directory", "/nonexistent/x.nc"), ("/proc", "/proc/x.nc"),
                ("bad suffix", f"{OUT}/x.txt")):
    case(f"buoy mpc --save <{what}>", BM("--save", p), "refuse", must=["save"])
case("buoy mpc --plot /proc/x", BM("--plot", "/proc/x"), "refuse", must=["plot"])
case("buoy mpc --plot <a file>", BM("--plot", f"{T}/afile"), "refuse", must=["plot"])
# the default record (100 Tp) with a power take-off: its mechanical optimum is the yardstick
for opt, v in (("--damping-coefficient", "1"), ("--efficiency", "0.9"),
               ("--torque-limit", "50")):  # the first: the default itself, no PTO
    case(f"buoy mpc {opt} {v}, the default record",
         ["buoy", "--controller", "mpc", "--hs", "0.5", "--tp", "2.5", opt, v, "--json"])
case("buoy mpc --repeat-period 900 --time-limit 20 (partial, within the limit)",
     ["buoy", "--controller", "mpc", "--hs", "0.5", "--tp", "2.5", "--repeat-period", "900",
      "--time-limit", "20", "--json"])
case("buoy --controller one-way-mpc (short record)",
     ["buoy", "--controller", "one-way-mpc", "--hs", "0.5", "--tp", "2.5", "--repeat-period",
      "10", "--json"])
for expr, must in (("controller='mpc', hs=0.5, tp=2.5, repeat_period=10, horizon='x'",
                    "horizon"),
                   ("controller='mpc', hs=0.5, tp=2.5, repeat_period=10, forecast=5",
                    "forecast"),
                   ("controller='mpc', hs=0.5, tp=2.5, repeat_period=10, forecast=['ar']",
                    "forecast"),
                   ("controller=5", "controller"), ("controller=['mpc']", "controller"),
                   ("controller='mpc', hs=0.5, tp=2.5, repeat_period=10, time_limit='x'",
                    "time-limit"),
                   ("controller='mpc', hs=0.5, tp=2.5, repeat_period=10, "
                    "update_interval=[0.1]", "update-interval")):
    case(f"api buoy({expr[:70]})", ("api", f"parapend.buoy({expr})"), "refuse", must=[must])

# ===== buoy --dofs surge,heave,pitch =======================================================
case("buoy --dofs surge,heave,pitch (the default barge)", HULL(), "ok")
for v in ("foo", "surge", "surge,heave", "surge,surge,heave,pitch", "", "pitch,heave,surge"):
    case(f"buoy --dofs '{v}'", B("--dofs", v), "either" if v == "pitch,heave,surge" else
         "refuse", must=["dofs"])
for opt, v in (("--pivot-height", "nan"), ("--pivot-height", "1e300"),
               ("--pivot-offset", "1e300"), ("--pivot-offset", "inf"),
               ("--hull-pitch-inertia", "-1"), ("--hull-pitch-inertia", "0"),
               ("--barge-length", "0"), ("--barge-length", "nan"), ("--barge-beam", "-1"),
               ("--barge-draft", "1e300"), ("--copper-loss", "-1"), ("--copper-loss", "nan")):
    case(f"hull {opt} {v}", HULL(opt, v), "refuse", must=[opt[2:]])
for opt, v in (("--pivot-height", "0.5"), ("--pivot-offset", "0.5"),
               ("--hull-pitch-inertia", "1000"), ("--barge-length", "5"),
               ("--barge-beam", "5"), ("--barge-draft", "1")):
    case(f"buoy {opt} {v} (heave only: no hull)", B(opt, v), "refuse", must=[opt[2:]])
case("hull --controller mpc", HULL("--controller", "mpc"), "refuse", must=["controller"])
case("hull --horizon 2", HULL("--horizon", "2"), "refuse", must=["horizon"])
case("hull --forecast ar", HULL("--forecast", "ar"), "refuse", must=["forecast"])
case("hull --optimize-design mass", HULL("--optimize-design", "mass"), "refuse",
     must=["optimize-design"])
case("hull --radius 1 (barge)", HULL("--radius", "1"), "refuse", must=["radius"])
case("hull --body cylinder --draft 1e300", HULL("--body", "cylinder", "--draft", "1e300"),
     "refuse", must=["draft"])
case("hull --mesh <missing>", HULL("--mesh", f"{T}/none.gdf"), "refuse", must=["mesh"])
case("hull --hydro <text>", HULL("--hydro", f"{T}/text.nc"), "refuse", must=["hydro"])
case("hull --hydro <heave-only toy>", HULL("--hydro", f"{T}/good.nc"), "refuse",
     must=["hydro"])
case("hull --save /proc/x.nc", HULL("--save", "/proc/x.nc"), "refuse", must=["save"])
case("hull --wave-direction 1 (no --hydro)", HULL("--wave-direction", "1"), "refuse",
     must=["wave-direction"])
case("hull --torque-limit -1", HULL("--torque-limit", "-1"), "refuse", must=["torque-limit"])
case("hull --efficiency 2", HULL("--efficiency", "2"), "refuse", must=["efficiency"])
case("hull --time-limit nan", HULL("--time-limit", "nan"), "refuse", must=["time-limit"])
for opt, v in (("--spectrum", "jonswap"), ("--gamma-peak", "2"), ("--cutoff", "2"),
               ("--taper", "0.2")):
    case(f"hull {opt} {v} (regular wave)", HULL(opt, v), "refuse", must=[opt[2:]])
case("hull --hs 1 --tp 6 --wave-height 1", HULL("--hs", "1", "--tp", "6", "--wave-height", "1"),
     "refuse", must=["wave-height"])
case("hull --hs 1 --tp 6 --wave-period 6", HULL("--hs", "1", "--tp", "6", "--wave-period", "6"),
     "refuse", must=["wave-period"])
for opt, v in (("--gamma-peak", "0"), ("--cutoff", "0"), ("--taper", "0.2")):
    case(f"hull --hs 1 --tp 6 {opt} {v}", HULL("--hs", "1", "--tp", "6", opt, v), "refuse",
         must=[opt[2:]])
case("hull --winding 1000", HULL("--winding", "1000"), "refuse", must=["winding"])
for expr, must in (("dofs=5", "dofs"), ("dofs=['surge', 'heave', 'pitch']", ""),
                   ("dofs='surge,heave,pitch', pivot_height='x'", "pivot-height"),
                   ("dofs='surge,heave,pitch', barge_length=[5]", "barge-length"),
                   ("dofs='surge,heave,pitch', copper_loss='x'", "copper-loss"),
                   ("dofs='surge,heave,pitch', hull_pitch_inertia=float('nan')",
                    "hull-pitch-inertia")):
    case(f"api buoy({expr})", ("api", f"parapend.buoy({expr})"),
         "ok" if not must else "refuse", must=[must] if must else [])

# ===== power-matrix --device buoy --controller mpc ==========================================
case("pm buoy mpc --forecast perfect", PMC("--forecast", "perfect"), "ok")
case("pm buoy mpc --forecast ar", PMC("--forecast", "ar"), "ok")
# both forecasts on the 4 bins are estimated at about 124 s: refused (the rule), or a result
case("pm buoy mpc --forecast perfect,ar --netcdf", PMC("--forecast", "perfect,ar", "--netcdf",
                                                       f"{OUT}/pm1.nc"), must=["hs"])
case("pm buoy mpc (default forecast) --csv", PMC("--csv", f"{OUT}/pm2.csv"), "ok")
for v in ("foo", "", "perfect,perfect", "none", "ar,foo"):
    case(f"pm buoy mpc --forecast '{v}'", PMC("--forecast", v), "refuse", must=["forecast"])
case("pm buoy mpc --forecast ' perfect , ar '", PMC("--forecast", " perfect , ar "))
case("pm buoy --forecast ar (no --controller)", PM("--forecast", "ar"), "refuse",
     must=["forecast"])
case("pm buoy --horizon 1 (no --controller)", PM("--horizon", "1"), "refuse",
     must=["horizon"])
for v in ("0", "nan", "-1", "100"):
    case(f"pm buoy mpc --horizon {v}", PMC("--horizon", v), "refuse", must=["horizon"])
for v in ("0", "nan", "0.001", "2"):
    case(f"pm buoy mpc --update-interval {v}", PMC("--update-interval", v), "refuse",
         must=["update-interval"])
for v in ("-1", "nan", "1e6"):
    case(f"pm buoy mpc --warm-up {v}", PMC("--warm-up", v), "refuse", must=["warm-up"])
case("pm buoy mpc --plan-samples 4", PMC("--plan-samples", "4"), "refuse",
     must=["plan-samples"])
case("pm buoy mpc --speed-limit 1", PMC("--speed-limit", "1"), "refuse", must=["speed-limit"])
case("pm buoy mpc --controller foo", PM("--controller", "foo"), "refuse", must=["controller"])
case("pm buoy mpc --dofs surge,heave,pitch", PMC("--dofs", "surge,heave,pitch"), "refuse",
     must=["controller"])
case("pm buoy mpc --efficiency 0.9", PMC("--efficiency", "0.9"))
case("pm buoy mpc --torque-limit 1", PMC("--torque-limit", "1"))
case("pm buoy mpc --gamma 0.1 (pendulum only)", PMC("--gamma", "0.1"), "refuse",
     must=["gamma"])
case("pm buoy mpc --gravity 9 (pendulum only)", PMC("--gravity", "9"), "refuse",
     must=["gravity"])
for v in ("0", "nan", "-1"):
    case(f"pm buoy mpc --time-limit {v}", PMC("--time-limit", v), "refuse",
         must=["time-limit"])
case("pm buoy mpc --time-limit 0.001 --netcdf (partial)",
     PMC("--time-limit", "0.001", "--netcdf", f"{OUT}/pm_tl.nc"))
case("pm buoy mpc 50 x 50 bins (refused: estimate)",
     ["power-matrix", "--device", "buoy", "--controller", "mpc", "--hs", "0.5:3:50", "--te",
      "2:5:50", "--json"], "refuse")
case("pm buoy mpc --waves 1e6 (refused)", PMC("--waves", "1000000"), "refuse",
     must=["waves"])
for what, p in (("no directory", "/nonexistent/x.nc"), ("/proc", "/proc/x.nc")):
    case(f"pm buoy mpc --netcdf <{what}>", PMC("--netcdf", p), "refuse", must=["netcdf"])
case("pm buoy mpc --csv /proc/x.csv", PMC("--csv", "/proc/x.csv"), "refuse", must=["csv"])
case("pm buoy mpc --plot /nonexistent/x.png", PMC("--plot", "/nonexistent/x.png"), "refuse",
     must=["plot"])
case("pm buoy mpc --hydro <missing>", PMC("--hydro", f"{T}/none.nc"), "refuse",
     must=["hydro"])
case("pm buoy mpc --seed -1", PMC("--seed", "-1"), "refuse", must=["seed"])
case("pm buoy mpc --realizations 0", PMC("--realizations", "0"), "refuse",
     must=["realizations"])
for expr, must in (("forecast=5", "forecast"), ("forecast=['ar']", ""),
                   ("horizon='x'", "horizon"), ("warm_up='x'", "warm-up"),
                   ("controller=5", "controller")):
    case(f"api power_matrix(device='buoy', controller='mpc', {expr})",
         ("api", "parapend.power_matrix(device='buoy', hs='0.5,1', te='2.2,2.5', realizations=1, "
                 f"waves=3, workers=1, controller='mpc', {expr})"
          if "controller=" not in expr else
          "parapend.power_matrix(device='buoy', hs='0.5,1', te='2.2,2.5', realizations=1, "
          f"waves=3, workers=1, {expr})"),
         "ok" if not must else "refuse", must=[must] if must else [])

# ===== the defaults themselves (long) ======================================================
case("horizon --device buoy (the default curve; estimated 82 s)", HB + ["--json"])


def outputs(argv):
    """The output paths of a case that lie under the fixtures' out/ (their presence after
    the run is checked)."""
    if argv[0] == "api":
        return []
    return [a for a in argv if a.startswith(OUT + "/")]


def checks(out):
    try:
        d = json.loads(out)
    except ValueError:
        return "stdout is not JSON"
    if not isinstance(d, dict):
        return ""
    bad = []
    if d.get("success") and any(k in str(d.get("status", "")).lower()
                                for k in ("fail", "infeasible", "time_limit")):
        bad.append("success with a failed status")
    pw = d.get("power_w")
    if d.get("success") and isinstance(pw, (int, float)) and not math.isfinite(pw):
        bad.append(f"success with power_w {pw}")
    return "; ".join(bad)


def run(cid, argv, expect, must, mustnot):
    if argv[0] == "api":
        cmd = [sys.executable, "-c", API.format(expr=argv[1])]
    else:
        cmd = [sys.executable, "-m", "parapend", *argv]
    cmd = ["timeout", str(CAP_S), "prlimit", f"--as={CAP_AS}", "--", *cmd]
    fo, fe = os.path.join(TMP, "stdout"), os.path.join(TMP, "stderr")
    t0 = time.monotonic()
    with open(fo, "w") as o, open(fe, "w") as e:
        p = subprocess.Popen(cmd, stdout=o, stderr=e, stdin=subprocess.DEVNULL, env=ENV,
                             cwd=ROOT)
        _, status, ru = os.wait4(p.pid, 0)
        rc = os.waitstatus_to_exitcode(status)
    dt = time.monotonic() - t0
    rss = ru.ru_maxrss * 1024
    out, err = open(fo).read(), open(fe).read()
    lines = [ln for ln in err.splitlines() if ln.strip()]
    # notices and warnings of a run are not refusals
    refusal = [ln for ln in lines if "Warning" not in ln and not ln.startswith("warning")
               and "compiling the" not in ln and "(Ctrl-C stops it)" not in ln]
    first = (refusal[0] if refusal else lines[0] if lines else "").strip()
    why = []
    if rc in (124, 137) or dt >= CAP_S - 1:
        why.append("time cap (>150 s)")
    elif dt > 120:
        why.append(f"{dt:.0f} s, over 2 minutes")
    if "Traceback" in err:
        why.append("traceback")
    if "MemoryError" in err:
        why.append("MemoryError")
    files = outputs(argv)
    if not why:
        if rc == 2:
            if len(refusal) != 1:
                why.append(f"exit 2 with {len(refusal)} stderr lines")
            if expect == "ok":
                why.append("good input refused")
            low = err.lower()
            for m in must:
                if m.lower() not in low:
                    why.append(f"message lacks '{m}'")
            for m in mustnot:
                if m.lower() in low:
                    why.append(f"message names '{m}'")
            for f in files:
                if os.path.exists(f):
                    why.append(f"refused but left {os.path.basename(f)}")
        elif rc == 0:
            if expect == "refuse":
                why.append("exit 0 (should be refused)")
            bad = checks(out)
            if bad:
                why.append(bad)
            for f in files:
                if not os.path.exists(f) or (os.path.isfile(f) and not os.path.getsize(f)):
                    why.append(f"no {os.path.basename(f)} written")
        else:
            why.append(f"exit {rc}")
    verdict = "PASS" if not why else "FAIL: " + "; ".join(why)
    return rc, dt, rss, first, verdict


def main(sel):
    fixtures()
    rows = []
    print(f"# fuzz31: {len(CASES)} cases, cap {CAP_S} s and --as={CAP_AS}, fixtures in {TMP}",
          flush=True)
    print("| case | exit | s | peak RSS MB | stderr, first line | verdict |")
    print("|---|---|---|---|---|---|", flush=True)
    for c in CASES:
        if sel and not any(s in c[0] for s in sel):
            continue
        rc, dt, rss, first, verdict = run(*c)
        rows.append(verdict)
        first = first.replace("|", "/")[:160]
        print(f"| {c[0]} | {rc} | {dt:.1f} | {rss / 2**20:.0f} | {first} | {verdict} |",
              flush=True)
    n = sum(v == "PASS" for v in rows)
    print(f"\n# {n} pass, {len(rows) - n} fail, of {len(rows)} run")


if __name__ == "__main__":
    main(sys.argv[1:])
