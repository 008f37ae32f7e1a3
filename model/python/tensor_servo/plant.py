"""Plant for closed-loop simulation: the physical joints the servo core drives (float64).

    p = Plant(q0, dt=1e-3, tau=0.0, counts=None)
    q_meas = p.measure()        # what the core sees (encoder-quantised when ``counts`` is given)
    p.step(qd_cmd)              # one tick: the command is held for dt (zero-order hold)
    p.q, p.rate                 # true joint values and actual joint rates

Model, per joint i (double precision: it stands for the physical world, not for the core):

* Ideal joint-rate integrator (``tau = 0``): ``q(t + dt) = q(t) + dt * u``, u the command held over
  the tick.
* First-order actuator lag (``tau > 0``, s): the actual rate r follows the command,
  ``tau r' + r = u``.  Integrated exactly over the tick for a held u:
  ``r(t + dt) = u + (r - u) a``, ``q(t + dt) = q + u dt + (r - u) tau (1 - a)``, ``a = exp(-dt/tau)``.
* Encoder quantisation (``counts`` per joint unit, e.g. 2^20 / (2 pi) per rad): the measured value
  is the nearest count, ``round(q c) / c`` (error at most half a count).
* Optional mechanical stops (``lower``/``upper``): q is clamped and the rate zeroed at a stop.
  The tracking loop does not use them by default (a correct core never commands past a limit).

``tau``, ``counts``, ``lower`` and ``upper`` are scalars or one value per joint.  Bad parameters
raise :class:`InputError` naming the parameter.
"""
from __future__ import annotations

import math

import numpy as np

from .errors import InputError


def _per_joint(v, n: int, name: str, *, positive: bool = False, nonneg: bool = False) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    if a.ndim == 0:
        a = np.full(n, float(a))
    if a.shape != (n,):
        raise InputError(name, f"expected a scalar or {n} values, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(name, "not finite")
    if positive and not np.all(a > 0):
        raise InputError(name, "must be positive")
    if nonneg and not np.all(a >= 0):
        raise InputError(name, "must not be negative")
    return a


class Plant:
    """Joint-rate plant with optional first-order lag, encoder quantisation and stops."""

    def __init__(self, q0, dt: float, tau=0.0, counts=None, lower=None, upper=None):
        q0 = np.asarray(q0, dtype=float)
        if q0.ndim != 1 or q0.size == 0:
            raise InputError("q0", f"expected a vector of joint values, got shape {q0.shape}")
        if not np.all(np.isfinite(q0)):
            raise InputError("q0", "not finite")
        if not (isinstance(dt, (int, float, np.floating)) and math.isfinite(dt) and dt > 0):
            raise InputError("dt", f"must be a positive finite number (got {dt!r})")
        self.n = q0.size
        self.dt = float(dt)
        self.tau = _per_joint(tau, self.n, "tau", nonneg=True)
        self.counts = None if counts is None else _per_joint(counts, self.n, "counts", positive=True)
        self.lower = None if lower is None else _per_joint(lower, self.n, "lower")
        self.upper = None if upper is None else _per_joint(upper, self.n, "upper")
        if self.lower is not None and self.upper is not None and np.any(self.lower > self.upper):
            raise InputError("lower", "greater than upper")
        lag = self.tau > 0
        self._a = np.where(lag, np.exp(-self.dt / np.where(lag, self.tau, 1.0)), 0.0)
        self._b = np.where(lag, self.tau * (1.0 - self._a), 0.0)   # tau (1 - a)
        self.reset(q0)

    def reset(self, q0, rate=None) -> None:
        self.q = np.array(q0, dtype=float)
        self.rate = np.zeros(self.n) if rate is None else np.array(rate, dtype=float)
        self._clamp()

    def measure(self) -> np.ndarray:
        """The joint values the core sees."""
        if self.counts is None:
            return self.q.copy()
        return np.round(self.q * self.counts) / self.counts

    def step(self, u) -> np.ndarray:
        """Advance one tick with the command ``u`` held; returns the new true q."""
        u = np.asarray(u, dtype=float)
        if u.shape != (self.n,):
            raise InputError("qd", f"expected {self.n} joint rates, got shape {u.shape}")
        # tau = 0: a = 0, b = 0 -> q += u dt, rate = u (exact limit of the lag formulae)
        self.q = self.q + u * self.dt + (self.rate - u) * self._b
        self.rate = u + (self.rate - u) * self._a
        self._clamp()
        return self.q

    def _clamp(self) -> None:
        if self.lower is not None:
            low = self.q < self.lower
            self.q = np.where(low, self.lower, self.q)
            self.rate = np.where(low & (self.rate < 0), 0.0, self.rate)
        if self.upper is not None:
            high = self.q > self.upper
            self.q = np.where(high, self.upper, self.q)
            self.rate = np.where(high & (self.rate > 0), 0.0, self.rate)
