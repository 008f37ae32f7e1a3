"""Bench of rtl/ts_mul.v, both implementations (GENERIC inferred, ECP5 MULT18X18D instances simulated
with tb/sim/MULT18X18D.v) on both simulators: four instances with the operand shapes the datapath uses
in a configuration, exact products (fx operator* is the exact integer product) on random operands
and the edge cases of the ECP5 decomposition (extremes, the 17-bit split boundary, zero, +-1).
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
    sh = shapes(cfg)
    params = {"TARGET": target}
    for k, (aw, bw) in enumerate(sh):
        params[f"AW{k}"], params[f"BW{k}"] = aw, bw
    here = os.path.dirname(os.path.abspath(__file__))
    tsbench.run_bench(toplevel="tb_ts_mul", test_file=__file__,
                      sources=[os.path.join(here, "tb_ts_mul.v")] + rtlparams.sources(MODULE, target),
                      parameters=params, sim=sim, build_name=f"{cfg}-{target}-{sim}",
                      env={"TS_SHAPES": json.dumps(sh), "TS_TARGET": target})
