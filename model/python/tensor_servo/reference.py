"""Float reference (float64, numpy): forward kinematics, the Jacobian by screw transport, and the
forward velocity problem, written the way N. F. Sorokin's "tensor tracking system" (2017, seed 000)
builds them.  Equation numbers (eq. N) refer to the seed; [FIX] refers to the corrections in the
seed digest (``seed-000-002-digest.md``, part (a), in the shared docs).  This module is the readable
specification that the fixed-point model is compared with; it depends only on numpy and
:mod:`tensor_servo.chain`.

Conventions (the same everywhere in tensor-servo)
-------------------------------------------------

* Chain: ``T(q) = base * prod_i (origin_i * M_i(q_i)) * tool``.  ``M_i`` rotates by ``s_i q_i``
  about the unit ``axis_i`` (revolute) or translates by ``s_i q_i axis_i`` (prismatic); the axis is
  expressed in joint frame i and ``s_i = joint.scale``.
* Frame indices: 0 = base frame (pose ``base`` in the root frame), i = 1..n = frame of joint i
  *after* its motion, n+1 = tool.  ``fk_frames`` returns ``^rootT_k`` for k = 0..n+1.
* Poses are 4x4 homogeneous matrices; ``^aT_b`` (pose of frame b seen from frame a) maps
  b-coordinates to a-coordinates.  The seed's ``H_a^b`` (eq. 1, [FIX]) is ``^aT_b``.
* Twists are (omega; v), angular first (eqs. 3, 12-18); v is the velocity of the *reference point*,
  which is always the origin of a frame, never the root origin (no "space" Jacobian).
* A *basis* is only a set of axes.  ``basis="base"`` means the root frame's axes (Pinocchio's
  LOCAL_WORLD_ALIGNED), ``"tool"`` the tool frame's axes (LOCAL for the tool), an int k the axes
  of frame k (0..n+1).  Note that ``basis=0`` (the base frame) differs from ``"base"`` (the root
  frame) when ``chain.base`` has a rotation.
"""
from __future__ import annotations

import math

import numpy as np

from .chain import Chain, Joint

__all__ = [
    "skew", "vee", "rotation", "rotvec", "pose_inv", "adjoint",
    "joint_motion", "fk_frames", "fk_frames_before",
    "joint_twist", "transport", "frame_index", "jacobian", "frame_twists",
]


# ---- small SO(3)/SE(3) helpers ----------------------------------------------------------------

def skew(v: np.ndarray) -> np.ndarray:
    """[v]x: the 3x3 matrix with ``skew(v) @ u == cross(v, u)``."""
    x, y, z = v
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def vee(S: np.ndarray) -> np.ndarray:
    """Inverse of :func:`skew` applied to the skew-symmetric part of S: ``vee(skew(v)) == v``."""
    return 0.5 * np.array([S[2, 1] - S[1, 2], S[0, 2] - S[2, 0], S[1, 0] - S[0, 1]])


def rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation matrix by ``angle`` (rad) about the unit ``axis`` (Rodrigues' formula)."""
    K = skew(np.asarray(axis, dtype=float))
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * (K @ K)


def rotvec(R: np.ndarray) -> np.ndarray:
    """Rotation vector (SO(3) logarithm) of R: ``rotation(w/|w|, |w|) == R`` with |w| in [0, pi].

    The "rotation vector rho" of the seed's position 6-vector (r, rho) (section 3).  Accurate near
    0 (series) and near pi (axis from the symmetric part, sign from the skew part).
    """
    R = np.asarray(R, dtype=float)
    s = vee(R)                                    # sin(theta) * a
    c = 0.5 * (np.trace(R) - 1.0)                 # cos(theta)
    sin_t = float(np.linalg.norm(s))
    theta = math.atan2(sin_t, c)
    if theta < 1e-4:
        return s * (1.0 + theta * theta / 6.0)    # theta / sin(theta) to O(theta^4)
    if theta < math.pi - 1e-2:
        return s * (theta / sin_t)
    # near pi: (R + R^T)/2 = cos(theta) I + (1 - cos(theta)) a a^T
    A = (0.5 * (R + R.T) - c * np.eye(3)) / (1.0 - c)
    k = int(np.argmax(np.diag(A)))
    a = A[:, k] / math.sqrt(A[k, k])
    if float(a @ s) < 0.0:
        a = -a
    return theta * a / np.linalg.norm(a)


def pose_inv(T: np.ndarray) -> np.ndarray:
    """Inverse of a rigid transform: ``(R, p)^-1 = (R^T, -R^T p)``."""
    R, p = T[:3, :3], T[:3, 3]
    Ti = np.eye(4)
    Ti[:3, :3] = R.T
    Ti[:3, 3] = -R.T @ p
    return Ti


def adjoint(T: np.ndarray) -> np.ndarray:
    """Adjoint map of ``T = ^aT_b = (R, p)`` for (omega; v) twists ([FIX] after eq. 21).

    ``Ad_T = [[R, 0], [[p]x R, R]]`` maps a twist of a body referenced at origin b in basis b to the
    same motion referenced at origin a in basis a.  Only used by the tests and as documentation: the
    Jacobian below is built the seed's way, by transport then rotation.
    """
    R, p = T[:3, :3], T[:3, 3]
    A = np.zeros((6, 6))
    A[:3, :3] = R
    A[3:, 3:] = R
    A[3:, :3] = skew(p) @ R
    return A


def _rot6(R: np.ndarray) -> np.ndarray:
    """blockdiag(R, R): changes the basis of a 6-vector (the seed's H acting on vectors, eq. 13)."""
    B = np.zeros((6, 6))
    B[:3, :3] = R
    B[3:, 3:] = R
    return B


# ---- forward kinematics ------------------------------------------------------------------------

def joint_motion(joint: Joint, q: float) -> np.ndarray:
    """``M_i(q_i)``: the joint's own motion, 4x4 in joint frame i (before motion)."""
    a = np.asarray(joint.axis, dtype=float)
    M = np.eye(4)
    if joint.prismatic:
        M[:3, 3] = joint.scale * q * a
    else:
        M[:3, :3] = rotation(a, joint.scale * q)
    return M


def _check_q(chain: Chain, q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.shape != (chain.n,):
        raise ValueError(f"q has shape {q.shape}, expected ({chain.n},)")
    return q


def _parents(chain: Chain) -> list[int]:
    """Parent frame of every frame 1..n+ntips (index 0 unused): serial chain k -> k-1."""
    tips = chain.tip_list()
    idx = {j.name: i for i, j in enumerate(chain.joints)}
    return [0] + chain.parent_frames() + [idx[t.parent] + 1 for t in tips]


def fk_frames(chain: Chain, q: np.ndarray) -> np.ndarray:
    """(n+1+ntips, 4, 4): ``^rootT_k`` for k = 0 (base), 1..n (joint frames after motion), then the
    tips (a serial chain has one, the tool: n+1).

    The seed's absolute poses ``P_k^(0)`` (eq. 1): ``T_0 = base``,
    ``T_i = T_{parent(i)} origin_i M_i(q_i)`` (serial: parent(i) = i-1), ``T_tip = T_parent tip``.
    """
    q = _check_q(chain, q)
    tips = chain.tip_list()
    par = _parents(chain)
    T = np.empty((chain.n + 1 + len(tips), 4, 4))
    T[0] = chain.base.matrix()
    for i, (joint, qi) in enumerate(zip(chain.joints, q), start=1):
        T[i] = T[par[i]] @ joint.origin.matrix() @ joint_motion(joint, qi)
    for t, tip in enumerate(tips):
        T[chain.n + 1 + t] = T[par[chain.n + 1 + t]] @ tip.pose.matrix()
    return T


def moving_joints(chain: Chain, k: int) -> set[int]:
    """Joints (1-based) that move frame k: its ancestors (serial chain: 1..min(k, n))."""
    par = _parents(chain)
    out = set()
    while k >= 1:
        if k <= chain.n:
            out.add(k)
        k = par[k]
    return out


def fk_frames_before(chain: Chain, q: np.ndarray) -> np.ndarray:
    """(n, 4, 4): joint frames *before* their own motion, ``T_{i-1} origin_i`` for i = 1..n.

    Entry i-1 is joint i's frame with ``M_i`` not yet applied.  The joint axis has the same
    direction in both frames (M_i fixes it); for a revolute joint the origins coincide too.
    """
    T = fk_frames(chain, q)
    return np.array([T[i - 1] @ j.origin.matrix() for i, j in enumerate(chain.joints, start=1)])


# ---- the seed's building blocks ------------------------------------------------------------------

def joint_twist(joint: Joint) -> np.ndarray:
    """``W_i`` (eq. 14): the twist of joint frame i per unit joint rate, in basis i, at origin i.

    Revolute (eq. 15): ``(s a; 0)``; prismatic (eq. 16): ``(0; s a)``; ``s = joint.scale``.  It is a
    constant: M_i leaves the axis fixed, and the origin of frame i lies on a revolute joint's axis.
    """
    W = np.zeros(6)
    sa = joint.scale * np.asarray(joint.axis, dtype=float)
    if joint.prismatic:
        W[3:] = sa
    else:
        W[:3] = sa
    return W


def transport(r: np.ndarray) -> np.ndarray:
    """``R_i^j`` (eq. 18 with the [FIX]): move the point of application of a twist by r.

    ``R(r) @ [omega; v] == [omega; omega x r + v]``, i.e. ``[[I, 0], [-[r]x, I]]``; r goes *from*
    the old reference point (origin i) *to* the new one (origin j) and is expressed in the same
    basis as the twist.  (The seed prints the lower-left block -[r]x but omits the lower-right I.)
    """
    X = np.eye(6)
    X[3:, :3] = -skew(np.asarray(r, dtype=float))
    return X


def frame_index(chain: Chain, k: int | str, *, what: str = "frame") -> int:
    """Frame index of ``k``: an int, ``"tool"`` (n+1, the first tip) or ``"base"`` (0)."""
    last = chain.n + len(chain.tip_list())
    if isinstance(k, str):
        if k == "tool":
            return chain.n + 1
        if k == "base":
            return 0
        raise ValueError(f"{what}: unknown name {k!r} (use 'base', 'tool' or an index)")
    k = int(k)
    if not 0 <= k <= last:
        raise ValueError(f"{what}: index {k} outside 0..{last}")
    return k


def _basis_rotation(chain: Chain, T: np.ndarray, basis: int | str) -> np.ndarray:
    """``^rootR_b``: the axes of the requested basis in the root frame ('base' = root axes)."""
    if isinstance(basis, str) and basis == "base":
        return np.eye(3)
    return T[frame_index(chain, basis, what="basis")][:3, :3]


# ---- the Jacobian by screw transport (section 4) ---------------------------------------------

def jacobian(chain: Chain, q: np.ndarray, ref: int | str = "tool", basis: int | str = "base") -> np.ndarray:
    """(6, n) Jacobian of frame ``ref`` (rows (omega; v); v = velocity of the origin of ``ref``).

    Built literally with the seed's 3-step algorithm (section 4, eqs. 13-21):

    for every joint i <= ref
      1. ``H_i^ref = (^rootT_i)^-1 ^rootT_ref``: the pose of the reference frame seen from joint
         frame i, "the ratio of absolute poses";
      2. ``R_i^ref W_i``: transport the constant joint twist W_i (eqs. 15/16) from origin i to the
         reference point with R(r) (eq. 18 [FIX]), r = translation of H_i^ref (basis i);
      3. rotate the 6-vector from basis i into the computation basis b with ``^bR_i`` (eq. 19
         [FIX]: the rotation *from basis i*, not H_i^s applied to a basis-j quantity).

    Columns of joints after ``ref`` are zero (eq. 8); in a tree, of joints not on ref's branch.  Column i depends only on q_{i+1..ref} when
    expressed in basis i or basis ref (eq. 20).  ``ref``: ``"tool"`` (= n+1) or a frame index
    0..n+1.  ``basis``: ``"base"`` (root axes), ``"tool"`` or a frame index 0..n+1 (see module doc).
    """
    T = fk_frames(chain, q)
    j = frame_index(chain, ref, what="ref")
    Rb = _basis_rotation(chain, T, basis)             # ^rootR_b
    J = np.zeros((6, chain.n))
    for i in sorted(moving_joints(chain, j)):         # joints that precede (or are) ref
        W = joint_twist(chain.joints[i - 1])          # W_i, basis i
        H = pose_inv(T[i]) @ T[j]                     # step 1: H_i^ref = ^iT_ref
        V_i = transport(H[:3, 3]) @ W                 # step 2: R_i^ref W_i, basis i, point = origin ref
        R_bi = Rb.T @ T[i][:3, :3]                    # step 3: ^bR_i = ^bR_root ^rootR_i
        J[:, i - 1] = _rot6(R_bi) @ V_i
    return J


# ---- forward velocity problem (eqs. 6-12) -----------------------------------------------------

def frame_twists(chain: Chain, q: np.ndarray, qd: np.ndarray, basis: str = "base") -> np.ndarray:
    """(n+2, 6): twist (omega; v) of every frame k = 0..n+1 from the joint rates ``qd``.

    Each twist is referenced at its own frame's origin and expressed in the root basis
    (``basis="base"``) or in the frame's own basis (``basis="own"``); the base frame's twist is 0.

    Computed recursively, as eq. (12) suggests ("the velocities of all links from the generalized
    velocities"): the twist of frame k-1 is transported to origin k with R(p_k - p_{k-1}) (eq. 18,
    root basis) and joint k adds its own ``W_k qd_k`` (eqs. 15/16) rotated into the root basis.  This
    is a different evaluation order from :func:`jacobian`; both must agree: V_k = J(ref=k) qd.
    """
    q = _check_q(chain, q)
    qd = np.asarray(qd, dtype=float)
    if qd.shape != (chain.n,):
        raise ValueError(f"qd has shape {qd.shape}, expected ({chain.n},)")
    if basis not in ("base", "own"):
        raise ValueError(f"basis: unknown {basis!r} (use 'base' or 'own')")
    T = fk_frames(chain, q)
    par = _parents(chain)
    nf = len(T)
    V = np.zeros((nf, 6))                              # root basis
    for k in range(1, nf):
        V[k] = transport(T[k][:3, 3] - T[par[k]][:3, 3]) @ V[par[k]]
        if k <= chain.n:
            V[k] += _rot6(T[k][:3, :3]) @ joint_twist(chain.joints[k - 1]) * qd[k - 1]
    if basis == "own":
        V = np.array([_rot6(T[k][:3, :3].T) @ V[k] for k in range(nf)])
    return V
