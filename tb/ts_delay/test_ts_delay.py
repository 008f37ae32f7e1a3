"""Bench of rtl/ts_delay.v: DEPTH 0 (a wire), 1 and D, with D and W from the longest operand delay of
the datapath in each configuration (the axis of ts_joint_quat: 3 quat_t components over the
angle product, wrap and sincos); every output equals the input of exactly DEPTH cycles earlier on
every cycle (valid or not); reset clears the whole line (zeros for DEPTH cycles after reset).  The
long line runs in both implementations (ring in a memory and shift register), with rings of 2 and
16 words beside it; resets come with the lines full, part-filled, twice in a row and at random.
"""
import os
import random

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
    class ShiftRef:
        """Reference line of DEPTH stages: a synchronous reset clears every stage."""

        def __init__(self, depth):
            self.s = [0] * depth

        def edge(self, x, rst):
            self.s = [0] * len(self.s) if rst else [x] + self.s[:-1]

        def out(self):
            return self.s[-1]

    @cocotb.test()
    async def delay_every_cycle(dut):
        w, d = int(os.environ["TS_W"]), int(os.environ["TS_D"])
        seed = int(os.environ["TS_SEED"])
        rnd = random.Random(seed)
        dut._log.info("W %d, D %d, seed %d", w, d, seed)
        lines = {"out_d1": 1, "out_d3": 3, "out_d17": 17, "out_dd": d, "out_ds": d}
        ref = {name: ShiftRef(depth) for name, depth in lines.items()}
        vref = ShiftRef(d)
        cocotb.start_soon(Clock(dut.clk, 10, units="ns").start())
        dut.rst.value = 1
        dut.in_valid.value = 0
        dut.in_d.value = 0
        for _ in range(3):
            await FallingEdge(dut.clk)
        # Resets: with the lines full, with the rings part-filled (after 2, 9 and d // 2 - 1 words), on two
        # cycles in a row, and at random (1 in 300 cycles)
        n = N_RANDOM
        forced = {d + 5, d + 5 + 3, d + 5 + 3 + 10, d + 5 + 3 + 10 + d // 2, d + 5 + 3 + 10 + d // 2 + 1}
        resets = 0
        for t in range(n + 40):
            x, v = rnd.getrandbits(w), int(rnd.random() < 0.7)
            r = int(t in forced or (t > 60 and rnd.random() < 1 / 300))
            resets += r
            dut.in_d.value = x
            dut.in_valid.value = v
            dut.rst.value = r
            await FallingEdge(dut.clk)
            assert int(dut.out_d0.value) == x, f"DEPTH 0 differs at cycle {t}"
            for line in ref.values():
                line.edge(x, r)
            vref.edge(v, r)
            for name, line in ref.items():
                got = int(getattr(dut, name).value)
                assert got == line.out(), (f"{name} (DEPTH {lines[name]}) at cycle {t} after "
                                           f"{resets} resets: {got:x} != {line.out():x}")
            assert int(dut.out_valid.value) == vref.out(), f"valid DEPTH {d} differs at cycle {t}"
        assert resets >= len(forced)


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("cfg", tsbench.CONFIGS)
def test_ts_delay(cfg, sim):
    w, d = shape(cfg)
    here = os.path.dirname(os.path.abspath(__file__))
    tsbench.run_bench(toplevel="tb_ts_delay", test_file=__file__,
                      sources=[os.path.join(here, "tb_ts_delay.v")] + rtlparams.sources(MODULE),
                      parameters={"W": w, "D": d}, sim=sim, build_name=f"{cfg}-{sim}",
                      env={"TS_W": str(w), "TS_D": str(d)})
