"""Bench of rtl/ts_core_commit.v: the configuration commit step, bit-exact with the model's
ts::commit_config (tensor_servo._model.commit_raw).

Every commit is driven directly on the module's inputs (the register block's words; no AXI) and the
result -- accept/reject, error code, error joint (0xFF for the model's -1), every joint's kturn raw
value -- is compared with commit_raw on the same words.  Cases: the example robots (PUMA 560, UR5,
Panda, Stanford arm with its prismatic joint) and variants of them, each error code provoked on
purpose (with the boundary of every exact check on both sides: unit norms at 1 +- 2^-10, the
kturn saturation, the three reach bounds), and random mutations of the robots (``TS_NVEC``, default
300; seed printed, replay with ``TS_SEED``).  Also checked: the shadow outputs (the global words
and the joints' JCFG bits) equal the words at the start edge (a change of those words during the
commit does not disturb it), the loader's port shows every joint's words (from in_joint_*, which
have no shadow and which the bench, as the core, holds still during the commit), out_busy/out_done
timing, a restart while busy, X-freedom after reset, and (without a simulator) that the module's
CONFIG-derived format parameters equal the model's formats.
"""
from __future__ import annotations

import json
import math
import os
import random
import re
from pathlib import Path

import numpy as np
import pytest

import rtlparams
import tsbench

MODULE = "ts_core_commit"
#: joint blocks of the bench build (8; ``TS_NMAX`` = 8..60 for a one-off run at another size)
NMAX = int(os.environ.get("TS_NMAX", "8"))
N_RANDOM = int(os.environ.get("TS_NVEC", "300"))
ROBOTS = ("puma560", "ur5", "panda", "stanford")

try:
    import cocotb
except ImportError:  # pragma: no cover
    cocotb = None


# ---- formats ---------------------------------------------------------------------------------------
def fw(cfg: str, name: str) -> tuple[int, int]:
    """(W, F) of a model format."""
    return rtlparams.fmt(cfg, name)


def rmax(cfg, name):
    return (1 << (fw(cfg, name)[0] - 1)) - 1


def rmin(cfg, name):
    return -(1 << (fw(cfg, name)[0] - 1))


q = rtlparams.quantize_const   # raw value of x in a format (round half up, saturate): what software writes


def expected_params(cfg: str) -> dict:
    """The module's CONFIG-derived parameters, from the model's formats."""
    p = {}
    for key, name in (("ANGLE", "angle_t"), ("DT", "dt_t"), ("GAIN", "gain_t"), ("KLIM", "klim_t"),
                      ("LCHAR", "lchar_t"), ("LEN", "len_t"), ("MU", "mu_t"), ("QD", "qd_t"),
                      ("QUAT", "quat_t"), ("SCALE", "scale_t")):
        p[f"{key}_W"] = fw(cfg, name)[0]
    for key, name in (("QUAT", "quat_t"), ("SCALE", "scale_t"), ("LEN", "len_t"), ("ANGLE", "angle_t"),
                      ("KT", "kturn_t"), ("INV", "inv4pi_t"), ("LEVER", "lever_t"), ("POS", "pos_t"),
                      ("JV", "jv_t")):
        p[f"{key}_F"] = fw(cfg, name)[1]
    for key, name in (("KT", "kturn_t"), ("INV", "inv4pi_t"), ("LEVER", "lever_t"), ("POS", "pos_t"),
                      ("JV", "jv_t")):
        p[f"{key}_W"] = fw(cfg, name)[0]
    p["INV4PI"] = rtlparams.quantize_const(1.0 / (4.0 * math.pi), cfg, "inv4pi_t")
    return p


def mul_latency(cfg: str) -> int:
    """Latency of the module's shared multiplier (MA_W x MB_W as the module derives them)."""
    lw, lf = fw(cfg, "lever_t")
    _, fl = fw(cfg, "len_t")
    rb = lw + fl - lf if fl >= lf else lw - (lf - fl)
    ma = max(fw(cfg, "quat_t")[0], fw(cfg, "scale_t")[0])
    mb = max(fw(cfg, "quat_t")[0], fw(cfg, "inv4pi_t")[0], fw(cfg, "angle_t")[0], rb)
    return rtlparams.mul_lat(ma, mb)


def commit_cycles(cfg: str, n: int, code: int, joint: int) -> int:
    """Cycle of out_done after the cycle of in_start (docs/rtl/ts_core_commit.md)."""
    lat = mul_latency(cfg)
    if code == 1:
        return 2
    if code == 3 and joint < 0:
        return 12 + lat
    if joint >= 0:
        return 22 + 10 * joint + lat
    return 10 * n + 2 * lat + 15


def verilog_defaults(config: int) -> dict:
    """Default values of the module's parameters of the form ``(CONFIG == 0) ? a : b`` or a constant."""
    text = (rtlparams.RTL / f"{MODULE}.v").read_text()
    out = {}
    for m in re.finditer(r"parameter\s+(\w+)\s*=\s*([^,\n]+?)\s*,?\s*$", text, re.M):
        name, val = m.group(1), m.group(2).strip()
        t = re.fullmatch(r"\(CONFIG == 0\) \? (-?\d+) : (-?\d+)", val)
        if t:
            out[name] = int(t.group(1) if config == 0 else t.group(2))
        elif re.fullmatch(r"-?\d+", val):
            out[name] = int(val)
    return out


# ---- raw register words ------------------------------------------------------------------------------
SERVO = {"kp": ("gain_t", 300.0), "ko": ("gain_t", 300.0), "lchar": ("lchar_t", 0.5),
         "klim": ("klim_t", 500.0), "dt": ("dt_t", 0.001)}


def raw_from_chain(chain, cfg: str) -> dict:
    """The register words software writes for a chain (rtlparams.core_raw): the safe servo
    defaults of docs/registers.md, NMAX joint blocks (the unused ones at reset)."""
    return rtlparams.core_raw(chain, cfg, NMAX, SERVO)


def copy_raw(raw: dict) -> dict:
    return json.loads(json.dumps(raw))


def model(cfg: str, raw: dict) -> dict:
    from tensor_servo import _model
    res, _ = _model.commit_raw(cfg, raw, NMAX)
    return dict(res)


def sum_of_squares(target: int, m: int) -> list[int] | None:
    """m (3 or 4) non-negative integers, the first near sqrt(target), whose squares sum to target
    (None if there are none: 4^a (8 b + 7) for m = 3).  Factors 4 are taken out first: a sum of
    squares divisible by 8 has only even terms."""
    k = 0
    while target > 0 and target % 4 == 0:
        target //= 4
        k += 1
    if k:
        r = sum_of_squares(target, m)
        return None if r is None else [v << k for v in r]
    w0 = math.isqrt(target)
    if m == 3:
        for dw in range(0, min(400, w0 + 1)):
            r = target - (w0 - dw) ** 2
            x = math.isqrt(r)
            while 2 * x * x >= r:
                y = math.isqrt(r - x * x)
                if y * y == r - x * x:
                    return [w0 - dw, x, y]
                x -= 1
        return None
    for dw in range(0, min(3000, w0 + 1)):
        r = target - (w0 - dw) ** 2
        x0 = math.isqrt(r)
        for dx in range(0, 64):
            if x0 - dx < 0:
                break
            r2 = r - (x0 - dx) ** 2
            y = math.isqrt(r2)
            for dy in range(0, 8):
                if y - dy < 0:
                    break
                r3 = r2 - (y - dy) ** 2
                z = math.isqrt(r3)
                if z * z == r3:
                    return [w0 - dw, x0 - dx, y - dy, z]
    return None


def kturn_raw(cfg: str, s: int) -> int:
    """cvt<kturn_t>(s * inv4pi) without saturation (to find the saturation boundary)."""
    _, fs = fw(cfg, "scale_t")
    _, fi = fw(cfg, "inv4pi_t")
    _, fk = fw(cfg, "kturn_t")
    sh = fs + fi - fk
    inv = rtlparams.quantize_const(1.0 / (4.0 * math.pi), cfg, "inv4pi_t")
    return (s * inv + (1 << (sh - 1))) >> sh


# ---- cases ---------------------------------------------------------------------------------------------
def directed_cases(cfg: str) -> list[tuple[str, dict, int | None]]:
    """(name, raw, code the model must give or None) of the robots and the deliberate errors."""
    from tensor_servo import robots
    base = {r: raw_from_chain(robots.load(r), cfg) for r in ROBOTS}
    cases = []
    for r in ROBOTS:
        cases.append((r, base[r], 0))
    _, qf = fw(cfg, "quat_t")
    one_q = 1 << qf
    one2, tol = 1 << (2 * qf), 1 << (2 * qf - 10)

    def mut(name, code, f, robot="puma560"):
        raw = copy_raw(base[robot])
        f(raw)
        cases.append((name, clamp_raw(cfg, raw), code))

    def setn(v):
        return lambda r: r.__setitem__("n", v)

    mut("n = 0", 1, setn(0))
    mut("n = NMAX + 1", 1, setn(NMAX + 1))
    mut("n = 255", 1, setn(255))
    mut("n = NMAX", None, setn(NMAX))
    mut("n = 1", 0, setn(1))
    # chain20: 20 joints (a count error unless NMAX >= 20)
    from tensor_servo import robots as rb
    c20 = rb.load("chain20")
    raw20 = raw_from_chain(c20, cfg)
    raw20["joints"] = raw20["joints"][:NMAX]
    cases.append(("chain20 (n = 20)", raw20, 1 if c20.n > NMAX else None))

    # unit norms at the boundary: sum of squares = 1 +- 2^-10 passes, one LSB^2 beyond fails
    # (2^(2F) - 2^(2F-10) - {0, 1} are not sums of three squares: the axis uses -tol+1 and -tol-2)
    for side, tgt in (("+tol", one2 + tol), ("-tol", one2 - tol), ("+tol+1", one2 + tol + 1),
                      ("-tol-1", one2 - tol - 1), ("-tol+1", one2 - tol + 1), ("-tol-2", one2 - tol - 2)):
        qq = sum_of_squares(tgt, 4)
        a3 = sum_of_squares(tgt, 3) if side not in ("-tol", "-tol-1") else None
        assert qq is not None and (a3 is not None or side in ("-tol", "-tol-1")), side
        code = 0 if side in ("+tol", "-tol", "-tol+1") else 3
        mut(f"base quat {side}", code, lambda r, qq=qq: r.__setitem__("base_q", list(qq)))
        mut(f"tool quat {side}", code, lambda r, qq=[-qq[0]] + qq[1:]: r.__setitem__("tool_q", list(qq)))
        mut(f"origin quat j3 {side}", code, lambda r, qq=[qq[1], -qq[0], qq[3], qq[2]]: r["joints"][3].__setitem__("qo", list(qq)))
        if a3 is not None:
            mut(f"axis j2 {side}", 0 if code == 0 else 2,
                lambda r, a=[a3[2], -a3[1], a3[0]]: r["joints"][2].__setitem__("axis", a))
    mut("base quat zero", 3, lambda r: r.__setitem__("base_q", [0, 0, 0, 0]))
    mut("base quat w = 1 + 2^-9", 3, lambda r: r["base_q"].__setitem__(0, one_q + (one_q >> 9)))
    mut("tool quat negative identity", 0, lambda r: r.__setitem__("tool_q", [-one_q, 0, 0, 0]))
    mut("tool quat (2, 0, 0, 0) saturated", 3, lambda r: r.__setitem__("tool_q", [rmax(cfg, "quat_t"), 0, 0, 0]))
    mut("origin quat j0 most negative", 3, lambda r: r["joints"][0].__setitem__("qo", [rmin(cfg, "quat_t")] * 4))
    mut("origin quat j5 scaled", 3, lambda r: r["joints"][5].__setitem__("qo", [x * 2 for x in r["joints"][5]["qo"]]))
    mut("axis j0 zero", 2, lambda r: r["joints"][0].__setitem__("axis", [0, 0, 0]))
    mut("axis j4 x2", 2, lambda r: r["joints"][4].__setitem__("axis", [x * 2 for x in r["joints"][4]["axis"]]))
    mut("quat before axis (j1 both bad)", 3, lambda r: (r["joints"][1].__setitem__("axis", [0, 0, 0]),
                                                       r["joints"][1].__setitem__("qo", [0, 0, 0, 0])))
    # scale
    mut("scale j2 zero", 5, lambda r: r["joints"][2].__setitem__("scale", 0))
    mut("scale j0 max (kturn overflow)", 5, lambda r: r["joints"][0].__setitem__("scale", rmax(cfg, "scale_t")))
    mut("scale j0 min (kturn overflow)", 5, lambda r: r["joints"][0].__setitem__("scale", rmin(cfg, "scale_t")))
    ktmax, ktmin = rmax(cfg, "kturn_t"), rmin(cfg, "kturn_t")
    s_hi = None
    if kturn_raw(cfg, rmax(cfg, "scale_t")) > ktmax:  # largest scale whose k does not saturate
        lo, hi = 1, rmax(cfg, "scale_t")
        while hi - lo > 1:
            mid = (lo + hi) // 2
            lo, hi = (mid, hi) if kturn_raw(cfg, mid) <= ktmax else (lo, mid)
        s_hi = lo
    if s_hi is not None:
        mut("scale at kturn max", 0, lambda r: r["joints"][5].__setitem__("scale", s_hi))
        mut("scale at kturn max + 1", 5, lambda r: r["joints"][5].__setitem__("scale", s_hi + 1))
        s_lo = min(s for s in range(-s_hi - 4, -s_hi + 4) if kturn_raw(cfg, s) >= ktmin)
        mut("scale at kturn min", 0, lambda r: r["joints"][4].__setitem__("scale", s_lo))
        mut("scale at kturn min - 1", 5, lambda r: r["joints"][4].__setitem__("scale", s_lo - 1))
    def odd_scales(r):
        top = s_hi if s_hi is not None else rmax(cfg, "scale_t")
        for j, v in enumerate((1, 3, -5, top // 3 | 1, -(top // 7) | 1, top - 2)):
            r["joints"][j]["scale"] = v
    mut("odd scales (kturn rounding)", 0, odd_scales)
    mut("scale negative small", 0, lambda r: r["joints"][1].__setitem__("scale", -3))
    mut("scale 1 LSB", 0, lambda r: r["joints"][1].__setitem__("scale", 1))
    mut("prismatic scale min (no kturn)", None, lambda r: r["joints"][2].__setitem__("scale", rmin(cfg, "scale_t")),
        robot="stanford")
    # limits
    mut("prismatic without limits", 4, lambda r: r["joints"][2].__setitem__("jcfg", 1), robot="stanford")
    mut("prismatic unlimited but vlimited", 4, lambda r: r["joints"][2].__setitem__("jcfg", 5), robot="stanford")
    mut("lower > upper", 4, lambda r: r["joints"][3].__setitem__("lower", r["joints"][3]["upper"] + 1))
    mut("lower = upper", 0, lambda r: r["joints"][3].__setitem__("lower", r["joints"][3]["upper"]))
    mut("lower > upper, not limited", 0, lambda r: (r["joints"][3].__setitem__("jcfg", 4),
                                                    r["joints"][3].__setitem__("lower", 5),
                                                    r["joints"][3].__setitem__("upper", -5)))
    mut("vmax 0", 4, lambda r: r["joints"][4].__setitem__("vmax", 0))
    mut("vmax negative", 4, lambda r: r["joints"][4].__setitem__("vmax", -1))
    mut("vmax most negative", 4, lambda r: r["joints"][0].__setitem__("vmax", rmin(cfg, "qd_t")))
    mut("vmax 1 LSB", 0, lambda r: r["joints"][4].__setitem__("vmax", 1))
    mut("vmax 0 without VLIMITED", 0, lambda r: (r["joints"][4].__setitem__("vmax", 0),
                                                 r["joints"][4].__setitem__("jcfg", 2)))
    mut("mu negative", 10, lambda r: r["joints"][5].__setitem__("mu", -1))
    mut("mu most negative", 10, lambda r: r["joints"][0].__setitem__("mu", rmin(cfg, "mu_t")))
    mut("mu 0", 0, lambda r: r["joints"][5].__setitem__("mu", 0))
    mut("mu max", 0, lambda r: r["joints"][5].__setitem__("mu", rmax(cfg, "mu_t")))
    mut("limits before mu (j2)", 4, lambda r: (r["joints"][2].__setitem__("mu", -5),
                                               r["joints"][2].__setitem__("vmax", 0)))
    mut("joint order: j1 mu before j4 axis", 10, lambda r: (r["joints"][1].__setitem__("mu", -5),
                                                           r["joints"][4].__setitem__("axis", [0, 0, 0])))
    # reach bounds (len_t raw units), on both sides of each
    _, fl = fw(cfg, "len_t")
    lmax = rmax(cfg, "len_t")

    def less(x, fx, y, fy):
        return x < (y << (fx - fy)) if fx >= fy else (x << (fy - fx)) < y

    def max_reach(bound_ok):
        """Largest R with bound_ok(R)."""
        lo, hi = 0, 1 << 70
        while hi - lo > 1:
            mid = (lo + hi) // 2
            lo, hi = (mid, hi) if bound_ok(mid) else (lo, mid)
        return lo

    r1 = max_reach(lambda R: less(R, fl, rmax(cfg, "lever_t"), fw(cfg, "lever_t")[1]))

    def spread(raw, total, n_used, keys=("po",)):
        """Write offsets whose L1 norms add to total over the tool and the first n_used joints."""
        raw["tool_p"] = [0, 0, 0]
        for j in range(n_used):
            raw["joints"][j]["po"] = [0, 0, 0]
        slots = [("tool", a) for a in range(3)] + [(j, a) for j in range(n_used) for a in range(3)]
        left = total
        for k, (who, a) in enumerate(slots):
            v = min(left, lmax)
            sign = -1 if k % 2 else 1
            if who == "tool":
                raw["tool_p"][a] = sign * v
            else:
                raw["joints"][who]["po"][a] = sign * v
            left -= v
        assert left == 0, "reach not representable"

    for name, R, code in (("reach = lever max", r1, None), ("reach = lever max + 1", r1 + 1, 7)):
        def f(raw, R=R):
            spread(raw, R, 6)
            for j in raw["joints"]:
                j["scale"] = 1  # keep the Jacobian bound clear
        mut(name, code, f)
    # base offset + reach vs pos_t
    for extra, code in ((0, None), (1, 7)):
        def f(raw, extra=extra):
            spread(raw, r1, 6)
            for j in raw["joints"]:
                j["scale"] = 1
            rpos = max_reach(lambda R: less(R, fl, rmax(cfg, "pos_t"), fw(cfg, "pos_t")[1]))
            rem = rpos - r1 + extra
            bp = []
            for _ in range(3):
                v = min(rem, lmax)
                bp.append(-v)
                rem -= v
            assert rem == 0
            raw["base_p"] = bp
        mut(f"base + reach = pos max{' + 1' if extra else ''}", code, f)
    # scale x reach vs jv_t: prismatic joint with the largest scale, short stroke
    _, fs = fw(cfg, "scale_t")
    fjv = fw(cfg, "jv_t")[1]
    jvmax = rmax(cfg, "jv_t")
    smag = -rmin(cfg, "scale_t")
    for d, code in ((0, None), (1, 7)):
        def f(raw, d=d):
            j2 = raw["joints"][2]
            j2["scale"] = -smag
            j2["lower"], j2["upper"] = 0, 0  # stroke 0
            rj = max_reach(lambda R: less(smag * R, fs + fl, jvmax, fjv))
            spread(raw, rj + d, 6)
        mut(f"smax x reach = jv max{' + 1' if d else ''}", code, f, robot="stanford")
    # stroke rounding up: one LSB of stroke pushes the reach over the lever bound
    def f_stroke(raw):
        j2 = raw["joints"][2]
        j2["scale"] = 1
        j2["lower"], j2["upper"] = 0, 1  # |s| max = 1 raw^2: rounds up to 1 len_t LSB
        spread(raw, r1, 6)
    mut("prismatic stroke rounds up over the lever bound", 7, f_stroke, robot="stanford")

    def f_stroke_big(raw):
        j2 = raw["joints"][2]
        j2["scale"] = rmax(cfg, "scale_t")
        j2["lower"], j2["upper"] = rmin(cfg, "angle_t"), rmax(cfg, "angle_t")
    mut("prismatic full-scale stroke", 7, f_stroke_big, robot="stanford")
    mut("reach order: lever before servo params", 7,
        lambda r: (f_stroke_big(r), r.__setitem__("lchar", 0)), robot="stanford")
    # servo parameters
    mut("lchar 0", 10, lambda r: r.__setitem__("lchar", 0))
    mut("lchar negative", 10, lambda r: r.__setitem__("lchar", -1))
    mut("lchar 1 LSB", 0, lambda r: r.__setitem__("lchar", 1))
    mut("dt 0", 10, lambda r: r.__setitem__("dt", 0))
    mut("dt negative", 10, lambda r: r.__setitem__("dt", rmin(cfg, "dt_t")))
    mut("dt 1 LSB", 0, lambda r: r.__setitem__("dt", 1))
    mut("kp negative", 10, lambda r: r.__setitem__("kp", -1))
    mut("ko negative", 10, lambda r: r.__setitem__("ko", rmin(cfg, "gain_t")))
    mut("kp ko 0", 0, lambda r: (r.__setitem__("kp", 0), r.__setitem__("ko", 0)))
    mut("klim negative", 10, lambda r: r.__setitem__("klim", -1))
    mut("klim 0", 0, lambda r: r.__setitem__("klim", 0))
    mut("sweeps 0", 10, lambda r: r.__setitem__("sweeps", 0))
    mut("sweeps 1", 0, lambda r: r.__setitem__("sweeps", 1))
    mut("sweeps 255", 0, lambda r: r.__setitem__("sweeps", 255))
    # MODE.SWEEPS is 8 bits: a written 256 is stored as 0 (and the model, given the stored 0, rejects)
    mut("sweeps 256 as stored (0)", 10, lambda r: r.__setitem__("sweeps", 256 & 0xFF))
    mut("warm leak 15 (largest storable)", 0, lambda r: r.__setitem__("warm_leak", 15))
    mut("warm leak 0", 0, lambda r: r.__setitem__("warm_leak", 0))
    mut("mode bits", 0, lambda r: r.__setitem__("mode", 3))
    mut("param order: lchar before dt", 10, lambda r: (r.__setitem__("lchar", 0), r.__setitem__("dt", 0)))
    mut("param order: dt before gains", 10, lambda r: (r.__setitem__("kp", -1), r.__setitem__("dt", 0)))
    mut("joint before param", 4, lambda r: (r.__setitem__("lchar", 0), r["joints"][5].__setitem__("vmax", 0)))
    return cases


def random_case(cfg: str, rng, base: dict) -> dict:
    """A robot's words with 1-3 random mutations (aimed at the checks' boundaries)."""
    raw = copy_raw(base)
    names = {"qo": "quat_t", "axis": "quat_t", "po": "len_t", "scale": "scale_t", "lower": "angle_t",
             "upper": "angle_t", "vmax": "qd_t", "mu": "mu_t"}
    glob = {"kp": "gain_t", "ko": "gain_t", "lchar": "lchar_t", "klim": "klim_t", "dt": "dt_t"}
    _, qf = fw(cfg, "quat_t")

    def rnd(fmt):
        w, _ = fw(cfg, fmt)
        kind = rng.integers(0, 4)
        if kind == 0:
            return int(rng.integers(-(1 << (w - 1)), 1 << (w - 1)))
        if kind == 1:
            return int(rng.choice([0, 1, -1, (1 << (w - 1)) - 1, -(1 << (w - 1))]))
        return int(rng.integers(-(1 << (w - 4)), 1 << (w - 4)))

    for _ in range(int(rng.integers(1, 4))):
        m = int(rng.integers(0, 12))
        j = int(rng.integers(0, NMAX if rng.random() < 0.2 else max(1, min(raw["n"], NMAX))))
        jt = raw["joints"][j]
        if m == 0:
            raw["n"] = int(rng.choice([0, 1, 2, 3, 5, 6, 7, NMAX, NMAX + 1, 200]))
        elif m in (1, 2):
            key = str(rng.choice(list(names)))
            if key in ("qo", "axis", "po"):
                a = int(rng.integers(0, len(jt[key])))
                if key != "po" and rng.random() < 0.6:
                    # perturb a unit component near the tolerance
                    jt[key][a] += int(rng.choice([-1, 1])) * int(rng.integers(0, 1 << max(0, qf - 9)))
                    w = fw(cfg, "quat_t")[0]
                    jt[key][a] = max(-(1 << (w - 1)), min((1 << (w - 1)) - 1, jt[key][a]))
                else:
                    jt[key][a] = rnd(names[key])
            else:
                jt[key] = rnd(names[key])
        elif m == 3:
            jt["jcfg"] = int(rng.integers(0, 8))
        elif m == 4:
            key = str(rng.choice(["base_q", "tool_q"]))
            a = int(rng.integers(0, 4))
            raw[key][a] += int(rng.choice([-1, 1])) * int(rng.integers(0, 1 << max(0, qf - 9)))
            w = fw(cfg, "quat_t")[0]
            raw[key][a] = max(-(1 << (w - 1)), min((1 << (w - 1)) - 1, raw[key][a]))
        elif m == 5:
            key = str(rng.choice(["base_p", "tool_p"]))
            raw[key][int(rng.integers(0, 3))] = rnd("len_t")
        elif m == 6:
            key = str(rng.choice(list(glob)))
            raw[key] = rnd(glob[key])
        elif m == 7:
            raw["sweeps"] = int(rng.choice([0, 1, 10, 255, int(rng.integers(0, 256))]))
            raw["warm_leak"] = int(rng.integers(0, 16))
            raw["mode"] = int(rng.integers(0, 4))
        elif m == 8:
            # large offsets on every joint (reach bounds)
            lmax = rmax(cfg, "len_t")
            for jj in raw["joints"]:
                jj["po"] = [int(rng.integers(-lmax, lmax + 1)) >> int(rng.integers(0, 4)) for _ in range(3)]
        elif m == 9:
            # scale near the kturn saturation / large prismatic scale
            smax = rmax(cfg, "scale_t")
            jt["scale"] = int(rng.integers(-smax - 1, smax + 1)) >> int(rng.integers(0, 3))
        elif m == 10:
            # prismatic joint with a random stroke
            jt["jcfg"] = 1 | 2 | int(rng.integers(0, 2)) * 4
            a, b = rnd("angle_t"), rnd("angle_t")
            jt["lower"], jt["upper"] = min(a, b), max(a, b)
        else:
            jt["lower"], jt["upper"] = jt["upper"], jt["lower"]
    return clamp_raw(cfg, raw)


# ---- cocotb side -------------------------------------------------------------------------------------
JOINT_PORTS = [  # (port suffix, raw key, index or None, format)
    ("origin_qw", "qo", 0, "quat_t"), ("origin_qx", "qo", 1, "quat_t"), ("origin_qy", "qo", 2, "quat_t"),
    ("origin_qz", "qo", 3, "quat_t"), ("origin_px", "po", 0, "len_t"), ("origin_py", "po", 1, "len_t"),
    ("origin_pz", "po", 2, "len_t"), ("axis_x", "axis", 0, "quat_t"), ("axis_y", "axis", 1, "quat_t"),
    ("axis_z", "axis", 2, "quat_t"), ("scale", "scale", None, "scale_t"), ("lower", "lower", None, "angle_t"),
    ("upper", "upper", None, "angle_t"), ("vmax", "vmax", None, "qd_t"), ("mu", "mu", None, "mu_t")]
GLOBAL_PORTS = [("kp", "kp", None, "gain_t"), ("ko", "ko", None, "gain_t"), ("lchar", "lchar", None, "lchar_t"),
                ("klim", "klim", None, "klim_t"), ("dt", "dt", None, "dt_t")] + \
    [(f"base_q{c}", "base_q", i, "quat_t") for i, c in enumerate("wxyz")] + \
    [(f"base_p{c}", "base_p", i, "len_t") for i, c in enumerate("xyz")] + \
    [(f"tool_q{c}", "tool_q", i, "quat_t") for i, c in enumerate("wxyz")] + \
    [(f"tool_p{c}", "tool_p", i, "len_t") for i, c in enumerate("xyz")]


def port_words(cfg: str, raw: dict) -> dict:
    """Unsigned port values (suffix -> int) of a raw configuration."""
    out = {"njoints": raw["n"] & 0xFF, "mode_err_b": raw["mode"] & 1, "mode_error_only": (raw["mode"] >> 1) & 1,
           "mode_sweeps": raw["sweeps"] & 0xFF, "mode_warm_leak": raw["warm_leak"] & 0xF}
    for port, key, i, fmt in GLOBAL_PORTS:
        w, _ = fw(cfg, fmt)
        v = raw[key] if i is None else raw[key][i]
        out[port] = v & ((1 << w) - 1)
    js = raw["joints"]
    for bit, name in ((1, "prismatic"), (2, "limited"), (4, "vlimited")):
        out[f"joint_jcfg_{name}"] = sum((1 << j) for j in range(NMAX) if js[j]["jcfg"] & bit)
    for port, key, i, fmt in JOINT_PORTS:
        w, _ = fw(cfg, fmt)
        word = 0
        for j in range(NMAX):
            v = js[j][key] if i is None else js[j][key][i]
            word |= (v & ((1 << w) - 1)) << (j * w)
        out[f"joint_{port}"] = word
    return out


def shadowed(port: str) -> bool:
    """Whether the commit engine keeps a shadow of in_<port>: the global words and the JCFG bits, not
    the joints' other words (the core holds those still from the start until its loader is done)."""
    return not port.startswith("joint_") or port.startswith("joint_jcfg_")


def clamp_raw(cfg: str, raw: dict) -> dict:
    """Saturate every word to its format (what a mutation may have pushed out of range)."""
    def c(v, fmt):
        return max(rmin(cfg, fmt), min(rmax(cfg, fmt), v))
    for port, key, i, fmt in GLOBAL_PORTS:
        if i is None:
            raw[key] = c(raw[key], fmt)
        else:
            raw[key][i] = c(raw[key][i], fmt)
    for j in raw["joints"]:
        for port, key, i, fmt in JOINT_PORTS:
            if i is None:
                j[key] = c(j[key], fmt)
            else:
                j[key][i] = c(j[key][i], fmt)
    return raw


def check_fits(cfg: str, raw: dict) -> None:
    """The words must be what the register block can hold (W-bit values): the model then sees
    exactly the RTL's words."""
    for port, key, i, fmt in GLOBAL_PORTS:
        v = raw[key] if i is None else raw[key][i]
        assert rmin(cfg, fmt) <= v <= rmax(cfg, fmt), (port, v)
    for j in raw["joints"]:
        for port, key, i, fmt in JOINT_PORTS:
            v = j[key] if i is None else j[key][i]
            assert rmin(cfg, fmt) <= v <= rmax(cfg, fmt), (port, v)
    assert 0 <= raw["n"] <= 255 and 0 <= raw["sweeps"] <= 255 and 0 <= raw["warm_leak"] <= 15


if cocotb is not None:
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge, RisingEdge, Timer

    async def drive(dut, words: dict) -> None:
        for k, v in words.items():
            getattr(dut, f"in_{k}").value = v

    async def commit(dut, cfg: str, raw: dict, disturb=None) -> tuple[dict, int]:
        """Drive the words, pulse in_start, wait for out_done.  Returns (result, cycles from the
        start edge to the edge that raised out_done)."""
        words = port_words(cfg, raw)
        await drive(dut, words)
        dut.in_start.value = 1
        await FallingEdge(dut.clk)
        dut.in_start.value = 0
        assert int(dut.out_busy.value) == 1, "out_busy not set after the start edge"
        if disturb is not None:   # only the shadowed words may change (the core holds the others)
            await drive(dut, {k: v for k, v in port_words(cfg, disturb).items() if shadowed(k)})
        cyc = 1
        ld_rnd = random.Random(int(os.environ["TS_SEED"]) + cyc)
        while not int(dut.out_done.value):
            assert int(dut.out_busy.value) == 1, "out_busy dropped before out_done"
            dut.in_ld_j.value = ld_rnd.randrange(NMAX)   # the loader's joint is ignored while busy
            await FallingEdge(dut.clk)
            cyc += 1
            assert cyc < 2000, "commit did not finish"
        assert int(dut.out_busy.value) == 0
        ok = int(dut.out_cfg_ok.value)
        assert ok + int(dut.out_cfg_err.value) == 1
        res = {"ok": ok, "code": int(dut.out_err_code.value), "joint": int(dut.out_err_joint.value)}
        kw = fw(cfg, "kturn_t")[0]
        kt = int(dut.out_joint_kturn.value)
        res["kturn"] = [tsbench.to_signed((kt >> (j * kw)) & ((1 << kw) - 1), kw) for j in range(NMAX)]
        # shadow outputs = the words of the start edge
        for k, v in words.items():
            if shadowed(k):
                got = int(getattr(dut, f"out_{k}").value)
                assert got == v, f"shadow out_{k}: {got:#x}, words at start {v:#x}"
        await FallingEdge(dut.clk)
        assert int(dut.out_done.value) == 0, "out_done longer than one cycle"
        await check_loader_port(dut, cfg, raw, words)
        return res, cyc

    #: the loader's port: out_ld_* -> the input bus with joint j's word
    LD_PORTS = [("qo0", "joint_origin_qw"), ("qo1", "joint_origin_qx"), ("qo2", "joint_origin_qy"),
                ("qo3", "joint_origin_qz"), ("ax0", "joint_axis_x"), ("ax1", "joint_axis_y"),
                ("ax2", "joint_axis_z"), ("pox", "joint_origin_px"), ("poy", "joint_origin_py"),
                ("poz", "joint_origin_pz"), ("s", "joint_scale"), ("lo", "joint_lower"),
                ("hi", "joint_upper"), ("vmax", "joint_vmax"), ("mu", "joint_mu")]

    async def check_loader_port(dut, cfg: str, raw: dict, words: dict) -> None:
        """While idle, out_ld_* show joint in_ld_j's words (the core's loader reads them); VMAX as the
        model holds it: the word when JCFG.VLIMITED (of the start edge), else max(qd_t)."""
        for j in range(NMAX):
            dut.in_ld_j.value = j
            await Timer(1, units="ns")
            for ld, bus in LD_PORTS:
                w = len(getattr(dut, f"out_ld_{ld}"))
                want = (words[bus] >> (j * w)) & ((1 << w) - 1)
                if ld == "vmax" and not raw["joints"][j]["jcfg"] & 4:
                    want = rmax(cfg, "qd_t")
                got = int(getattr(dut, f"out_ld_{ld}").value)
                assert got == want, f"out_ld_{ld} for joint {j}: {got:#x}, word {want:#x}"
        dut.in_ld_j.value = 0
        await FallingEdge(dut.clk)      # back on the bench's phase (inputs change at falling edges)

    def compare(cfg: str, name: str, raw: dict, res: dict, exp: dict, cyc: int) -> None:
        ok = exp["code"] == 0
        ej = exp["joint"] & 0xFF
        assert (res["ok"], res["code"], res["joint"]) == (int(ok), exp["code"], ej), (
            f"{name}: rtl ok={res['ok']} code={res['code']} joint={res['joint']:#x}; model code={exp['code']} "
            f"joint={exp['joint']} ({exp['field']}: {exp['message']})")
        want = commit_cycles(cfg, raw["n"], exp["code"], exp["joint"])
        assert cyc == want, f"{name}: out_done {cyc} cycles after the start, documented {want}"
        if ok:
            n = raw["n"]
            assert res["kturn"][:n] == list(exp["kturn_raw"]), f"{name}: kturn rtl {res['kturn'][:n]} model {exp['kturn_raw']}"

    @cocotb.test()
    async def commit_bit_exact(dut):
        from tensor_servo import robots
        cfg = os.environ["TS_CONFIG"]
        seed = int(os.environ["TS_SEED"])
        rng = np.random.default_rng(seed)
        dut._log.info("config %s, seed %d, %d random cases", cfg, seed, N_RANDOM)
        cocotb.start_soon(Clock(dut.clk, 10, units="ns").start())
        dut.rst.value = 1
        dut.in_start.value = 0
        dut.in_ld_j.value = 0
        await drive(dut, port_words(cfg, raw_from_chain(robots.load("puma560"), cfg)))
        for _ in range(4):
            await FallingEdge(dut.clk)
        dut.rst.value = 0
        await FallingEdge(dut.clk)
        for h in dut:
            if h._name.startswith("out_"):
                assert h.value.is_resolvable, f"{h._name} is {h.value.binstr} after reset"
        assert int(dut.out_busy.value) == 0 and int(dut.out_cfg_ok.value) == 0 and int(dut.out_cfg_err.value) == 0

        codes = {}
        cycles = {}
        # directed cases
        cases = directed_cases(cfg)
        for name, raw, want in cases:
            check_fits(cfg, raw)
            exp = model(cfg, raw)
            if want is not None:
                assert exp["code"] == want, f"case '{name}' should give code {want}, the model gives {exp}"
            res, cyc = await commit(dut, cfg, raw)
            compare(cfg, name, raw, res, exp, cyc)
            codes[exp["code"]] = codes.get(exp["code"], 0) + 1
            if exp["code"] == 0:
                cycles.setdefault(raw["n"], set()).add(cyc)
            dut._log.debug("%s: code %d joint %d, %d cycles", name, exp["code"], exp["joint"], cyc)
        dut._log.info("directed: %d cases, codes %s", len(cases), dict(sorted(codes.items())))
        for c in (1, 2, 3, 4, 5, 7, 10, 0):
            assert c in codes, f"code {c} not covered by the directed cases"

        # a register write during the commit does not disturb it
        base = {r: raw_from_chain(robots.load(r), cfg) for r in ROBOTS}
        bad = copy_raw(base["panda"])
        bad["joints"][0]["axis"] = [0, 0, 0]
        # shadowed words that would fail the commit (count, base quaternion) or change its result
        # (JCFG.PRISMATIC of joint 1, kturn 0)
        disturb = copy_raw(base["panda"])
        disturb["n"] = 0
        disturb["base_q"] = [0, 0, 0, 0]
        disturb["joints"][1]["jcfg"] |= 1
        assert model(cfg, disturb)["code"] != 0
        res, cyc = await commit(dut, cfg, base["panda"], disturb=disturb)
        compare(cfg, "panda, words changed during the commit", base["panda"], res, model(cfg, base["panda"]), cyc)
        # a start while busy restarts with the new words
        await drive(dut, port_words(cfg, bad))
        dut.in_start.value = 1
        await FallingEdge(dut.clk)
        dut.in_start.value = 0
        for _ in range(int(rng.integers(1, 16))):  # the bad words fail at joint 0, after > 20 cycles
            await FallingEdge(dut.clk)
        assert int(dut.out_busy.value) == 1
        res, cyc = await commit(dut, cfg, base["ur5"])
        compare(cfg, "restart while busy", base["ur5"], res, model(cfg, base["ur5"]), cyc)

        # random mutations
        rcodes = {}
        for k in range(N_RANDOM):
            raw = random_case(cfg, rng, base[ROBOTS[k % len(ROBOTS)]])
            check_fits(cfg, raw)
            exp = model(cfg, raw)
            res, cyc = await commit(dut, cfg, raw)
            compare(cfg, f"random {k}", raw, res, exp, cyc)
            rcodes[exp["code"]] = rcodes.get(exp["code"], 0) + 1
            if exp["code"] == 0:
                cycles.setdefault(raw["n"], set()).add(cyc)
        dut._log.info("random: %d cases, codes %s", N_RANDOM, dict(sorted(rcodes.items())))
        dut._log.info("cycles per successful commit by joint count: %s",
                      {n: sorted(c) for n, c in sorted(cycles.items())})
        for n, c in cycles.items():
            assert len(c) == 1, f"cycles of a successful commit with n = {n} vary: {c}"
        Path(os.environ["TS_CYCLES_FILE"]).write_text(json.dumps({n: min(c) for n, c in cycles.items()}))


# ---- pytest side --------------------------------------------------------------------------------------
@pytest.mark.parametrize("cfg", tsbench.CONFIGS)
def test_ts_core_commit_params(cfg):
    """The module's CONFIG-derived widths and constants are the model's formats."""
    got = verilog_defaults(tsbench.CONFIGS.index(cfg))
    exp = expected_params(cfg)
    bad = {k: (got.get(k), v) for k, v in exp.items() if got.get(k) != v}
    assert not bad, f"parameter defaults (verilog, model) differ: {bad}"


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("cfg", tsbench.CONFIGS)
def test_ts_core_commit(cfg, sim):
    target = tsbench.target_for(sim)
    p = {"NMAX": NMAX, "CONFIG": tsbench.CONFIGS.index(cfg), "TARGET": target}
    build = f"{cfg}-{target}-{sim}" + (f"-nmax{NMAX}" if NMAX != 8 else "")
    cyc_file = tsbench.BUILD / "ts_core_commit" / f"cycles-{build}.json"
    cyc_file.parent.mkdir(parents=True, exist_ok=True)
    tsbench.run_bench(toplevel=MODULE, test_file=__file__, sources=rtlparams.sources(MODULE, target),
                      parameters=p, sim=sim, build_name=build,
                      env={"TS_CONFIG": cfg, "TS_CYCLES_FILE": str(cyc_file), "TS_NMAX": str(NMAX)})
    print(f"[{MODULE} {build}] cycles per commit by n: {cyc_file.read_text()}")
