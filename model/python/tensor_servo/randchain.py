"""Random open chains for tests: arbitrary origins and axes, mixed joint types and scales.

    random_chain(rng, n) -> Chain
"""
from __future__ import annotations

import math

import numpy as np

from .chain import Chain, Joint, Limits, Pose


def random_unit(rng, n):
    """A random unit vector of n components."""
    v = rng.normal(size=n)
    return v / np.linalg.norm(v)


def _rand_pose(rng, lo=0.05, hi=0.5):
    return Pose(random_unit(rng, 3) * rng.uniform(lo, hi), random_unit(rng, 4))


def random_chain(rng, n: int, velocity: float | None = None, scales: tuple[float, float] | None = None,
                 offset: tuple[float, float] = (0.05, 0.5)) -> Chain:
    """Random unit-quaternion origins, random axes, offsets ``offset`` m (0.05-0.5), ~1/3 prismatic
    joints, non-identity base and tool, non-unit (also negative / degree-like) scales on some
    joints.  ``velocity``: a velocity limit (joint units/s) on every joint; ``scales`` (a, b):
    every scale of magnitude in [a, b], random sign, instead (for narrow joint-value formats)."""
    joints = []
    for i in range(n):
        prismatic = rng.random() < 0.35
        u = rng.random()
        if scales is not None:
            scale = float(rng.choice([-1, 1]) * rng.uniform(*scales))
        else:
            scale = 1.0 if u < 0.4 else (math.pi / 180 if u < 0.6 else float(rng.choice([-1, 1]) * rng.uniform(0.2, 3.0)))
        reach = 0.5 if prismatic else math.pi          # range of scale*q
        v = None if velocity is None else velocity / abs(scale)
        lim = Limits(-reach / abs(scale), reach / abs(scale), v)
        joints.append(Joint(f"j{i}", "prismatic" if prismatic else "revolute", _rand_pose(rng, *offset), random_unit(rng, 3),
                            lim, scale))
    return Chain(f"rand{n}", joints, _rand_pose(rng, 2 * offset[0], 2 * offset[1]), _rand_pose(rng, *offset))
