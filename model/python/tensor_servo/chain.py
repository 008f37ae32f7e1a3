"""Chain description: the data model, JSON load/save and validation (docs/chain-format.md).

Semantics (as URDF): the pose of the tool in the root frame is

    T(q) = base * prod_i (origin_i * M_i(q_i)) * tool

where ``M_i`` rotates by ``scale_i * q_i`` about ``axis_i`` (revolute) or translates by
``scale_i * q_i * axis_i`` (prismatic), ``axis_i`` being a unit vector in joint frame i.
Poses are ``{"xyz": [x, y, z], "quat_wxyz": [w, x, y, z]}``.

Loading validates every field and raises :class:`InputError` naming the field.  Quaternions and
axes are normalised when their norm is within ``UNIT_TOL`` of one (quaternions) or non-zero (axes);
quaternions further from unit norm are rejected.
"""
from __future__ import annotations

import json
import math
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .errors import InputError

#: relative tolerance on a quaternion norm: normalised within it, rejected beyond
UNIT_TOL = 1e-3
JOINT_TYPES = ("revolute", "prismatic")


@dataclass
class Pose:
    """A rigid transform: translation ``xyz`` (m) and unit quaternion ``quat_wxyz``."""

    xyz: np.ndarray = field(default_factory=lambda: np.zeros(3))
    quat_wxyz: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0, 0.0]))

    def to_dict(self) -> dict:
        return {"xyz": [float(v) for v in self.xyz], "quat_wxyz": [float(v) for v in self.quat_wxyz]}

    def matrix(self) -> np.ndarray:
        """4x4 homogeneous matrix."""
        T = np.eye(4)
        T[:3, :3] = quat_to_matrix(self.quat_wxyz)
        T[:3, 3] = self.xyz
        return T

    @staticmethod
    def from_matrix(T: np.ndarray) -> "Pose":
        return Pose(np.array(T[:3, 3], dtype=float), matrix_to_quat(T[:3, :3]))


@dataclass
class Limits:
    """Joint limits in joint units; ``lower``/``upper`` None = no position limit (continuous)."""

    lower: float | None = None
    upper: float | None = None
    velocity: float | None = None

    @property
    def bounded(self) -> bool:
        return self.lower is not None and self.upper is not None

    def to_dict(self) -> dict:
        return {"lower": self.lower, "upper": self.upper, "velocity": self.velocity}


@dataclass
class Joint:
    name: str
    type: str  # "revolute" | "prismatic"
    origin: Pose
    axis: np.ndarray
    limits: Limits = field(default_factory=Limits)
    scale: float = 1.0
    #: parent frame: None = the previous joint (serial chain), "base", or an earlier joint's name
    parent: str | None = None

    @property
    def prismatic(self) -> bool:
        return self.type == "prismatic"

    def to_dict(self) -> dict:
        d = {
            "name": self.name,
            "type": self.type,
            "origin": self.origin.to_dict(),
            "axis": [float(v) for v in self.axis],
            "limits": self.limits.to_dict(),
        }
        if self.scale != 1.0:
            d["scale"] = float(self.scale)
        if self.parent is not None:
            d["parent"] = self.parent
        return d


@dataclass
class Tip:
    """A frame fixed to a joint frame: one controlled frame of a tree of chains."""

    name: str
    parent: str  # joint name
    pose: Pose = field(default_factory=Pose)
    weight: float = 1.0  # row weight of this tip's task in the stacked solve

    def to_dict(self) -> dict:
        d = {"name": self.name, "parent": self.parent, **self.pose.to_dict()}
        if self.weight != 1.0:
            d["weight"] = float(self.weight)
        return d


@dataclass
class Chain:
    name: str
    joints: list[Joint]
    base: Pose = field(default_factory=Pose)
    tool: Pose = field(default_factory=Pose)
    #: trees of chains (seed section 12): several named tips; empty = serial chain with `tool`
    tips: list[Tip] = field(default_factory=list)

    @property
    def n(self) -> int:
        return len(self.joints)

    @property
    def is_serial(self) -> bool:
        return not self.tips and all(j.parent is None for j in self.joints)

    def parent_frames(self) -> list[int]:
        """Frame index of each joint's parent frame: 0 = base, k = joint k-1's frame (1-based)."""
        idx = {j.name: i for i, j in enumerate(self.joints)}
        return [i if j.parent is None else (0 if j.parent == "base" else idx[j.parent] + 1)
                for i, j in enumerate(self.joints)]

    def tip_list(self) -> list[Tip]:
        """The tips; a serial chain has one, the tool on the last joint."""
        return self.tips or [Tip("tool", self.joints[-1].name, self.tool)]

    @property
    def lower(self) -> np.ndarray:
        """Lower position limits (-inf where unlimited)."""
        return np.array([-np.inf if j.limits.lower is None else j.limits.lower for j in self.joints])

    @property
    def upper(self) -> np.ndarray:
        return np.array([np.inf if j.limits.upper is None else j.limits.upper for j in self.joints])

    @property
    def scales(self) -> np.ndarray:
        return np.array([j.scale for j in self.joints])

    def to_dict(self) -> dict:
        d = {
            "name": self.name,
            "units": {"length": "m", "angle": "rad"},
            "base": self.base.to_dict(),
        }
        if self.tips:
            d["tips"] = [t.to_dict() for t in self.tips]
        else:
            d["tool"] = self.tool.to_dict()
        d["joints"] = [j.to_dict() for j in self.joints]
        return d

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2) + "\n"

    def save(self, path: str | os.PathLike) -> None:
        write_atomic(path, self.to_json().encode())

    def random_q(self, rng: np.random.Generator, size: int | None = None, wrap: float = math.pi) -> np.ndarray:
        """Uniform random joint values within the limits (unlimited joints: within +-wrap)."""
        lo = np.where(np.isfinite(self.lower), self.lower, -wrap)
        hi = np.where(np.isfinite(self.upper), self.upper, wrap)
        shape = (self.n,) if size is None else (size, self.n)
        return rng.uniform(lo, hi, size=shape)


# ---- quaternion helpers (float) --------------------------------------------------------------

def quat_to_matrix(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def matrix_to_quat(R: np.ndarray) -> np.ndarray:
    """Unit quaternion (w >= 0) of a rotation matrix (Shepperd's method)."""
    R = np.asarray(R, dtype=float)
    tr = np.trace(R)
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        q = [0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s]
    elif R[0, 0] > R[1, 1] and R[0, 0] > R[2, 2]:
        s = 2.0 * math.sqrt(1.0 + R[0, 0] - R[1, 1] - R[2, 2])
        q = [(R[2, 1] - R[1, 2]) / s, 0.25 * s, (R[0, 1] + R[1, 0]) / s, (R[0, 2] + R[2, 0]) / s]
    elif R[1, 1] > R[2, 2]:
        s = 2.0 * math.sqrt(1.0 + R[1, 1] - R[0, 0] - R[2, 2])
        q = [(R[0, 2] - R[2, 0]) / s, (R[0, 1] + R[1, 0]) / s, 0.25 * s, (R[1, 2] + R[2, 1]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + R[2, 2] - R[0, 0] - R[1, 1])
        q = [(R[1, 0] - R[0, 1]) / s, (R[0, 2] + R[2, 0]) / s, (R[1, 2] + R[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    q /= np.linalg.norm(q)
    return q if q[0] >= 0 else -q


# ---- validation ----------------------------------------------------------------------------------

def _get(d: Any, key: str, where: str, required: bool = True, default: Any = None) -> Any:
    if not isinstance(d, dict):
        raise InputError(where, "expected an object")
    if key not in d:
        if required:
            raise InputError(f"{where}.{key}" if where else key, "missing")
        return default
    return d[key]


def _finite_vector(v: Any, n: int, where: str) -> np.ndarray:
    if not isinstance(v, (list, tuple)) or len(v) != n:
        raise InputError(where, f"expected a list of {n} numbers")
    out = []
    for x in v:
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            raise InputError(where, f"expected a list of {n} numbers")
        if not math.isfinite(x):
            raise InputError(where, "not finite")
        out.append(float(x))
    return np.array(out)


def _number(x: Any, where: str, allow_none: bool = False) -> float | None:
    if x is None and allow_none:
        return None
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        raise InputError(where, "expected a number")
    if not math.isfinite(x):
        raise InputError(where, "not finite")
    return float(x)


def unit_quat(v: Any, where: str) -> np.ndarray:
    q = _finite_vector(v, 4, where)
    nrm = float(np.linalg.norm(q))
    if abs(nrm - 1.0) > UNIT_TOL:
        raise InputError(where, f"quaternion norm {nrm:.6g} is not 1 (tolerance {UNIT_TOL:g})")
    return q / nrm


def unit_axis(v: Any, where: str) -> np.ndarray:
    a = _finite_vector(v, 3, where)
    nrm = float(np.linalg.norm(a))
    if nrm < 1e-9:
        raise InputError(where, "zero vector")
    return a / nrm


def pose_from_dict(d: Any, where: str) -> Pose:
    xyz = _finite_vector(_get(d, "xyz", where), 3, f"{where}.xyz")
    q = unit_quat(_get(d, "quat_wxyz", where), f"{where}.quat_wxyz")
    return Pose(xyz, q)


def joint_from_dict(d: Any, where: str) -> Joint:
    name = _get(d, "name", where)
    if not isinstance(name, str) or not name:
        raise InputError(f"{where}.name", "expected a non-empty string")
    jtype = _get(d, "type", where)
    if jtype not in JOINT_TYPES:
        raise InputError(f"{where}.type", f"must be one of {', '.join(JOINT_TYPES)} (got {jtype!r})")
    origin = pose_from_dict(_get(d, "origin", where), f"{where}.origin")
    axis = unit_axis(_get(d, "axis", where), f"{where}.axis")
    ld = _get(d, "limits", where, required=False, default={}) or {}
    if not isinstance(ld, dict):
        raise InputError(f"{where}.limits", "expected an object")
    lim = Limits(
        _number(ld.get("lower"), f"{where}.limits.lower", allow_none=True),
        _number(ld.get("upper"), f"{where}.limits.upper", allow_none=True),
        _number(ld.get("velocity"), f"{where}.limits.velocity", allow_none=True),
    )
    if (lim.lower is None) != (lim.upper is None):
        raise InputError(f"{where}.limits", "give both lower and upper, or neither (continuous joint)")
    if lim.bounded and lim.lower > lim.upper:
        raise InputError(f"{where}.limits", f"lower {lim.lower:g} > upper {lim.upper:g}")
    if jtype == "prismatic" and not lim.bounded:
        raise InputError(f"{where}.limits", "a prismatic joint needs lower and upper limits")
    if lim.velocity is not None and lim.velocity <= 0:
        raise InputError(f"{where}.limits.velocity", "must be positive")
    scale = _number(_get(d, "scale", where, required=False, default=1.0), f"{where}.scale")
    if scale == 0.0:
        raise InputError(f"{where}.scale", "must be non-zero")
    parent = _get(d, "parent", where, required=False, default=None)
    if parent is not None and (not isinstance(parent, str) or not parent):
        raise InputError(f"{where}.parent", "expected a joint name or \"base\"")
    return Joint(name, jtype, origin, axis, lim, scale, parent)


def tip_from_dict(d: Any, where: str) -> Tip:
    name = _get(d, "name", where)
    if not isinstance(name, str) or not name:
        raise InputError(f"{where}.name", "expected a non-empty string")
    parent = _get(d, "parent", where)
    if not isinstance(parent, str) or not parent:
        raise InputError(f"{where}.parent", "expected a joint name")
    pose = pose_from_dict(d, where)
    weight = _number(_get(d, "weight", where, required=False, default=1.0), f"{where}.weight")
    if not 0.0 < weight < 4.0:
        raise InputError(f"{where}.weight", "must lie in (0, 4)")
    return Tip(name, parent, pose, weight)


def chain_from_dict(d: Any) -> Chain:
    if not isinstance(d, dict):
        raise InputError("chain", "expected a JSON object at the top level")
    name = _get(d, "name", "")
    if not isinstance(name, str) or not name:
        raise InputError("name", "expected a non-empty string")
    units = _get(d, "units", "", required=False, default={"length": "m", "angle": "rad"})
    if not isinstance(units, dict):
        raise InputError("units", "expected an object")
    if units.get("length", "m") != "m":
        raise InputError("units.length", f"only 'm' is supported (got {units.get('length')!r})")
    if units.get("angle", "rad") != "rad":
        raise InputError("units.angle", f"only 'rad' is supported (got {units.get('angle')!r}); use a joint 'scale'")
    base = pose_from_dict(_get(d, "base", "", required=False, default={"xyz": [0, 0, 0], "quat_wxyz": [1, 0, 0, 0]}), "base")
    if "tips" in d and "tool" in d:
        raise InputError("tool", "give either 'tool' (serial chain) or 'tips' (tree), not both")
    tool = pose_from_dict(_get(d, "tool", "", required=False, default={"xyz": [0, 0, 0], "quat_wxyz": [1, 0, 0, 0]}), "tool")
    jl = _get(d, "joints", "")
    if not isinstance(jl, list) or not jl:
        raise InputError("joints", "expected a non-empty list")
    joints = [joint_from_dict(j, f"joints[{i}]") for i, j in enumerate(jl)]
    names = [j.name for j in joints]
    dup = sorted({x for x in names if names.count(x) > 1})
    if dup:
        raise InputError("joints", f"duplicate joint name {dup[0]!r}")
    for i, j in enumerate(joints):
        if j.parent is not None and j.parent != "base" and j.parent not in names[:i]:
            raise InputError(f"joints[{i}].parent", f"{j.parent!r} is not an earlier joint (or \"base\")")
    tips = []
    if "tips" in d:
        tl = d["tips"]
        if not isinstance(tl, list) or not tl:
            raise InputError("tips", "expected a non-empty list")
        tips = [tip_from_dict(t, f"tips[{i}]") for i, t in enumerate(tl)]
        for i, t in enumerate(tips):
            if t.parent not in names:
                raise InputError(f"tips[{i}].parent", f"no joint named {t.parent!r}")
        tn = [t.name for t in tips]
        if len(set(tn)) != len(tn):
            raise InputError("tips", "duplicate tip name")
    return Chain(name, joints, base, tool, tips)


def load(path: str | os.PathLike) -> Chain:
    """Load and validate a chain JSON file, or an embedded example by name (see robots.names())."""
    p = Path(path)
    if not p.exists():
        from . import robots

        if str(path) in robots.names() or str(path) in robots.tree_names():
            return robots.load(str(path))
        raise InputError(str(path), "no such file")
    try:
        d = json.loads(p.read_text())
    except UnicodeDecodeError:
        raise InputError(str(path), "not a text file") from None
    except json.JSONDecodeError as e:
        raise InputError(str(path), f"malformed JSON at line {e.lineno} column {e.colno}: {e.msg}") from None
    return chain_from_dict(d)


def write_atomic(path: str | os.PathLike, data: bytes) -> None:
    """Write a file atomically: a temporary file in the same folder, then rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=str(path.parent))
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the file the usual mode
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


# ---- helpers for tools that write chains (importers, examples) ------------------------------------

def reach(chain: Chain) -> float:
    """Bound on the distance between two frame origins of the chain, from the first joint frame on:
    sum of |origin xyz|, |tool xyz| and prismatic strokes (|scale| * max(|lower|, |upper|)).
    The same bound as the C++ model's ``chain_reach`` (it is checked against the lever-arm format)."""
    r = float(np.linalg.norm(chain.tool.xyz))
    for j in chain.joints:
        r += float(np.linalg.norm(j.origin.xyz))
        if j.prismatic and j.limits.bounded:
            r += abs(j.scale) * max(abs(j.limits.lower), abs(j.limits.upper))
    return r


def _is_stable_unit(v: np.ndarray) -> bool:
    return bool(np.array_equal(v / float(np.linalg.norm(v)), v))


def _stable_unit(v: np.ndarray) -> np.ndarray:
    """``v / |v|``, moved by a few ulps if needed so that normalising it again returns it unchanged.

    The loader normalises every quaternion and axis; for about 2 % of unit vectors that is not
    exactly idempotent in floating point, so a saved chain would not read back bit-identical."""
    u = np.asarray(v, dtype=float)
    for _ in range(4):
        if _is_stable_unit(u):
            return u
        u = u / float(np.linalg.norm(u))
    for k in range(1, 8):
        for i in np.argsort(-np.abs(u)):
            for direction in (np.inf, -np.inf):
                w = u.copy()
                for _ in range(k):
                    w[i] = np.nextafter(w[i], direction)
                if _is_stable_unit(w):
                    return w
    return u  # not reached in practice; the round trip is then off by one ulp


def canonical(chain: Chain, eps: float = 1e-15) -> Chain:
    """The chain as it will read back from its own JSON, validated.

    Components of xyz, quaternions and axes with magnitude below ``eps`` are set to 0 (they are
    rounding residue of importers, e.g. cos(pi/2)); quaternions and axes are normalised so that
    ``chain_from_dict(json.loads(c.to_json()))`` reproduces ``c`` exactly.  Raises InputError if the
    chain is not valid (the message names the field as in the JSON file)."""
    def clean(v: np.ndarray) -> np.ndarray:
        v = np.array(v, dtype=float)
        v[np.abs(v) < eps] = 0.0
        return v

    def pose(p: Pose) -> Pose:
        q = clean(p.quat_wxyz)
        return Pose(clean(p.xyz), _stable_unit(q) if np.any(q) else q)

    joints = [Joint(j.name, j.type, pose(j.origin), _stable_unit(a) if np.any(a := clean(j.axis)) else a,
                    Limits(j.limits.lower, j.limits.upper, j.limits.velocity), j.scale, j.parent)
              for j in chain.joints]
    tips = [Tip(t.name, t.parent, pose(t.pose), t.weight) for t in chain.tips]
    c = Chain(chain.name, joints, pose(chain.base), pose(chain.tool), tips)
    return chain_from_dict(json.loads(c.to_json()))
