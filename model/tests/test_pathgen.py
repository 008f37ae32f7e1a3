"""Paths and the point-array generator (tensor_servo.pathgen): sampling, twists of the sampled
curves, and joint arrays that reproduce the path within tolerance and stay within the limits."""
import numpy as np
import pytest

from tensor_servo import reference, robots
from tensor_servo.errors import InputError
from tensor_servo.pathgen import circle, displaced, figure8, line_path, point_array, transition_twist
from tensor_servo.track import pose_errors

PUMA_Q = np.array([0.2, 1.0, -2.8, 0.3, 0.8, 0.2])
PANDA_Q = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8])


def angle_between(Ra, Rb):
    return np.linalg.norm(reference.rotvec(Ra @ Rb.T))


def test_line_path_sampling_and_slerp():
    T0 = reference.fk_frames(robots.load("puma560"), PUMA_Q)[-1]
    W1 = displaced(T0, [0.03, -0.02, 0.01], [0.1, -0.2, 0.05])
    W2 = displaced(W1, [0.0, 0.0, -0.004])
    T = line_path(T0, [W1, W1, W2], step=2e-3, step_rot=1e-2)    # the repeated waypoint is skipped
    assert np.array_equal(T[0], T0) and np.allclose(T[-1], W2, atol=1e-15)
    d = np.linalg.norm(np.diff(T[:, :3, 3], axis=0), axis=1)
    a = np.array([angle_between(T[k + 1, :3, :3], T[k, :3, :3]) for k in range(len(T) - 1)])
    assert d.max() <= 2e-3 + 1e-12 and a.max() <= 1e-2 + 1e-12
    assert np.all(d + a > 1e-9)                                      # no zero step
    # first segment: 23 steps (rotation 0.2291 rad / 0.01); orientation turns at a constant rate
    # about one fixed axis, position moves on the straight line
    m1 = int(np.ceil(np.linalg.norm([0.1, -0.2, 0.05]) / 1e-2))
    seg = T[: m1 + 1]
    assert np.allclose(seg[m1], W1, atol=1e-14)
    w = np.array([reference.rotvec(seg[k, :3, :3] @ T0[:3, :3].T) for k in range(m1 + 1)])
    assert np.allclose(w, np.outer(np.arange(m1 + 1) / m1, [0.1, -0.2, 0.05]), atol=1e-14)
    p = seg[:, :3, 3] - T0[:3, 3]
    assert np.allclose(p, np.outer(np.arange(m1 + 1) / m1, [0.03, -0.02, 0.01]), atol=1e-15)
    # second segment: 2 steps of 2 mm (no rotation)
    assert len(T) == 1 + m1 + 2


def test_line_path_rejects_bad_steps():
    with pytest.raises(InputError, match="--step"):
        line_path(np.eye(4), [np.eye(4)], step=0.0)
    with pytest.raises(InputError, match="--step-rot"):
        line_path(np.eye(4), [np.eye(4)], step_rot=-1.0)


@pytest.mark.parametrize("make", [
    lambda T0, dt: circle(T0, 0.05, 1.0, dt, 0.4, plane=((0, 1, 0), (0, 0, 1)), tilt=0.3, axis=(1, 1, 0)),
    lambda T0, dt: figure8(T0, 0.05, 1.5, dt, 0.6, tilt=0.25),
])
def test_curve_twists_are_the_derivatives_of_the_poses(make):
    """V = (omega; v): omega in the root basis with [omega]x = R' R^T, v = p' (central differences)."""
    T0 = reference.fk_frames(robots.load("panda"), PANDA_Q)[-1]
    dt = 1e-4
    T, V = make(T0, dt)
    assert np.allclose(T[0], T0, atol=1e-15)
    for k in range(1, len(T) - 1, 97):
        v = (T[k + 1, :3, 3] - T[k - 1, :3, 3]) / (2 * dt)
        w = reference.rotvec(T[k + 1, :3, :3] @ T[k - 1, :3, :3].T) / (2 * dt)
        assert np.allclose(V[k, 3:], v, atol=1e-6, rtol=0)
        assert np.allclose(V[k, :3], w, atol=1e-6, rtol=0)


def test_transition_twist_carries_one_pose_onto_the_next():
    Ta = reference.fk_frames(robots.load("puma560"), PUMA_Q)[-1]
    Tb = displaced(Ta, [1e-3, 2e-3, -1e-3], [0.01, 0.02, -0.03])
    V = transition_twist(Ta, Tb, 0.5)
    ang = np.linalg.norm(V[:3]) * 0.5
    R = reference.rotation(V[:3] / np.linalg.norm(V[:3]), ang) @ Ta[:3, :3]
    assert np.allclose(R, Tb[:3, :3], atol=1e-15)
    assert np.allclose(Ta[:3, 3] + 0.5 * V[3:], Tb[:3, 3], atol=1e-15)


@pytest.mark.parametrize("model", ["float", "fixed"])
@pytest.mark.parametrize("name,q0", [("puma560", PUMA_Q), ("panda", PANDA_Q)])
def test_point_array_reproduces_the_path(name, q0, model):
    ch = robots.load(name)
    T0 = reference.fk_frames(ch, q0)[-1]
    T = line_path(T0, [displaced(T0, [0.06, -0.04, 0.05], [0.15, 0.1, -0.2]), displaced(T0, [0.0, 0.05, 0.0])],
                  step=4e-3, step_rot=2e-2)
    tol = (1e-6, 1e-5)
    res = point_array(ch, T, q0, model=model, tol_pos=tol[0], tol_rot=tol[1])
    assert res.q.shape == (len(T), ch.n) and np.array_equal(res.q[0], q0)
    assert res.converged.all()
    # float check against the float64 kinematics (independent of the core's own error): the
    # tolerance plus, for fixed point, the model's kinematic accuracy (<= 1e-6 m / 1e-6 rad)
    extra = 0.0 if model == "float" else 1e-6
    for m in range(len(T)):
        Tq = reference.fk_frames(ch, res.q[m])[-1]
        assert np.linalg.norm(Tq[:3, 3] - T[m, :3, 3]) <= tol[0] + extra
        assert angle_between(Tq[:3, :3], T[m, :3, :3]) <= tol[1] + extra
    assert np.all(res.q >= ch.lower) and np.all(res.q <= ch.upper)
    # joint-space linear interpolation between samples stays near the straight line (chord error
    # of 4 mm steps: well under 0.1 mm)
    mid = 0.5 * (res.q[1:] + res.q[:-1])
    tm = 0.5 * (T[1:, :3, 3] + T[:-1, :3, 3])
    pe, _ = pose_errors(ch, mid, _poses_at(tm))
    assert pe.max() < 1e-4


def _poses_at(p):
    T = np.repeat(np.eye(4)[None], len(p), 0)
    T[:, :3, 3] = p
    return T


def test_point_array_stays_within_limits_on_an_unreachable_path():
    """Turning the PUMA tool about the joint-5 axis by 1.2 rad needs q5 = 2.1 > 1.745 (the wrist
    cannot flip: q4 +- pi is outside its range).  The samples beyond are reported as not
    converged, joint 5 rests at its limit (limit flag raised) and every q is within the limits."""
    ch = robots.load("puma560")
    q0 = np.array([0.0, 0.7, -2.6, 0.0, 0.9, 0.0])
    F = reference.fk_frames(ch, q0)
    axis = F[5][:3, :3] @ ch.joints[4].axis
    T = line_path(F[-1], [displaced(F[-1], [0.0, 0.0, 0.0], 1.2 * axis)], step=0.02, step_rot=0.05)
    res = point_array(ch, T, q0, model="fixed", iters=30)
    reachable = np.array([0.9 + 1.2 * m / (len(T) - 1) <= ch.upper[4] - 0.01 for m in range(len(T))])
    assert res.converged[reachable].all() and not res.converged[-1]
    assert np.all(res.q >= ch.lower) and np.all(res.q <= ch.upper)
    assert abs(res.q[-1, 4] - ch.upper[4]) < 1e-6
    assert res.flags[-1] & 0x10000          # limit_active
