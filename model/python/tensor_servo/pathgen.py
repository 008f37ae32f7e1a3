"""Cartesian paths and the point-array generator (the seed's section 8, digest a.6).

Paths (float64):

    T = line_path(T0, waypoints, step=1e-3, step_rot=1e-2)   # straight segments, slerped orientation
    T, V = circle(T0, radius, period, dt, duration, ...)       # sampled curves with their twists
    T, V = figure8(T0, size, period, dt, duration, ...)

Point arrays:

    res = point_array(chain, T, q0, model="fixed", config="default")
    res.q (M, n): joint values whose tool pose reproduces T[m] (T[0] must be the pose of q0)

The generator runs the *virtual* tracking servo (the core's own integration
``q_next = clamp(q + q' dt)``, no plant) along the samples, as the seed describes: for each step
P_m -> P_{m+1}

  1. one feed-forward tick with setpoint P_m and twist ``log(P_{m+1} P_m^-1) / dt`` (the transition
     tensor D of the seed, as a 6-vector (omega; v) in the root basis), which moves the model frame
     onto P_{m+1} to first order, plus the correction of whatever error remained at P_m;
  2. correction ticks with setpoint P_{m+1} and zero twist until the core's own error (checked
     before each move) is within ``tol_pos``/``tol_rot`` or ``iters`` ticks have run.

The tick period of the virtual servo has no physical meaning (1/64 s keeps the twist of a
centimetre step far inside the velocity format); the gains are K dt = ``kdt`` (1: the full
correction each tick), 10 sweeps with mu = 1.5, no warm start (every tick solved from zero, so
a redundant chain gets no null-space drift along the array: docs/solver.md, section 3), and
velocity limits are off (geometry only).  About 3 correction ticks per 2 mm sample (measured).  Position limits are honoured by the core's bounds (klim dt = 0.5), so
every returned q is within the limits.  The float errors of the answer (``pos_err``, ``rot_err``,
from the float64 kinematics) are returned with it; ``converged`` is the core's own verdict.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .chain import Chain
from .errors import InputError
from .reference import rotation, rotvec
from .track import make_tick, pose_errors

VIRTUAL_DT = 1.0 / 64.0


# ---- paths -----------------------------------------------------------------------------------------

def _segment(Ta: np.ndarray, Tb: np.ndarray, m: int) -> np.ndarray:
    """m samples after Ta on the straight line Ta -> Tb (position linear, orientation slerped)."""
    Ra, Rb = Ta[:3, :3], Tb[:3, :3]
    w = rotvec(Rb @ Ra.T)                      # root basis
    ang = float(np.linalg.norm(w))
    ax = w / ang if ang > 0 else np.array([1.0, 0.0, 0.0])
    out = np.empty((m, 4, 4))
    for j in range(1, m + 1):
        s = j / m
        T = np.eye(4)
        T[:3, :3] = rotation(ax, s * ang) @ Ra
        T[:3, 3] = (1 - s) * Ta[:3, 3] + s * Tb[:3, 3]
        out[j - 1] = T
    out[-1] = Tb
    return out


def line_path(T0: np.ndarray, waypoints: np.ndarray, step: float = 1e-3, step_rot: float = 1e-2) -> np.ndarray:
    """Samples (M, 4, 4) from T0 through every waypoint: straight lines with slerped orientation,
    each segment cut into ceil(max(length / step, angle / step_rot)) equal steps; zero-length
    segments are skipped.  T[0] = T0."""
    if not (step > 0 and math.isfinite(step)):
        raise InputError("--step", "must be a positive number (m)")
    if not (step_rot > 0 and math.isfinite(step_rot)):
        raise InputError("--step-rot", "must be a positive number (rad)")
    out = [np.asarray(T0, dtype=float)]
    for W in np.asarray(waypoints, dtype=float):
        Ta = out[-1]
        d = float(np.linalg.norm(W[:3, 3] - Ta[:3, 3]))
        a = float(np.linalg.norm(rotvec(W[:3, :3] @ Ta[:3, :3].T)))
        m = int(math.ceil(max(d / step, a / step_rot) - 1e-9))
        if m == 0:
            continue
        out.extend(_segment(Ta, W, m))
    return np.array(out)


def displaced(T0: np.ndarray, dp, drot=(0.0, 0.0, 0.0)) -> np.ndarray:
    """T0 moved by dp (m, root axes) and rotated by the rotation vector drot (rad, root axes)."""
    T = np.array(T0, dtype=float)
    drot = np.asarray(drot, dtype=float)
    a = float(np.linalg.norm(drot))
    if a > 0:
        T[:3, :3] = rotation(drot / a, a) @ T[:3, :3]
    T[:3, 3] = T[:3, 3] + np.asarray(dp, dtype=float)
    return T


def _curve(T0, dt, duration, pos, vel, tilt):
    """Sample a curve: pos(t), vel(t) (root axes), tilt(t) -> (R_rel(t), omega_rel(t)) in T0's axes."""
    K = int(round(duration / dt))
    t = np.arange(K) * dt
    R0 = T0[:3, :3]
    T = np.broadcast_to(np.eye(4), (K, 4, 4)).copy()
    V = np.zeros((K, 6))
    for k, tk in enumerate(t):
        Rr, wr = tilt(tk)
        T[k, :3, :3] = R0 @ Rr
        T[k, :3, 3] = pos(tk)
        V[k, :3] = R0 @ wr
        V[k, 3:] = vel(tk)
    return T, V


def circle(T0: np.ndarray, radius: float, period: float, dt: float, duration: float,
           plane: tuple = ((1, 0, 0), (0, 1, 0)), tilt: float = 0.2,
           axis=(1.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """A circle through T0's origin (which it starts from) in the plane (e1, e2) (root axes), with
    the orientation rocking about ``axis`` (T0's axes) by ``tilt * sin(2 pi t / period)``.
    Returns T (K,4,4) and the exact twists V (K,6) (omega; v), root basis, v of the tool origin."""
    e1, e2 = (np.asarray(e, dtype=float) / np.linalg.norm(e) for e in plane)
    W = 2 * math.pi / period
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    c = T0[:3, 3] - radius * e1
    return _curve(T0, dt, duration,
                  lambda t: c + radius * (math.cos(W * t) * e1 + math.sin(W * t) * e2),
                  lambda t: radius * W * (-math.sin(W * t) * e1 + math.cos(W * t) * e2),
                  lambda t: (rotation(a, tilt * math.sin(W * t)), a * tilt * W * math.cos(W * t)))


def figure8(T0: np.ndarray, size: float, period: float, dt: float, duration: float,
            plane: tuple = ((1, 0, 0), (0, 1, 0)), tilt: float = 0.2,
            axes=((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))) -> tuple[np.ndarray, np.ndarray]:
    """A figure-eight (Gerono lemniscate p = T0 + size (sin Wt e1 + sin 2Wt / 2 e2)) through T0's
    origin, with the orientation turning about two axes (T0's axes):
    ``R = exp(tilt sin Wt a1) exp(tilt sin 2Wt a2)``.  Returns T and the exact twists V."""
    e1, e2 = (np.asarray(e, dtype=float) / np.linalg.norm(e) for e in plane)
    W = 2 * math.pi / period
    a1, a2 = (np.asarray(x, dtype=float) / np.linalg.norm(x) for x in axes)
    p0 = T0[:3, 3].copy()

    def tilt_fn(t):
        th1, th2 = tilt * math.sin(W * t), tilt * math.sin(2 * W * t)
        d1, d2 = tilt * W * math.cos(W * t), 2 * tilt * W * math.cos(2 * W * t)
        R1 = rotation(a1, th1)
        return R1 @ rotation(a2, th2), a1 * d1 + R1 @ a2 * d2

    return _curve(T0, dt, duration,
                  lambda t: p0 + size * (math.sin(W * t) * e1 + 0.5 * math.sin(2 * W * t) * e2),
                  lambda t: size * W * (math.cos(W * t) * e1 + math.cos(2 * W * t) * e2),
                  tilt_fn)


# ---- point arrays ------------------------------------------------------------------------------------

@dataclass
class PointArray:
    q: np.ndarray          # (M, n) joint values, q[0] = q0
    T: np.ndarray          # (M, 4, 4) the samples
    pos_err: np.ndarray    # (M,) float check of q against T (m)
    rot_err: np.ndarray    # (M,) rad
    ticks: np.ndarray      # (M,) servo ticks spent on each sample
    converged: np.ndarray  # (M,) the core's own error within tolerance
    flags: np.ndarray      # (M,) status bits raised while reaching each sample

    def as_dict(self) -> dict:
        return dict(q=self.q, T=self.T, pos_err=self.pos_err, rot_err=self.rot_err, ticks=self.ticks,
                    converged=self.converged, flags=self.flags)


def transition_twist(Ta: np.ndarray, Tb: np.ndarray, dt: float) -> np.ndarray:
    """(omega; v), root basis: the constant twist that carries Ta onto Tb in dt (v of the origin)."""
    V = np.empty(6)
    V[:3] = rotvec(Tb[:3, :3] @ Ta[:3, :3].T) / dt
    V[3:] = (Tb[:3, 3] - Ta[:3, 3]) / dt
    return V


def point_array(chain: Chain, T: np.ndarray, q0: np.ndarray, *, model: str = "fixed", config: str = "default",
                tol_pos: float = 1e-6, tol_rot: float = 1e-5, iters: int = 50, kdt: float = 1.0,
                sweeps: int = 10, mu: float = 1.5, L: float = 0.5, mode: str = "A", tick=None) -> PointArray:
    """Joint values for every sample of T (see the module doc).  ``tick``: a ready tick-callable
    (its q_next is used); otherwise one is made from ``model``/``config`` and the parameters."""
    dt = VIRTUAL_DT
    if tick is None:
        tick = make_tick(model, chain, config=config, dt=dt, kp=kdt / dt, ko=kdt / dt, klim=0.5 / dt,
                         sweeps=sweeps, mu=mu, L=L, mode=mode, vlimits=False)
    T = np.asarray(T, dtype=float)
    M, n = T.shape[0], chain.n
    q = np.empty((M, n))
    ticks = np.zeros(M, dtype=np.int32)
    conv = np.zeros(M, dtype=bool)
    flags = np.zeros(M, dtype=np.uint32)
    zero6, zero_n = np.zeros(6), np.zeros(n)

    def refine(qc, U, m):
        for _ in range(iters + 1):
            o = tick(qc, U, zero6, zero_n)
            flags[m] |= np.uint32(o.flags)
            if np.linalg.norm(o.ep) <= tol_pos and np.linalg.norm(o.eo) <= tol_rot:
                conv[m] = True
                return qc
            if ticks[m] >= iters:
                return qc
            qc = np.array(o.q_next)
            ticks[m] += 1
        return qc

    q[0] = refine(np.asarray(q0, dtype=float), T[0], 0)
    for m in range(M - 1):
        o = tick(q[m], T[m], transition_twist(T[m], T[m + 1], dt), zero_n)
        flags[m + 1] |= np.uint32(o.flags)
        ticks[m + 1] = 1
        q[m + 1] = refine(np.array(o.q_next), T[m + 1], m + 1)
    pe, re = pose_errors(chain, q, T)
    return PointArray(q, T, pe, re, ticks, conv, flags)
