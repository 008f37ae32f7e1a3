"""The tracking loop (tensor_servo.track): float kinematics and errors, the pluggable model
registry, the loop's timing, the warm-start policies, and fixed point vs float steady state."""
import math
from types import SimpleNamespace

import numpy as np
import pytest

from tensor_servo import reference, robots
from tensor_servo.errors import InputError
from tensor_servo.model import formats
from tensor_servo.plant import Plant
from tensor_servo.track import (MODEL_FACTORIES, TickModel, check_dt, check_poses, check_q0, frame_poses,
                                make_tick, pose_errors, register_model, relative_poses, track, warm_start)

PUMA_Q = np.array([0.2, 1.0, -2.8, 0.3, 0.8, 0.2])


def lsb(config, name):
    W, I = formats(config)[name]
    return 2.0 ** (I - W)


@pytest.mark.parametrize("name", ["puma560", "panda", "stanford"])
def test_frame_poses_match_the_reference(name):
    ch = robots.load(name)
    Q = ch.random_q(np.random.default_rng(4), 7)
    F = frame_poses(ch, Q, tuple(range(ch.n + 2)))
    for s in range(7):
        ref = reference.fk_frames(ch, Q[s])
        for k in range(ch.n + 2):
            assert np.abs(F[k][s] - ref[k]).max() < 1e-13
    rel = relative_poses(ch, Q, 2)
    for s in range(7):
        ref = reference.fk_frames(ch, Q[s])
        assert np.abs(rel[s] - reference.pose_inv(ref[2]) @ ref[-1]).max() < 1e-13


@pytest.mark.parametrize("angle", [0.0, 1e-9, 3e-6, 0.4, 3.0])
def test_pose_errors_of_a_known_offset(angle):
    ch = robots.load("puma560")
    T = reference.fk_frames(ch, PUMA_Q)[-1].copy()
    d = np.array([3e-4, -2e-4, 1e-4])
    axis = np.array([1.0, 2.0, -2.0]) / 3.0
    U = T.copy()
    U[:3, 3] += d
    U[:3, :3] = reference.rotation(axis, angle) @ T[:3, :3]
    pe, re = pose_errors(ch, PUMA_Q[None], U[None])
    assert abs(pe[0] - np.linalg.norm(d)) < 1e-15
    assert abs(re[0] - angle) < 1e-15 + 1e-12 * angle


def test_registered_model_runs_in_the_loop_with_the_documented_timing():
    """A numpy resolved-rate servo (pseudo-inverse, no fixed point) registered as a new back end:
    the loop must call it with the measured q and setpoint k, and integrate its command."""
    ch = robots.load("puma560")
    calls = []

    def factory(chain, config, dt, params):
        K = params["kdt"] / dt

        def tick(q, U, V, w):
            calls.append((q.copy(), U.copy()))
            T = reference.fk_frames(chain, q)[-1]
            e = np.concatenate([reference.rotvec(U[:3, :3] @ T[:3, :3].T), U[:3, 3] - T[:3, 3]])
            qd = np.linalg.pinv(reference.jacobian(chain, q)) @ (V + K * e)
            return SimpleNamespace(qd=qd, flags=0)
        return TickModel(tick, "numpy", config)

    register_model("numpy-test", factory)
    try:
        dt = 1e-3
        tick = make_tick("numpy-test", ch, dt=dt, kdt=0.5)
        U = reference.fk_frames(ch, PUMA_Q + 0.01)[-1]
        T = np.repeat(U[None], 30, 0)
        res = track(ch, T, np.zeros((30, 6)), PUMA_Q, tick, Plant(PUMA_Q, dt))
    finally:
        del MODEL_FACTORIES["numpy-test"]
    assert len(calls) == 30
    assert np.array_equal(calls[0][0], PUMA_Q)
    assert np.allclose(res.q[1], PUMA_Q + dt * res.qd[0], atol=1e-15)
    assert np.allclose(calls[1][0], res.q[1])
    # the error at tick k is the error of q[k]; it halves each tick (K dt = 0.5, exact solver)
    e0 = pose_errors(ch, PUMA_Q[None], U[None])[0][0]
    assert abs(res.pos_err[0] - e0) < 1e-15
    ratio = res.pos_err[1:12] / res.pos_err[:11]
    assert np.all(np.abs(ratio - 0.5) < 0.02), ratio
    assert res.pos_err[-1] < 1e-9


def test_unknown_model_is_an_input_error():
    with pytest.raises(InputError, match="--model"):
        make_tick("rtl-not-yet", robots.load("puma560"), dt=1e-3)


def test_warm_start_policies():
    qd = np.array([1.0, -1.0, 3 * 2.0 ** -21, -3 * 2.0 ** -21, 0.0])
    assert np.array_equal(warm_start(qd, "prev", None), qd)
    assert np.array_equal(warm_start(qd, "zero", None), np.zeros(5))
    assert np.allclose(warm_start(qd, 5, None), qd * 31 / 32, rtol=0, atol=0)
    # fixed point: raw - (raw >> 5), an arithmetic shift (floor): -3 >> 5 = -1
    got = warm_start(qd, 5, 2.0 ** -21) / 2.0 ** -21
    assert np.array_equal(got, [2 ** 21 - 2 ** 16, -(2 ** 21) + 2 ** 16, 3, -2, 0])
    with pytest.raises(InputError, match="--warm"):
        warm_start(qd, "sometimes", None)
    with pytest.raises(InputError, match="--warm"):
        warm_start(qd, 0, None)


def test_leak_removes_null_space_self_motion_of_a_redundant_arm():
    """Panda (7 joints): with the previous command as warm start, a null-space joint rate picked
    up during a transient is never corrected (it does not change the error), so the arm keeps
    moving after the error has converged; with the leak it dies out."""
    ch = robots.load("panda")
    q0 = np.array([0.3, -0.2, 0.4, -2.0, 0.3, 2.1, 0.5])
    Tq = reference.fk_frames(ch, q0)[-1]
    U = Tq.copy()
    U[:3, 3] += [0.02, -0.01, 0.015]
    U[:3, :3] = reference.rotation(np.array([0.0, 0.6, 0.8]), 0.02) @ Tq[:3, :3]
    dt, H = 1e-3, 1000
    T = np.repeat(U[None], H, 0)
    out = {}
    for warm in ("prev", 5):
        tick = make_tick("float", ch, dt=dt, sweeps=10, mu=1.5)
        out[warm] = track(ch, T, np.zeros((H, 6)), q0, tick, Plant(q0, dt), warm=warm)
    leak, prev = out[5], out["prev"]
    assert leak.pos_err[-1] < 1e-9 and leak.rot_err[-1] < 1e-8
    assert np.abs(leak.qd[-1]).max() < 1e-9
    assert np.abs(leak.q[-1] - leak.q[300]).max() < 1e-4
    # previous command: the tool is nearly still (micrometres), the joints keep moving fast
    assert prev.pos_err[-1] < 1e-5
    assert np.abs(prev.qd[-1]).max() > 0.1
    assert np.abs(prev.q[-1] - prev.q[300]).max() > 0.1


def test_fixed_point_reaches_the_float_steady_state_within_a_few_lsb():
    """Static targets: the bit-accurate loop ends within 4 LSB of perr_t (position) and rot_t
    (orientation) of where the float loop ends (which is the target itself, to 1e-12)."""
    rng = np.random.default_rng(11)
    for name, q0 in (("puma560", PUMA_Q), ("panda", np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8]))):
        ch = robots.load(name)
        for _ in range(3):
            qt = q0 + rng.uniform(-0.02, 0.02, ch.n)
            U = reference.fk_frames(ch, qt)[-1]
            H, dt = 300, 1e-3
            T = np.repeat(U[None], H, 0)
            res = {}
            for model in ("float", "fixed"):
                tick = make_tick(model, ch, dt=dt, sweeps=10, mu=1.5)
                res[model] = track(ch, T, np.zeros((H, 6)), q0, tick, Plant(q0, dt), warm=5)
            fl, fx = res["float"], res["fixed"]
            assert fl.pos_err[-1] < 1e-12 and fl.rot_err[-1] < 1e-12
            pf = relative_poses(ch, fl.q[-1][None])[0]
            px = relative_poses(ch, fx.q[-1][None])[0]
            dp = np.linalg.norm(px[:3, 3] - pf[:3, 3])
            dr = pose_errors(ch, fx.q[-1][None], pf[None])[1][0]
            assert dp <= 4 * lsb("default", "perr_t"), (name, dp / lsb("default", "perr_t"))
            assert dr <= 4 * lsb("default", "rot_t"), (name, dr / lsb("default", "rot_t"))
            assert not np.bitwise_or.reduce(fx.flags) & 0xFFFF


def test_validation_helpers():
    ch = robots.load("puma560")
    T = np.repeat(np.eye(4)[None], 3, 0)
    with pytest.raises(InputError, match="shape"):
        check_poses(T[:, :3], "T")
    bad = T.copy()
    bad[1, 0, 0] = 1.1
    with pytest.raises(InputError, match="pose 1"):
        check_poses(bad, "T")
    bad = T.copy()
    bad[2, 3, 0] = 0.5
    with pytest.raises(InputError, match="last row"):
        check_poses(bad, "T")
    mirror = T.copy()
    mirror[0, 2, 2] = -1
    with pytest.raises(InputError, match="det"):
        check_poses(mirror, "T")
    tm = make_tick("fixed", ch, config="compact", dt=1e-3)
    assert check_dt(1e-3, "dt", tm) == 1e-3
    for dt in (0.0, -1e-3, math.inf, 0.07, 1e-6):
        with pytest.raises(InputError, match="dt"):
            check_dt(dt, "dt", tm)
    assert check_dt(1e-6, "dt") == 1e-6      # float model: any positive dt
    with pytest.raises(InputError, match="joint 1"):
        check_q0(ch, np.array([0.0, 4.5, 0, 0, 0, 0]), "q0")
    with pytest.raises(InputError, match="shape"):
        check_q0(ch, np.zeros(7), "q0")


def test_bench_tracking_table_meets_the_lsb_goal_on_one_path():
    """The benchmark's own comparison on one case (the full table is make bench): a markdown row
    whose fixed - float distance, recomputed here in LSB of perr_t, is within the 4 LSB goal."""
    from tensor_servo.bench_tracking import bench_tracking

    md = bench_tracking(robots_=("panda",), paths=("circle",), rates=(1000.0,), configs=("default",))
    lines = md.strip().splitlines()
    assert len(lines) == 3 and lines[0].startswith("| robot |")
    cells = [c.strip() for c in lines[2].strip("|").split("|")]
    assert cells[:4] == ["panda", "circle", "1 kHz", "default"]
    dist = float(cells[6])
    assert 0 < dist <= 4 * lsb("default", "perr_t")
    assert cells[7].endswith("ok") and cells[8] == "0x0"


def test_core_warm_leak_equals_the_loop_leak():
    """The servo's own warm-start leak (ServoParams.warm_leak, what the core and the HLS kernel
    implement) is bit for bit the leak track.warm_start applies outside the tick."""
    from tensor_servo.servo import Servo

    ch = robots.load("panda")
    rng = np.random.default_rng(5)
    q = ch.random_q(rng)
    U = reference.fk_frames(ch, ch.random_q(rng))[-1]
    inner = Servo(ch, "default", dt=1e-3, warm_leak=5)
    outer = Servo(ch, "default", dt=1e-3)
    W, I = formats("default")["qd_t"]
    lsb = 2.0 ** -(W - I)
    w = np.zeros(ch.n)
    for _ in range(20):
        a = inner.tick(q, U, None, w)
        b = outer.tick(q, U, None, warm_start(w, 5, lsb))
        assert np.array_equal(a.raw["qd"], b.raw["qd"])
        w = a.qd
    assert np.any(w != 0)
