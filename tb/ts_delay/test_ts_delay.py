"""Bench of rtl/ts_delay.v: DEPTH 0 (a wire), 1 and D, with D and W from the longest operand delay of
the datapath in each configuration (the axis of ts_joint_quat: 3 quat_t components over the
angle product, wrap and sincos); every output equals the input of exactly DEPTH cycles earlier on
every cycle (valid or not); reset clears the whole line (zeros for DEPTH cycles after reset).
"""
import os

import numpy as np
import pytest

import rtlparams
import tsbench

MODULE = "ts_delay"
N_RANDOM = int(os.environ.get("TS_NVEC", "10000"))


def shape(cfg):
    p = rtlparams.joint_quat(cfg)
    d = rtlparams.mul_lat(p["ANG_W"], p["KT_W"]) + rtlparams.ROUND_LAT + rtlparams.latency("ts_sincos", p)
    return 3 * p["Q_W"], d


try:
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge
except ImportError:  # pragma: no cover
    cocotb = None

if cocotb is not None:
    @cocotb.test()
    async def delay_every_cycle(dut):
        w, d = int(os.environ["TS_W"]), int(os.environ["TS_D"])
        seed = int(os.environ["TS_SEED"])
        rng = np.random.default_rng(seed)
        import random
        rnd = random.Random(seed)
        dut._log.info("W %d, D %d, seed %d", w, d, seed)
        cocotb.start_soon(Clock(dut.clk, 10, units="ns").start())
        dut.rst.value = 1
        dut.in_valid.value = 0
        dut.in_d.value = 0
        for _ in range(3):
            await FallingEdge(dut.clk)
        # fill the line with data, then reset in the middle of the stream
        for _ in range(d + 5):
            dut.rst.value = 0
            dut.in_d.value = rnd.getrandbits(w)
            dut.in_valid.value = 1
            await FallingEdge(dut.clk)
        dut.rst.value = 1
        await FallingEdge(dut.clk)
        dut.rst.value = 0
        hist = []
        n = N_RANDOM
        for t in range(n + d + 1):
            # outputs now: line state after the last rising edge
            if t >= 1:
                x0 = int(dut.out_d0.value)
                assert x0 == hist[-1][0], f"DEPTH 0 differs at cycle {t}"
                assert int(dut.out_d1.value) == hist[-1][0], f"DEPTH 1 differs at cycle {t}"
                want = hist[t - d] if t - d >= 0 else (0, 0)
                assert int(dut.out_dd.value) == want[0], f"DEPTH {d}: cycle {t}: {int(dut.out_dd.value):x} != {want[0]:x}"
                assert int(dut.out_valid.value) == want[1], f"valid DEPTH {d} differs at cycle {t}"
            v = (rnd.getrandbits(w), int(rng.random() < 0.7))
            dut.in_d.value = v[0]
            dut.in_valid.value = v[1]
            hist.append(v)
            await FallingEdge(dut.clk)


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("cfg", tsbench.CONFIGS)
def test_ts_delay(cfg, sim):
    w, d = shape(cfg)
    here = os.path.dirname(os.path.abspath(__file__))
    tsbench.run_bench(toplevel="tb_ts_delay", test_file=__file__,
                      sources=[os.path.join(here, "tb_ts_delay.v")] + rtlparams.sources(MODULE),
                      parameters={"W": w, "D": d}, sim=sim, build_name=f"{cfg}-{sim}",
                      env={"TS_W": str(w), "TS_D": str(d)})
