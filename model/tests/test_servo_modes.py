"""Servo law in the closed loop: error choices A and B, error-only mode, setpoint relative to a
frame of the chain (moving local basis).  Expected values come from the loop's first-order
theory (error ratio 1 - K dt per tick, velocity lag v/K, feed-forward lag dt |a| / (2K)) and from
float64 kinematics of the plant, never from the servo's own outputs."""
import numpy as np
import pytest

from tensor_servo import reference, robots
from tensor_servo.model import formats
from tensor_servo.pathgen import circle
from tensor_servo.plant import Plant
from tensor_servo.track import make_tick, relative_poses, track

PUMA_Q = np.array([0.2, 1.0, -2.8, 0.3, 0.8, 0.2])
DT = 1e-3
KDT = 0.3
PARAMS = dict(sweeps=10, mu=1.5)   # the recommended solver settings (docs/solver.md)
LEAK = 5


def lsb(name):
    W, I = formats("default")[name]
    return 2.0 ** (I - W)


def offset_target(ch, q, dp, angle, axis=(0.0, 0.6, 0.8)):
    T = reference.fk_frames(ch, q)[-1]
    U = T.copy()
    U[:3, 3] += dp
    U[:3, :3] = reference.rotation(np.asarray(axis), angle) @ T[:3, :3]
    return U


def run(ch, T, V, q0, model="float", disturb=None, setpoint_frame=-1, **kw):
    p = {**PARAMS, "kp": KDT / DT, "ko": KDT / DT, "setpoint_frame": setpoint_frame, **kw}
    tick = make_tick(model, ch, dt=DT, **p)
    return track(ch, T, V, q0, tick, Plant(q0, DT), setpoint_frame=setpoint_frame, warm=LEAK, disturb=disturb)


@pytest.mark.parametrize("model", ["float", "fixed"])
@pytest.mark.parametrize("mode", ["A", "B"])
def test_static_target_converges(mode, model):
    ch = robots.load("puma560")
    U = offset_target(ch, PUMA_Q, [2e-3, -1e-3, 2e-3], 3e-3)
    H = 200
    r = run(ch, np.repeat(U[None], H, 0), np.zeros((H, 6)), PUMA_Q, model, mode=mode)
    e = np.sqrt(r.pos_err ** 2 + (0.5 * r.rot_err) ** 2)
    # first-order loop: the error shrinks by (1 - K dt) per tick once the solver has caught up;
    # ideal 1e-3 reduction in ln(1e-3)/ln(0.7) = 19.4 ticks; allow 3x for the solver
    assert e[60] < 1e-3 * e[0], e[[0, 20, 40, 60]] / e[0]
    if model == "float":
        assert r.pos_err[-1] < 1e-12 and r.rot_err[-1] < 1e-12
    else:   # fixed point: its own kinematics' accuracy, a few LSB of the error formats
        assert r.pos_err[-1] < 4 * lsb("perr_t") and r.rot_err[-1] < 4 * lsb("rot_t")
        assert not np.bitwise_or.reduce(r.flags) & 0xFFFF


def circle_path(ch, q0, dur=2.0):
    T0 = relative_poses(ch, q0[None])[0]
    return circle(T0, 0.05, 2.0, DT, dur, plane=((0, 1, 0), (0, 0, 1)), tilt=0.2, axis=(1.0, 1.0, 0.0))


@pytest.mark.parametrize("mode", ["A", "B"])
def test_moving_target_is_tracked_with_the_feed_forward_lag(mode):
    ch = robots.load("puma560")
    T, V = circle_path(ch, PUMA_Q)
    r = run(ch, T, V, PUMA_Q, mode=mode)
    # holding the twist of tick k over the tick misses the path by dt^2 a / 2 per tick; the loop
    # removes a fraction K dt per tick: steady error dt |a| / (2 K) (a: acceleration of the point)
    a = np.linalg.norm(np.diff(V[:, 3:], axis=0), axis=1).max() / DT
    alpha = np.linalg.norm(np.diff(V[:, :3], axis=0), axis=1).max() / DT
    K = KDT / DT
    half = len(T) // 2
    pe, re = r.pos_err[half:].max(), r.rot_err[half:].max()
    assert pe < 2.0 * DT * a / (2 * K), (pe, DT * a / (2 * K))
    assert re < 2.0 * DT * alpha / (2 * K), (re, DT * alpha / (2 * K))
    assert pe > 0.3 * DT * a / (2 * K)          # the lag is there (the test can see it)


def test_error_only_mode_lags_by_v_over_k_and_converges_when_static():
    ch = robots.load("puma560")
    v = np.array([0.0, 0.03, -0.04])           # 5 cm/s straight line, constant orientation
    T0 = reference.fk_frames(ch, PUMA_Q)[-1]
    H1, H2 = 600, 400
    T = np.repeat(T0[None], H1 + H2, 0)
    T[:H1, :3, 3] += np.arange(H1)[:, None] * DT * v
    T[H1:, :3, 3] += H1 * DT * v               # then it stops
    V = np.zeros((H1 + H2, 6))
    V[:H1, 3:] = v
    K = KDT / DT
    r = run(ch, T, V, PUMA_Q, feedforward=False)
    # discrete first-order loop: e_{k+1} = e_k + v dt - K dt e_k  ->  e = v dt / (K dt) = v / K
    lag = np.linalg.norm(v) / K
    steady = r.pos_err[H1 - 100:H1]
    assert np.all(np.abs(steady - lag) < 0.03 * lag), (steady.min(), steady.max(), lag)
    # the error is behind the setpoint, along the motion
    P = relative_poses(ch, r.q[H1 - 1][None])[0]
    d = T[H1 - 1, :3, 3] - P[:3, 3]
    assert np.dot(d, v) / (np.linalg.norm(d) * np.linalg.norm(v)) > 0.999
    assert r.pos_err[-1] < 1e-10 and r.rot_err[-1] < 1e-10
    # with the feed-forward the same line is followed with no lag (a = 0)
    ff = run(ch, T, V, PUMA_Q)
    assert ff.pos_err[H1 - 100:H1].max() < 1e-3 * lag


def disturb_joints_1_2(k, qd):
    u = np.array(qd, dtype=float)
    t = k * DT
    u[0] = 1.2 * np.cos(2 * np.pi * t / 1.5)
    u[1] = -0.4 * np.sin(2 * np.pi * t / 1.1)
    return u


@pytest.mark.parametrize("mode", ["A", "B"])
@pytest.mark.parametrize("model", ["float", "fixed"])
def test_tool_held_relative_to_frame_2_while_joints_1_2_are_disturbed(mode, model):
    ch = robots.load("puma560")
    q_goal = PUMA_Q + np.array([0, 0, 0.02, -0.03, 0.02, 0.04])
    Tg = reference.fk_frames(ch, q_goal)
    U = reference.pose_inv(Tg[2]) @ Tg[-1]            # tool relative to frame 2
    H = 700
    r = run(ch, np.repeat(U[None], H, 0), np.zeros((H, 6)), PUMA_Q, model, disturb=disturb_joints_1_2,
            setpoint_frame=2, mode=mode)
    # the disturbance really moved the chain: joints 1-2 swing, the tool moves in the root frame
    assert np.ptp(r.q[:, 0]) > 0.2 and np.ptp(r.q[:, 1]) > 0.1
    tool = relative_poses(ch, r.q)[:, :3, 3]
    assert np.linalg.norm(tool - tool[0], axis=1).max() > 0.1
    # ... and the relative pose converged and stays put (true errors, float kinematics)
    assert r.pos_err[0] > 5e-3
    tol_p, tol_r = (1e-10, 1e-10) if model == "float" else (4 * lsb("perr_t"), 4 * lsb("rot_t"))
    pe, re = r.pos_err[300:].max(), r.rot_err[300:].max()
    assert pe < tol_p and re < tol_r, (pe, re)


def test_moving_setpoint_relative_to_frame_2():
    """A moving setpoint given in frame 2's coordinates (pose and twist in frame 2's axes) is
    tracked while joints 1-2 are disturbed.  Relative to frame 2 only joints 3..6 act, so the
    setpoint is made reachable: the relative pose of a smooth motion of joints 3..6, with its twist
    from the float Jacobian in frame 2's axes."""
    ch = robots.load("puma560")
    H = 1000
    t = np.arange(H) * DT
    amp = np.array([0.15, -0.2, 0.2, 0.2])      # joint rates stay inside the velocity limits
    w = 2 * np.pi / np.array([1.3, 1.7, 1.1, 0.9])
    T, V = np.empty((H, 4, 4)), np.empty((H, 6))
    for k in range(H):
        qs = PUMA_Q.copy()
        qs[2:] += amp * np.sin(w * t[k])
        qds = np.zeros(6)
        qds[2:] = amp * w * np.cos(w * t[k])
        F = reference.fk_frames(ch, qs)
        T[k] = reference.pose_inv(F[2]) @ F[-1]
        V[k] = reference.jacobian(ch, qs, ref="tool", basis=2) @ qds
    r = run(ch, T, V, PUMA_Q, disturb=disturb_joints_1_2, setpoint_frame=2)
    a = np.linalg.norm(np.diff(V[:, 3:], axis=0), axis=1).max() / DT
    alpha = np.linalg.norm(np.diff(V[:, :3], axis=0), axis=1).max() / DT
    K = KDT / DT
    half = H // 2
    assert r.pos_err[half:].max() < 2.0 * DT * a / (2 * K), (r.pos_err[half:].max(), DT * a / (2 * K))
    assert r.rot_err[half:].max() < 2.0 * DT * alpha / (2 * K), (r.rot_err[half:].max(), DT * alpha / (2 * K))
    assert not np.bitwise_or.reduce(r.flags)
    tool = relative_poses(ch, r.q)[:, :3, 3]
    assert np.linalg.norm(tool - tool[0], axis=1).max() > 0.1
