"""``tservo track`` (closed-loop tracking with a simulated plant) and ``tservo path`` (point arrays).

    tservo track CHAIN.json --path PATH.npz --q0 Q0.npy [--model float|fixed|rtl] [--config default|compact]
                 [--mode A|B] [--error-only] [--kp K] [--ko K] [--kdt X] [--klim K] [--L M] [--sweeps N]
                 [--mu MU[,MU...]] [--warm auto|prev|zero|S] [--no-vlimits] [--setpoint-frame K]
                 [--lag TAU] [--counts C] -o OUT.npz

PATH (.npz): ``T`` (K,4,4) setpoint poses (root frame, or relative to ``--setpoint-frame``),
``V`` (K,6) setpoint twists (omega; v), same axes, v = velocity of the tool origin, ``dt`` (s).
OUT (.npz): ``q`` (K+1,n) plant joint values, ``qd`` (K,n) commands, ``pos_err`` (K,) and
``rot_err`` (K,) true errors at each tick (float64, from the plant's q), ``flags`` (K,) status bits
raised in each tick, ``q_meas`` (K,n) the values the core saw.  Gains are in 1/s (``--kdt X`` sets
kp = ko = X/dt); defaults: ``servo.default_params``.  ``--lag`` is the actuator time constant (s),
``--counts`` the encoder counts per joint unit.

    tservo path CHAIN.json (--poses POSES.npy | --line DX DY DZ [RX RY RZ]) --q0 Q0.npy
                [--step S] [--step-rot R] [--model float|fixed] [--config default|compact]
                [--tol-pos M] [--tol-rot R] [--iters N] -o OUT.npz

A Cartesian path from the tool pose at q0: through the waypoints of POSES ((M,4,4), .npy or
``file.npz:T``; a densely sampled curve is just many waypoints), or one straight line displaced by
(DX, DY, DZ) m and rotated by the rotation vector (RX, RY, RZ) rad (root axes); straight segments
with slerped orientation cut at ``--step`` m / ``--step-rot`` rad.  The virtual servo turns the
samples into joint values (``pathgen.point_array``).  OUT: ``q`` (M,n), ``T`` (M,4,4), ``pos_err``,
``rot_err`` (float check), ``ticks``, ``converged``, ``flags``.  Exit status 1 (output written) if
some sample is not within tolerance.

Bad input: one line ``tservo: error: <field>: <problem>``, exit status 2, nothing written.
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from . import chain as chainmod
from .arrays import check_shape, load_array, save_npz
from .errors import InputError


def _add_model(p: argparse.ArgumentParser, rtl: bool = False) -> None:
    from .track import model_names

    names = model_names() if rtl else tuple(m for m in model_names() if m != "rtl")
    p.add_argument("--model", choices=names, default="fixed",
                   help="float (C++ double), fixed point" + (", or rtl (the Verilated servo core)" if rtl else ""))
    p.add_argument("--config", choices=("default", "compact"), default="default", help="fixed-point configuration")


def register(sub) -> None:
    p = sub.add_parser("track", help="closed-loop tracking of a setpoint path with a simulated plant")
    p.add_argument("chain", help="chain JSON file or embedded example name")
    p.add_argument("--path", required=True, help="setpoints: .npz with T (K,4,4), V (K,6), dt")
    p.add_argument("--q0", required=True, help="initial joint values, .npy (n,)")
    _add_model(p, rtl=True)
    p.add_argument("--nmax", type=int, default=None,
                   help="--model rtl: the core's NMAX parameter, the joints it is built for (n..60; default max(8, n))")
    p.add_argument("--mode", choices=("A", "B"), default="A", help="error choice A (root basis) or B (body basis)")
    p.add_argument("--error-only", action="store_true", help="no feed-forward of the setpoint twist")
    p.add_argument("--kp", type=float, help="position gain (1/s)")
    p.add_argument("--ko", type=float, help="orientation gain (1/s)")
    p.add_argument("--kdt", type=float, help="set kp = ko = KDT / dt")
    p.add_argument("--klim", type=float, help="limit-approach gain (1/s), at most 1/dt")
    p.add_argument("--L", type=float, help="characteristic length (m/rad)")
    p.add_argument("--sweeps", type=int, help="coordinate-descent sweeps per tick")
    p.add_argument("--mu", help="per-joint multiplier: one value or n comma-separated values in [0, 2)")
    p.add_argument("--warm", default=None,
                   help="solver warm start: auto (leak of ~30 ms, default), prev, zero, or a leak shift S (1..20)")
    p.add_argument("--no-vlimits", action="store_true", help="ignore the chain's velocity limits")
    p.add_argument("--setpoint-frame", type=int, default=-1, help="setpoints relative to frame K (0..n)")
    p.add_argument("--lag", type=float, default=0.0, help="actuator time constant (s), 0 = ideal")
    p.add_argument("--counts", type=float, default=None, help="encoder counts per joint unit")
    p.add_argument("-o", "--output", required=True, help="output .npz")
    p.set_defaults(func=cmd_track)

    p = sub.add_parser("path", help="point array: Cartesian path -> joint values by the virtual servo")
    p.add_argument("chain", help="chain JSON file or embedded example name")
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--poses", help="waypoints (M,4,4): .npy or file.npz:key")
    g.add_argument("--line", nargs="+", type=float, metavar="X",
                   help="DX DY DZ [RX RY RZ]: one straight line from the start pose (m, rad, root axes)")
    p.add_argument("--q0", required=True, help="initial joint values, .npy (n,)")
    p.add_argument("--step", type=float, default=1e-3, help="largest translation between samples (m)")
    p.add_argument("--step-rot", type=float, default=1e-2, help="largest rotation between samples (rad)")
    _add_model(p)
    p.add_argument("--tol-pos", type=float, default=None, help="position tolerance (m) of the core's own error")
    p.add_argument("--tol-rot", type=float, default=None, help="orientation tolerance (rad)")
    p.add_argument("--iters", type=int, default=50, help="correction ticks per sample at most")
    p.add_argument("-o", "--output", required=True, help="output .npz")
    p.set_defaults(func=cmd_path)


# ---- input helpers ---------------------------------------------------------------------------------

def _positive(v, name: str, allow_zero: bool = False) -> float:
    if v is None or not math.isfinite(v) or v < 0 or (v == 0 and not allow_zero):
        raise InputError(name, f"must be a {'non-negative' if allow_zero else 'positive'} finite number (got {v!r})")
    return float(v)


def load_path_npz(path: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    p = Path(path)
    if not p.exists():
        raise InputError("--path", f"{path}: no such file")
    try:
        d = np.load(p, allow_pickle=False)
    except Exception as e:
        raise InputError("--path", f"{path}: not a readable .npz file ({type(e).__name__})") from None
    if not isinstance(d, np.lib.npyio.NpzFile):
        raise InputError("--path", f"{path}: expected an .npz with arrays T, V and dt")
    out = []
    for key in ("T", "V", "dt"):
        if key not in d.files:
            raise InputError(f"--path: {key}", f"missing (the file has {', '.join(d.files) or 'no arrays'})")
        a = d[key]
        if a.dtype.kind not in "fiu":
            raise InputError(f"--path: {key}", f"expected a numeric array, got dtype {a.dtype}")
        out.append(np.asarray(a, dtype=np.float64))
    return out[0], out[1], out[2]


def _load_q0(path: str, n: int) -> np.ndarray:
    q = load_array(path, "--q0")
    if q.ndim == 2 and q.shape[0] == 1:
        q = q[0]
    return check_shape(q, "--q0", (n,))


def _mu(text: str | None, n: int):
    if text is None:
        return None
    try:
        vals = [float(x) for x in text.split(",")]
    except ValueError:
        raise InputError("--mu", f"expected numbers separated by commas (got {text!r})") from None
    if len(vals) not in (1, n):
        raise InputError("--mu", f"expected 1 or {n} values, got {len(vals)}")
    if not all(math.isfinite(v) and 0 <= v < 2 for v in vals):
        raise InputError("--mu", "every value must lie in [0, 2)")
    return vals * n if len(vals) == 1 else vals


def _warm(text: str | None):
    if text is None:
        return None
    if text in ("prev", "zero", "auto"):
        return text
    try:
        s = int(text)
    except ValueError:
        raise InputError("--warm", f"expected auto, prev, zero or a leak shift 1..20 (got {text!r})") from None
    if not 1 <= s <= 20:
        raise InputError("--warm", f"leak shift must be 1..20 (got {s})")
    return s


def _check_gain(v: float, name: str, tm, key: str) -> None:
    if tm is None or key not in tm.ranges:
        return
    from .model import formats

    hi = tm.ranges[key]
    W, I = formats(tm.config)[f"{key}_t"]
    step = 2.0 ** (I - W)
    if v >= hi:
        raise InputError(name, f"{v:g} outside the {tm.config} format (< {hi:g})")
    if v > 0 and abs(round(v / step) * step - v) > 0.01 * v:
        raise InputError(name, f"{v:g} is not representable to 1 % in the {tm.config} format (LSB {step:g})")


def servo_params(args, ch, dt: float) -> dict:
    """Servo parameters from the command line (only those given; the rest are the defaults)."""
    from .servo import default_params

    d = default_params(ch, dt)
    p: dict = {"mode": args.mode, "feedforward": not args.error_only, "vlimits": not args.no_vlimits}
    if args.kdt is not None:
        k = _positive(args.kdt, "--kdt") / dt
        p["kp"] = p["ko"] = k
    if args.kp is not None:
        p["kp"] = _positive(args.kp, "--kp")
    if args.ko is not None:
        p["ko"] = _positive(args.ko, "--ko")
    if args.klim is not None:
        p["klim"] = _positive(args.klim, "--klim", allow_zero=True)
    klim = p.get("klim", d["klim"])
    if klim * dt > 1.0 + 1e-12:
        raise InputError("--klim", f"{klim:g}/s exceeds 1/dt = {1 / dt:g}/s (the core could command past a limit)")
    if args.L is not None:
        L = _positive(args.L, "--L")
        if L >= 4:
            raise InputError("--L", f"{L:g} m outside the characteristic-length format (< 4 m)")
        p["L"] = L
    if args.sweeps is not None:
        if not 1 <= args.sweeps <= 1000:
            raise InputError("--sweeps", f"must be 1..1000 (got {args.sweeps})")
        p["sweeps"] = args.sweeps
    mu = _mu(args.mu, ch.n)
    if mu is not None:
        p["mu"] = mu
    sf = args.setpoint_frame
    if not -1 <= sf <= ch.n:
        raise InputError("--setpoint-frame", f"must be -1 (root) or a frame 0..{ch.n} before the tool (got {sf})")
    p["setpoint_frame"] = sf
    return p


# ---- commands ------------------------------------------------------------------------------------

def cmd_track(args) -> int:
    from .plant import Plant
    from .servo import default_params
    from .track import (TRACK_DEFAULTS, TickModel, check_dt, check_poses, check_q0, check_setpoints,
                        format_ranges, run_model)

    ch = chainmod.load(args.chain)
    T, V, dt_arr = load_path_npz(args.path)
    T = check_poses(T, "--path: T")
    dt = check_dt(dt_arr, "--path: dt")
    params = servo_params(args, ch, dt)
    if args.nmax is not None:
        if args.model != "rtl":
            raise InputError("--nmax", f"only --model rtl builds a core with an NMAX (got --model {args.model})")
        params["nmax"] = args.nmax
    warm = _warm(args.warm) or TRACK_DEFAULTS["warm"]
    lag = _positive(args.lag, "--lag", allow_zero=True)
    counts = None if args.counts is None else _positive(args.counts, "--counts")
    # The model's formats first (so that range errors name the input, not the C++ call).
    probe = None
    if args.model != "float":
        ranges, dt_lsb, qd_lsb = format_ranges(args.config)
        probe = TickModel(None, args.model, args.config, ranges, dt_lsb, qd_lsb)
        check_dt(dt_arr, "--path: dt", probe)
        full = {**default_params(ch, dt), **params}
        _check_gain(full["kp"], "--kp", probe, "gain")
        _check_gain(full["ko"], "--ko", probe, "gain")
        _check_gain(full["klim"], "--klim", probe, "klim")
    q0 = check_q0(ch, _load_q0(args.q0, ch.n), "--q0", probe)
    check_setpoints(T, V, probe, "--path: T", "--path: V")
    plant = Plant(q0, dt, tau=lag, counts=counts)
    res, _, _ = run_model(args.model, ch, T, V, q0, plant, config=args.config, dt=dt, warm=warm, **params)
    save_npz(args.output, **res.as_dict())
    return 0


def cmd_path(args) -> int:
    from .pathgen import displaced, line_path, point_array
    from .track import TickModel, check_poses, check_q0, format_ranges, relative_poses

    ch = chainmod.load(args.chain)
    probe = None
    if args.model != "float":
        ranges, dt_lsb, qd_lsb = format_ranges(args.config)
        probe = TickModel(None, args.model, args.config, ranges, dt_lsb, qd_lsb)
    q0 = check_q0(ch, _load_q0(args.q0, ch.n), "--q0", probe)
    T0 = relative_poses(ch, q0[None])[0]
    _positive(args.step, "--step")
    _positive(args.step_rot, "--step-rot")
    if args.poses is not None:
        W = check_poses(load_array(args.poses, "--poses"), "--poses")
    else:
        v = args.line
        if len(v) not in (3, 6) or not all(math.isfinite(x) for x in v):
            raise InputError("--line", "expected 3 (DX DY DZ) or 6 (DX DY DZ RX RY RZ) finite numbers")
        rv = np.array(v[3:] if len(v) == 6 else [0.0, 0.0, 0.0])
        if np.linalg.norm(rv) >= math.pi:
            raise InputError("--line", "the rotation must be shorter than pi rad")
        W = displaced(T0, v[:3], rv)[None]
    if not 1 <= args.iters <= 100000:
        raise InputError("--iters", f"must be 1..100000 (got {args.iters})")
    T = line_path(T0, W, args.step, args.step_rot)
    if probe is not None:
        pmax = probe.ranges["pos"]
        bad = np.abs(T[:, :3, 3]).max(axis=1) >= pmax
        if np.any(bad):
            raise InputError("--poses" if args.poses else "--line",
                             f"the path leaves the {args.config} position format (|p| < {pmax:g} m)")
    tol_pos, tol_rot = default_tolerances(args.model, args.config)
    if args.tol_pos is not None:
        tol_pos = _positive(args.tol_pos, "--tol-pos")
    if args.tol_rot is not None:
        tol_rot = _positive(args.tol_rot, "--tol-rot")
    res = point_array(ch, T, q0, model=args.model, config=args.config, tol_pos=tol_pos, tol_rot=tol_rot,
                      iters=args.iters)
    save_npz(args.output, **res.as_dict())
    if not res.converged.all():
        m = int(np.argmin(res.converged))
        print(f"tservo: warning: {int((~res.converged).sum())} of {len(T)} samples not within tolerance "
              f"(first: sample {m}, error {res.pos_err[m]:.2g} m / {res.rot_err[m]:.2g} rad); output written",
              file=sys.stderr)
        return 1
    return 0


def default_tolerances(model: str, config: str) -> tuple[float, float]:
    """1 um / 10 urad, or 4 LSB of the position / orientation error formats if coarser."""
    if model == "float":
        return 1e-6, 1e-5
    from .model import formats

    f = formats(config)
    lp = 2.0 ** (f["perr_t"][1] - f["perr_t"][0])
    lr = 2.0 ** (f["rot_t"][1] - f["rot_t"][0])
    return max(1e-6, 4 * lp), max(1e-5, 4 * lr)
