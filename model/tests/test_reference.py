"""Tests of the float reference (tensor_servo.reference) against Pinocchio, finite differences and
the properties the seed states (eqs. 8, 18, 20).  Twists are (omega; v) throughout."""
from __future__ import annotations

import importlib
import math

import numpy as np
import pinocchio as pin
import pytest

from tensor_servo import reference as ref
from tensor_servo.chain import Chain, Joint, Limits, Pose
from tensor_servo.oracle import PinChain
from tensor_servo.randchain import random_chain, random_unit

TOL_PIN = 1e-12     # absolute, against Pinocchio (lengths ~ 1 m)
TOL_FD = 1e-7       # absolute, against central finite differences
EXPECTED_ROBOTS = ("puma560", "ur5", "panda", "stanford", "chain20")

# largest errors seen, printed at the end of the module (-v or -s; see _report_max_errors)
MAX_ERR: dict[str, float] = {}


@pytest.fixture(autouse=True, scope="module")
def _report_max_errors(request):
    yield
    cfg = request.config
    tr = cfg.pluginmanager.getplugin("terminalreporter")
    cm = cfg.pluginmanager.getplugin("capturemanager")
    if tr is None or cm is None or not MAX_ERR or (cfg.option.verbose <= 0 and cfg.option.capture != "no"):
        return
    with cm.global_and_fixture_disabled():           # what capsys.disabled() does
        tr.write_line("\ntest_reference: largest absolute errors")
        for key in sorted(MAX_ERR):
            tr.write_line(f"  {key:28s} {MAX_ERR[key]:.3e}")


def _record(key: str, err: float) -> float:
    MAX_ERR[key] = max(MAX_ERR.get(key, 0.0), float(err))
    return err


# ---- random chains --------------------------------------------------------------------------

def _chains(seed: int, sizes) -> list[Chain]:
    rng = np.random.default_rng(seed)
    return [random_chain(rng, n) for n in sizes]


RAND_SIZES = [1, 2, 3, 5, 6, 7, 9, 12, 16, 20]


def _err(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b)))) if np.size(a) else 0.0


# ---- Pinocchio helpers (independent of reference.py) ------------------------------------------

def _pin_point_jacobians(pc: PinChain, q) -> list[np.ndarray]:
    """For k = 0..n+1: Pinocchio's LOCAL_WORLD_ALIGNED Jacobian of frame k's origin, (omega; v)."""
    n = pc.chain.n
    qq = np.asarray(q, float) * pc.scales
    pin.computeJointJacobians(pc.model, pc.data, qq)
    pin.framesForwardKinematics(pc.model, pc.data, qq)
    out = [np.zeros((6, n))]
    LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    for k in range(1, n + 1):
        out.append(pin.getJointJacobian(pc.model, pc.data, k, LWA))
    out.append(pin.getFrameJacobian(pc.model, pc.data, pc.tool_id, LWA))
    out = [np.reshape(J, (6, n)) for J in out]      # n = 1: Pinocchio returns (6,) vectors
    return [np.vstack([J[3:], J[:3]]) * pc.scales[None, :] for J in out]


def _pin_local_joint_jacobian(pc: PinChain, q, k: int) -> np.ndarray:
    qq = np.asarray(q, float) * pc.scales
    J = np.reshape(pin.computeJointJacobian(pc.model, pc.data, qq, k), (6, pc.chain.n))  # LOCAL, joint k
    return np.vstack([J[3:], J[:3]]) * pc.scales[None, :]


def _pin_frames(pc: PinChain, q) -> np.ndarray:
    """(n+2, 4, 4) frame poses from Pinocchio (frame 0 = chain.base, constant)."""
    return np.concatenate([pc.chain.base.matrix()[None], pc.joint_poses(q), pc.tool_pose(q)[None]])


def _check_against_pinocchio(chain: Chain, q, label: str, every_basis: bool = True):
    n = chain.n
    pc = PinChain(chain)
    T = ref.fk_frames(chain, q)
    assert T.shape == (n + 2, 4, 4)
    Tp = _pin_frames(pc, q)
    assert _record("pin fk frames", _err(T, Tp)) < TOL_PIN, label

    # tool Jacobian: the oracle's own accessors
    for basis, pb in (("base", "base"), ("tool", "tool")):
        # reshape: for n = 1 Pinocchio hands back a (6,) vector and the oracle then returns (2, 3)
        e = _err(ref.jacobian(chain, q, "tool", basis), np.reshape(pc.jacobian(q, pb), (6, n)))
        assert _record(f"pin tool J {basis}", e) < TOL_PIN, (label, basis)

    # every reference point k = 0..n+1 in every basis: rotate Pinocchio's LWA Jacobian of point k
    Jp = _pin_point_jacobians(pc, q)
    for k in range(n + 2):
        # every basis on small chains; on long ones: root, tool, base frame, own frame, one more
        bases = ["base", "tool", *range(n + 2)] if every_basis else ["base", "tool", 0, k, (5 * k + 3) % (n + 2)]
        for b in bases:
            Rb = np.eye(3) if b == "base" else Tp[n + 1 if b == "tool" else b][:3, :3]
            want = np.kron(np.eye(2), Rb.T) @ Jp[k]
            e = _err(ref.jacobian(chain, q, k, b), want)
            assert _record("pin J(ref=k, basis=b)", e) < TOL_PIN, (label, k, b)
        if 1 <= k <= n:   # joint frame k in its own basis: Pinocchio's LOCAL joint Jacobian
            e = _err(ref.jacobian(chain, q, k, k), _pin_local_joint_jacobian(pc, q, k))
            assert _record("pin joint J LOCAL", e) < TOL_PIN, (label, k)


# ---- unit-level pieces -------------------------------------------------------------------------

def test_transport_matches_eq18_fix():
    rng = np.random.default_rng(1)
    for _ in range(20):
        r, w, v = rng.normal(size=(3, 3))
        X = ref.transport(r)
        assert np.allclose(X @ np.r_[w, v], np.r_[w, np.cross(w, r) + v], atol=1e-15, rtol=0)
        assert np.array_equal(X[:3, :3], np.eye(3)) and np.array_equal(X[3:, 3:], np.eye(3))
        assert np.array_equal(X[:3, 3:], np.zeros((3, 3)))
        r1, r2 = rng.normal(size=(2, 3))
        # successive transports add up (r from i to j, then from j to k)
        assert np.allclose(ref.transport(r2) @ ref.transport(r1), ref.transport(r1 + r2), atol=1e-15)
    # the seed's printed block (eq. 18) is -[r]x: row 1 = (0, r3, -r2)
    X = ref.transport([1.0, 2.0, 3.0])
    assert np.array_equal(X[3:, :3], [[0, 3, -2], [-3, 0, 1], [2, -1, 0]])


def test_joint_twist_eq15_eq16():
    a = np.array([0.0, 0.6, 0.8])
    rv = Joint("r", "revolute", Pose(), a, Limits(), 2.5)
    pr = Joint("p", "prismatic", Pose(), a, Limits(-1, 1), -0.5)
    assert np.array_equal(ref.joint_twist(rv), np.r_[2.5 * a, 0, 0, 0])
    assert np.array_equal(ref.joint_twist(pr), np.r_[0, 0, 0, -0.5 * a])


def test_rotvec_inverts_rotation():
    rng = np.random.default_rng(2)
    angles = [0.0, 1e-9, 1e-5, 9.9e-5, 1.01e-4, 1e-3, 0.3, 1.0, 2.0, 3.0, math.pi - 1e-2, math.pi - 1e-5, math.pi - 1e-9]
    for th in angles + list(rng.uniform(0, math.pi, 30)):
        a = random_unit(rng, 3)
        # rotation matrix from an independent construction (quaternion), not from ref.rotation
        R = Pose(np.zeros(3), np.r_[math.cos(th / 2), math.sin(th / 2) * a]).matrix()[:3, :3]
        assert np.allclose(ref.rotation(a, th), R, atol=1e-15, rtol=0)
        w = ref.rotvec(R)
        assert _err(w, th * a) < 1e-9 if th > math.pi - 1e-3 else _err(w, th * a) < 1e-14, th


def test_fk_frames_before_motion():
    chain = _chains(3, [7])[0]
    q = chain.random_q(np.random.default_rng(3))
    T = ref.fk_frames(chain, q)
    B = ref.fk_frames_before(chain, q)
    for i, j in enumerate(chain.joints, start=1):
        assert _err(B[i - 1] @ ref.joint_motion(j, q[i - 1]), T[i]) < 1e-14
        # the axis has the same direction before and after the motion
        assert _err(B[i - 1][:3, :3] @ j.axis, T[i][:3, :3] @ j.axis) < 1e-14


# ---- against Pinocchio ---------------------------------------------------------------------

@pytest.mark.parametrize("seed", [10, 11, 12])
def test_random_chains_vs_pinocchio(seed):
    rng = np.random.default_rng(seed + 100)
    for chain in _chains(seed, RAND_SIZES):
        for _ in range(3):
            _check_against_pinocchio(chain, chain.random_q(rng), f"{chain.name} seed {seed}", every_basis=chain.n <= 7)


def test_random_chains_have_the_features_we_claim():
    chains = [c for s in (10, 11, 12) for c in _chains(s, RAND_SIZES)]
    joints = [j for c in chains for j in c.joints]
    assert any(j.prismatic for j in joints) and any(not j.prismatic for j in joints)
    assert sum(j.scale != 1.0 for j in joints) > 10 and any(j.scale < 0 for j in joints)
    assert all(not np.allclose(c.base.matrix(), np.eye(4)) for c in chains)
    assert all(not np.allclose(c.tool.matrix(), np.eye(4)) for c in chains)
    assert {c.n for c in chains} >= {1, 20}


def _robots():
    # must fail (not skip) while tensor_servo.robots is missing or incomplete
    robots = importlib.import_module("tensor_servo.robots")
    assert hasattr(robots, "names") and hasattr(robots, "load"), "tensor_servo.robots lacks names()/load()"
    return robots


def test_embedded_robots_listed():
    names = list(_robots().names())
    missing = [n for n in EXPECTED_ROBOTS if n not in names]
    assert not missing, f"robots.names() lacks {missing}"


def test_embedded_robots_vs_pinocchio():
    robots = _robots()
    names = list(robots.names())
    assert names, "robots.names() is empty"
    rng = np.random.default_rng(20)
    for name in names:
        chain = robots.load(name)
        for _ in range(4):
            _check_against_pinocchio(chain, chain.random_q(rng), name, every_basis=chain.n <= 8)


# ---- against finite differences -----------------------------------------------------------

def _fd_twists(frames_of, h: float) -> np.ndarray:
    """Central differences of the pose curve t -> frames_of(t) at t = 0: (n+2, 6) twists (omega; v)
    in the root basis, each at its frame's origin.  omega = log(R(h) R(-h)^T) / 2h."""
    Tp, Tm = frames_of(+h), frames_of(-h)
    return np.array([np.r_[ref.rotvec(A[:3, :3] @ B[:3, :3].T), A[:3, 3] - B[:3, 3]] / (2 * h)
                     for A, B in zip(Tp, Tm)])


@pytest.mark.parametrize("seed", [30, 31])
def test_jacobian_vs_finite_differences(seed):
    rng = np.random.default_rng(seed)
    for chain in _chains(seed, [1, 4, 6, 9, 14, 20]):
        q = chain.random_q(rng)
        n = chain.n
        T0 = ref.fk_frames(chain, q)
        cols = []                                              # per joint: (n+2, 6) FD twists
        for i in range(n):
            h = 1e-5 / abs(chain.joints[i].scale)               # 1e-5 rad (or m) of joint motion
            e = np.eye(n)[i]
            cols.append(_fd_twists(lambda t: ref.fk_frames(chain, q + t * e), h))
        for k in range(n + 2):
            Jfd = np.array([c[k] for c in cols]).T              # (6, n), base basis, point = origin k
            assert _record("fd J base", _err(ref.jacobian(chain, q, k, "base"), Jfd)) < TOL_FD, (chain.name, k)
            # body form: rotate the FD result into frame k's own basis
            Rk = T0[k][:3, :3]
            Jfd_k = np.kron(np.eye(2), Rk.T) @ Jfd
            assert _record("fd J own", _err(ref.jacobian(chain, q, k, k), Jfd_k)) < TOL_FD, (chain.name, k)
        # the independent body-angular FD: log(R(q-h)^T R(q+h)) / 2h in the tool basis
        for i in range(n):
            h = 1e-5 / abs(chain.joints[i].scale)
            e = np.eye(n)[i]
            Rp = ref.fk_frames(chain, q + h * e)[n + 1][:3, :3]
            Rm = ref.fk_frames(chain, q - h * e)[n + 1][:3, :3]
            w_body = ref.rotvec(Rm.T @ Rp) / (2 * h)
            assert _record("fd J tool body omega", _err(ref.jacobian(chain, q, "tool", "tool")[:3, i], w_body)) < TOL_FD


def test_fd_tolerance_is_meaningful():
    """A wrong Jacobian (reference point at origin i instead of origin ref, i.e. no transport) must
    exceed the FD tolerance by orders of magnitude: the FD test can fail."""
    chain = _chains(32, [6])[0]
    q = chain.random_q(np.random.default_rng(32))
    T = ref.fk_frames(chain, q)
    n = chain.n
    wrong = np.zeros((6, n))
    for i in range(1, n + 1):
        wrong[:, i - 1] = np.kron(np.eye(2), T[i][:3, :3]) @ ref.joint_twist(chain.joints[i - 1])
    good = ref.jacobian(chain, q, "tool", "base")
    assert _err(wrong, good) > 1e3 * TOL_FD


# ---- frame-k basis and joint reference points, independent derivation ------------------------

@pytest.mark.parametrize("seed", [40, 41])
def test_jacobian_equals_adjoint_form(seed):
    """[FIX] after eq. 21: J_i (ref k, basis k) = Ad_{^kT_i} W_i; any basis b: rotate by ^bR_k."""
    rng = np.random.default_rng(seed)
    for chain in _chains(seed, [3, 8, 15]):
        q = chain.random_q(rng)
        T = ref.fk_frames(chain, q)
        n = chain.n
        for k in range(n + 2):
            want = np.zeros((6, n))
            for i in range(1, min(k, n) + 1):
                want[:, i - 1] = ref.adjoint(ref.pose_inv(T[k]) @ T[i]) @ ref.joint_twist(chain.joints[i - 1])
            assert _record("adjoint J own", _err(ref.jacobian(chain, q, k, k), want)) < TOL_PIN, k
            for b in range(n + 2):
                R_bk = T[b][:3, :3].T @ T[k][:3, :3]
                e = _err(ref.jacobian(chain, q, k, b), np.kron(np.eye(2), R_bk) @ want)
                assert _record("adjoint J basis b", e) < TOL_PIN, (k, b)
            e = _err(ref.jacobian(chain, q, k, "base"), np.kron(np.eye(2), T[k][:3, :3]) @ want)
            assert e < TOL_PIN


def test_names_and_indices_agree():
    chain = _chains(42, [5])[0]
    q = chain.random_q(np.random.default_rng(42))
    n = chain.n
    assert np.array_equal(ref.jacobian(chain, q, "tool", "tool"), ref.jacobian(chain, q, n + 1, n + 1))
    assert np.array_equal(ref.jacobian(chain, q), ref.jacobian(chain, q, n + 1, "base"))
    # 'base' is the root basis; 0 is the base frame's basis: different when base is rotated
    assert _err(ref.jacobian(chain, q, "tool", "base"), ref.jacobian(chain, q, "tool", 0)) > 1e-3
    for bad in (n + 2, -1, "world"):
        with pytest.raises(ValueError):
            ref.jacobian(chain, q, bad)
        with pytest.raises(ValueError):
            ref.jacobian(chain, q, "tool", bad)
    with pytest.raises(ValueError):
        ref.fk_frames(chain, q[:-1])


# ---- forward velocity problem --------------------------------------------------------------

@pytest.mark.parametrize("seed", [50, 51])
def test_frame_twists(seed):
    rng = np.random.default_rng(seed)
    for chain in _chains(seed, [1, 5, 11, 20]):
        n = chain.n
        q = chain.random_q(rng)
        qd = rng.uniform(-1, 1, n) / chain.scales              # O(1) rad/s or m/s per joint
        T = ref.fk_frames(chain, q)
        V = ref.frame_twists(chain, q, qd, "base")
        Vo = ref.frame_twists(chain, q, qd, "own")
        assert V.shape == Vo.shape == (n + 2, 6)
        assert np.array_equal(V[0], np.zeros(6)) and np.array_equal(Vo[0], np.zeros(6))
        for k in range(n + 2):
            assert _record("twists vs J qd", _err(V[k], ref.jacobian(chain, q, k, "base") @ qd)) < TOL_PIN, k
            assert _record("twists vs J qd", _err(Vo[k], ref.jacobian(chain, q, k, k) @ qd)) < TOL_PIN, k
        # finite differences along q + t qd
        h = 1e-5
        Tp = ref.fk_frames(chain, q + h * qd)
        Tm = ref.fk_frames(chain, q - h * qd)
        for k in range(n + 2):
            w = ref.rotvec(Tp[k][:3, :3] @ Tm[k][:3, :3].T) / (2 * h)
            v = (Tp[k][:3, 3] - Tm[k][:3, 3]) / (2 * h)
            assert _record("fd twists base", _err(V[k], np.r_[w, v])) < TOL_FD, k
            wb = ref.rotvec(Tm[k][:3, :3].T @ Tp[k][:3, :3]) / (2 * h)    # body angular velocity
            vb = T[k][:3, :3].T @ v
            assert _record("fd twists own", _err(Vo[k], np.r_[wb, vb])) < TOL_FD, k


def test_frame_twists_vs_pinocchio_velocities():
    """Pinocchio's forward velocities (data.v, LOCAL at each joint) for the joint frames."""
    rng = np.random.default_rng(52)
    for chain in _chains(52, [4, 13]):
        pc = PinChain(chain)
        q = chain.random_q(rng)
        qd = rng.uniform(-1, 1, chain.n) / chain.scales
        pin.forwardKinematics(pc.model, pc.data, q * pc.scales, qd * pc.scales)
        Vo = ref.frame_twists(chain, q, qd, "own")
        for k in range(1, chain.n + 1):
            m = pc.data.v[k]
            assert _record("pin twists own", _err(Vo[k], np.r_[m.angular, m.linear])) < TOL_PIN, k


# ---- properties stated by the seed --------------------------------------------------------

@pytest.mark.parametrize("seed", [60, 61])
def test_eq8_later_joints_do_not_move_earlier_frames(seed):
    rng = np.random.default_rng(seed)
    for chain in _chains(seed, [4, 9, 16]):
        n = chain.n
        q = chain.random_q(rng)
        T = ref.fk_frames(chain, q)
        for k in range(n + 1):
            J = ref.jacobian(chain, q, k, "base")
            assert np.array_equal(J[:, k:], np.zeros((6, n - k))), k       # joints k+1..n: exactly 0
            if k >= 1:
                assert np.all(np.abs(J[:, :k]).max(axis=0) > 1e-6), k      # earlier ones are not
            # and the poses: moving joints k+1..n leaves frames 0..k unchanged
            dq = np.zeros(n)
            dq[k:] = rng.uniform(-1, 1, n - k) / chain.scales[k:]
            T2 = ref.fk_frames(chain, q + dq)
            assert _err(T2[: k + 1], T[: k + 1]) < 1e-13
            if k < n:
                assert _err(T2[k + 1:], T[k + 1:]) > 1e-6


@pytest.mark.parametrize("seed", [70, 71])
def test_eq20_column_depends_only_on_intermediate_joints(seed):
    """Eq. 20: J_i^k = H_i^k R_i^k W_i depends only on q_{i+1..k}.  That holds for column i expressed
    in basis k (the seed's J_i^k, the body form) and in basis i (R_i^k W_i); it does *not* hold in
    the root basis, where joints 1..i rotate the column."""
    rng = np.random.default_rng(seed)
    for chain in _chains(seed, [5, 10, 18]):
        n = chain.n
        q = chain.random_q(rng)
        for k in range(1, n + 2):
            Jk = ref.jacobian(chain, q, k, k)
            J0 = ref.jacobian(chain, q, k, "base")
            for i in range(1, min(k, n) + 1):
                col_i = ref.jacobian(chain, q, k, i)[:, i - 1]
                # perturb q_1..q_i and q_{k+1..n}: the "outside" joints
                dq = rng.uniform(-1, 1, n) / chain.scales
                dq[i:min(k, n)] = 0.0
                q2 = q + dq
                assert _record("eq20 invariance", _err(ref.jacobian(chain, q2, k, k)[:, i - 1], Jk[:, i - 1])) < 1e-12, (k, i)
                assert _err(ref.jacobian(chain, q2, k, i)[:, i - 1], col_i) < 1e-12, (k, i)
                # the root-basis column does change: a revolute joint before i rotates it, and a
                # revolute joint i swings the lever arm p_k - p_i (zero when k == i)
                revs = [not j.prismatic for j in chain.joints[:i]]
                if any(revs[:-1]) or (revs[-1] and k > i):
                    assert _err(ref.jacobian(chain, q2, k, "base")[:, i - 1], J0[:, i - 1]) > 1e-6, (k, i)
                # and the intermediate joints q_{i+1..k} do matter (a revolute one rotates the
                # column; a prismatic one changes the lever arm of a revolute joint i)
                mid = range(i, min(k, n))                      # 0-based indices of joints i+1..k
                if any(not chain.joints[m].prismatic for m in mid) or (mid and not chain.joints[i - 1].prismatic):
                    dq = np.zeros(n)
                    dq[mid.start:mid.stop] = rng.uniform(-1, 1, len(mid)) / chain.scales[mid.start:mid.stop]
                    assert _err(ref.jacobian(chain, q + dq, k, k)[:, i - 1], Jk[:, i - 1]) > 1e-8, (k, i)
