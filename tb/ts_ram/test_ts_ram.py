"""Bench of rtl/ts_ram.v: 2^AW words of W bits, one synchronous write port, R asynchronous read
ports, no reset.  Against a Python list, on every cycle: random writes (half the cycles) and
random read addresses, reads of the word being written in the same cycle (the old word, as a
register array with nonblocking writes) and every word 0 before its first write."""
import os
import random

import pytest

import tsbench

N_RANDOM = int(os.environ.get("TS_NVEC", "3000"))
SHAPES = [(18, 3, 1), (54, 3, 2), (96, 5, 2), (8, 1, 1)]    # (W, AW, R): per-joint words, NMAX 32, one address bit

try:
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge, Timer
except ImportError:  # pragma: no cover
    cocotb = None

if cocotb is not None:
    @cocotb.test()
    async def write_read_every_cycle(dut):
        w, aw, r = (int(os.environ[k]) for k in ("TS_W", "TS_AW", "TS_R"))
        rnd = random.Random(int(os.environ["TS_SEED"]))
        cocotb.start_soon(Clock(dut.clk, 10, units="ns").start())
        mem = [0] * (1 << aw)
        dut.in_we.value = 0
        dut.in_waddr.value = 0
        dut.in_wdata.value = 0
        dut.in_raddr.value = 0
        await FallingEdge(dut.clk)
        same = 0
        for t in range(N_RANDOM):
            we = int(rnd.random() < 0.5)
            wa = rnd.randrange(1 << aw)
            wd = rnd.getrandbits(w)
            ra = [wa if (rnd.random() < 0.25) else rnd.randrange(1 << aw) for _ in range(r)]
            dut.in_we.value = we
            dut.in_waddr.value = wa
            dut.in_wdata.value = wd
            dut.in_raddr.value = sum(a << (k * aw) for k, a in enumerate(ra))
            await Timer(1, units="ns")     # before the rising edge: the words before this write
            got = int(dut.out_rdata.value)
            for k, a in enumerate(ra):
                want = mem[a]
                g = (got >> (k * w)) & ((1 << w) - 1)
                assert g == want, f"cycle {t}: port {k} word {a}: {g:#x} != {want:#x}"
                same += int(we and a == wa)
            await FallingEdge(dut.clk)     # the write happens at the rising edge in between
            if we:
                mem[wa] = wd
        assert same > 0


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("w,aw,r", SHAPES)
def test_ts_ram(w, aw, r, sim):
    import rtlparams
    tsbench.run_bench(toplevel="ts_ram", test_file=__file__, sources=rtlparams.sources("ts_ram"),
                      parameters={"W": w, "AW": aw, "R": r}, sim=sim, build_name=f"{w}x{aw}x{r}-{sim}",
                      env={"TS_W": str(w), "TS_AW": str(aw), "TS_R": str(r)})
