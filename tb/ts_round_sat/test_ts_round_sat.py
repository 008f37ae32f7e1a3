"""Bench of rtl/ts_round_sat.v (the model's cvt and wrap): eight instances with the parameter sets the
datapath uses in a configuration (plus a left shift and a narrow-result case), bit-exact with the
statement of fixed.hpp in tb/fxref.py, which is itself checked against the C++ model's cvt (through
prim_qmul with single-product quaternions: r.w = cvt<quat_t>(a.w b.w)) on random values, exact ties
and saturating products.
"""
import json
import os

import numpy as np
import pytest

import fxref
import rtlparams
import tsbench

MODULE = "ts_round_sat"
N_RANDOM = int(os.environ.get("TS_NVEC", "10000"))


def param_sets(cfg):
    """(IN_W, SHIFT, OUT_W, SAT) of the eight instances (tb/rtlparams.py round_sat_sets)."""
    return rtlparams.round_sat_sets(cfg)


def expected(sets, x):
    out = np.zeros(x.shape, dtype=np.int64)
    sat = np.zeros(x.shape, dtype=np.int64)
    for k, (iw, sh, ow, sa) in enumerate(sets):
        for i, v in enumerate(x[:, k].tolist()):
            if sa:
                out[i, k], sat[i, k] = fxref.cvt(v, sh, ow)
            else:
                out[i, k] = fxref.wrap(v, sh, ow)
    return out, sat


def inputs(sets, seed, n):
    """n input values per instance (Python ints: some formats exceed int64 products): full range, a
    range around the output's limits, exact rounding ties, and the extremes."""
    import random
    rnd = random.Random(seed)
    cols = []
    for iw, sh, ow, sa in sets:
        lo, hi = -(1 << (iw - 1)), (1 << (iw - 1)) - 1
        clip = lambda v: max(lo, min(hi, v))  # noqa: E731
        lim = 1 << max(ow - 1 + sh, 0)       # the output range, in input LSB
        col = [rnd.randint(lo, hi) for _ in range(n // 2)]
        col += [clip(rnd.randint(-2 * lim, 2 * lim)) for _ in range(n - n // 2 - 24)]
        if sh > 0:
            col += [clip((rnd.randint(-lim, lim) >> sh << sh) + (1 << (sh - 1))) for _ in range(12)]
        col += [lo, hi, 0, -1, 1, clip(lim), clip(lim - 1), clip(-lim), clip(-lim - 1)]
        col = (col + [rnd.randint(lo, hi) for _ in range(n)])[:n]
        cols.append(col)
    return np.array(cols, dtype=object).T


try:
    import cocotb
except ImportError:  # pragma: no cover
    cocotb = None

if cocotb is not None:
    @cocotb.test()
    async def round_sat_bit_exact(dut):
        cfg = os.environ["TS_CONFIG"]
        sets = [tuple(s) for s in json.loads(os.environ["TS_SETS"])]
        seed = int(os.environ["TS_SEED"])
        dut._log.info("config %s, sets %s, seed %d", cfg, sets, seed)
        rng = np.random.default_rng(seed)
        x = inputs(sets, seed, N_RANDOM)
        out_e, sat_e = expected(sets, x)
        m64 = (1 << 64) - 1
        rows = [tuple(int(v) & m64 for v in r) for r in x.tolist()]
        st = tsbench.Stream(dut, [f"in_x{k}" for k in range(8)], [f"out_y{k}" for k in range(8)] + ["out_sat"],
                            rtlparams.ROUND_LAT, rng, unsigned=("out_sat",))
        await st.reset()
        got = await st.run(rows)
        out = np.array([g[:8] for g in got], dtype=np.int64)
        sat = np.array([[(g[8] >> k) & 1 for k in range(8)] for g in got], dtype=np.int64)
        problems = []
        for k, s in enumerate(sets):
            if not np.array_equal(out[:, k], out_e[:, k]):
                problems.append(tsbench.report_mismatch(f"instance {k} {s} out", out_e[:, k:k + 1], out[:, k:k + 1],
                                                        {"x": x[:, k]}))
            if not np.array_equal(sat[:, k], sat_e[:, k]):
                problems.append(tsbench.report_mismatch(f"instance {k} {s} sat", sat_e[:, k:k + 1], sat[:, k:k + 1],
                                                        {"x": x[:, k]}))
            if s[3] and s[0] - max(s[1], 0) + 1 > s[2] and sat_e[:, k].sum() == 0:
                problems.append(f"instance {k}: saturation not covered")
        assert not problems, "\n".join(problems)


@pytest.mark.parametrize("cfg", tsbench.CONFIGS)
def test_reference_is_the_model(cfg):
    """tb/fxref.cvt equals the C++ model's cvt<quat_t> of single products (random, ties, saturation)."""
    from tensor_servo import _model
    qw, qf = rtlparams.fmt(cfg, "quat_t")
    rng = np.random.default_rng(7)
    lo, hi = -(1 << (qw - 1)), (1 << (qw - 1)) - 1
    a = rng.integers(lo, hi, 20000, endpoint=True)
    b = rng.integers(lo, hi, 20000, endpoint=True)
    half = 1 << (qf - 1)
    a = np.concatenate([a, np.arange(-50, 51), [lo, lo, hi, hi]])
    b = np.concatenate([b, np.full(101, half), [lo, hi, lo, hi]])
    z = np.zeros_like(a)
    out, st = _model.prim_qmul(cfg, np.stack([a, z, z, z], 1), np.stack([b, z, z, z], 1))
    ref = [fxref.cvt(int(x) * int(y), qf, qw) for x, y in zip(a, b)]
    assert np.array_equal(np.asarray(out)[:, 0], [r[0] for r in ref])
    assert np.array_equal((np.asarray(st) != 0).astype(int), [r[1] for r in ref])
    assert 0 < sum(r[1] for r in ref) < len(ref)


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("cfg", tsbench.CONFIGS)
def test_ts_round_sat(cfg, sim):
    sets = param_sets(cfg)
    params = {}
    for k, (iw, sh, ow, sa) in enumerate(sets):
        params.update({f"IW{k}": iw, f"SH{k}": sh, f"OW{k}": ow, f"SA{k}": sa})
    here = os.path.dirname(os.path.abspath(__file__))
    tsbench.run_bench(toplevel="tb_ts_round_sat", test_file=__file__,
                      sources=[os.path.join(here, "tb_ts_round_sat.v")] + rtlparams.sources(MODULE) + [
                          str(rtlparams.RTL / "ts_resize.v"), str(rtlparams.RTL / "ts_delay.v")],
                      parameters=params, sim=sim, build_name=f"{cfg}-{sim}",
                      env={"TS_CONFIG": cfg, "TS_SETS": json.dumps(sets)})
