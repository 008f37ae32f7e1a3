"""Python API of the servo tick (bit-accurate C++ model: ``servo.hpp``, ``solver.hpp``).

    s = Servo(chain, "default", dt=1e-3)            # "double", "default" or "compact"
    out = s.tick(q, U, Ud, qd_warm)                 # one tick
    out.qd        joint-rate command (n,)
    out.q_next    q + qd dt clamped to the limits (virtual mode)
    out.ep, out.eo  position error (m) and orientation error (rotation vector, rad)
    out.flags     sticky status bits (tensor_servo.model.STATUS_BITS)

U is the setpoint pose (4x4, root frame, or relative to ``setpoint_frame``), Ud its twist
(omega; v), v the velocity of the controlled point, in the same axes.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _model
from .chain import Chain, matrix_to_quat
from .errors import InputError
from .model import CONFIGS, model_spec


def default_params(chain: Chain, dt: float) -> dict:
    """Safe defaults (docs/solver.md, "Safe defaults"): gains 0.3/dt, limit-approach gain 0.5/dt,
    L = 0.5 m, 10 sweeps with relaxation mu = 1.5 (measured on PUMA 560: worst-case settling 43
    ticks instead of > 600 with 2 sweeps / mu = 1; stable with actuator lags up to 10 ticks)."""
    return {
        "L": 0.5, "kp": 0.3 / dt, "ko": 0.3 / dt, "dt": dt, "klim": 0.5 / dt, "sweeps": 10,
        "mu": [1.5] * chain.n, "mode": "A", "feedforward": True, "controlled": -1, "setpoint_frame": -1,
        "vlimits": True, "weights": None,
        "warm_leak": 0,  # leak of the warm start inside the tick (track.py applies its own by default)
        "cg": 0,  # conjugate-direction steps after the sweeps (offline IK only; the core has none)
    }


@dataclass
class TickOut:
    qd: np.ndarray
    q_next: np.ndarray
    ep: np.ndarray
    eo: np.ndarray
    r: np.ndarray
    flags: int
    raw: dict | None = None


def pose_to_quat_pos(U: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    U = np.asarray(U, dtype=float)
    if U.shape != (4, 4):
        raise InputError("U", f"expected a 4x4 pose, got shape {U.shape}")
    return matrix_to_quat(U[:3, :3]), U[:3, 3].copy()


class Servo:
    """The servo tick of one chain in one number configuration."""

    def __init__(self, chain: Chain, config: str = "default", dt: float = 1e-3, **params):
        if config not in CONFIGS:
            raise InputError("config", f"unknown configuration {config!r} ({', '.join(CONFIGS)})")
        p = default_params(chain, dt)
        unknown = set(params) - set(p)
        if unknown:
            raise InputError("params", f"unknown parameter(s) {', '.join(sorted(unknown))}")
        p.update(params)
        if np.isscalar(p["mu"]):
            p["mu"] = [float(p["mu"])] * chain.n
        if p["controlled"] == "tool":
            p["controlled"] = -1
        ctl = p["controlled"]
        p["controlled"] = [int(c) for c in ctl] if isinstance(ctl, (list, tuple)) else [int(ctl)]
        if p["weights"] is None:
            p["weights"] = [1.0] * len(p["controlled"])
        if p["setpoint_frame"] is None:
            p["setpoint_frame"] = -1
        self.ntasks = len(p["controlled"])
        self.chain, self.config, self.params = chain, config, p
        try:
            self._s = _model.Servo(config, model_spec(chain), p)
        except ValueError as e:
            raise InputError("servo", str(e)) from None
        self.n = chain.n

    def tick(self, q: np.ndarray, U: np.ndarray, Ud: np.ndarray | None = None, qd_warm: np.ndarray | None = None) -> TickOut:
        """One tick.  One task: U (4,4), Ud (6,); T tasks (trees): U (T,4,4), Ud (T,6), and
        ep/eo come back (T,3) instead of (3,)."""
        U = np.asarray(U, dtype=float)
        single = U.ndim == 2
        Us = U[None] if single else U
        if Us.shape[0] != self.ntasks:
            raise InputError("U", f"{self.ntasks} setpoint(s) expected, got {Us.shape[0]}")
        qp = [pose_to_quat_pos(u) for u in Us]
        uq = np.array([a for a, _ in qp]); up = np.array([b for _, b in qp])
        Ud = np.zeros((self.ntasks, 6)) if Ud is None else np.asarray(Ud, dtype=float).reshape(self.ntasks, 6)
        w = np.zeros(self.n) if qd_warm is None else np.asarray(qd_warm, dtype=float)
        try:
            d = self._s.tick(np.asarray(q, dtype=float), uq, up, np.ascontiguousarray(Ud[:, :3]),
                             np.ascontiguousarray(Ud[:, 3:]), w)
        except ValueError as e:
            raise InputError("tick", str(e)) from None
        raw = {k[:-4]: v for k, v in d.items() if k.endswith("_raw")} or None
        ep, eo = (d["ep"][0], d["eo"][0]) if single else (d["ep"], d["eo"])
        if raw and single:
            raw["ep"], raw["eo"] = raw["ep"][0], raw["eo"][0]
        return TickOut(d["qd"], d["q_next"], ep, eo, d["r"], int(d["flags"]), raw)

    def ik(self, q0: np.ndarray, targets: np.ndarray, max_ticks: int = 500, tol_pos: float = 1e-6,
           tol_rot: float = 1e-5) -> dict:
        """Virtual-mode IK in C++: (N, n) seeds, (N, 4, 4) targets -> q, ticks, converged, flags.
        Convergence is the model's own error test; callers check the answer in float."""
        T = np.asarray(targets, dtype=float)
        quat = np.array([matrix_to_quat(t[:3, :3]) for t in T]).reshape(-1, 4)
        return dict(self._s.ik(np.asarray(q0, dtype=float).reshape(-1, self.n), quat,
                               np.ascontiguousarray(T[:, :3, 3]), int(max_ticks), float(tol_pos), float(tol_rot)))
