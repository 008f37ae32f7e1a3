"""Closed-loop tracking: the servo core (a tick-callable) driving the simulated plant.

    tick = make_tick("fixed", chain, config="default", dt=1e-3, mode="A")   # or "float"
    res = track(chain, T, V, dt, q0, tick, Plant(q0, dt))
    res.q (K+1, n)  res.qd (K, n)  res.pos_err (K,)  res.rot_err (K,)  res.flags (K,)

Timing (one tick k = 0..K-1): the core reads the plant's measured joint values, receives the
setpoint pose ``T[k]`` and twist ``V[k]`` (omega; v), and returns the command ``qd[k]``; the plant
holds it for dt, giving ``q[k+1]``.  ``pos_err[k]`` / ``rot_err[k]`` are the *true* errors at tick k,
computed in float64 from the plant's true ``q[k]`` (not the measured one, not the core's own error):
``|p_U - p(q)|`` and the angle of ``R_U R(q)^T``.  With a setpoint frame k the pose compared is the
tool relative to frame k, ``T_k(q)^-1 T_tool(q)``.  ``flags[k]`` are the status bits the core raised
during tick k (``tensor_servo.model.STATUS_BITS``; OR them for the whole run).

Models are pluggable: :func:`make_tick` looks the name up in ``MODEL_FACTORIES`` (``float``: the C++
model instantiated on double; ``fixed``: bit-accurate, ``config`` default|compact; ``rtl``: the
Verilated servo core, rtl_core.RtlServo, bit-identical to ``fixed``); further back ends register
themselves with :func:`register_model` and must return a callable with the same contract:
``tick(q_meas, U (4,4), V (6,), qd_warm (n,)) -> object with .qd (n,) and .flags``.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .chain import Chain
from .errors import InputError
from .plant import Plant

#: loop settings that are not servo parameters (docs/solver.md): the solver's warm start
#: ("auto": the previous command with a leak of time constant about LEAK_TIME)
TRACK_DEFAULTS = {"warm": "auto"}
LEAK_TIME = 0.03


def leak_shift(dt: float, leak_time: float = LEAK_TIME) -> int:
    """Leak shift s with 2^s dt closest (in log) to ``leak_time``: 5 at 1 kHz, 8 at 10 kHz."""
    return int(min(20, max(1, round(math.log2(leak_time / dt)))))

# ---- models --------------------------------------------------------------------------------------


@dataclass
class TickModel:
    """A tick-callable plus the input ranges of its number formats (None: unbounded, float)."""

    fn: Callable
    name: str
    config: str
    ranges: dict = field(default_factory=dict)   # 'angle', 'pos', 'vel', 'gain', 'klim', 'qd', 'dt': |x| < value
    dt_lsb: float | None = None                  # LSB of the tick-period format (None: float)
    qd_lsb: float | None = None                  # LSB of the joint-rate format (None: float)
    set_warm: Callable | None = None             # told the loop's warm-start policy (a core keeping its own)
    core: object | None = None                   # the back end object (rtl: RtlServo, .cycles per tick)

    def __call__(self, q, U, V, qd_warm):
        return self.fn(q, U, V, qd_warm)


def format_ranges(config: str) -> tuple[dict, float, float]:
    """Ranges |x| < 2^(I-1) of the servo's input formats, and the LSBs of dt_t and qd_t, for a
    fixed-point configuration."""
    from .model import formats

    f = formats(config)
    rng = {k: 2.0 ** (f[t][1] - 1) for k, t in
           (("angle", "angle_t"), ("pos", "pos_t"), ("vel", "vel_t"), ("gain", "gain_t"), ("klim", "klim_t"),
            ("qd", "qd_t"), ("dt", "dt_t"))}
    lsb = {t: 2.0 ** (f[t][1] - f[t][0]) for t in ("dt_t", "qd_t")}
    return rng, lsb["dt_t"], lsb["qd_t"]


def _servo_factory(cpp_config: str | None):
    def make(chain: Chain, config: str, dt: float, params: dict) -> TickModel:
        from .servo import Servo

        cfg = cpp_config or config
        s = Servo(chain, cfg, dt=dt, **params)
        if cfg == "double":
            return TickModel(s.tick, "float", "double")
        ranges, dt_lsb, qd_lsb = format_ranges(cfg)
        return TickModel(s.tick, "fixed", cfg, ranges, dt_lsb, qd_lsb)
    return make


def _rtl_factory(chain: Chain, config: str, dt: float, params: dict) -> TickModel:
    """The Verilated servo core (rtl_core.RtlServo): bit-identical to ``fixed``."""
    from .rtl_core import RtlServo

    core = RtlServo(chain, config, dt=dt, **params)
    ranges, dt_lsb, qd_lsb = format_ranges(config)
    return TickModel(core.tick, "rtl", config, ranges, dt_lsb, qd_lsb, set_warm=core.set_warm, core=core)


MODEL_FACTORIES: dict[str, Callable[..., TickModel]] = {
    "float": _servo_factory("double"),
    "fixed": _servo_factory(None),
    "rtl": _rtl_factory,
}


def register_model(name: str, factory: Callable[..., TickModel]) -> None:
    """Add a back end: ``factory(chain, config, dt, params) -> TickModel``."""
    MODEL_FACTORIES[name] = factory


def model_names() -> tuple[str, ...]:
    return tuple(MODEL_FACTORIES)


def make_tick(model: str, chain: Chain, *, config: str = "default", dt: float, **params) -> TickModel:
    """The tick-callable of a model name (``float``, ``fixed``, later ``rtl``)."""
    if model not in MODEL_FACTORIES:
        raise InputError("--model", f"unknown model {model!r} ({', '.join(MODEL_FACTORIES)})")
    return MODEL_FACTORIES[model](chain, config, dt, params)


# ---- float kinematics, vectorised over samples ---------------------------------------------------

def _rodrigues(axis: np.ndarray, ang: np.ndarray) -> np.ndarray:
    x, y, z = axis
    K = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    s, c = np.sin(ang)[:, None, None], np.cos(ang)[:, None, None]
    return np.eye(3)[None] + s * K[None] + (1.0 - c) * (K @ K)[None]


def frame_poses(chain: Chain, Q: np.ndarray, frames: tuple[int, ...] = (-1,)) -> list[np.ndarray]:
    """(N, 4, 4) root-frame poses of the requested frames (0 base, 1..n joints, n+1 or -1 tool)
    for every row of Q (N, n); float64, the same construction as ``reference.fk_frames``."""
    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    N, n = Q.shape
    want = [chain.n + 1 if f == -1 else int(f) for f in frames]
    out: dict[int, np.ndarray] = {}
    T = np.broadcast_to(chain.base.matrix(), (N, 4, 4)).copy()
    out[0] = T.copy()
    for i, j in enumerate(chain.joints, start=1):
        T = T @ j.origin.matrix()
        ang = j.scale * Q[:, i - 1]
        M = np.broadcast_to(np.eye(4), (N, 4, 4)).copy()
        if j.prismatic:
            M[:, :3, 3] = ang[:, None] * np.asarray(j.axis)[None]
        else:
            M[:, :3, :3] = _rodrigues(np.asarray(j.axis, dtype=float), ang)
        T = T @ M
        out[i] = T
    out[chain.n + 1] = T @ chain.tool.matrix()
    return [out[k] for k in want]


def relative_poses(chain: Chain, Q: np.ndarray, setpoint_frame: int = -1) -> np.ndarray:
    """Tool poses (N,4,4) in the root frame, or relative to frame ``setpoint_frame`` (>= 0)."""
    if setpoint_frame is None or setpoint_frame < 0:
        return frame_poses(chain, Q, (-1,))[0]
    Tk, Tt = frame_poses(chain, Q, (setpoint_frame, -1))
    Rk = Tk[:, :3, :3]
    rel = np.broadcast_to(np.eye(4), Tt.shape).copy()
    rel[:, :3, :3] = np.swapaxes(Rk, 1, 2) @ Tt[:, :3, :3]
    rel[:, :3, 3] = np.einsum("nji,nj->ni", Rk, Tt[:, :3, 3] - Tk[:, :3, 3])
    return rel


def rotation_angles(Ra: np.ndarray, Rb: np.ndarray) -> np.ndarray:
    """Angle (rad) of Ra Rb^T for stacks (N,3,3); accurate near 0 (atan2 of sine and cosine)."""
    E = Ra @ np.swapaxes(Rb, 1, 2)
    s = 0.5 * np.stack([E[:, 2, 1] - E[:, 1, 2], E[:, 0, 2] - E[:, 2, 0], E[:, 1, 0] - E[:, 0, 1]], axis=1)
    c = 0.5 * (np.trace(E, axis1=1, axis2=2) - 1.0)
    return np.arctan2(np.linalg.norm(s, axis=1), c)


def pose_errors(chain: Chain, Q: np.ndarray, T: np.ndarray, setpoint_frame: int = -1) -> tuple[np.ndarray, np.ndarray]:
    """True position (m) and orientation (rad) errors of joint values Q (N,n) against poses T (N,4,4)."""
    P = relative_poses(chain, Q, setpoint_frame)
    pe = np.linalg.norm(T[:, :3, 3] - P[:, :3, 3], axis=1)
    re = rotation_angles(T[:, :3, :3], P[:, :3, :3])
    return pe, re


# ---- validation of the path and of q0 --------------------------------------------------------------

def check_poses(T: np.ndarray, name: str, tol: float = 1e-6) -> np.ndarray:
    """(K,4,4) finite homogeneous rigid transforms (rotation orthonormal within tol, det +1)."""
    T = np.asarray(T, dtype=float)
    if T.ndim != 3 or T.shape[1:] != (4, 4) or T.shape[0] < 1:
        raise InputError(name, f"shape {tuple(T.shape)} does not match (K, 4, 4)")
    if not np.all(np.isfinite(T)):
        bad = np.argwhere(~np.isfinite(T))[0]
        raise InputError(name, f"non-finite value at index {tuple(int(i) for i in bad)}")
    last = np.abs(T[:, 3, :] - np.array([0.0, 0.0, 0.0, 1.0])).max(axis=1)
    if np.any(last > 0):
        k = int(np.argmax(last > 0))
        raise InputError(name, f"pose {k}: last row is not [0, 0, 0, 1]")
    R = T[:, :3, :3]
    orth = np.abs(np.swapaxes(R, 1, 2) @ R - np.eye(3)).max(axis=(1, 2))
    det = np.linalg.det(R)
    bad = (orth > tol) | (det < 0)
    if np.any(bad):
        k = int(np.argmax(bad))
        raise InputError(name, f"pose {k}: rotation is not orthonormal with det +1 (deviation {orth[k]:.2g})")
    return T


def check_dt(dt, name: str, model: TickModel | None = None) -> float:
    """A tick period: positive, finite, within the model's dt format and representable to 1 %."""
    a = np.asarray(dt, dtype=float)
    if a.size != 1:
        raise InputError(name, f"expected a scalar, got shape {a.shape}")
    d = float(a.reshape(()))
    if not math.isfinite(d) or d <= 0:
        raise InputError(name, f"must be a positive finite number of seconds (got {d!r})")
    if model is not None and model.dt_lsb is not None:
        hi = model.ranges["dt"]
        if d >= hi:
            raise InputError(name, f"{d:g} s outside the {model.config} tick-period format (dt < {hi:g} s)")
        qd = round(d / model.dt_lsb) * model.dt_lsb
        if abs(qd - d) > 0.01 * d:
            raise InputError(name, f"{d:g} s is not representable to 1 % in the {model.config} tick-period "
                                   f"format (LSB {model.dt_lsb:.3g} s)")
    return d


def check_q0(chain: Chain, q0: np.ndarray, name: str, model: TickModel | None = None) -> np.ndarray:
    q0 = np.asarray(q0, dtype=float)
    if q0.ndim == 2 and q0.shape[0] == 1:
        q0 = q0[0]
    if q0.shape != (chain.n,):
        raise InputError(name, f"shape {tuple(q0.shape)} does not match ({chain.n},)")
    if not np.all(np.isfinite(q0)):
        raise InputError(name, f"non-finite value at joint {int(np.argmax(~np.isfinite(q0)))}")
    out = (q0 < chain.lower) | (q0 > chain.upper)
    if np.any(out):
        j = int(np.argmax(out))
        raise InputError(name, f"joint {j}: {q0[j]:g} outside its limits [{chain.lower[j]:g}, {chain.upper[j]:g}]")
    if model is not None and "angle" in model.ranges:
        big = np.abs(q0) >= model.ranges["angle"]
        if np.any(big):
            j = int(np.argmax(big))
            raise InputError(name, f"joint {j}: {q0[j]:g} outside the {model.config} joint-value format "
                                   f"(|q| < {model.ranges['angle']:g})")
    return q0


def check_setpoints(T: np.ndarray, V: np.ndarray, model: TickModel | None, tname: str, vname: str) -> None:
    """Setpoint positions and twists within the model's input formats."""
    if V.ndim != 2 or V.shape != (T.shape[0], 6):
        raise InputError(vname, f"shape {tuple(V.shape)} does not match ({T.shape[0]}, 6)")
    if not np.all(np.isfinite(V)):
        bad = np.argwhere(~np.isfinite(V))[0]
        raise InputError(vname, f"non-finite value at index {tuple(int(i) for i in bad)}")
    if model is None or "pos" not in model.ranges:
        return
    pmax, vmax = model.ranges["pos"], model.ranges["vel"]
    bad = np.abs(T[:, :3, 3]).max(axis=1) >= pmax
    if np.any(bad):
        raise InputError(tname, f"pose {int(np.argmax(bad))}: position outside the {model.config} position format "
                                f"(|p| < {pmax:g} m)")
    bad = np.abs(V).max(axis=1) >= vmax
    if np.any(bad):
        raise InputError(vname, f"sample {int(np.argmax(bad))}: twist outside the {model.config} velocity format "
                                f"(|.| < {vmax:g})")


# ---- the loop ------------------------------------------------------------------------------------

@dataclass
class TrackResult:
    q: np.ndarray         # (K+1, n) true plant joint values
    qd: np.ndarray        # (K, n) commands
    pos_err: np.ndarray   # (K,) m
    rot_err: np.ndarray   # (K,) rad
    flags: np.ndarray     # (K,) uint32
    q_meas: np.ndarray    # (K, n) what the core saw

    def as_dict(self) -> dict:
        return {"q": self.q, "qd": self.qd, "pos_err": self.pos_err, "rot_err": self.rot_err,
                "flags": self.flags, "q_meas": self.q_meas}


def warm_start(qd: np.ndarray, policy, qd_lsb: float | None) -> np.ndarray:
    """The next tick's solver warm start from this tick's command ``qd``.

    ``"prev"``: qd itself (what the C++ servo's caller does today); ``"zero"``: no warm start;
    ``"auto"`` (resolved by :func:`track` to ``leak_shift(dt)``) or an int s >= 1: a leak,
    ``qd - qd 2^-s`` -- in a fixed-point model exactly ``raw - (raw >> s)`` on the raw joint-rate integers (arithmetic shift, i.e. floor), which is
    what a core's warm-start register would do with one shifter and one subtractor.  The leak
    makes a joint-rate component that no longer does anything (the null space of a redundant
    chain) die out instead of persisting as self-motion (docs/solver.md, "warm start")."""
    if isinstance(policy, str):
        if policy == "prev":
            return qd
        if policy == "zero":
            return np.zeros_like(qd)
        raise InputError("--warm", f"unknown warm-start policy {policy!r} (prev, zero or a leak shift)")
    s = int(policy)
    if s < 1 or s > 20:
        raise InputError("--warm", f"leak shift must be 1..20 (got {s})")
    if qd_lsb is None:
        return qd * (1.0 - 2.0 ** -s)
    raw = np.rint(np.asarray(qd) / qd_lsb).astype(np.int64)
    return (raw - (raw >> s)).astype(np.float64) * qd_lsb


def track(chain: Chain, T: np.ndarray, V: np.ndarray, q0: np.ndarray, tick: Callable, plant: Plant, *,
          setpoint_frame: int = -1, warm="auto",
          disturb: Callable[[int, np.ndarray], np.ndarray] | None = None) -> TrackResult:
    """Run the closed loop over the K setpoints.  ``warm``: the solver's warm start (see
    :func:`warm_start`; default: a leak with a time constant of about 30 ms).
    ``disturb(k, qd_cmd)`` may replace the rates the plant receives (an external disturbance on
    some joints)."""
    T = np.asarray(T, dtype=float)
    V = np.asarray(V, dtype=float)
    K, n = T.shape[0], chain.n
    q = np.empty((K + 1, n))
    qm = np.empty((K, n))
    qd = np.empty((K, n))
    flags = np.zeros(K, dtype=np.uint32)
    qd_lsb = getattr(tick, "qd_lsb", None)
    if isinstance(warm, str) and warm == "auto":
        warm = leak_shift(plant.dt)
    warm_start(np.zeros(n), warm, qd_lsb)  # validates the policy before the run
    if getattr(tick, "set_warm", None) is not None:
        tick.set_warm(warm)
    plant.reset(q0)
    q[0] = plant.q
    w = np.zeros(n)
    for k in range(K):
        qm[k] = plant.measure()
        o = tick(qm[k], T[k], V[k], w)
        qd[k] = o.qd
        flags[k] = o.flags
        w = warm_start(o.qd, warm, qd_lsb)
        u = o.qd if disturb is None else disturb(k, o.qd)
        q[k + 1] = plant.step(u)
    pe, re = pose_errors(chain, q[:K], T, setpoint_frame)
    return TrackResult(q, qd, pe, re, flags, qm)


def run_model(model: str, chain: Chain, T: np.ndarray, V: np.ndarray, q0: np.ndarray, plant: Plant, *,
              config: str = "default", dt: float, warm="auto", **params) -> tuple[TrackResult, TickModel, float]:
    """:func:`make_tick` then :func:`track` (setpoint frame from ``params``), releasing the back
    end afterwards (the rtl model's simulation process).  Returns the result, the tick model
    (``.core.cycles`` for rtl) and the seconds the loop took (construction not included)."""
    tick = make_tick(model, chain, config=config, dt=dt, **params)
    try:
        t0 = time.perf_counter()
        res = track(chain, T, V, q0, tick, plant, setpoint_frame=params.get("setpoint_frame", -1), warm=warm)
        return res, tick, time.perf_counter() - t0
    finally:
        if tick.core is not None:
            tick.core.close()
