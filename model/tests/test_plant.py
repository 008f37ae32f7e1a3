"""The simulation plant: ideal integrator, first-order lag, encoder quantisation, stops, bad input.

Expected values come from closed-form solutions or an independent fine-step integration, not from
the plant's own update formula."""
import math

import numpy as np
import pytest

from tensor_servo.errors import InputError
from tensor_servo.plant import Plant


def test_ideal_integrator_sums_the_commands():
    rng = np.random.default_rng(1)
    q0 = rng.uniform(-1, 1, 4)
    p = Plant(q0, dt=1e-3)
    U = rng.uniform(-2, 2, (250, 4))
    for u in U:
        p.step(u)
    assert np.allclose(p.q, q0 + U.sum(axis=0) * 1e-3, rtol=0, atol=1e-12)
    assert np.array_equal(p.rate, U[-1])
    assert np.array_equal(p.measure(), p.q)


def test_lag_step_response_is_the_closed_form():
    # tau r' + r = u with r(0) = 0 and u constant: r = u (1 - e^-t/tau), q = q0 + u (t - tau (1 - e^-t/tau))
    tau, dt, u = 0.02, 1e-3, np.array([1.5, -0.7])
    p = Plant(np.zeros(2), dt, tau=tau)
    for k in range(1, 101):
        p.step(u)
        t = k * dt
        assert np.allclose(p.rate, u * (1 - math.exp(-t / tau)), atol=1e-13)
        assert np.allclose(p.q, u * (t - tau * (1 - math.exp(-t / tau))), atol=1e-13)


def test_lag_against_fine_integration_with_changing_commands():
    # joints 0, 1 lag (RK4 with 2000 sub-steps per tick as the reference); joint 2 is ideal
    tau, dt = np.array([0.005, 0.03, 0.0]), 1e-3
    rng = np.random.default_rng(2)
    U = rng.uniform(-1, 1, (40, 3))
    p = Plant(np.zeros(3), dt, tau=tau)
    q, r = [0.0, 0.0], [0.0, 0.0]
    n_sub = 500
    h = dt / n_sub
    for u3 in U:
        p.step(u3)
        for j in range(2):            # exact ODE solution is smooth: RK4 in plain floats
            u, ta, qq, rr = u3[j], tau[j], q[j], r[j]
            for _ in range(n_sub):
                k1 = (u - rr) / ta
                k2 = (u - (rr + h / 2 * k1)) / ta
                k3 = (u - (rr + h / 2 * k2)) / ta
                k4 = (u - (rr + h * k3)) / ta
                qq += h / 6 * (rr + 2 * (rr + h / 2 * k1) + 2 * (rr + h / 2 * k2) + (rr + h * k3))
                rr += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            q[j], r[j] = qq, rr
    assert np.allclose(p.q[:2], q, atol=1e-12)
    assert np.allclose(p.rate[:2], r, atol=1e-12)
    assert abs(p.q[2] - U[:, 2].sum() * dt) < 1e-14
    assert p.rate[2] == U[-1, 2]


def test_encoder_quantisation_nearest_count():
    c = np.array([1000.0, 2.0 ** 16 / (2 * math.pi)])
    p = Plant(np.array([0.12349, -0.5]), 1e-3, counts=c)
    m = p.measure()
    assert abs(m[0] - 0.123) < 1e-15
    assert np.all(np.abs(m - p.q) <= 0.5 / c + 1e-15)
    assert np.allclose(m * c, np.round(m * c), atol=1e-9)     # on the count grid
    # sweep: the measurement error never exceeds half a count and is not always zero
    errs = []
    for _ in range(500):
        p.step(np.array([0.37, -0.41]))
        errs.append(np.abs(p.measure() - p.q) * c)
    errs = np.array(errs)
    assert errs.max() <= 0.5 + 1e-9 and errs.max() > 0.4


def test_stops_clamp_and_zero_the_rate():
    p = Plant(np.array([0.0, 0.0]), 0.01, tau=0.05, lower=-0.1, upper=0.1)
    for _ in range(200):
        p.step(np.array([1.0, -1.0]))
    assert np.array_equal(p.q, [0.1, -0.1])
    assert np.array_equal(p.rate, [0.0, 0.0])
    p.step(np.array([-1.0, 1.0]))
    assert p.q[0] < 0.1 and p.q[1] > -0.1


@pytest.mark.parametrize("kw,field", [
    (dict(dt=0.0), "dt"), (dict(dt=float("nan")), "dt"), (dict(dt=-1e-3), "dt"),
    (dict(dt=1e-3, tau=-0.1), "tau"), (dict(dt=1e-3, tau=[0.1, 0.2, 0.3]), "tau"),
    (dict(dt=1e-3, counts=0.0), "counts"), (dict(dt=1e-3, counts=float("inf")), "counts"),
    (dict(dt=1e-3, lower=1.0, upper=0.0), "lower"),
])
def test_bad_parameters_name_the_field(kw, field):
    with pytest.raises(InputError) as e:
        Plant(np.zeros(2), **kw)
    assert e.value.field == field


def test_bad_q0_and_command():
    with pytest.raises(InputError, match="q0"):
        Plant(np.array([0.0, np.nan]), 1e-3)
    p = Plant(np.zeros(2), 1e-3)
    with pytest.raises(InputError, match="qd"):
        p.step(np.zeros(3))
