"""tensor_servo._model.Model(config, spec, checked=False): the model without the core's configuration
checks, which the RTL benches use to drive chains whose kinematics saturate (tb/ts_core_fk)."""
import numpy as np
import pytest

from tensor_servo import _model, robots
from tensor_servo.model import STATUS_BITS, model_spec


def long_puma() -> dict:
    """PUMA 560 with 3.5 m offsets and no origin rotations: at q = 0 they add up to 21 m."""
    sp = model_spec(robots.load("puma560"))
    for j in sp["joints"]:
        j["origin_xyz"], j["origin_quat"] = [3.5, -3.5, 3.5], [1.0, 0.0, 0.0, 0.0]
    return sp


@pytest.mark.parametrize("cfg", ["default", "compact"])
def test_checked_refuses_the_reach(cfg):
    with pytest.raises(ValueError, match="reach exceeds"):
        _model.Model(cfg, long_puma())


@pytest.mark.parametrize("cfg", ["default", "compact"])
def test_unchecked_saturates_and_flags(cfg):
    m = _model.Model(cfg, long_puma(), checked=False)
    r = m.jacobian(np.zeros((1, m.n), dtype=np.int64), raw=True)
    flags = int(r["flags"][0])
    assert flags & STATUS_BITS["ovf_pos"] and flags & STATUS_BITS["ovf_lever"], hex(flags)
    # the tool's position is the largest pos_t value on the saturated axes, not a wrapped one
    w, i = _model.formats(cfg)["pos_t"]
    top = (1 << (w - 1)) - 1
    p = np.asarray(r["pos_raw"])[0, m.n + 1]
    assert p[0] == top and p[1] == -top - 1 and p[2] == top, p


@pytest.mark.parametrize("cfg", ["default", "compact"])
def test_unchecked_equals_checked_on_an_accepted_chain(cfg):
    sp = model_spec(robots.load("stanford"))
    a, b = _model.Model(cfg, sp), _model.Model(cfg, sp, checked=False)
    ca, cb = a.constants(), b.constants()
    assert ca.keys() == cb.keys()
    for k in ca:
        assert np.array_equal(np.asarray(ca[k]), np.asarray(cb[k])), k
    q = a.quantize_q(np.random.default_rng(7).uniform(-1.0, 1.0, (20, a.n)))["q_raw"]
    ra, rb = a.jacobian(q, raw=True), b.jacobian(q, raw=True)
    for k in ("J_raw", "pos_raw", "quat_raw", "flags"):
        assert np.array_equal(np.asarray(ra[k]), np.asarray(rb[k])), k


def test_unchecked_still_quantises_within_the_formats():
    sp = model_spec(robots.load("puma560"))
    sp["joints"][0]["scale"] = 5.0  # scale_t holds |s| < 4
    with pytest.raises(ValueError, match="scale"):
        _model.Model("default", sp, checked=False)
