"""Rebuild the embedded example chains.

    python -m tensor_servo.robots.regenerate           # rewrite robots/*.json
    python -m tensor_servo.robots.regenerate --check   # exit 1 if a file is out of date

puma560, ur5, panda and stanford come from their DH tables in ``dh/`` (through ``tservo chain
from-dh``'s converter, tensor_servo.dh); chain20 is synthetic and built by :func:`chain20` below.
"""
from __future__ import annotations

import argparse
import json
import math
import sys

import numpy as np

from .. import dh
from ..chain import Chain, Joint, Limits, Pose, canonical, write_atomic
from . import HERE

DH_DIR = HERE / "dh"


def _rpy(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """Rotation Rz(yaw) Ry(pitch) Rx(roll) (URDF's fixed-axis roll-pitch-yaw)."""
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch),
                              math.cos(yaw), math.sin(yaw))
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def _pose(xyz, rpy) -> Pose:
    T = np.eye(4)
    T[:3, :3] = _rpy(*rpy)
    T[:3, 3] = xyz
    return Pose.from_matrix(T)


#: chain20: joint indices of the prismatic and of the continuous (unlimited revolute) joints
CHAIN20_PRISMATIC = (5, 13)
CHAIN20_CONTINUOUS = (3, 11, 19)


def chain20() -> Chain:
    """A synthetic 20-joint test chain.

    Deterministic closed-form parameters (no random generator, so the file does not depend on a
    library version), rounded to a few decimals: every axis is oblique (no component is 0), every
    origin is rotated, 2 joints are prismatic and 3 revolute joints are continuous; origins are
    about 0.1 m long so that the reach stays near 2.5 m, within the compact format's +-4 m
    lever-arm range.
    """
    joints = []
    for i in range(20):
        axis = np.round([math.cos(2.4 * i + 0.5), math.sin(1.3 * i + 0.2), 0.8 + 0.4 * math.cos(0.7 * i)], 3)
        axis[np.abs(axis) < 0.05] = 0.05  # keep every component non-zero (oblique axes)
        xyz = np.round([0.06 * math.cos(1.1 * i), 0.05 * math.sin(0.9 * i + 1.0), 0.07 + 0.02 * math.sin(1.7 * i)], 4)
        rpy = np.round([0.4 * math.sin(i + 0.5), 0.3 * math.cos(1.3 * i), 0.5 * math.sin(0.7 * i + 0.4)], 3)
        if i in CHAIN20_PRISMATIC:
            jtype = "prismatic"
            lower, upper = (-0.05, 0.15) if i == CHAIN20_PRISMATIC[0] else (0.0, 0.2)
            velocity = 0.25 if i == CHAIN20_PRISMATIC[0] else 0.4
        elif i in CHAIN20_CONTINUOUS:
            jtype, lower, upper, velocity = "revolute", None, None, 3.0
        else:
            jtype = "revolute"
            lower = -round(1.5 + 1.2 * abs(math.sin(0.9 * i)), 3)
            upper = round(1.2 + 1.5 * abs(math.cos(0.6 * i)), 3)
            velocity = round(1.5 + 0.1 * (i % 10), 2)
        joints.append(Joint(f"j{i + 1}", jtype, _pose(xyz, rpy), axis / np.linalg.norm(axis),
                            Limits(lower, upper, velocity)))
    base = _pose([0.1, -0.05, 0.2], [0.0, 0.0, 0.3])
    tool = _pose([0.02, -0.01, 0.06], [0.0, 0.3, 0.2])
    return canonical(Chain("chain20", joints, base, tool))


def build() -> dict[str, str]:
    """name -> JSON text of every embedded example."""
    out = {p.stem: dh.load(p).to_json() for p in sorted(DH_DIR.glob("*.json"))}
    out["chain20"] = chain20().to_json()
    return out


#: last-place tolerance of up_to_date: the generator's few derived floats (normalised axes, rotations)
#: go through numpy and BLAS, whose kernels (AVX2, AVX-512, FMA) round the last bit differently
#: from one CPU to another
ULPS = 4


def _same(a, b) -> bool:
    if float in (type(a), type(b)):     # a JSON number on either side (type(), so a bool is no number)
        return {type(a), type(b)} <= {int, float} and abs(a - b) <= ULPS * math.ulp(max(abs(a), abs(b)))
    if isinstance(a, dict) and isinstance(b, dict):
        return list(a) == list(b) and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    return type(a) is type(b) and a == b


def up_to_date(committed: str, built: str) -> bool:
    """True if the committed JSON text is what the generator built: the same keys, order, strings
    and integers, and every float within ULPS units in the last place (so a file generated on
    another CPU is not stale, but any real change is)."""
    return committed == built or _same(json.loads(committed), json.loads(built))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tensor_servo.robots.regenerate", description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="only check that the files are up to date")
    args = ap.parse_args(argv)
    stale = []
    for name, text in build().items():
        path = HERE / f"{name}.json"
        if path.exists() and up_to_date(path.read_text(), text):
            continue
        stale.append(name)
        if not args.check:
            write_atomic(path, text.encode())
            print(f"wrote {path}")
    if args.check and stale:
        print(f"out of date: {', '.join(stale)} (run python -m tensor_servo.robots.regenerate)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
