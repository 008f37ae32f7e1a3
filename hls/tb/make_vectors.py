#!/usr/bin/env python3
"""Write the inputs of the HLS C-simulation (hls/tb/tb_hls.cpp) as plain text, from the model.

Per example chain and fixed-point configuration, into OUTDIR:
    chain_<name>_<cfg>.txt   the chain's raw constants (Model.constants()) and the raw servo
                             parameters of the default servo set-up (Servo.params_raw())
    kin_<name>_<cfg>.txt     the committed golden vectors tb/golden/kin_<name>_<cfg>.npz
    servo_<name>_<cfg>.txt   sequences of servo ticks computed by the model through its Python
                             bindings (_model.Servo.tick_raw), each sequence starting cold and
                             warm-starting from the model's previous q'

Format: one array per line, "key count v0 v1 ...", integers only; "#" lines are comments.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from tensor_servo import _model, robots
from tensor_servo.model import FIXED_CONFIGS, Model, model_spec
from tensor_servo.servo import default_params

ROOT = Path(__file__).resolve().parents[2]
GOLDEN = ROOT / "tb" / "golden"
# Joints whose value 0 makes the chain singular (found with the Pinocchio oracle: median
# cond(J) > 1e16 with the listed joints at 0 and the others random).
SINGULAR = {"puma560": [[4]], "ur5": [[2], [4]], "panda": [[1, 3]], "stanford": [[4], [1]], "chain20": []}
# Servo set-ups of the bindings-computed sequences (overrides of default_params).
VARIANTS = [
    {},
    {"mode": "B"},
    {"feedforward": False, "sweeps": 3},
    {"mode": "B", "sweeps": 1, "setpoint_frame": 0, "vlimits": False},
    {"setpoint_frame": 2, "sweeps": 4, "mu": 1.5},
    {"warm_leak": 5, "sweeps": 3},
]


def line(key: str, a) -> str:
    v = np.asarray(a).astype(np.int64).ravel()
    return f"{key} {v.size} " + " ".join(str(int(x)) for x in v)


def chain_file(name: str, cfg: str) -> str:
    ch = robots.load(name)
    m = Model(ch, cfg)
    c = m.constants()
    n = ch.n
    out = [f"# {name} {cfg}: raw constants of the model", line("n", [n])]
    for k in ("base_quat", "base_xyz", "tool_quat", "tool_xyz"):
        out.append(line(k, c[k]))
    out.append(line("parent_frame", c.get("parent_frame", np.arange(n))))
    out.append(line("tool_parent", [n]))
    for k in ("prismatic", "origin_quat", "origin_xyz", "axis", "scale", "kturn"):
        out.append(line(k, c[k]))
    p = default_params(ch, 1e-3)
    p.update(controlled=[-1], weights=[1.0])
    s = _model.Servo(cfg, model_spec(ch), p).params_raw()
    for k in ("L", "klim", "sweeps", "kp", "ko", "dt", "mode", "feedforward", "setpoint_frame", "warm_leak"):
        out.append(line(k, [int(s[k])]))
    for k in ("mu", "limited", "lo", "hi", "vmax"):
        out.append(line(k, s[k]))
    out.append(line("singular_count", [len(SINGULAR.get(name, []))]))
    for i, js in enumerate(SINGULAR.get(name, [])):
        out.append(line(f"singular_{i}", js))
    return "\n".join(out) + "\n"


def kin_file(name: str, cfg: str) -> str:
    d = np.load(GOLDEN / f"kin_{name}_{cfg}.npz")
    out = [f"# tb/golden/kin_{name}_{cfg}.npz", line("samples", [d["q_raw"].shape[0]]), line("n", [d["q_raw"].shape[1]])]
    for k in ("q_raw", "quat_raw", "pos_raw", "axis_raw", "J_raw", "J_tool_raw", "flags"):
        out.append(line(k, d[k]))
    for k in d.files:
        if k.startswith("const_"):
            out.append(line(k, d[k]))
    return "\n".join(out) + "\n"


def servo_file(name: str, cfg: str, ticks: int, seed: int) -> str:
    ch = robots.load(name)
    n = ch.n
    m = Model(ch, cfg)
    fm = _model.formats(cfg)
    frac = {k: fm[k][0] - fm[k][1] for k in ("vel_t",)}
    rng = np.random.Generator(np.random.PCG64([seed, sum(map(ord, name)), FIXED_CONFIGS.index(cfg)]))
    out = [f"# {name} {cfg}: servo ticks of the model (Python bindings)", line("variants", [len(VARIANTS)])]
    for vi, var in enumerate(VARIANTS):
        p = default_params(ch, 1e-3)
        p.update(controlled=[-1], weights=[1.0])
        p.update(var)
        if np.isscalar(p["mu"]):
            p["mu"] = [float(p["mu"])] * n
        s = _model.Servo(cfg, model_spec(ch), p)
        pr = s.params_raw()
        pre = f"v{vi}_"
        for k in ("L", "klim", "sweeps", "kp", "ko", "dt", "mode", "feedforward", "setpoint_frame", "warm_leak"):
            out.append(line(pre + k, [int(pr[k])]))
        for k in ("mu", "limited", "lo", "hi", "vmax"):
            out.append(line(pre + k, pr[k]))
        q_raw, ok = m.quantize_q(ch.random_q(rng, ticks))
        assert ok.all()
        # Setpoint: the model's tool pose at a nearby q (taken as relative to the setpoint frame
        # when there is one: any pose is a valid input), a small random twist.
        fa = fm["angle_t"][0] - fm["angle_t"][1]
        qs_raw, _ = m.quantize_q(q_raw * 2.0 ** -fa + rng.normal(0, 0.05, (ticks, n)))
        fk = m.fk(qs_raw, raw=True)
        uq, up = fk.quat_raw[:, -1], fk.pos_raw[:, -1]
        uw = np.round(rng.uniform(-0.3, 0.3, (ticks, 3)) * 2.0 ** frac["vel_t"]).astype(np.int64)
        uv = np.round(rng.uniform(-0.3, 0.3, (ticks, 3)) * 2.0 ** frac["vel_t"]).astype(np.int64)
        cold = np.zeros(ticks, np.int64)
        cold[::10] = 1
        res = {key: [] for key in ("qd", "q_next", "ep", "eo", "r", "flags")}
        warm = np.zeros(n, np.int64)
        for t in range(ticks):
            if cold[t]:
                warm = np.zeros(n, np.int64)
            d = s.tick_raw(q_raw[t], uq[t][None], up[t][None], uw[t][None], uv[t][None], warm)
            for key in ("qd", "q_next", "r"):
                res[key].append(d[key + "_raw"])
            res["ep"].append(d["ep_raw"][0])
            res["eo"].append(d["eo_raw"][0])
            res["flags"].append(d["flags"])
            warm = d["qd_raw"]
        out += [line(pre + "ticks", [ticks]), line(pre + "cold", cold), line(pre + "q", q_raw),
                line(pre + "uq", uq), line(pre + "up", up), line(pre + "uw", uw), line(pre + "uv", uv)]
        for key in ("qd", "q_next", "ep", "eo", "r", "flags"):
            out.append(line(pre + key, np.array(res[key])))
    return "\n".join(out) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdir", type=Path)
    ap.add_argument("--chains", default="puma560,ur5,panda,stanford,chain20")
    ap.add_argument("--servo-ticks", type=int, default=30)
    ap.add_argument("--seed", type=int, default=20261122)
    args = ap.parse_args(argv)
    args.outdir.mkdir(parents=True, exist_ok=True)
    for name in args.chains.split(","):
        for cfg in FIXED_CONFIGS:
            (args.outdir / f"chain_{name}_{cfg}.txt").write_text(chain_file(name, cfg))
            (args.outdir / f"kin_{name}_{cfg}.txt").write_text(kin_file(name, cfg))
            (args.outdir / f"servo_{name}_{cfg}.txt").write_text(servo_file(name, cfg, args.servo_ticks, args.seed))
    return 0


if __name__ == "__main__":
    sys.exit(main())
