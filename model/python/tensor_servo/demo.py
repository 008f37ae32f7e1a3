"""``make demo``: the main job on the embedded default robot (PUMA 560).

Forward kinematics and the screw-transport Jacobian of the PUMA 560 in float (the numpy reference,
the seed's construction) and in the two fixed-point configurations of the bit-accurate model, side
by side, with the measured error against the float reference and against Pinocchio.
"""
from __future__ import annotations

import sys

import numpy as np

from . import reference, robots
from .accuracy import measure, rotation_angle
from .model import Model, formats


def _fmt_vec(v) -> str:
    return "[" + ", ".join(f"{x:+.7f}" for x in v) + "]"


def main(argv: list[str] | None = None) -> int:
    name = (argv or sys.argv[1:] or ["puma560"])[0]
    ch = robots.load(name)
    print(f"tensor-servo demo: {ch.name}, {ch.n} joints")
    print("Forward kinematics and Jacobian by screw transport, float reference vs bit-accurate fixed point.\n")
    rng = np.random.default_rng(2026)
    q = ch.random_q(rng, 3)
    models = {cfg: Model(ch, cfg) for cfg in ("default", "compact")}
    for k, qk in enumerate(q):
        print(f"configuration {k}: q = {_fmt_vec(qk)} rad")
        T_ref = reference.fk_frames(ch, qk)[-1]
        J_ref = reference.jacobian(ch, qk, ref="tool", basis="base")
        print(f"  {'float':8s} tool p = {_fmt_vec(T_ref[:3, 3])} m")
        for cfg, m in models.items():
            r = m.jacobian(qk)
            T = r.T[0, -1]
            dp = np.abs(T[:3, 3] - T_ref[:3, 3]).max()
            dr = float(rotation_angle(T[:3, :3], T_ref[:3, :3]))
            dj = np.abs(r.J[0] - J_ref).max()
            print(f"  {cfg:8s} tool p = {_fmt_vec(T[:3, 3])} m   |dp| {dp:.2e} m  |dR| {dr:.2e} rad  "
                  f"|dJ| {dj:.2e}  flags {int(r.flags[0]):#x}")
        print()
    print("Jacobian (default configuration, configuration 0), rows (omega; v), root axes, tool origin:")
    J = models["default"].jacobian(q[0]).J[0]
    for row, lab in zip(J, ("wx", "wy", "wz", "vx", "vy", "vz")):
        print(f"  {lab} " + " ".join(f"{x:+.6f}" for x in row))
    print()
    n = 2000
    print(f"Worst error over {n} random configurations against Pinocchio (independent oracle):")
    print(f"  {'config':8s} {'position m':>11s} {'orient rad':>11s} {'J element':>11s}  quat format")
    for cfg in ("default", "compact"):
        e = measure(ch, cfg, samples=n, seed=7)
        W, I = formats(cfg)["quat_t"]
        print(f"  {cfg:8s} {e['pos']:11.2e} {e['rot']:11.2e} {e['jac']:11.2e}  ap_fixed<{W},{I}>")
    print("\n(The servo core, its solver and the Verilated RTL are not in this demo yet.)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
