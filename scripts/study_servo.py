#!/usr/bin/env python3
"""Stability and convergence study of the servo loop (docs/solver.md, "Stability study").

    .venv/bin/python scripts/study_servo.py [--only conv lag rate step track] [--jobs 2] [--write]

Every run is the closed loop of ``tensor_servo.track`` (servo tick -> ideal joint-rate plant
unless a lag is stated), on PUMA 560 and Panda.  Sections:

  conv   static target 1 mm + 1 mrad away (random directions) from 8 random well-conditioned
         configurations per robot (15 % away from the limits, condition number of the L-scaled
         Jacobian <= 30); float model, 1 kHz, velocity limits off (linear regime).  Settling
         ticks = ticks until the weighted error sqrt(|e_p|^2 + (L |e_o|)^2) stays below 1e-3 of
         its start, median / worst over the 8 configurations; "unstable" if it ends above its start.
         Grid: K dt x sweeps x mu, for the warm start "prev" (the previous command) and "leak 5"
         (the previous command minus 2^-5 of it: the "auto" leak at 1 kHz).
  convfx the same grid at K dt = 0.3 and 1.0, bit-accurate (default configuration) at 10 kHz.
  lag    the same with a first-order actuator lag of 1, 3 and 10 ticks.
  rate   the same targets at 1 kHz and 10 kHz, float vs fixed (default, compact): settling ticks
         and the final error (median / worst over configurations, in LSB of perr_t).
  step   2 cm + 20 mrad step, velocity limits on, 1 kHz: ticks to 1e-4 of the start and the
         self-motion left once settled (largest |q'| at the end, joint travel after settling).
  track  steady tracking error on the circle / figure-eight of the tracking benchmark vs K dt and
         the warm start, against the prediction dt |a| / (2 K) (a: the setpoint's acceleration).

With --write the tables replace the marked blocks of docs/solver.md.
"""
from __future__ import annotations

import argparse
import re
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "model" / "python"))

from tensor_servo import robots  # noqa: E402
from tensor_servo.bench_tracking import DURATION, HOME, PATHS, lsb, run_case  # noqa: E402
from tensor_servo.plant import Plant  # noqa: E402
from tensor_servo.reference import jacobian, rotation  # noqa: E402
from tensor_servo.track import leak_shift, make_tick, relative_poses, track  # noqa: E402

DOC = ROOT / "docs" / "solver.md"
ROBOTS = ("puma560", "panda")
L = 0.5


def targets(name: str, m: int = 8, seed: int = 0, e_p: float = 1e-3, e_o: float = 1e-3, cmax: float = 30.0):
    ch = robots.load(name)
    rng = np.random.default_rng(seed)
    lo = ch.lower + 0.15 * (ch.upper - ch.lower)
    hi = ch.upper - 0.15 * (ch.upper - ch.lower)
    out = []
    while len(out) < m:
        q0 = rng.uniform(lo, hi)
        J = jacobian(ch, q0)
        J[:3] *= L
        s = np.linalg.svd(J, compute_uv=False)
        d = rng.normal(size=3)
        a = rng.normal(size=3)
        if s[0] / s[-1] > cmax:
            continue
        T = relative_poses(ch, q0[None])[0]
        U = T.copy()
        U[:3, 3] += e_p * d / np.linalg.norm(d)
        U[:3, :3] = rotation(a / np.linalg.norm(a), e_o) @ T[:3, :3]
        out.append((q0, U))
    return out


def static_run(name, q0, U, *, kdt=0.3, sweeps=2, mu=1.0, warm="prev", rate=1000.0, model="float",
               config="default", tau_ticks=0.0, ticks=600, vlimits=False):
    ch = robots.load(name)
    dt = 1.0 / rate
    tick = make_tick(model, ch, config=config, dt=dt, kp=kdt / dt, ko=kdt / dt, sweeps=sweeps, mu=mu,
                     vlimits=vlimits, L=L)
    r = track(ch, np.repeat(U[None], ticks, 0), np.zeros((ticks, 6)), q0, tick,
              Plant(q0, dt, tau=tau_ticks * dt), warm=warm)
    e = np.sqrt(r.pos_err ** 2 + (L * r.rot_err) ** 2)
    return e, r


def settle(e: np.ndarray, frac: float) -> int:
    above = np.nonzero(e > frac * e[0])[0]
    return int(above[-1] + 1) if len(above) else 0


def conv_cell(args) -> str:
    name, kw, H = args
    st, unstable = [], False
    for q0, U in targets(name):
        e, _ = static_run(name, q0, U, ticks=H, **kw)
        if not np.isfinite(e[-1]) or e[-1] > e[0]:
            unstable = True
            break
        st.append(settle(e, 1e-3))
    if unstable:
        return "unstable"
    st = np.array(st)
    worst = f">{H}" if st.max() >= H else str(st.max())
    return f"{int(np.median(st))} / {worst}"


def grid_table(name, pool, kdts, sweeps_mu, warms, tau=0.0, H=600, **extra) -> str:
    cells = [(name, dict(kdt=k, sweeps=s, mu=m, warm=w, tau_ticks=tau, **extra), H)
             for w in warms for s, m in sweeps_mu for k in kdts]
    res = list(pool.map(conv_cell, cells))
    head = "| warm start | sweeps | mu | " + " | ".join(f"K dt = {k:g}" for k in kdts) + " |"
    rows = [head, "|" + "---|" * (3 + len(kdts))]
    i = 0
    for w in warms:
        for s, m in sweeps_mu:
            cols = res[i:i + len(kdts)]
            i += len(kdts)
            rows.append(f"| {w if isinstance(w, str) else f'leak {w}'} | {s} | {m:g} | " + " | ".join(cols) + " |")
    return "\n".join(rows) + "\n"


def section_conv(pool) -> str:
    out = []
    sm = [(s, m) for s in (1, 2, 4, 10) for m in (1.0, 1.5)]
    for name in ROBOTS:
        out.append(f"**{name}** — settling ticks (median / worst of 8), float, 1 kHz, no lag\n")
        out.append(grid_table(name, pool, (0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5), sm, ("prev", 5)))
    return "\n".join(out)


def section_convfx(pool) -> str:
    out = []
    sm = [(s, m) for s in (1, 2, 4, 10) for m in (1.0, 1.5)]
    for name in ROBOTS:
        out.append(f"**{name}** — settling ticks (median / worst of 8), bit-accurate default configuration, "
                   f"10 kHz, no lag\n")
        out.append(grid_table(name, pool, (0.3, 1.0), sm, ("auto",), rate=10000.0, model="fixed"))
    return "\n".join(out)


def section_lag(pool) -> str:
    out = []
    sm = [(2, 1.0), (4, 1.0), (4, 1.5), (10, 1.0), (10, 1.5)]
    for name in ROBOTS:
        for tau in (1.0, 3.0, 10.0):
            out.append(f"**{name}**, actuator lag tau = {tau:g} tick(s) — settling ticks (median / worst of 8), "
                       f"float, 1 kHz\n")
            out.append(grid_table(name, pool, (0.2, 0.3, 0.5, 0.7, 1.0), sm, (5,), tau=tau))
    return "\n".join(out)


def rate_cell(args):
    name, setting, rate, model, config = args
    kw = dict(setting)
    st, fin = [], []
    floor = 4 * lsb(config, "perr_t") if model == "fixed" else 0.0
    for q0, U in targets(name):
        e, r = static_run(name, q0, U, rate=rate, model=model, config=config, ticks=600, **kw)
        st.append(settle(e, max(1e-3, floor / e[0])))
        fin.append(r.pos_err[-1])
    return np.array(st), np.array(fin)


def section_rate(pool) -> str:
    settings = {"current (2 sweeps, mu 1, K dt 0.3, warm prev)": dict(kdt=0.3, sweeps=2, mu=1.0, warm="prev"),
                "proposed (10 sweeps, mu 1.5, K dt 0.3, leak auto)": dict(kdt=0.3, sweeps=10, mu=1.5, warm="auto")}
    cases = [(name, tuple(kw.items()), rate, model, cfg) for name in ROBOTS for kw in settings.values()
             for rate in (1000.0, 10000.0) for model, cfg in (("float", "default"), ("fixed", "default"),
                                                              ("fixed", "compact"))]
    res = list(pool.map(rate_cell, cases))
    rows = ["| robot | setting | tick | model | settling ticks median / worst (to 1e-3, or 4 LSB of perr_t) | "
            "final position error median / "
            "worst (m) | in LSB of perr_t |", "|---|---|---|---|---|---|---|"]
    labels = {tuple(kw.items()): lab for lab, kw in settings.items()}
    for (name, kw, rate, model, cfg), (st, fin) in zip(cases, res):
        m = "float" if model == "float" else f"fixed {cfg}"
        l_ = lsb(cfg, "perr_t") if model == "fixed" else None
        ls = f"{np.median(fin) / l_:.2f} / {fin.max() / l_:.2f}" if l_ else "-"
        worst = ">600" if st.max() >= 600 else str(st.max())
        rows.append(f"| {name} | {labels[kw]} | {rate / 1000:g} kHz | {m} | {int(np.median(st))} / {worst} | "
                    f"{np.median(fin):.2e} / {fin.max():.2e} | {ls} |")
    return "\n".join(rows) + "\n"


def step_cell(args):
    name, kw = args
    out = []
    for q0, U in targets(name, m=6, seed=5, e_p=2e-2, e_o=2e-2):
        H = 1500
        e, r = static_run(name, q0, U, ticks=H, vlimits=True, **dict(kw))
        s = settle(e, 1e-4)
        out.append((s, float(np.abs(r.qd[-1]).max()), float(np.abs(r.q[-1] - r.q[min(s, H)]).max())))
    return out


def section_step(pool) -> str:
    settings = [("2 sweeps, mu 1, warm prev (current)", dict(kdt=0.3, sweeps=2, mu=1.0, warm="prev")),
                ("10 sweeps, mu 1.5, warm prev", dict(kdt=0.3, sweeps=10, mu=1.5, warm="prev")),
                ("10 sweeps, mu 1.5, warm zero", dict(kdt=0.3, sweeps=10, mu=1.5, warm="zero")),
                ("10 sweeps, mu 1.5, leak auto = 5 (proposed)", dict(kdt=0.3, sweeps=10, mu=1.5, warm="auto"))]
    cases = [(name, tuple(kw.items())) for name in ROBOTS for _, kw in settings]
    res = list(pool.map(step_cell, cases))
    rows = ["| robot | setting (K dt 0.3, velocity limits on) | ticks to 1e-4, median / worst of 6 | "
            "self-motion left: largest abs(q') at the end (rad/s) | joint travel after settling (rad) |",
            "|---|---|---|---|---|"]
    i = 0
    for name in ROBOTS:
        for lab, _ in settings:
            r = res[i]
            i += 1
            st = np.array([x[0] for x in r])
            worst = ">1500" if st.max() >= 1500 else str(st.max())
            rows.append(f"| {name} | {lab} | {int(np.median(st))} / {worst} | {max(x[1] for x in r):.1e} | "
                        f"{max(x[2] for x in r):.2f} |")
    return "\n".join(rows) + "\n"


def path_accel(path: str, name: str, dt: float) -> float:
    ch = robots.load(name)
    T0 = relative_poses(ch, HOME[name][None])[0]
    T, V = PATHS[path](T0, dt, DURATION[path])
    return float(np.abs(np.linalg.norm(np.diff(V[:, 3:], axis=0), axis=1) / dt).max())


def track_cell(args):
    name, path, rate, kdt, warm, model = args
    dt = 1.0 / rate
    r = run_case(name, path, rate, model, kp=kdt / dt, ko=kdt / dt, sweeps=10, mu=1.5, warm=warm)
    return r["steady_pos"], r["steady_rot"]


def section_track(pool) -> str:
    cases = [(name, path, rate, kdt, warm, "float") for name in ROBOTS for path in ("circle", "figure8")
             for rate in (1000.0, 10000.0) for kdt, warm in ((0.1, "auto"), (0.3, "auto"), (0.5, "auto"),
                                                             (0.3, "prev"))]
    res = list(pool.map(track_cell, cases))
    rows = ["| robot | path | tick | K dt | warm start | steady position error (m) | "
            "prediction dt abs(a) / (2 K) (m) | "
            "steady orientation error (rad) |", "|---|---|---|---|---|---|---|---|"]
    for (name, path, rate, kdt, warm, _), (pe, re) in zip(cases, res):
        dt = 1.0 / rate
        a = path_accel(path, name, dt)
        w = f"leak {leak_shift(dt)}" if warm == "auto" else warm
        pred = dt * a / (2 * kdt / dt)
        rows.append(f"| {name} | {path} | {rate / 1000:g} kHz | {kdt:g} | {w} | {pe:.2e} | {pred:.2e} | {re:.2e} |")
    return "\n".join(rows) + "\n"


SECTIONS = {"conv": section_conv, "convfx": section_convfx, "lag": section_lag, "rate": section_rate, "step": section_step,
            "track": section_track}


def write_block(text: str, key: str, body: str) -> str:
    begin, end = f"<!-- BEGIN study:{key} -->", f"<!-- END study:{key} -->"
    if begin not in text:
        raise SystemExit(f"docs/solver.md has no block {begin}")
    return re.sub(re.escape(begin) + ".*?" + re.escape(end), lambda _: f"{begin}\n{body}{end}", text, flags=re.S)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", nargs="*", choices=list(SECTIONS), default=list(SECTIONS))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--write", action="store_true", help="replace the tables in docs/solver.md")
    a = ap.parse_args()
    out = {}
    with ProcessPoolExecutor(a.jobs) as pool:
        for key in a.only:
            t0 = time.time()
            out[key] = SECTIONS[key](pool)
            print(f"## {key} ({time.time() - t0:.0f} s)\n\n{out[key]}", flush=True)
    if a.write:
        text = DOC.read_text()
        for key, body in out.items():
            text = write_block(text, key, body)
        DOC.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
