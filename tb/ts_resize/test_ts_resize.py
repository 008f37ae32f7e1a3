"""Bench of rtl/ts_resize.v (combinational): out = (in * 2^LSH) mod 2^OUT_W read as two's complement,
in its six cases, for random inputs and the extremes; W = the configuration's quat_t width."""
import os

import pytest

import rtlparams
import tsbench

N_RANDOM = int(os.environ.get("TS_NVEC", "10000"))
CASES = [("out_ext", 0, 8), ("out_same", 0, 0), ("out_trunc", 0, -4),
         ("out_sh_ext", 5, 9), ("out_sh_same", 5, 5), ("out_sh_trunc", 5, 2)]   # (port, LSH, OUT_W - W)

try:
    import cocotb
    from cocotb.triggers import Timer
except ImportError:  # pragma: no cover
    cocotb = None

if cocotb is not None:
    @cocotb.test()
    async def resize_cases(dut):
        import random
        w = int(os.environ["TS_W"])
        seed = int(os.environ["TS_SEED"])
        rnd = random.Random(seed)
        dut._log.info("W %d, seed %d", w, seed)
        lo, hi = -(1 << (w - 1)), (1 << (w - 1)) - 1
        xs = [lo, hi, 0, -1, 1] + [rnd.randint(lo, hi) for _ in range(N_RANDOM)]
        handles = [(getattr(dut, n), sh, w + dw) for n, sh, dw in CASES]
        for x in xs:
            dut.in_x.value = x & ((1 << w) - 1)
            await Timer(1, units="ns")
            for h, sh, ow in handles:
                want = tsbench.to_signed((x << sh) & ((1 << ow) - 1), ow)
                got = tsbench.to_signed(int(h.value), ow)
                assert got == want, f"{h._name}: in {x}: {got} != {want}"


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("cfg", tsbench.CONFIGS)
def test_ts_resize(cfg, sim):
    w = rtlparams.fmt(cfg, "quat_t")[0]
    here = os.path.dirname(os.path.abspath(__file__))
    tsbench.run_bench(toplevel="tb_ts_resize", test_file=__file__,
                      sources=[os.path.join(here, "tb_ts_resize.v"), str(rtlparams.RTL / "ts_resize.v")],
                      parameters={"W": w, "L": 5}, sim=sim, build_name=f"{cfg}-{sim}", env={"TS_W": str(w)})
