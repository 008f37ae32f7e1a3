"""Python API of the bit-accurate C++ model (the compiled module ``tensor_servo._model``).

    m = Model(chain, "default")          # "double", "default" or "compact"
    fk = m.fk(q)                         # q: (N, n) float joint values
    fk.T        (N, n+2, 4, 4) poses of every frame: base, joint 1..n (after motion), tool
    fk.quat_raw (N, n+2, 4)    raw integers (fixed-point configurations)
    jac = m.jacobian(q, ref="tool", basis="base")
    jac.J       (N, 6, n) rows (omega; v), reference point = origin of `ref`, axes of `basis`

Frame indices: 0 = base, 1..n = joint frames, n+1 = tool; basis "base" means the root frame's axes
(the URDF's base link), "tool" the tool frame's, an int k the axes of frame k.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _model
from .chain import Chain
from .errors import InputError

CONFIGS = tuple(_model.CONFIGS)
FIXED_CONFIGS = ("default", "compact")

#: status bits (fixed.hpp StatusBit)
STATUS_BITS = {
    "ovf_angle": 1 << 0, "ovf_turn": 1 << 1, "ovf_trig": 1 << 2, "ovf_quat": 1 << 3, "ovf_pos": 1 << 4,
    "ovf_lever": 1 << 5, "ovf_jac": 1 << 6, "ovf_const": 1 << 7, "ovf_solver": 1 << 8, "ovf_servo": 1 << 9,
    "limit_active": 1 << 16, "vlimit_active": 1 << 17,
}
OVF_MASK = 0xFFFF


def model_spec(chain: Chain) -> dict:
    """The chain as the C++ model's ChainSpec (a plain dict)."""
    joints = []
    parents = chain.parent_frames()
    for i, j in enumerate(chain.joints):
        lim = j.limits
        joints.append({
            "prismatic": j.prismatic,
            "origin_quat": [float(v) for v in j.origin.quat_wxyz],
            "origin_xyz": [float(v) for v in j.origin.xyz],
            "axis": [float(v) for v in j.axis],
            "scale": float(j.scale),
            "limited": lim.bounded,
            "lower": float(lim.lower) if lim.bounded else 0.0,
            "upper": float(lim.upper) if lim.bounded else 0.0,
            "velocity": float(lim.velocity) if lim.velocity is not None else 0.0,
            "parent": -2 if j.parent is None else parents[i] - 1,
        })
    spec = {
        "base_quat": [float(v) for v in chain.base.quat_wxyz], "base_xyz": [float(v) for v in chain.base.xyz],
        "tool_quat": [float(v) for v in chain.tool.quat_wxyz], "tool_xyz": [float(v) for v in chain.tool.xyz],
        "joints": joints,
    }
    if chain.tips:
        idx = {j.name: i for i, j in enumerate(chain.joints)}
        spec["tips"] = [{"parent": idx[t.parent], "quat": [float(v) for v in t.pose.quat_wxyz],
                         "xyz": [float(v) for v in t.pose.xyz]} for t in chain.tips]
    return spec


def check_config(chain: Chain) -> dict[str, str | None]:
    """For each configuration: None if the chain fits its formats, else the one-line reason."""
    out = {}
    spec = model_spec(chain)
    for cfg in CONFIGS:
        try:
            _model.Model(cfg, spec)
            out[cfg] = None
        except ValueError as e:
            out[cfg] = str(e)
    return out


def formats(config: str) -> dict[str, tuple[int, int]]:
    """Formats of a fixed-point configuration: signal name -> (W, I) as in ap_fixed<W, I>."""
    return {k: v for k, v in _model.formats(config).items() if isinstance(v, tuple)}


def quat_to_matrices(quat: np.ndarray) -> np.ndarray:
    """Rotation matrices of (..., 4) quaternions (w, x, y, z); normalised first (presentation only)."""
    q = quat / np.linalg.norm(quat, axis=-1, keepdims=True)
    w, x, y, z = np.moveaxis(q, -1, 0)
    R = np.empty(q.shape[:-1] + (3, 3))
    R[..., 0, 0] = 1 - 2 * (y * y + z * z); R[..., 0, 1] = 2 * (x * y - w * z); R[..., 0, 2] = 2 * (x * z + w * y)
    R[..., 1, 0] = 2 * (x * y + w * z); R[..., 1, 1] = 1 - 2 * (x * x + z * z); R[..., 1, 2] = 2 * (y * z - w * x)
    R[..., 2, 0] = 2 * (x * z - w * y); R[..., 2, 1] = 2 * (y * z + w * x); R[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return R


def poses(quat: np.ndarray, pos: np.ndarray) -> np.ndarray:
    T = np.zeros(quat.shape[:-1] + (4, 4))
    T[..., :3, :3] = quat_to_matrices(quat)
    T[..., :3, 3] = pos
    T[..., 3, 3] = 1.0
    return T


@dataclass
class FKResult:
    quat: np.ndarray          # (N, n+2, 4) float
    pos: np.ndarray           # (N, n+2, 3) float
    axis: np.ndarray          # (N, n, 3) joint axes in the root frame
    flags: np.ndarray         # (N,) uint32 sticky status
    quat_raw: np.ndarray | None = None
    pos_raw: np.ndarray | None = None
    axis_raw: np.ndarray | None = None

    @property
    def T(self) -> np.ndarray:
        return poses(self.quat, self.pos)

    @property
    def overflow(self) -> np.ndarray:
        return (self.flags & OVF_MASK) != 0


@dataclass
class JacobianResult:
    J: np.ndarray             # (N, 6, n)
    quat: np.ndarray
    pos: np.ndarray
    flags: np.ndarray
    J_raw: np.ndarray | None = None
    quat_raw: np.ndarray | None = None
    pos_raw: np.ndarray | None = None

    @property
    def T(self) -> np.ndarray:
        return poses(self.quat, self.pos)

    @property
    def overflow(self) -> np.ndarray:
        return (self.flags & OVF_MASK) != 0


class Model:
    """The bit-accurate model of one chain in one number configuration."""

    def __init__(self, chain: Chain, config: str = "default"):
        if config not in CONFIGS:
            raise InputError("--model/config", f"unknown configuration {config!r} ({', '.join(CONFIGS)})")
        self.chain = chain
        self.config = config
        try:
            self._m = _model.Model(config, model_spec(chain))
        except ValueError as e:
            raise InputError("chain", f"does not fit the {config} configuration: {e}") from None
        self.n = chain.n

    @property
    def fixed(self) -> bool:
        return self.config != "double"

    def frame_index(self, frame: str | int, what: str) -> int:
        """'base' -> -1 (root axes) for a basis; 'tool' -> n+1; ints pass through (checked)."""
        if frame == "tool":
            return self.n + 1
        if frame == "base" and what == "basis":
            return -1
        last = self.n + len(self.chain.tip_list())
        if isinstance(frame, (int, np.integer)) and 0 <= int(frame) <= last:
            return int(frame)
        raise InputError(what, f"expected 'base', 'tool' or a frame index 0..{last} (got {frame!r})")

    def quantize_q(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Raw joint values and a per-sample flag 'representable' (no saturation)."""
        d = self._m.quantize_q(np.atleast_2d(np.asarray(q, dtype=np.float64)))
        return d["q_raw"], d["ok"]

    def fk(self, q: np.ndarray, raw: bool = False) -> FKResult:
        q2 = np.atleast_2d(q)
        d = self._m.fk(np.asarray(q2, dtype=np.int64 if raw else np.float64), raw)
        return FKResult(d["quat"], d["pos"], d["axis"], d["flags"], d.get("quat_raw"), d.get("pos_raw"), d.get("axis_raw"))

    def jacobian(self, q: np.ndarray, ref: str | int = "tool", basis: str | int = "base", raw: bool = False) -> JacobianResult:
        q2 = np.atleast_2d(q)
        r = self.frame_index(ref, "ref")
        if r < 1:
            raise InputError("ref", "the reference point must be a joint frame or the tool")
        b = self.frame_index(basis, "basis")
        d = self._m.jacobian(np.asarray(q2, dtype=np.int64 if raw else np.float64), raw, r, b)
        return JacobianResult(d["J"], d["quat"], d["pos"], d["flags"], d.get("J_raw"), d.get("quat_raw"), d.get("pos_raw"))

    def constants(self) -> dict[str, np.ndarray]:
        """Raw quantised constants of the chain (fixed-point configurations)."""
        return dict(self._m.constants())
