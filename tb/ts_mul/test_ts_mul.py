"""Bench of rtl/ts_mul.v, both implementations (GENERIC inferred, ECP5 MULT18X18D instances simulated
with tb/sim/MULT18X18D.v) on both simulators: four instances with the operand shapes the datapath uses
in a configuration, exact products (fx operator* is the exact integer product) on random operands
and the edge cases of the ECP5 decompositions (extremes, the 16- and 17-bit split boundaries, zero,
+-1).  The ECP5 three-multiplier form (MUL3 = 1) runs on the shapes that take it, from the smallest
(19 x 19) to the largest (33 x 33), and on a shape it must leave to the four-multiplier form.
"""
import json
import os

import numpy as np
import pytest

import rtlparams
import tsbench

MODULE = "ts_mul"
N_RANDOM = int(os.environ.get("TS_NVEC", "10000"))


def shapes(cfg):
    f = lambda n: rtlparams.fmt(cfg, n)[0]  # noqa: E731
    r = f("turn_t") - 2 - int(rtlparams.formats(cfg)["TRIG_TABLE_BITS"])
    used = [(f("quat_t"), f("quat_t")), (f("angle_t"), f("kturn_t")), (r + 1, f("twopi_t")),
            (f("dsq_t"), f("sixth_t"))]
    out = []
    for s in used + [(18, 17), (9, 18), (2, 18)]:   # fillers where a configuration repeats a shape
        if s not in out:
            out.append(s)
    return out[:4]


def operands(w, seed, n):
    import random
    rnd = random.Random(seed)
    lo, hi = -(1 << (w - 1)), (1 << (w - 1)) - 1
    edge = [lo, hi, 0, 1, -1, lo + 1, hi - 1]
    for b in (16, 17, 18):
        edge += [(1 << b) - 1, 1 << b, -(1 << b), -(1 << b) - 1, (1 << b) + 1]
    edge = [max(lo, min(hi, e)) for e in edge]
    vals = [rnd.choice(edge) for _ in range(n // 8)] + [rnd.randint(lo, hi) for _ in range(n - n // 8)]
    rnd.shuffle(vals)
    return vals


try:
    import cocotb
except ImportError:  # pragma: no cover
    cocotb = None

if cocotb is not None:
    @cocotb.test()
    async def mul_exact(dut):
        sh = [tuple(s) for s in json.loads(os.environ["TS_SHAPES"])]
        seed = int(os.environ["TS_SEED"])
        dut._log.info("shapes %s, target %s, seed %d", sh, os.environ["TS_TARGET"], seed)
        rng = np.random.default_rng(seed)
        ops = []
        for k, (aw, bw) in enumerate(sh):
            ops.append(operands(aw, seed + 2 * k, N_RANDOM))
            ops.append(operands(bw, seed + 2 * k + 1, N_RANDOM))
        rows = [tuple(o[i] & ((1 << 64) - 1) for o in ops) for i in range(N_RANDOM)]
        lat = max(rtlparams.mul_lat(a, b) for a, b in sh)
        st = tsbench.Stream(dut, [f"in_{x}{k}" for k in range(4) for x in "ab"], [f"out_p{k}" for k in range(4)], lat, rng)
        await st.reset()
        got = await st.run(rows)
        for k in range(4):
            want = [a * b for a, b in zip(ops[2 * k], ops[2 * k + 1])]
            have = [g[k] for g in got]
            bad = [i for i in range(N_RANDOM) if want[i] != have[i]]
            assert not bad, (f"instance {k} {sh[k]}: {len(bad)} wrong products, first: "
                             f"{ops[2 * k][bad[0]]} * {ops[2 * k + 1][bad[0]]} = {want[bad[0]]}, rtl {have[bad[0]]}")


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("target", rtlparams.TARGETS)
@pytest.mark.parametrize("cfg", tsbench.CONFIGS)
def test_ts_mul(cfg, target, sim):
    run(shapes(cfg), target, sim, f"{cfg}-{target}-{sim}")


#: MUL3 shapes: both widths in 19..33 (the Karatsuba range), the range's corners, and 34 x 27,
#: which must fall back to the four-multiplier form
MUL3_SHAPES = [(33, 33), (19, 19), (27, 32), (34, 27)]


@pytest.mark.parametrize("sim", tsbench.SIMS)
def test_ts_mul_mul3(sim):
    run(MUL3_SHAPES, "ECP5", sim, f"mul3-{sim}", mul3=1)


def run(sh, target, sim, build_name, mul3=0):
    params = {"TARGET": target, "MUL3": mul3}
    for k, (aw, bw) in enumerate(sh):
        params[f"AW{k}"], params[f"BW{k}"] = aw, bw
    here = os.path.dirname(os.path.abspath(__file__))
    tsbench.run_bench(toplevel="tb_ts_mul", test_file=__file__,
                      sources=[os.path.join(here, "tb_ts_mul.v")] + rtlparams.sources(MODULE, target),
                      parameters=params, sim=sim, build_name=build_name,
                      env={"TS_SHAPES": json.dumps(sh), "TS_TARGET": target})


def mult18_count(aw, bw, mul3):
    """MULT18X18D cells of one ts_mul (TARGET "ECP5") as Debian yosys elaborates it."""
    import re
    import shutil
    import subprocess
    exe = shutil.which("yosys")
    assert exe, "Debian yosys is not installed (scripts/setup_system.sh installs it)"
    rtl = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "rtl")
    files = " ".join(os.path.join(rtl, f) for f in ("ts_mul.v", "ts_resize.v", "ts_delay.v", "ts_ecp5_mult18.v"))
    script = (f"read_verilog -lib +/ecp5/cells_bb.v; read_verilog -I{rtl} {files}; "
              f"chparam -set A_W {aw} -set B_W {bw} -set TARGET \"ECP5\" -set MUL3 {mul3} ts_mul; "
              "hierarchy -top ts_mul; flatten; stat")
    p = subprocess.run([exe, "-p", script], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr[-2000:]
    m = re.findall(r"^\s+MULT18X18D\s+(\d+)\s*$", p.stdout, re.M)
    return int(m[-1]) if m else 0


@pytest.mark.parametrize("aw,bw,mul3,want", [
    (27, 32, 1, 3), (33, 33, 1, 3), (19, 19, 1, 3),   # the three-multiplier range
    (34, 27, 1, 4), (27, 34, 1, 4),                   # a pre-add would not fit 18 bits
    (27, 18, 1, 2), (18, 18, 1, 1),                   # not a four-part product: untouched
    (27, 32, 0, 4), (33, 33, 0, 4)])                  # MUL3 = 0: the four-multiplier form
def test_ts_mul_mul3_multipliers(aw, bw, mul3, want):
    """MUL3 = 1 takes one MULT18X18D off a four-part product exactly where its pre-adds fit."""
    assert mult18_count(aw, bw, mul3) == want
