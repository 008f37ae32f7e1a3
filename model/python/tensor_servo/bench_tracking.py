"""Tracking benchmark: task-space circle and figure-eight with changing orientation.

    from tensor_servo.bench_tracking import bench_tracking
    print(bench_tracking())          # markdown table (scripts/bench.py writes it to docs/benchmarks.md)

For PUMA 560 and Panda, at 1 kHz and 10 kHz ticks, the servo (error choice A, feed-forward,
defaults of ``servo.default_params`` and the warm-start leak of ``track.TRACK_DEFAULTS``) drives
the ideal plant along each path, once with the ``float`` model (the C++ servo instantiated on
double) and once bit-accurate (``fixed``, default and compact configurations).  The
steady-state tracking error is the worst true error (float64 kinematics of the plant's q) over
the second half of the run, after the start-up transient.  "fixed - float" compares the two runs
tick by tick: the worst distance between the two tool positions over the second half, also in
LSB of ``perr_t`` (the position-error format of the configuration), against the goal of 4 LSB.
About 20 s of simulated motion, 2 x 10^5 ticks: 1-2 minutes.
"""
from __future__ import annotations


import numpy as np

from . import robots
from .model import formats
from .pathgen import circle, figure8
from .plant import Plant
from .track import relative_poses, run_model

#: start configurations (well-conditioned, away from the limits) per robot
HOME = {
    "puma560": np.array([0.2, 1.0, -2.8, 0.3, 0.8, 0.2]),
    "panda": np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8]),
}

#: the paths: circle of radius 5 cm in 2 s, figure-eight of 5 cm in 3 s, both in a vertical plane
#: with the orientation rocking by +-0.2 rad (one axis) / +-0.15 rad (two axes)
PATHS = {
    "circle": lambda T0, dt, dur: circle(T0, 0.05, 2.0, dt, dur, plane=((0, 1, 0), (0, 0, 1)), tilt=0.2,
                                         axis=(1.0, 1.0, 0.0)),
    "figure8": lambda T0, dt, dur: figure8(T0, 0.05, 3.0, dt, dur, plane=((0, 1, 0), (0, 0, 1)), tilt=0.15),
}
DURATION = {"circle": 2.0, "figure8": 3.0}


def lsb(config: str, name: str) -> float:
    W, I = formats(config)[name]
    return 2.0 ** (I - W)


def run_case(robot: str, path: str, rate: float, model: str, config: str = "default", warm="auto",
             **params) -> dict:
    ch = robots.load(robot)
    dt = 1.0 / rate
    q0 = HOME[robot]
    T0 = relative_poses(ch, q0[None])[0]
    T, V = PATHS[path](T0, dt, DURATION[path])
    res, _, elapsed = run_model(model, ch, T, V, q0, Plant(q0, dt), config=config, dt=dt, warm=warm, **params)
    half = len(T) // 2
    P = relative_poses(ch, res.q[:-1])
    return {"res": res, "pos": P[:, :3, 3], "steady_pos": float(res.pos_err[half:].max()),
            "steady_rot": float(res.rot_err[half:].max()), "flags": int(np.bitwise_or.reduce(res.flags)),
            "ticks": len(T), "seconds": elapsed, "half": half}


def bench_tracking(robots_: tuple = ("puma560", "panda"), paths: tuple = ("circle", "figure8"),
                   rates: tuple = (1000.0, 10000.0), configs: tuple = ("default", "compact"), **params) -> str:
    """Markdown table of steady tracking errors, fixed point vs float (see the module doc)."""
    rows = ["| robot | path | tick | config | steady pos. error float / fixed (m) | steady rot. error float / "
            "fixed (rad) | fixed - float, worst tool distance (m) | in LSB of perr_t (goal <= 4) | flags |",
            "|---|---|---|---|---|---|---|---|---|"]
    for rb in robots_:
        for path in paths:
            for rate in rates:
                fl = run_case(rb, path, rate, "float", **params)
                for cfg in configs:
                    fx = run_case(rb, path, rate, "fixed", cfg, **params)
                    d = float(np.linalg.norm(fx["pos"] - fl["pos"], axis=1)[fl["half"]:].max())
                    n_lsb = d / lsb(cfg, "perr_t")
                    rows.append(f"| {rb} | {path} | {rate / 1000:g} kHz | {cfg} | {fl['steady_pos']:.2e} / "
                                f"{fx['steady_pos']:.2e} | {fl['steady_rot']:.2e} / {fx['steady_rot']:.2e} | "
                                f"{d:.2e} | {n_lsb:.2f} {'ok' if n_lsb <= 4 else 'MISSED'} | "
                                f"{fx['flags']:#x} |")
    return "\n".join(rows) + "\n"


if __name__ == "__main__":
    print(bench_tracking())
