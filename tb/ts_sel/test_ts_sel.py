"""Bench of rtl/ts_sel.v (combinational): out_el = element in_idx of in_vec (element k at
[k*W +: W]), 0 for in_idx >= N; every index, random buses, for the shapes the core uses (N a power
of two, N = 6 with a 3-bit index, N = 20 with a 5-bit index, the banks' N = FOLD, one element)."""
import os

import pytest

import tsbench

N_RANDOM = int(os.environ.get("TS_NVEC", "2000"))
SHAPES = [(18, 8, 3), (32, 6, 3), (27, 20, 5), (18, 7, 3), (27, 9, 4), (5, 1, 1)]    # (W, N, IW): core selects, bank phases, one element

try:
    import cocotb
    from cocotb.triggers import Timer
except ImportError:  # pragma: no cover
    cocotb = None

if cocotb is not None:
    @cocotb.test()
    async def select_every_index(dut):
        import random
        w, n, iw = (int(os.environ[k]) for k in ("TS_W", "TS_N", "TS_IW"))
        rnd = random.Random(int(os.environ["TS_SEED"]))
        vecs = [(1 << (n * w)) - 1, 0] + [rnd.getrandbits(n * w) for _ in range(max(1, N_RANDOM // (1 << iw)))]
        for vec in vecs:
            dut.in_vec.value = vec
            for idx in range(1 << iw):
                dut.in_idx.value = idx
                await Timer(1, units="ns")
                want = (vec >> (idx * w)) & ((1 << w) - 1) if idx < n else 0
                got = int(dut.out_el.value)
                assert got == want, f"W {w} N {n}: index {idx}: {got:#x} != {want:#x}"


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("w,n,iw", SHAPES)
def test_ts_sel(w, n, iw, sim):
    from rtlparams import RTL
    tsbench.run_bench(toplevel="ts_sel", test_file=__file__, sources=[str(RTL / "ts_sel.v")],
                      parameters={"W": w, "N": n, "IW": iw}, sim=sim, build_name=f"{w}x{n}-{sim}",
                      env={"TS_W": str(w), "TS_N": str(n), "TS_IW": str(iw)})
