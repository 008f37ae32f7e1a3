"""Accuracy of the bit-accurate model against the independent oracle (Pinocchio).

``measure(chain, config, samples, seed)`` draws joint values uniformly within the limits
(continuous joints: +-pi), evaluates the model and Pinocchio at the *same* (quantised) joint values,
and returns the worst errors over all samples:

    pos     max |p_model - p_pin| (m), tool origin, component-wise max
    rot     max rotation angle (rad) between the tool orientations (model quaternion normalised)
    jac     max |J_model - J_pin| over all elements, tool origin, root axes, rows (omega; v)
    jac_tool  the same in the tool frame's axes
    qnorm   max | |q_tool| - 1 | of the model's raw tool quaternion (drift indicator)

Joint values are quantised to the model's angle format first, so input quantisation is not
counted as an error; geometry (offsets, axes, origin rotations) is quantised by the model and
*is* counted, as it is part of what the core computes.
"""
from __future__ import annotations

import functools

import numpy as np

from .chain import Chain
from .model import Model, formats
from .oracle import PinChain

METRICS = ("pos", "rot", "jac", "jac_tool", "qnorm")

#: the measurement published in docs/numerics.md and enforced by the tests
SAMPLES = 10_000
SEED = 1
#: accuracy goals of the default configuration (issue: FK 5 um / 10 urad, Jacobian 1e-5)
GOALS = {"pos": 5e-6, "rot": 10e-6, "jac": 1e-5, "jac_tool": 1e-5}
#: bounds every example chain must meet (about twice the worst measured; docs/numerics.md)
BOUNDS = {
    "default": {"pos": 3e-6, "rot": 2e-6, "jac": 3e-6, "jac_tool": 4e-6},
    "compact": {"pos": 1e-3, "rot": 1e-3, "jac": 1e-3, "jac_tool": 2e-3},
}


def rotation_angle(Ra: np.ndarray, Rb: np.ndarray) -> np.ndarray:
    """Angle of Ra Rb^T for stacks of rotation matrices (robust near 0)."""
    D = Ra @ np.swapaxes(Rb, -1, -2)
    skew = np.stack([D[..., 2, 1] - D[..., 1, 2], D[..., 0, 2] - D[..., 2, 0], D[..., 1, 0] - D[..., 0, 1]], -1)
    s = 0.5 * np.linalg.norm(skew, axis=-1)
    c = 0.5 * (np.trace(D, axis1=-2, axis2=-1) - 1.0)
    return np.arctan2(s, c)


def measure(chain: Chain, config: str, samples: int = 10000, seed: int = 1) -> dict[str, float]:
    m = Model(chain, config)
    rng = np.random.default_rng(seed)
    q = chain.random_q(rng, samples)
    if m.fixed:
        q_raw, ok = m.quantize_q(q)
        assert ok.all()
        W, I = formats(config)["angle_t"]
        q = q_raw.astype(np.float64) * 2.0 ** -(W - I)
    jb = m.jacobian(q, basis="base")
    jt = m.jacobian(q, basis="tool")
    pin = PinChain(chain)
    Tp = np.empty((samples, 4, 4))
    Jp = np.empty((samples, 6, chain.n))
    Jpt = np.empty((samples, 6, chain.n))
    for s in range(samples):
        Jp[s] = pin.jacobian(q[s], "base")
        Jpt[s] = pin.jacobian(q[s], "tool")
        Tp[s] = pin.tool_pose(q[s])
    T = jb.T[:, -1]
    return {
        "pos": float(np.abs(T[:, :3, 3] - Tp[:, :3, 3]).max()),
        "rot": float(rotation_angle(T[:, :3, :3], Tp[:, :3, :3]).max()),
        "jac": float(np.abs(jb.J - Jp).max()),
        "jac_tool": float(np.abs(jt.J - Jpt).max()),
        "qnorm": float(np.abs(np.linalg.norm(jb.quat[:, -1], axis=-1) - 1.0).max()),
        "overflow": int((jb.overflow | jt.overflow).sum()),
    }


@functools.lru_cache(maxsize=None)
def measure_example(name: str, config: str) -> dict[str, float]:
    """``measure`` on an embedded example with the published sample count and seed (cached)."""
    from . import robots

    return measure(robots.load(name), config, SAMPLES, SEED)
