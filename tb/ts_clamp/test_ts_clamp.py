"""Bench of rtl/ts_clamp.v (combinational): out_y = max(in_lo, min(in_hi, in_x)) on signed W-bit
operands, the model's clamp order (std::min, then std::max).  W = 4: every (x, lo, hi), lo > hi
included; wider: random operands drawn so that the three are often equal, adjacent or at the
extremes of the range, plus random ones."""
import os

import pytest

import tsbench

N_RANDOM = int(os.environ.get("TS_NVEC", "2000"))
WIDTHS = [4, 18, 32]

try:
    import cocotb
    from cocotb.triggers import Timer
except ImportError:  # pragma: no cover
    cocotb = None


def clamp_ref(x: int, lo: int, hi: int) -> int:
    """The model's order: min with the upper bound, then max with the lower."""
    return max(lo, min(hi, x))


def signed(v: int, w: int) -> int:
    return v - (1 << w) if v >> (w - 1) else v


if cocotb is not None:
    @cocotb.test()
    async def clamp_against_reference(dut):
        import itertools
        import random
        w = int(os.environ["TS_W"])
        rnd = random.Random(int(os.environ["TS_SEED"]))
        lo_v, hi_v = -(1 << (w - 1)), (1 << (w - 1)) - 1
        if w <= 4:
            cases = itertools.product(range(lo_v, hi_v + 1), repeat=3)
        else:
            def draw(near):
                pick = rnd.randrange(4)
                if pick == 0:
                    return rnd.choice((lo_v, lo_v + 1, -1, 0, 1, hi_v - 1, hi_v))
                if pick == 1 and near is not None:
                    return max(lo_v, min(hi_v, near + rnd.randint(-1, 1)))
                return rnd.randint(lo_v, hi_v)
            cases = []
            for _ in range(N_RANDOM):
                x = draw(None)
                lo = draw(x)
                cases.append((x, lo, draw(rnd.choice((x, lo)))))
        n = 0
        for x, lo, hi in cases:
            dut.in_x.value, dut.in_lo.value, dut.in_hi.value = x, lo, hi
            await Timer(1, units="ns")
            got = signed(int(dut.out_y.value), w)
            assert got == clamp_ref(x, lo, hi), f"W {w}: x {x} lo {lo} hi {hi}: {got} != {clamp_ref(x, lo, hi)}"
            n += 1
        assert n >= min(N_RANDOM, 1 << (3 * w))


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("w", WIDTHS)
def test_ts_clamp(w, sim):
    from rtlparams import RTL
    tsbench.run_bench(toplevel="ts_clamp", test_file=__file__, sources=[str(RTL / "ts_clamp.v")],
                      parameters={"W": w}, sim=sim, build_name=f"w{w}-{sim}", env={"TS_W": str(w)})
