"""``make demo``: the main job on the embedded default robot (PUMA 560).

The servo core, Verilated (rtl/ts_servo_core.v through tensor_servo.rtl_core, configured over
AXI4-Lite, one AXI4-Stream packet in and out per tick), drives a simulated PUMA 560 (ideal
joint-rate integrator) along a task-space circle with rocking orientation at 1 kHz.  The same
loop runs with the bit-accurate C++ model (``fixed``) and with the C++ servo on double
(``float``).  Printed: the tracking error of each, whether the core's run is bit-identical to the
model's, the fixed-point vs float difference in LSB, the core's cycles per tick and the tick rate
they imply at a clock frequency; written: a PNG of the tracking errors.  Then the forward
kinematics and Jacobian accuracy of both configurations against Pinocchio.

    python -m tensor_servo.demo [--robot puma560] [--config default|compact] [--seconds S]
                                [--clock-mhz F] [-o PNG]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from . import robots
from .accuracy import measure
from .bench_tracking import HOME, lsb
from .errors import InputError
from .model import formats
from .pathgen import circle
from .plant import Plant
from .rtl_core import ROOT
from .track import relative_poses, run_model

DEFAULT_PNG = ROOT / "build" / "demo" / "tracking_error.png"
#: the clock the implied tick rate is quoted at (an assumption, printed as such): the primitives'
#: post-route Fmax goal on LFE5U-85F -6; the whole core's measured Fmax is in docs/resources.md
CLOCK_MHZ = 150.0


def plot(path: Path, t, runs: dict, title: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for name, (res, style) in runs.items():
        # from tick 1: tick 0 starts on the path (error 0)
        ax[0].semilogy(t[1:], np.maximum(res.pos_err[1:], 1e-10), style, label=name, lw=1)
        ax[1].semilogy(t[1:], np.maximum(res.rot_err[1:], 1e-10), style, label=name, lw=1)
    ax[0].set_ylabel("position error (m)")
    ax[1].set_ylabel("orientation error (rad)")
    ax[1].set_xlabel("time (s)")
    ax[0].set_title(title)
    for a in ax:
        a.grid(True, which="both", alpha=0.3)
        a.legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="tensor_servo.demo", description=__doc__.split("\n\n")[0])
    ap.add_argument("--robot", default="puma560", choices=sorted(HOME))
    ap.add_argument("--config", default="default", choices=("default", "compact"))
    ap.add_argument("--seconds", type=float, default=2.0, help="length of the run (s of motion, 1 kHz ticks)")
    ap.add_argument("--clock-mhz", type=float, default=CLOCK_MHZ, help="clock for the implied tick rate")
    ap.add_argument("-o", "--output", default=str(DEFAULT_PNG), help="PNG of the tracking errors")
    a = ap.parse_args(argv)
    try:
        if not 0.01 <= a.seconds <= 60:
            raise InputError("--seconds", f"must be 0.01..60 (got {a.seconds:g})")
        if not a.clock_mhz > 0:
            raise InputError("--clock-mhz", f"must be positive (got {a.clock_mhz:g})")
        return demo(a)
    except InputError as e:
        print(f"demo: error: {e}", file=sys.stderr)
        return 2


def demo(a) -> int:
    ch, cfg, dt = robots.load(a.robot), a.config, 1e-3
    q0 = HOME[a.robot]
    T0 = relative_poses(ch, q0[None])[0]
    T, V = circle(T0, 0.05, 2.0, dt, a.seconds, plane=((0, 1, 0), (0, 0, 1)), tilt=0.2, axis=(1.0, 1.0, 0.0))
    K = len(T)
    print(f"tensor-servo demo: {ch.name}, {ch.n} joints, {cfg} configuration")
    print(f"Task-space circle (radius 5 cm, 2 s) with the orientation rocking by 0.2 rad, {K} ticks at 1 kHz;")
    print("the servo's safe defaults (error choice A, feed-forward, 10 sweeps), ideal plant.\n")
    print("The servo core in Verilator (building it the first time takes about a minute) ...", flush=True)
    rt, tick, secs = run_model("rtl", ch, T, V, q0, Plant(q0, dt), config=cfg, dt=dt)
    fx, _, _ = run_model("fixed", ch, T, V, q0, Plant(q0, dt), config=cfg, dt=dt)
    fl, _, _ = run_model("float", ch, T, V, q0, Plant(q0, dt), config=cfg, dt=dt)
    same = all(np.array_equal(getattr(rt, k), getattr(fx, k)) for k in ("q", "qd", "flags"))
    half = K // 2
    print(f"  {'run':34s} {'steady pos. error':>18s} {'steady rot. error':>18s}  flags")
    for name, r in (("float (C++ servo on double)", fl), (f"fixed ({cfg}, bit-accurate model)", fx),
                    ("rtl (Verilated servo core)", rt)):
        print(f"  {name:34s} {r.pos_err[half:].max():16.3e} m {r.rot_err[half:].max():14.3e} rad  "
              f"{int(np.bitwise_or.reduce(r.flags)):#x}")
    P_fl = relative_poses(ch, fl.q[half:-1])[:, :3, 3]
    P_rt = relative_poses(ch, rt.q[half:-1])[:, :3, 3]
    d = float(np.linalg.norm(P_rt - P_fl, axis=1).max())
    print(f"\n  core vs model: {'bit-identical' if same else 'DIFFERENT'} over {K} ticks "
          f"(joint commands, plant path, status flags)")
    print(f"  core vs float: worst tool distance {d:.3g} m over the second half = {d / lsb(cfg, 'perr_t'):.2f} LSB "
          f"of the position-error format (goal <= 4)")
    cyc = np.array(tick.core.cycles)
    c = int(np.median(cyc))
    ns = c / a.clock_mhz * 1e3
    print(f"  cycles per tick (TICK_CYCLES, 10 sweeps): {c} (min {cyc.min()}, max {cyc.max()}); at {a.clock_mhz:g} MHz "
          f"{ns / 1e3:.1f} us per tick, {1e9 / ns:,.0f} ticks/s")
    print(f"    ({a.clock_mhz:g} MHz is an assumed clock (--clock-mhz); the post-route Fmax of the whole core is in "
          "docs/resources.md)")
    print(f"  simulation: {K} ticks in {secs:.1f} s ({K * c / secs / 1e3:.0f} kcycles/s in Verilator)")
    out = Path(a.output)
    plot(out, np.arange(K) * dt, {"float": (fl, "k-"), f"fixed {cfg}": (fx, "b--"), "rtl core": (rt, "r:")},
         f"{ch.name}: tracking error, 1 kHz, {cfg} configuration")
    print(f"  plot: {out}\n")

    n = 1000
    print(f"Forward kinematics and Jacobian, worst error over {n} random configurations against Pinocchio:")
    print(f"  {'config':8s} {'position m':>11s} {'orient rad':>11s} {'J element':>11s}  quat format")
    for c2 in ("default", "compact"):
        e = measure(ch, c2, samples=n, seed=7)
        W, I = formats(c2)["quat_t"]
        print(f"  {c2:8s} {e['pos']:11.2e} {e['rot']:11.2e} {e['jac']:11.2e}  ap_fixed<{W},{I}>")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
