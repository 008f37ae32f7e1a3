"""Inverse kinematics by the servo in virtual mode (docs/ik.md).

    res = solve(chain, targets, q0, model="fixed", config="default", solver="cd")
    res.q (N, n)  res.ok (N,)  res.ticks (N,)  res.pos_err (N,)  res.rot_err (N,)

Each target (a 4x4 pose of the tool in the root frame) is approached by servo ticks in *virtual
mode*: the tick's joint-rate command q' is integrated into the model's own joint values,
``q <- q + q' dt``, with the setpoint fixed at the target (U' = 0), until the model's own error test
passes (position and orientation error components within an internal tolerance) or the tick budget
is spent.  ``solver="cd"`` runs the bit-accurate C++ servo (``servo.hpp``: the servo law and the
division-free coordinate-descent solver) in the ``double`` configuration (``model="float"``) or in
a fixed-point configuration (``model="fixed"``); ``"pinv"`` and ``"dls"`` are double-precision
references that replace the coordinate descent by the active-set pseudo-inverse or damped least
squares on the same weighted problem and the same box (``pinv.hpp`` semantics, numpy here).

Joint limits in virtual mode (``limits=``):

``"clip"``  the core's tracking rule: q' is boxed so that no tick commands past a limit.
``"wrap"``  revolute joints whose range spans a full turn (``upper - lower >= 2 pi / |scale|``) are
            searched without limits and wrapped after every tick into a one-turn window centred on
            their range (the same pose; always within the limits); the other joints are clipped.
``"free"``  (default) every revolute joint is searched without limits, wrapped into the one-turn
            window centred on its range (which then contains the range).  When the model's test
            passes with a joint outside its range, the joints are clamped into the limits and the
            search continues with the core's rule ("clip") from there.  Prismatic joints are always
            clipped.

Per target, the search is a small state machine around the tick (docs/ik.md, "How a target is
solved"): after ``polish_after`` ticks of an attempt the solver switches to more sweeps and a
higher relaxation (ill-conditioned targets converge slowly); every ``stall_window`` ticks the
model's own error must have fallen by 5 % or the attempt ends (a local minimum); ``restarts=R``
adds up to R further attempts from pseudo-random configurations (uniform within the limits,
reproducible from ``seed`` and the target index; each at most ``attempt_ticks`` ticks), and
``max_ticks`` bounds the ticks of all attempts of one target together.  A target that is not
reached gets the attempt whose answer has the smallest error by the model's own FK.

Whatever happens, every returned configuration lies within the joint limits (a revolute joint is
returned as the whole-turn representative closest to the caller's seed), and ``ok`` is computed
independently of the model: the tool pose of the returned q by the float reference
(``reference.py``), position error ``|p - p_target|`` (m) and orientation error
``angle(R_target^T R)`` (rad) against ``tol_pos``, ``tol_rot``.  The internal (model) tolerance is
``margin`` times the requested one on each error component (for fixed point never below half an
LSB of the error formats, i.e. a reading of zero passes), which leaves room for the 2-norm over
three components (sqrt 3) and the fixed-point model's own FK error (~0.5 um in default).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from . import _model, reference
from .chain import Chain, Limits, matrix_to_quat
from .errors import InputError

MODELS = ("float", "fixed")
SOLVERS = ("cd", "pinv", "dls")
LIMITS = ("free", "wrap", "clip")
#: a target's rotation block R must satisfy max|R^T R - I| <= RIGID_TOL and det R > 0
RIGID_TOL = 1e-6
#: most conjugate-direction steps per tick (solver.hpp CG_MAX)
CG_MAX = 64


@dataclass
class IKParams:
    """Parameters of the virtual-mode search (defaults: docs/ik.md, "Parameters")."""

    dt: float = 1.0 / 20        # virtual tick period (s); the gains below are per dt
    kdt: float = 1.0            # K dt: servo gains kp = ko = kdt / dt (1 = a full step)
    klim_dt: float = 1.0        # klim dt: limit-approach gain (1 = may reach the limit in one tick)
    L: float = 0.25             # characteristic length of the weighted problem (m/rad)
    sweeps: int = 30            # coordinate-descent sweeps per tick
    mu: float = 1.6             # relaxation of the coordinate descent (0 < mu < 2)
    margin: float = 0.25        # internal tolerance = margin x requested tolerance (per component)
    lsb_floor: float = 0.5      # fixed point: internal tolerance >= this many LSBs of the error formats
                                # (0.5: an error that reads zero passes)
    restarts: int = 0           # further attempts from pseudo-random configurations
    attempt_ticks: int = 100    # ticks per restart attempt (the first attempt, from the given seed,
                                # is only ended by the stall test or the budget)
    seed: int = 0               # restarts' pseudo-random configurations
    clip_from_seed: bool = True  # "free": the clip phase starts again from the attempt's seed
    polish_after: int | None = 50  # cd: after this many ticks of an attempt switch to ...
    polish_mu: float | None = None  # ... this relaxation (None: 1.9 for n <= 6 joints, else mu) ...
    polish_sweeps: int = 60     # ... and this many sweeps (ill-conditioned targets converge slowly) ...
    polish_cg: int | None = None  # ... followed by this many conjugate-direction steps (solver.hpp
                                  # solver_cg; None: 2 n (at most CG_MAX), 0: none) ...
    cg_below: float = 0.1       # ... once the model's error max(|e_p|, L |e_o|) is below this (m)
    cg: int = 0                 # conjugate-direction steps after the sweeps before the polish
    stall_window: int | None = 100  # every this many ticks of an attempt ...
    stall_ratio: float = 0.95   # ... the model's error must have fallen below this fraction of
                                # its value at the previous test, or the attempt ends ...
    stall_min_err: float = 1e-4  # ... unless it is already below this (m; max(|e_p|, L |e_o|)) and
                                 # above 10 LSB of the position error format (fixed point)
    lambda_max: float = 0.05    # dls: maximum damping (units of the weighted Jacobian)
    dls_eps: float = 0.05       # dls: damping starts below this smallest singular value


@dataclass
class IKResult:
    q: np.ndarray               # (N, n) within the joint limits
    ok: np.ndarray              # (N,) float errors within tolerance (and q within limits)
    ticks: np.ndarray           # (N,) ticks (moves) spent, all attempts
    pos_err: np.ndarray         # (N,) m, float reference
    rot_err: np.ndarray         # (N,) rad, float reference
    converged: np.ndarray       # (N,) the model's own test passed (within limits)
    attempts: np.ndarray        # (N,) attempts used (1 + restarts taken)
    polish_ticks: np.ndarray | None = None  # (N,) of ticks, those made by the polish engine


# ---- input checks ------------------------------------------------------------------------------

def check_targets(T: np.ndarray, name: str = "--targets") -> np.ndarray:
    """(N, 4, 4) finite rigid transforms (a single (4, 4) is taken as N = 1)."""
    T = np.asarray(T, dtype=np.float64)
    if T.ndim == 2 and T.shape == (4, 4):
        T = T[None]
    if T.ndim != 3 or T.shape[1:] != (4, 4) or T.shape[0] < 1:
        raise InputError(name, f"shape {tuple(T.shape)} does not match (N, 4, 4) with N >= 1")
    bad = ~np.isfinite(T)
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        raise InputError(name, f"non-finite value at index {idx}")
    last = np.abs(T[:, 3, :] - np.array([0.0, 0.0, 0.0, 1.0])).max(axis=1)
    if (last > RIGID_TOL).any():
        s = int(np.argmax(last > RIGID_TOL))
        raise InputError(name, f"target {s}: last row is not [0, 0, 0, 1]")
    R = T[:, :3, :3]
    orth = np.abs(np.einsum("nji,njk->nik", R, R) - np.eye(3)).max(axis=(1, 2))
    det = np.linalg.det(R)
    badr = (orth > RIGID_TOL) | (det <= 0)
    if badr.any():
        s = int(np.argmax(badr))
        what = f"max|R^T R - I| = {orth[s]:.3g}" if orth[s] > RIGID_TOL else f"det R = {det[s]:.3g}"
        raise InputError(name, f"target {s}: not a rigid transform ({what}, tolerance {RIGID_TOL:g})")
    return T


def check_q0(chain: Chain, q0: np.ndarray, N: int, name: str = "--q0") -> np.ndarray:
    """(n,) (same seed for every target) or (N, n) finite seeds -> (N, n)."""
    q0 = np.asarray(q0, dtype=np.float64)
    n = chain.n
    if q0.ndim == 1 and q0.shape[0] == n:
        q0 = np.broadcast_to(q0, (N, n))
    if q0.ndim != 2 or q0.shape != (N, n):
        raise InputError(name, f"shape {tuple(q0.shape)} does not match ({n},) or ({N}, {n}) (N targets, n joints)")
    bad = ~np.isfinite(q0)
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        raise InputError(name, f"non-finite value at index {idx}")
    return np.array(q0, dtype=np.float64)


def _check_params(p: IKParams, max_ticks: int, tol_pos: float, tol_rot: float) -> None:
    def pos(x, what):
        if not (isinstance(x, (int, float)) and math.isfinite(x) and x > 0):
            raise InputError(what, f"must be a positive number (got {x!r})")
    pos(tol_pos, "--tol-pos"); pos(tol_rot, "--tol-rot")
    if not isinstance(max_ticks, (int, np.integer)) or max_ticks < 0:
        raise InputError("--max-ticks", f"must be a non-negative integer (got {max_ticks!r})")
    pos(p.cg_below, "cg_below")
    pos(p.dt, "dt"); pos(p.kdt, "kdt"); pos(p.klim_dt, "klim_dt"); pos(p.L, "L"); pos(p.margin, "margin")
    if p.dt >= 1.0 / 16:
        raise InputError("dt", "must be below 1/16 s")
    if not (0 < p.mu < 2):
        raise InputError("mu", "must lie in (0, 2)")
    if p.kdt >= 2 or p.klim_dt > 1:
        raise InputError("kdt", "K dt must be below 2 and klim dt at most 1")
    if not (isinstance(p.sweeps, (int, np.integer)) and 1 <= p.sweeps <= 1000):
        raise InputError("sweeps", "must be 1..1000")
    for name, v in (("cg", p.cg), ("polish_cg", 0 if p.polish_cg is None else p.polish_cg)):
        if not (isinstance(v, (int, np.integer)) and 0 <= v <= CG_MAX):
            raise InputError(name, f"must be 0..{CG_MAX} conjugate-direction steps (got {v!r})")
    if not (isinstance(p.restarts, (int, np.integer)) and p.restarts >= 0):
        raise InputError("--restarts", "must be a non-negative integer")
    if not (isinstance(p.attempt_ticks, (int, np.integer)) and p.attempt_ticks >= 1):
        raise InputError("attempt_ticks", "must be at least 1")


# ---- joint-space geometry: limits, turns, windows ------------------------------------------------

@dataclass
class _Geometry:
    lo: np.ndarray        # lower limits (-inf unlimited)
    hi: np.ndarray
    rev: np.ndarray       # revolute
    turn: np.ndarray      # 2 pi / |scale| for revolute joints, inf for prismatic
    full: np.ndarray      # revolute whose range spans a turn (or unlimited)
    wlo: np.ndarray       # lower end of the one-turn window of each revolute joint, centred on
                          # its range (which it contains, or lies in when the range spans a turn)

    @staticmethod
    def of(chain: Chain) -> "_Geometry":
        lo, hi = chain.lower, chain.upper
        rev = np.array([not j.prismatic for j in chain.joints])
        turn = np.where(rev, 2 * np.pi / np.abs(chain.scales), np.inf)
        unl = ~np.isfinite(lo)
        with np.errstate(invalid="ignore"):
            full = rev & (unl | (hi - lo >= turn))
            mid = np.where(unl, 0.0, 0.5 * (lo + hi))
            wlo = np.where(rev, mid - 0.5 * turn, 0.0)
        return _Geometry(lo, hi, rev, turn, full, wlo)

    def wrap(self, q: np.ndarray, mask: np.ndarray) -> np.ndarray:
        """Joints in ``mask`` (revolute) wrapped into their window [wlo, wlo + turn)."""
        if not mask.any():
            return q
        q = q.copy()
        w, t = self.wlo[mask], self.turn[mask]
        q[:, mask] = w + np.mod(q[:, mask] - w, t)
        return q

    def into_limits(self, q: np.ndarray) -> np.ndarray:
        """Every joint into its limits: a revolute joint outside its range is first wrapped into
        its window (same pose), then anything still outside is clamped (a different pose)."""
        out = ((q < self.lo) | (q > self.hi)) & self.rev
        if out.any():
            w = self.wrap(q, self.rev)
            q = np.where(out, w, q)
        return np.clip(q, self.lo, self.hi)

    def nearest_turn(self, q: np.ndarray, ref: np.ndarray) -> np.ndarray:
        """Each revolute joint moved by whole turns to the representative within its limits that is
        closest to ``ref`` (the caller's seed); the pose is unchanged."""
        q = q.copy()
        for i in np.nonzero(self.rev)[0]:
            t = self.turn[i]
            k = np.round((ref[:, i] - q[:, i]) / t)
            for cand in (k, k - 1, k + 1):
                c = q[:, i] + cand * t
                ok = (c >= self.lo[i]) & (c <= self.hi[i]) & (np.abs(c - ref[:, i]) < np.abs(q[:, i] - ref[:, i]))
                q[ok, i] = c[ok]
        return q


def wrap_into_limits(chain: Chain, q: np.ndarray) -> np.ndarray:
    """Revolute joints outside their range shifted by whole turns (2 pi / |scale|) into it where
    possible; the pose is unchanged and nothing is clamped (used to check other solvers' answers
    the same way as ours)."""
    g = _Geometry.of(chain)
    q = np.atleast_2d(np.asarray(q, dtype=np.float64))
    out = ((q < g.lo) | (q > g.hi)) & g.rev
    return np.where(out, g.wrap(q, g.rev), q) if out.any() else q.copy()


def _search_chain(chain: Chain, free: np.ndarray) -> Chain:
    """The chain with the position limits of the ``free`` joints removed (search without limits)."""
    joints = [dataclasses.replace(j, limits=Limits(None, None, j.limits.velocity)) if f else j
              for j, f in zip(chain.joints, free)]
    return dataclasses.replace(chain, joints=joints)


# ---- engines: one virtual tick for a batch of problems --------------------------------------------

class _CDEngine:
    """The C++ servo (``servo.hpp``) through its IK loop, one tick per call (warm start off)."""

    def __init__(self, chain: Chain, config: str, p: IKParams):
        from .servo import Servo

        K = p.kdt / p.dt
        self.servo = Servo(chain, config, dt=p.dt, L=p.L, kp=K, ko=K, klim=p.klim_dt / p.dt,
                           sweeps=int(p.sweeps), mu=float(p.mu), vlimits=False, cg=int(p.cg))

    def step(self, q, quat, pos, tp, tr):
        """(q_next, moved (0/1), converged after the move): the model's test is done before the
        move (converged: no move) and after it."""
        r = self.servo._s.ik(np.ascontiguousarray(q), quat, pos, 1, tp, tr)
        return np.asarray(r["q"], dtype=np.float64), np.asarray(r["ticks"]), np.asarray(r["converged"], dtype=bool)


class _RefEngine:
    """Double-precision reference tick: FK and Jacobian of the C++ double model, the servo law of
    ``servo.hpp`` (error choice A, U' = 0), the weighted problem min |V - J q'|_W with
    W = diag(L^2 I3, I3) on the box of ``solver.hpp`` (position-limit approach for limited joints;
    a cap of 1 rad per tick on every joint, as the fixed-point joint-rate format), solved by the
    active-set pseudo-inverse (``pinv``) or adaptive damped least squares (``dls``), then
    ``q <- q + q' dt`` clamped to the limits.  (``pinv.hpp`` holds the C++ version.)"""

    def __init__(self, chain: Chain, solver: str, p: IKParams):
        from .model import Model

        self.model = Model(chain, "double")
        self.solver, self.p = solver, p
        self.lo, self.hi = chain.lower, chain.upper
        self.limited = np.isfinite(self.lo)
        self.K = p.kdt / p.dt
        self.klim = p.klim_dt / p.dt
        self.vcap = 1.0 / p.dt

    def _errors(self, q, Rt, pt):
        jr = self.model.jacobian(q, ref="tool", basis="base")
        T = jr.T[:, -1]
        ep = pt - T[:, :3, 3]
        Re = np.einsum("nij,nkj->nik", Rt, T[:, :3, :3])      # R_U R_P^T
        eo = np.array([reference.rotvec(R) for R in Re])
        return ep, eo, jr.J

    def step(self, q, Rt, pt, tp, tr):
        n = q.shape[1]
        ep, eo, J = self._errors(q, Rt, pt)
        conv0 = (np.abs(ep).max(axis=1) <= tp) & (np.abs(eo).max(axis=1) <= tr)
        qn = q.copy()
        mv = np.nonzero(~conv0)[0]
        if len(mv):
            S = np.array([self.p.L] * 3 + [1.0] * 3)
            A = J[mv] * S[None, :, None]
            b = np.concatenate([self.K * eo[mv], self.K * ep[mv]], axis=1) * S[None, :]
            lower = np.full((len(mv), n), -self.vcap)
            upper = np.full((len(mv), n), self.vcap)
            lim = self.limited
            if lim.any():
                plo = self.klim * (self.lo[lim] - q[mv][:, lim])
                phi = self.klim * (self.hi[lim] - q[mv][:, lim])
                lower[:, lim] = np.minimum(np.maximum(lower[:, lim], plo), self.vcap)
                upper[:, lim] = np.maximum(np.minimum(upper[:, lim], phi), -self.vcap)
            for k, s in enumerate(mv):
                if self.solver == "pinv":
                    x = box_lsq(A[k], b[k], lower[k], upper[k])
                else:
                    x = dls_solve(A[k], b[k], lower[k], upper[k], self.p.lambda_max, self.p.dls_eps)
                qn[s] = q[s] + x * self.p.dt
            qn[:, lim] = np.clip(qn[:, lim], self.lo[lim], self.hi[lim])
            ep1, eo1, _ = self._errors(qn[mv], Rt[mv], pt[mv])
            conv = conv0.copy()
            conv[mv] = (np.abs(ep1).max(axis=1) <= tp) & (np.abs(eo1).max(axis=1) <= tr)
        else:
            conv = conv0
        return qn, (~conv0).astype(np.int64), conv


def _minnorm(A: np.ndarray, b: np.ndarray, rank_tol: float = 1e-10) -> np.ndarray:
    """Minimum-norm least-squares solution (relative rank tolerance on the singular values)."""
    if A.shape[1] == 0:
        return np.zeros(0)
    U, s, Vt = np.linalg.svd(A, full_matrices=False)
    keep = s > rank_tol * (s[0] if len(s) else 0.0)
    return Vt[keep].T @ ((U[:, keep].T @ b) / s[keep])


def box_lsq(A: np.ndarray, b: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """min 1/2 |b - A x|^2 s.t. lower <= x <= upper: the seed's coordinate exclusion done as an
    active set with re-admission (the C++ reference ``pinv.hpp`` box_lsq, Exclusion::ActiveSet)."""
    return np.asarray(_model.box_lsq(np.asarray(A, float), np.asarray(b, float), np.asarray(lower, float),
                                     np.asarray(upper, float))["qd"])


def dls_solve(A: np.ndarray, b: np.ndarray, lower: np.ndarray, upper: np.ndarray, lambda_max: float,
              eps: float) -> np.ndarray:
    """Damped least squares with adaptive damping (Nakamura-Hanafusa / Maciejewski-Klein):
    lambda^2 = lambda_max^2 (1 - (sigma_min / eps)^2) when sigma_min < eps, else 0, sigma_min the
    min(6, n)-th singular value of A (the C++ reference ``pinv.hpp`` dls_solve; A is already
    weighted, so L = 1 there)."""
    return np.asarray(_model.dls_solve(np.asarray(A, float), np.asarray(b, float), 1.0, float(lambda_max), float(eps),
                                       np.asarray(lower, float), np.asarray(upper, float))["qd"])


# ---- float errors (honest, independent of the model) -----------------------------------------------

def pose_errors(chain: Chain, q: np.ndarray, targets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position error |p - p_t| (m) and orientation error angle(R_t^T R) (rad) of the tool pose of
    each q (float reference) against each target."""
    n = chain.n
    pe = np.empty(len(q))
    re = np.empty(len(q))
    for s, (qs, T) in enumerate(zip(q, targets)):
        P = reference.fk_frames(chain, qs)[n + 1]
        pe[s] = float(np.linalg.norm(P[:3, 3] - T[:3, 3]))
        re[s] = float(np.linalg.norm(reference.rotvec(T[:3, :3].T @ P[:3, :3])))
    return pe, re


# ---- the search ------------------------------------------------------------------------------------

def _internal_tol(config: str, tol_pos: float, tol_rot: float, margin: float, floor: float = 0.5) -> tuple[float, float]:
    tp, tr = margin * tol_pos, margin * tol_rot
    if config != "double":
        tp, tr = max(tp, floor * _lsb(config, "perr_t")), max(tr, floor * _lsb(config, "rot_t"))
    return tp, tr


def _lsb(config: str, name: str) -> float:
    """Weight of the last bit of a format of a fixed-point configuration."""
    from .model import formats

    W, I = formats(config)[name]
    return 2.0 ** -(W - I)


def solve(chain: Chain, targets: np.ndarray, q0: np.ndarray, *, model: str = "fixed", config: str = "default",
          solver: str = "cd", limits: str = "free", max_ticks: int = 1000, tol_pos: float = 1e-6,
          tol_rot: float = 1e-5, params: IKParams | None = None, **overrides) -> IKResult:
    """Virtual-mode IK of every target from its seed; see the module docstring."""
    if model not in MODELS:
        raise InputError("--model", f"must be one of {', '.join(MODELS)} (got {model!r})")
    if solver not in SOLVERS:
        raise InputError("--solver", f"must be one of {', '.join(SOLVERS)} (got {solver!r})")
    if limits not in LIMITS:
        raise InputError("--limits", f"must be one of {', '.join(LIMITS)} (got {limits!r})")
    if not getattr(chain, "is_serial", True):
        raise InputError("chain", "ik needs a serial chain (one tool)")
    p = dataclasses.replace(params or IKParams(), **overrides)
    _check_params(p, max_ticks, tol_pos, tol_rot)
    T = check_targets(targets)
    N, n = len(T), chain.n
    q = check_q0(chain, q0, N)
    cfg = "double" if (model == "float" or solver != "cd") else config
    if solver != "cd" and model == "fixed":
        raise InputError("--solver", f"{solver} is a double-precision reference: use --model float")
    g = _Geometry.of(chain)
    tp, tr = _internal_tol(cfg, tol_pos, tol_rot, p.margin, p.lsb_floor)

    # Engines: the search (strategy) and the core's rule ("clip"); unlimited joints never clip.
    unl = ~np.isfinite(g.lo)
    free = {"clip": unl, "wrap": g.full, "free": g.rev | unl}[limits]
    clip_free = unl

    def engine(free_mask, pp):
        ch = _search_chain(chain, free_mask) if free_mask.any() else chain
        if solver == "cd":
            return _CDEngine(ch, cfg, pp)
        return _RefEngine(ch, solver, pp)

    same = not (free & ~clip_free).any()
    eng_search = engine(free, p)
    eng_clip = eng_search if same else engine(clip_free, p)
    polish = solver == "cd" and p.polish_after is not None
    if polish:
        pp = polish_params(p, n)
        pn = dataclasses.replace(pp, cg=0)
        pol_search = engine(free, pn)
        pol_clip = pol_search if same else engine(clip_free, pn)
        if pp.cg:
            cg_search = engine(free, pp)
            cg_clip = cg_search if same else engine(clip_free, pp)
    if solver == "cd":
        tq = np.array([matrix_to_quat(t[:3, :3]) for t in T])
    else:
        tq = np.ascontiguousarray(T[:, :3, :3])
    tpos = np.ascontiguousarray(T[:, :3, 3])

    merr = _ModelError(chain, cfg, T, p.L)
    # a slow but close attempt goes on, unless the model's error is at its resolution (dithering)
    floor_e = 0.0 if cfg == "double" else 10 * _lsb(cfg, "perr_t")
    # Seeds into the limits (windows for revolute joints, clamp otherwise).
    q_user = np.clip(q, g.lo, g.hi)
    q = g.wrap(q_user, free)
    seed_q = q.copy()                        # each attempt's seed (the clip phase may restart there)
    SEARCH, CLIP, DONE, FAILED = 0, 1, 2, 3
    phase = np.full(N, SEARCH)
    ticks = np.zeros(N, dtype=np.int64)      # all moves
    pticks = np.zeros(N, dtype=np.int64)     # moves made by the polish engines
    att_ticks = np.zeros(N, dtype=np.int64)
    attempts = np.ones(N, dtype=np.int64)
    conv = np.zeros(N, dtype=bool)
    best_q = np.full((N, n), np.nan)
    best_e = np.full(N, np.inf)
    W = p.stall_window or 0
    next_check = np.full(N, W, dtype=np.int64)
    ref_e = np.full(N, np.inf)

    def end_attempt(idx):
        """Attempt over without convergence: keep its answer (within limits) if it is the best so
        far by the model's own error, then restart or fail."""
        if not len(idx):
            return
        qi = g.into_limits(q[idx])
        e = merr(qi, idx)
        better = e < best_e[idx]
        best_q[idx[better]], best_e[idx[better]] = qi[better], e[better]
        again = idx[(attempts[idx] <= p.restarts) & (ticks[idx] < max_ticks)]
        for s in again:
            rng = np.random.default_rng([p.seed, int(s), int(attempts[s])])
            q[s] = g.wrap(chain.random_q(rng)[None], free)[0]
            seed_q[s] = q[s]
        attempts[again] += 1
        att_ticks[again] = 0
        next_check[again] = W
        ref_e[again] = np.inf
        phase[again] = SEARCH
        phase[np.setdiff1d(idx, again)] = FAILED

    # engines: (phase, engine, free joints, polish, conjugate-direction refinement)
    groups = [(SEARCH, eng_search, free, False, False), (CLIP, eng_clip, clip_free, False, False)]
    use_cg = polish and pp.cg > 0
    if polish:
        groups += [(SEARCH, pol_search, free, True, False), (CLIP, pol_clip, clip_free, True, False)]
    if use_cg:
        groups += [(SEARCH, cg_search, free, True, True), (CLIP, cg_clip, clip_free, True, True)]
    near = np.zeros(N, dtype=bool)           # polish: close enough for the refinement
    for _ in range(max_ticks + 1):
        if use_cg:
            pidx = np.nonzero((phase <= CLIP) & (att_ticks >= p.polish_after))[0]
            if len(pidx):
                near[pidx] = merr(q[pidx], pidx) < p.cg_below
        for ph, eng, mask, pol, cg in groups:
            idx = np.nonzero(phase == ph)[0]
            if polish:
                idx = idx[(att_ticks[idx] >= p.polish_after) == pol]
            if use_cg and pol:
                idx = idx[near[idx] == cg]
            if not len(idx):
                continue
            qn, mv, c = eng.step(q[idx], tq[idx], tpos[idx], tp, tr)
            # out of budget (max_ticks = 0): the test only, no move
            cut = (mv > 0) & (ticks[idx] >= max_ticks)
            mv = np.where(cut, 0, mv)
            qn = np.where(cut[:, None], q[idx], qn)
            c = c & ~cut
            q[idx] = g.wrap(qn, mask)
            ticks[idx] += mv
            att_ticks[idx] += mv
            if pol:
                pticks[idx] += mv
            cidx = idx[c]
            if len(cidx):
                inside = np.all((q[cidx] >= g.lo) & (q[cidx] <= g.hi), axis=1)
                ok_idx = cidx[inside]
                phase[ok_idx], conv[ok_idx] = DONE, True
                out = cidx[~inside]
                if len(out):
                    q[out] = np.clip(seed_q[out] if p.clip_from_seed else q[out], g.lo, g.hi)
                    if ph == SEARCH and eng_clip is not eng_search:
                        phase[out] = CLIP
                        ref_e[out] = np.inf
                        next_check[out] = att_ticks[out] + W
                    else:
                        end_attempt(out)
            rest = idx[(phase[idx] == ph) & (((attempts[idx] > 1) & (att_ticks[idx] >= p.attempt_ticks)) | (ticks[idx] >= max_ticks))]
            end_attempt(rest)
        # Stall test every W ticks of an attempt: the model's error must have dropped by 5 %
        # (a slow but close attempt, below stall_min_err, goes on).
        if W:
            chk = np.nonzero((phase <= CLIP) & (att_ticks >= next_check))[0]
            if len(chk):
                e = merr(q[chk], chk)
                close = (e < p.stall_min_err) & (e > floor_e)
                stalled = (e > p.stall_ratio * ref_e[chk]) & ~close
                ref_e[chk] = e
                next_check[chk] = att_ticks[chk] + W
                end_attempt(chk[stalled])
        if not np.any(phase <= CLIP):
            break
    end_attempt(np.nonzero(phase <= CLIP)[0])

    qout = g.into_limits(q)
    failed = ~conv
    qout[failed] = np.where(np.isfinite(best_q[failed]), best_q[failed], qout[failed])
    qout = g.nearest_turn(qout, q_user)
    pe, re = pose_errors(chain, qout, T)
    inside = np.all((qout >= g.lo) & (qout <= g.hi), axis=1)
    ok = (pe <= tol_pos) & (re <= tol_rot) & inside
    return IKResult(qout, ok, ticks, pe, re, conv, attempts, pticks)


def polish_params(p: IKParams, n: int) -> IKParams:
    """The parameters of the polish engine (after ``polish_after`` ticks of an attempt)."""
    mu = p.polish_mu if p.polish_mu is not None else (1.9 if n <= 6 else p.mu)
    cg = p.polish_cg if p.polish_cg is not None else min(2 * n, CG_MAX)
    return dataclasses.replace(p, mu=mu, sweeps=p.polish_sweeps, cg=cg)


class _ModelError:
    """max(|e_p|, L |e_o|) of configurations by the model's own FK (the number type searched in):
    the stall test and the choice of the best failed attempt."""

    def __init__(self, chain: Chain, config: str, T: np.ndarray, L: float):
        from .model import Model

        self.model, self.T, self.L, self.k = Model(chain, config), T, L, chain.n + 1

    def __call__(self, q: np.ndarray, idx: np.ndarray) -> np.ndarray:
        P = self.model.fk(q).T[:, self.k]
        T = self.T[idx]
        ep = np.linalg.norm(P[:, :3, 3] - T[:, :3, 3], axis=1)
        Rr = np.einsum("nji,njk->nik", T[:, :3, :3], P[:, :3, :3])
        c = np.clip(0.5 * (np.trace(Rr, axis1=1, axis2=2) - 1.0), -1.0, 1.0)
        return np.maximum(ep, self.L * np.arccos(c))
