"""Admissible ranges of the inputs, checked at the API edge (see ``docs/limits-of-input.md``).

Each bound keeps the model meaningful and the numerics inside double precision and inside
a bounded time and memory (well under 2 minutes and 2 GB on one core); the reason for each
is in the document above. Only this module holds the numbers.
"""

from __future__ import annotations

__all__ = [
    "MAX_AMPLITUDE", "MAX_BVP_EXTREMA", "MAX_BVP_WORK", "MAX_BYTES_FILE", "MAX_FILE_ROWS",
    "MAX_FILE_GAP", "MAX_FOURIER_K", "MAX_GAMMA", "MAX_HARMONICS", "MAX_PHASE", "MAX_POINTS",
    "MAX_SWEEP_HARMONICS", "MAX_SWEEP_WORK", "MAX_TABLE_HARMONICS", "MAX_THRESHOLD_HARMONICS",
    "MAX_PTO_HARMONICS", "MAX_PTO_INTERVALS", "MAX_PTO_POINTS", "MAX_TORQUE_LIMIT",
    "MIN_AMPLITUDE", "MIN_TORQUE_LIMIT", "MAX_PTO_Q_HARMONICS", "MAX_PTO_CURVE_WORK",
    "MIN_BVP_GAMMA", "OMEGA_RANGE",
    "SQUARE_ALPHA_MIN", "MAP_MAX_POINTS", "MAP_MAX_PTO_POINTS", "MAP_MAX_HARMONICS",
    "MAP_MAX_WORK", "UNIT_GRAVITY_RANGE", "UNIT_INERTIA_RATIO", "UNIT_LENGTH_RANGE",
    "UNIT_MASS_RANGE", "SEA_MAX_RESAMPLED", "SEA_MIN_HS", "TRACK_MAX_STEP_RATE",
    "MAX_UNTIMED_SECONDS", "MAX_TIME_LIMIT", "PERSISTENCE_TP_RANGE", "PERSISTENCE_MAX_AXIS",
    "PERSISTENCE_MAX_WAVES", "PERSISTENCE_MAX_COMPONENTS", "PERSISTENCE_MAX_REALIZATIONS",
    "PERSISTENCE_MAX_DAMPING",
]

# --- long work: estimate first, then refuse or run under a time limit (parapend.deadline) ---
#: work whose up-front estimate exceeds this many seconds is refused in one line unless
#: ``--time-limit`` is given (then it runs until the limit and returns a partial result
#: marked "time_limit"): the design search, the buoy's period sweep and receding-horizon
#: run, horizon, track --controller mpc, and the power matrix without --store (a store
#: resumes, so its long work is announced and runs). Two minutes: the audits' bound on a
#: command; the estimates are rounded up, so work near it takes less
MAX_UNTIMED_SECONDS = 120.0
#: the largest --time-limit, s (a week: a resumable power matrix may run for days; the
#: bound keeps the deadline a finite float)
MAX_TIME_LIMIT = 7 * 86400.0

#: forcing frequency omega, units sqrt(g/l)
OMEGA_RANGE = (1e-3, 1e3)
#: |delta| and |amplitude| of a Fourier term or a sample of q (base acceleration over g)
MAX_AMPLITUDE = 1e3
#: smallest nonzero amplitude: |delta|, a Fourier amplitude, and the largest harmonic of q
#: (a file's or a sea record's); below it the products of the solvers reach the subnormal
#: range (5e-324 raised a ValueError in the root finder, 1e-308 already lost 8 digits)
MIN_AMPLITUDE = 1e-100
#: |phase| of a Fourier term, radians
MAX_PHASE = 1e6
#: viscous damping gamma (non-dimensional, unit sqrt(g/l))
MAX_GAMMA = 1e3
#: smallest gamma for the Euler-Lagrange BVP (epsilon = 2 gamma)
MIN_BVP_GAMMA = 1e-18
#: smallest tanh width of Eq. 26, as a fraction of the period 2 pi/omega
SQUARE_ALPHA_MIN = 1e-9
#: largest harmonic number k of a Fourier-series excitation
MAX_FOURIER_K = 1024
#: harmonics N of one Fourier solve (optimize)
MAX_HARMONICS = 1024
#: harmonics N of each solve inside threshold (several solves)
MAX_THRESHOLD_HARMONICS = 512
#: largest N of a harmonic table (continuation over N = from..to)
MAX_TABLE_HARMONICS = 128
#: harmonics N inside a damping sweep
MAX_SWEEP_HARMONICS = 256
#: dampings in a damping sweep
MAX_POINTS = 1001
#: points * harmonics**2 of a damping sweep (about a minute of work)
MAX_SWEEP_WORK = 1 << 20
#: extrema of q per period for the Euler-Lagrange BVP (each needs a boundary layer)
MAX_BVP_EXTREMA = 64
#: mesh nodes x harmonics of q for one BVP (each residual evaluates q at every node)
MAX_BVP_WORK = 4e7
#: rows of a sampled-excitation CSV file, and its size in bytes
MAX_FILE_ROWS = 16384
MAX_BYTES_FILE = 4 << 20
#: widest gap between successive samples of a file (cyclically), as a fraction of the period
MAX_FILE_GAP = 0.125
#: harmonics N of a power take-off solve (torque limit, efficiency): dense grid matrices of
#: M x (2N+1) with M >= 32 N, about 100 MB at N = 128
MAX_PTO_HARMONICS = 128
#: torque limit, units m g l (the paper-case ideal optimum needs 587 at N = 24)
MAX_TORQUE_LIMIT = 1e6
#: smallest torque limit, units m g l: the torque of a motion is evaluated to about 1e-14
#: absolute (inverse dynamics of terms of order 1 + |q|); at 1e-320 the limit was "met"
#: with a relative violation of 1e306
MIN_TORQUE_LIMIT = 1e-6
#: harmonics of q a power take-off solve accepts: its mesh (at most MAX_PTO_INTERVALS
#: intervals) cannot follow more, and each dense torque check costs O(harmonics) per point
#: (a 16384-row file, 8192 harmonics, ran past 5 minutes)
MAX_PTO_Q_HARMONICS = 1024
#: points x starting intervals of a pto-curve (each point solves on K and 2K intervals;
#: 2 to 10 s at K = 1024: 8 points of a 2048-row noisy record took 30 CPU-s, 105 s under
#: load): 6 points at K = 1024, 25 at K = 256, all 101 at K = 64
MAX_PTO_CURVE_WORK = 101 * 64
#: points of a pto-curve
MAX_PTO_POINTS = 101
#: Hermite intervals of the torque-limited optimum (the doubling stops here: 2048 intervals
#: take about a second per solve)
MAX_PTO_INTERVALS = 2048

# --- physical units (units.py) ------------------------------------------------------------
#: pendulum length l (m), mass m (kg), gravity g (m/s^2): the scales m g l, sqrt(l/g) and
#: m g^1.5 l^0.5 then stay between 1e-30 and 1e30 (1e308 overflowed l^2, 1e-320 made the
#: time unit 0)
UNIT_LENGTH_RANGE = (1e-6, 1e6)
UNIT_MASS_RANGE = (1e-12, 1e12)
UNIT_GRAVITY_RANGE = (1e-3, 1e3)
#: moment of inertia about the pivot, as a multiple of m l^2 (I = I_cm + m l^2 >= m l^2)
UNIT_INERTIA_RATIO = (1.0, 1e6)

# --- design maps (parapend sweep) ------------------------------------------------
#: points of one map (the issue asks for 10^4 to 10^6; at N = 24 about 1 ms of CPU each
#: for a harmonic excitation, so 2^20 points are about 15 to 20 CPU-minutes, resumable)
MAP_MAX_POINTS = 1 << 20
#: points of a map with a power take-off (0.2 to 0.5 s each at N = 24, 2 s infeasible:
#: 4096 points are up to 2 hours of CPU)
MAP_MAX_PTO_POINTS = 4096
#: harmonics N of each solve of a map
MAP_MAX_HARMONICS = 128
#: points * max(N, 24)^2 of a map (N = 24 at the point cap; N = 128 at 36 864 points)
MAP_MAX_WORK = MAP_MAX_POINTS * 24**2

# --- uncontrolled pendulum, paper Eq. 1 (simulate, basins, rotations) ---------------------
#: forcing frequency omega of Eq. 1 (steps are tied to the forcing period)
DYN_OMEGA_RANGE = (0.05, 50.0)
#: |p|, excitation strength of Eq. 1, and the damping gamma of Eq. 1
DYN_MAX_P = 100.0
DYN_MAX_GAMMA = 10.0
#: simulate: forcing periods, and the simulated time periods * 2 pi/omega times the fastest
#: natural frequency sqrt(1 + |p|) (DOP853 steps scale with it: omega = 0.05, p = 100 over
#: t = 5e4 took 150 s under load; 1e5 is about 30 s under load, 10 s idle)
SIM_MAX_PERIODS = 20000
SIM_MAX_WORK = 1e5
#: simulate: |phi0| (rad) and |dphi0| of the initial state; the work above counts the rate
#: too, periods * 2 pi/omega * (sqrt(1 + |p|) + |dphi0|) (a fast rotation needs DOP853 steps
#: in proportion to its speed: gamma = 0, dphi0 = 1000, 30 periods (9e4) took 6 s)
SIM_MAX_PHI0 = 1e3
SIM_MAX_DPHI0 = 1e3
#: basins: grid points per axis, period budget, and integrated points x periods (the
#: default grid is symmetric and integrates half its points: the 1000 x 1000, 300-period
#: map is 1.5e8; worst case, every point running the whole budget, about 180 s
#: of CPU, 1.5 minutes on two idle cores)
BASIN_MAX_RESOLUTION = 2000
BASIN_MAX_PERIODS = 5000
BASIN_MAX_WORK = 1.6e8
#: basins: RK4 steps per forcing period (the work above is counted at 128 steps and scales
#: with the steps), and the points of the accuracy check (re-run twice: 3 units each)
BASIN_STEPS_RANGE = (16, 1024)
BASIN_ACCURACY_RANGE = (100, 100000)
#: rotations: omega range, values of omega in one map, and the largest p followed; the
#: work is bounded by a time limit (seconds of continuation per command, the branch is
#: followed as far as the time allows and the result says where it stopped): continuation
#: to p = 5 at omega = 0.9 took 133 s under load, omega = 0.6 over 200 s
ROT_OMEGA_RANGE = (0.8, 10.0)
ROT_MAX_OMEGAS = 40
ROT_MAX_P = 10.0
ROT_TIME_LIMIT = 100.0
ROT_MAX_TIME_LIMIT = 600.0

# --- closed-loop control (track) ------------------------------------------------------
#: forcing periods of one closed-loop run (about 1.7 ms each at 256 samples per period)
MAX_TRACK_PERIODS = 2000
#: runs x periods of a seeded robustness batch (track --runs): 5 irregular runs of 2000
#: periods (10000) took 17.6 s and 443 MB under load about 2 (docs/control.md)
MAX_TRACK_WORK = 10000
#: largest sample interval of the closed loop, 2 pi/(256 omega), times the plant's fastest
#: rate max(gamma, sqrt(1 + max|q|)) (each with the largest model error, x 1.9): at least
#: 2 pi samples per fastest swing (omega = 1e-3 gave NaN LQR gains, gamma = 1e3 an unstable
#: RK4; at omega = 0.02 the paper's case still runs, not locked, at 0.05 it locks)
TRACK_MAX_STEP_RATE = 1.0

# --- irregular seas (sea command, docs/seas.md) ------------------------------------------
#: significant wave height and |z| of a measured record, m; the smallest Hs (below it q
#: drops towards the subnormal range: hs = 1e-320 gave q = 0)
SEA_MAX_HS = 30.0
SEA_MIN_HS = 1e-6
#: peak period, s
SEA_TP_RANGE = (1.0, 30.0)
#: repeat period in peak periods (about the number of waves in the record)
SEA_WAVES_RANGE = (2.0, 400.0)
#: components of q (harmonics of the repeat period) of one record
SEA_MAX_COMPONENTS = 8192
#: rows of a measured record CSV 't,z'
SEA_MAX_RECORD_ROWS = 1 << 17
#: points of a measured record resampled at its median spacing (8 MB per array; one late
#: sample, 40 rows 0.01 s apart and one at t = 3e5 s, reached 2.85 GB)
SEA_MAX_RESAMPLED = 1 << 20
#: harmonics N of the motion over one record (operator Newton: memory O(N), time O(N log N))
SEA_MAX_HARMONICS = 16384

# --- rotation persistence (parapend persistence, docs/persistence.md) ---------------------
#: peak period, s: wave-flume periods for a short pendulum (a 0.3 m pendulum rotates in
#: Tp of 0.2 to 0.5 s) up to the ocean's
PERSISTENCE_TP_RANGE = (0.05, 30.0)
#: values of the --hs and --tp axes (and of a --generator-damping list)
PERSISTENCE_MAX_AXIS = 256
#: record length in peak periods (the kernel keeps no trajectory; 2e4 peak periods of 30
#: steps each are 6e5 steps, 10 MB of z'' a record)
PERSISTENCE_MAX_WAVES = 20000.0
#: components of a record (its spectrum up to the cutoff)
PERSISTENCE_MAX_COMPONENTS = 1 << 17
#: realizations per sea state
PERSISTENCE_MAX_REALIZATIONS = 1 << 20
#: bearing and generator damping, N m s/rad
PERSISTENCE_MAX_DAMPING = 1e9

# --- the floating buoy (parapend buoy, docs/buoy.md) ---------------------------------------
#: radius and draft of a parametric body, m (1e-300 and 1e300 overflowed Capytaine's panel
#: counts: "Maximum allowed size exceeded")
BUOY_SIZE_RANGE = (1e-2, 1e3)
#: influence coefficients of one BEM frequency of a parametric (rotation-symmetric) body:
#: panels x panels of one slice. The default cylinder (1026 panels, 19 a slice, about 2e4)
#: took 12 s for its 48 frequencies under load, radius 2 m beside a 0.5 m draft (9416
#: panels, 4e5) 142 s: the cap keeps a body's BEM near a minute
BUOY_MAX_BEM_WORK = 1.5e5
#: panels of the immersed part of a mesh file (no symmetry: a dense panels x panels solve
#: per frequency; 20 000 panels reached 2.8 GB)
BUOY_MAX_MESH_PANELS = 1500
#: bytes of a mesh file or of a hydrodynamics dataset (a sparse 3 GB file was read whole)
BUOY_MAX_FILE_BYTES = 64 << 20
#: smallest efficiency of the power take-off, each way (1e-300 and 5e-324 gave infinite
#: motoring costs and NaN; below 1 % the take-off is not a generator)
BUOY_MIN_EFFICIENCY = 1e-2
#: relative asymmetry of A and B (between DOFs) a dataset may have before it is refused;
#: below it they are symmetrised (with a warning where above round-off)
BUOY_SYMMETRY_TOL = 1e-2
#: relative difference between a dataset's stated displacement (disp_mass, disp_volume x rho)
#: and its inertia_matrix's mass above which the result warns, naming both and the one used
DATASET_MASS_RTOL = 1e-3
#: negative heave radiation damping a dataset may hold at a frequency, as a fraction of its
#: largest B, before it is refused (at most this much: the frequencies are dropped, named)
BUOY_NEGATIVE_DAMPING_TOL = 1e-2
#: a dataset's water density (kg/m^3; power-matrix --density's range), and its smallest
#: water depth (m): a rho of 1e-300 gave a capture width of -1e302 m, a depth of 1e-300 one
#: of -5e148 m (the energy flux vanishes), a g of 1e-300 blamed a gamma
BUOY_RHO_RANGE = (500.0, 2000.0)
#: a hull's pitch inertia (kg m^2): --hull-pitch-inertia's range, and a dataset's
HULL_PITCH_INERTIA_RANGE = (1e-6, 1e12)
#: panels (with the lid's) of a barge's BEM, estimated before it runs (hydro.api's
#: barge_panels): the default barge's 486 (412 and a lid of 120) took 41 s for its 48
#: frequencies under load, a 10 x 2 m one (1152) 52 s; 3000 (a 10 m barge 1 m wide) keeps a
#: barge's BEM within minutes
HULL_MAX_BEM_PANELS = 3000
BUOY_MIN_DEPTH = 1e-2
#: frequencies of a dataset (``--hydro``, ``Hydro``, ``HullHydro``): the causal plant's
#: infinite-frequency added mass costs their square (20 000 took a minute, a million would
#: take days); a BEM's few hundred are far below
BUOY_MAX_DATASET_FREQUENCIES = 4096
#: the largest magnitude of a dataset's coefficient (A, B, F, C, M in SI units): the powers
#: square them (an excitation of 1e300 N/m gave an infinite radiation bound)
BUOY_MAX_COEFFICIENT = 1e100
#: radians a chosen wave direction may differ from one in the dataset
BUOY_DIRECTION_TOL = 1e-6
#: harmonics of the buoy's motion in a regular wave (--harmonics, or the default 24 per turn
#: x winding; the solve refines to twice as many): 512 took 18 s, 1024 over 2 minutes (the
#: solve and its two error estimates)
BUOY_MAX_HARMONICS = 512
#: the same with a power take-off (--efficiency, --torque-limit): the default 24 took 25 s
#: with an efficiency and 57 s with a 1 N m torque limit; 48, 64 and 128 with an efficiency
#: over 2 minutes
BUOY_MAX_PTO_HARMONICS = 24
#: a sweep over wave periods (--wave-period FROM:TO:N or T1,T2,...) solves each period as
#: alone: the periods times one period's estimated time must stay within this many seconds
#: (200 periods at 512 harmonics, about 2 hours, ran on unbounded)
BUOY_MAX_SWEEP_SECONDS = MAX_UNTIMED_SECONDS
#: one period's time (s; the solve and its error estimates, two shared cores under load),
#: ``a + b (N / 512)^2`` at N harmonics: 4 periods took 1.5 s each at the default 24, 2.7 s
#: at 128 and 34 s at 512
BUOY_PERIOD_SECONDS = (1.2, 33.0)
#: one period's time (s) with a power take-off (--efficiency, --torque-limit; at most 24
#: harmonics): 4 periods with --efficiency 0.9 or --torque-limit 100 ran past 150 s
BUOY_PTO_PERIOD_SECONDS = 40.0
#: --optimize-design: the estimated time of the search (its solves times one solve's) must
#: stay within this many seconds without --time-limit; it shows a progress bar on a terminal
#: (four variables ran silently past 150 s, one with --efficiency past 150 s; at 600 s the
#: four variables, estimated at about 3 minutes, were accepted and ran past 2 minutes)
BUOY_MAX_DESIGN_SECONDS = MAX_UNTIMED_SECONDS
#: one inner solve of the design search (s; the coupled optimum alone, two shared cores
#: under load): without and with a power take-off (241 solves of four variables took over
#: 150 s; about 25 of one variable with --efficiency 0.9 over 150 s)
BUOY_DESIGN_SOLVE_SECONDS = (0.7, 10.0)
#: a receding-horizon run of the buoy (--controller mpc): updates x horizon samples x solves
#: per update. The default run (100 peak periods, horizon 1, update 1/8: 832 x 64 x 2 =
#: 1.06e5) took 87 s under load; the cap keeps a run near two minutes (about 130 peak
#: periods of record at the default horizon; a 1000 s record at Tp 5 s is refused)
BUOY_MAX_MPC_WORK = 1.4e5
#: harmonics of the buoy's motion over an irregular record with a power take-off (given, or
#: the default 16 x max(the free heave's mean harmonic, winding)): 192 (--hs 2 --tp 8
#: --repeat-period 40 --efficiency 0.9) took 14 s of CPU, 512 (--repeat-period 256) over
#: 2 minutes and 1.3 GB, 800 (--repeat-period 160 --winding 20) 163 s of CPU
BUOY_MAX_PTO_RECORD_HARMONICS = 256
#: the same without a take-off (the operator Newton): the default 250 s record at Tp 2.5 s
#: (about 1600 harmonics) took 79 s under load, --harmonics 4096 over it 126 s, a 1000 s
#: record (6400 by default) over 150 s
BUOY_MAX_RECORD_HARMONICS = 4096

#: ``buoy --dofs surge,heave,pitch``: at most this many harmonics of the pendulum's motion
#: (the hull's harmonics follow; a Newton step costs O(N^3) with dense matrices, the
#: refinement doubles N up to HULL_MAX_REFINED_HARMONICS): a record of at most 10 waves
HULL_MAX_HARMONICS = 128
#: the harmonics' refinement (doubling until the power settles) stops here
HULL_MAX_REFINED_HARMONICS = 256
#: HULL_MAX_HARMONICS for an ideal take-off (no efficiency, loss or limit), whose records are
#: solved matrix-free (hydro/_hull_krylov.py; time and memory near-linear in N): 12 per wave to
#: a 300-wave record (benchmarks/bench_hull_record.out.txt: 200 waves, 2400 harmonics)
HULL_MAX_RECORD_HARMONICS = 3600
#: HULL_MAX_HARMONICS for a torque limit or a copper loss (an efficiency keeps HULL_MAX_HARMONICS:
#: its continuation stops once settled, but the refinement's doubling to 288 harmonics climbs
#: the kink's small widths for minutes each on the 10-wave record), whose
#: records are solved matrix-free from 100 harmonics (hydro/_hull_krylov.py: the limit's
#: augmented Lagrangian and the efficiency's smoothing on Newton with truncated conjugate
#: gradients; benchmarks/bench_hull_record.out.txt, its take-off table: the barge's 25-peak-
#: period record, 348 harmonics, under a torque limit in 371 s wall on the shared machine):
#: 30 waves
HULL_MAX_PTO_RECORD_HARMONICS = 360
#: ``buoy --dofs surge,heave,pitch --realizations``: at most this many seeded records of one
#: sea state (the power matrix's cap on realizations per bin)
HULL_MAX_REALIZATIONS = 1000

