"""Denavit-Hartenberg tables -> Chain (the table format is described in docs/chain-format.md).

Conventions, for row i (all transforms right-multiplied):

    standard (Denavit-Hartenberg, Paul):  A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)
    modified (Craig):                     A_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i)

    T(q) = base * A_1 * ... * A_n * tool

A revolute row has theta_i = s_i q_i + offset_i (its ``d`` is constant); a prismatic row has
d_i = s_i q_i + offset_i (its ``theta`` is constant); s_i is the joint's ``scale`` (default 1).
In a modified table the ``a`` and ``alpha`` of row i are a_{i-1} and alpha_{i-1}, as in Craig's
tables.

Mapping onto the chain T(q) = base * prod_i(origin_i * M_i(q_i)) * tool, where M_i rotates about or
translates along z: the joint motion Rz(s_i q_i) (or Tz(s_i q_i)) commutes with the Rz/Tz factors around it,
so with the constant part L_i of each row

    standard: A_i = M_i(q_i) * L_i,  L_i = Rz(theta_c) Tz(d_c) Tx(a_i) Rx(alpha_i)
              -> origin_1 = I, origin_{i+1} = L_i, chain tool = L_n * tool
    modified: A_i = L_i * M_i(q_i),  L_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_c) Tz(d_c)
              -> origin_i = L_i, chain tool = tool

(theta_c, d_c) = (offset_i, d_i) for a revolute row and (theta_i, offset_i) for a prismatic one.
"""
from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .chain import JOINT_TYPES, Chain, Joint, Limits, Pose, _get, _number, canonical, pose_from_dict
from .errors import InputError

CONVENTIONS = ("standard", "modified")
ANGLE_UNITS = {"rad": 1.0, "deg": math.pi / 180.0}

_TOP_KEYS = {"name", "convention", "units", "base", "tool", "joints", "source", "comment"}
_ROW_KEYS = {"name", "type", "a", "alpha", "d", "theta", "offset", "limits", "scale", "comment"}
_LIMIT_KEYS = {"lower", "upper", "velocity"}


@dataclass
class DHRow:
    """One joint of a DH table, in SI units (m, rad)."""

    name: str
    type: str          # "revolute" | "prismatic"
    a: float
    alpha: float
    d: float           # constant part of d (revolute); ignored for prismatic (d = q + offset)
    theta: float       # constant part of theta (prismatic); ignored for revolute (theta = q + offset)
    offset: float = 0.0
    limits: Limits = field(default_factory=Limits)
    scale: float = 1.0

    @property
    def prismatic(self) -> bool:
        return self.type == "prismatic"


@dataclass
class DHTable:
    name: str
    convention: str    # "standard" | "modified"
    rows: list[DHRow]
    base: Pose = field(default_factory=Pose)
    tool: Pose = field(default_factory=Pose)


# ---- elementary transforms -----------------------------------------------------------------------

def link_standard(theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    """Rz(theta) Tz(d) Tx(a) Rx(alpha)."""
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, a * ct],
                     [st, ct * ca, -ct * sa, a * st],
                     [0.0, sa, ca, d],
                     [0.0, 0.0, 0.0, 1.0]])


def link_modified(alpha: float, a: float, theta: float, d: float) -> np.ndarray:
    """Rx(alpha) Tx(a) Rz(theta) Tz(d)."""
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return np.array([[ct, -st, 0.0, a],
                     [st * ca, ct * ca, -sa, -sa * d],
                     [st * sa, ct * sa, ca, ca * d],
                     [0.0, 0.0, 0.0, 1.0]])


def row_matrix(row: DHRow, convention: str, q: float = 0.0) -> np.ndarray:
    """A_i(q) of one row, q in joint units (the joint variable is scale * q + offset)."""
    v = row.scale * q + row.offset
    theta = row.theta if row.prismatic else v
    d = v if row.prismatic else row.d
    if convention == "standard":
        return link_standard(theta, d, row.a, row.alpha)
    return link_modified(row.alpha, row.a, theta, d)


# ---- table -> chain ------------------------------------------------------------------------------

def to_chain(table: DHTable) -> Chain:
    """The chain of a DH table (validated, in the canonical form that round-trips through JSON)."""
    z = np.array([0.0, 0.0, 1.0])
    consts = []  # L_i: the row with its joint variable set to zero (the offset stays)
    for r in table.rows:
        theta_c = r.theta if r.prismatic else r.offset
        d_c = r.offset if r.prismatic else r.d
        if table.convention == "standard":
            consts.append(link_standard(theta_c, d_c, r.a, r.alpha))
        else:
            consts.append(link_modified(r.alpha, r.a, theta_c, d_c))
    if table.convention == "standard":
        origins = [np.eye(4)] + consts[:-1]
        tool = consts[-1] @ table.tool.matrix()
    else:
        origins = consts
        tool = table.tool.matrix()
    joints = [Joint(r.name, r.type, Pose.from_matrix(origins[i]), z.copy(),
                    Limits(r.limits.lower, r.limits.upper, r.limits.velocity), r.scale)
              for i, r in enumerate(table.rows)]
    return canonical(Chain(table.name, joints, table.base, Pose.from_matrix(tool)))


# ---- JSON table ----------------------------------------------------------------------------------

def _reject_unknown(d: dict, allowed: set[str], where: str) -> None:
    for k in d:
        if k not in allowed:
            raise InputError(f"{where}.{k}" if where else k, f"unknown key (allowed: {', '.join(sorted(allowed))})")


def _row_from_dict(d: Any, where: str, angle: float) -> DHRow:
    if not isinstance(d, dict):
        raise InputError(where, "expected an object")
    _reject_unknown(d, _ROW_KEYS, where)
    name = _get(d, "name", where)
    if not isinstance(name, str) or not name:
        raise InputError(f"{where}.name", "expected a non-empty string")
    jtype = _get(d, "type", where)
    if jtype not in JOINT_TYPES:
        raise InputError(f"{where}.type", f"must be one of {', '.join(JOINT_TYPES)} (got {jtype!r})")
    prismatic = jtype == "prismatic"
    # the joint variable replaces theta (revolute) or d (prismatic): that column must not be given
    variable, constant = ("d", "theta") if prismatic else ("theta", "d")
    if variable in d:
        raise InputError(f"{where}.{variable}", f"is the joint variable of a {jtype} joint; give its zero "
                                                f"position as 'offset'")
    a = _number(_get(d, "a", where), f"{where}.a")
    alpha = _number(_get(d, "alpha", where), f"{where}.alpha") * angle
    c = _number(_get(d, constant, where), f"{where}.{constant}")
    offset = _number(_get(d, "offset", where, required=False, default=0.0), f"{where}.offset")
    ld = _get(d, "limits", where, required=False, default={}) or {}
    if not isinstance(ld, dict):
        raise InputError(f"{where}.limits", "expected an object")
    _reject_unknown(ld, _LIMIT_KEYS, f"{where}.limits")
    scale = _number(_get(d, "scale", where, required=False, default=1.0), f"{where}.scale")
    # limits are in joint units: m and m/s (prismatic), the table's angle unit (revolute), or, with
    # a scale, whatever unit the scale converts from (then they are not converted)
    unit = 1.0 if prismatic or scale != 1.0 else angle
    lim = []
    for k in ("lower", "upper", "velocity"):
        v = _number(ld.get(k), f"{where}.limits.{k}", allow_none=True)
        lim.append(None if v is None else v * unit)
    if prismatic:
        return DHRow(name, jtype, a, alpha, 0.0, c * angle, offset, Limits(*lim), scale)
    return DHRow(name, jtype, a, alpha, c, 0.0, offset * angle, Limits(*lim), scale)


def table_from_dict(d: Any) -> DHTable:
    """Validate a DH table (parsed JSON); angles are converted to rad."""
    if not isinstance(d, dict):
        raise InputError("table", "expected a JSON object at the top level")
    _reject_unknown(d, _TOP_KEYS, "")
    name = _get(d, "name", "")
    if not isinstance(name, str) or not name:
        raise InputError("name", "expected a non-empty string")
    conv = _get(d, "convention", "")
    if conv not in CONVENTIONS:
        raise InputError("convention", f"must be one of {', '.join(CONVENTIONS)} (got {conv!r})")
    units = _get(d, "units", "", required=False, default={})
    if not isinstance(units, dict):
        raise InputError("units", "expected an object")
    _reject_unknown(units, {"length", "angle"}, "units")
    if units.get("length", "m") != "m":
        raise InputError("units.length", f"only 'm' is supported (got {units.get('length')!r})")
    if units.get("angle", "rad") not in ANGLE_UNITS:
        raise InputError("units.angle", f"must be 'rad' or 'deg' (got {units.get('angle')!r})")
    angle = ANGLE_UNITS[units.get("angle", "rad")]
    identity = {"xyz": [0, 0, 0], "quat_wxyz": [1, 0, 0, 0]}
    base = pose_from_dict(_get(d, "base", "", required=False, default=identity), "base")
    tool = pose_from_dict(_get(d, "tool", "", required=False, default=identity), "tool")
    jl = _get(d, "joints", "")
    if not isinstance(jl, list) or not jl:
        raise InputError("joints", "expected a non-empty list")
    rows = [_row_from_dict(r, f"joints[{i}]", angle) for i, r in enumerate(jl)]
    return DHTable(name, conv, rows, base, tool)


def read_json(path: str | os.PathLike) -> Any:
    """Parse a JSON file; InputError (naming the file) if it is missing or malformed."""
    p = Path(path)
    if not p.is_file():
        raise InputError(str(path), "no such file")
    try:
        return json.loads(p.read_text())
    except UnicodeDecodeError:
        raise InputError(str(path), "not a text file") from None
    except json.JSONDecodeError as e:
        raise InputError(str(path), f"malformed JSON at line {e.lineno} column {e.colno}: {e.msg}") from None


def load_table(path: str | os.PathLike) -> DHTable:
    return table_from_dict(read_json(path))


def load(path: str | os.PathLike) -> Chain:
    """Read a DH table file and convert it to a chain."""
    return to_chain(load_table(path))
