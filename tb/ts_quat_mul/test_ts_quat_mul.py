"""Bench of rtl/ts_quat_mul.v: bit-exact with ts::qmul<quat_t> (tensor_servo._model.prim_qmul) on the
golden vectors, the edge cases and fresh random vectors, streamed one per cycle with random gaps;
out_sat exactly when the model's status is non-zero; within 1/2 LSB of float math when not saturated.
"""
import json
import os

import numpy as np
import pytest

import rtlparams
import tsbench

MODULE = "ts_quat_mul"
N_RANDOM = int(os.environ.get("TS_NVEC", "10000"))
#: |rtl - exact product of the inputs| <= TOL_LSB quat_t LSB when no component saturates (one AP_RND)
TOL_LSB = 0.5

try:
    import cocotb
except ImportError:  # pragma: no cover
    cocotb = None

if cocotb is not None:
    @cocotb.test()
    async def quat_mul_bit_exact(dut):
        from tensor_servo import golden_prims as gp
        cfg = os.environ["TS_CONFIG"]
        p = json.loads(os.environ["TS_PARAMS"])
        seed = int(os.environ["TS_SEED"])
        dut._log.info("config %s, params %s, seed %d, %d random vectors", cfg, p, seed, N_RANDOM)
        rng = np.random.default_rng(seed)
        g_in, g_exp = gp.load(tsbench.GOLDEN, "quat_mul", cfg)
        ng = len(g_in["a"])
        ins = gp.concat(g_in, gp.edge_inputs("quat_mul", cfg, rng), gp.random_inputs("quat_mul", cfg, rng, N_RANDOM))
        exp = gp.expected("quat_mul", cfg, ins)
        rows = [tuple(r) for r in np.concatenate([ins["a"], ins["b"]], axis=1).tolist()]
        st = tsbench.Stream(dut, ["in_a_w", "in_a_x", "in_a_y", "in_a_z", "in_b_w", "in_b_x", "in_b_y", "in_b_z"],
                            ["out_w", "out_x", "out_y", "out_z", "out_sat"], rtlparams.latency(MODULE, p), rng,
                            ii=p.get("FOLD", 1))
        await st.reset()
        got = np.array(await st.run(rows), dtype=np.int64)
        out, sat = got[:, :4], got[:, 4]
        assert np.array_equal(out[:ng], g_exp["out"]), tsbench.report_mismatch("golden file", g_exp["out"], out[:ng], g_in)
        assert np.array_equal(sat[:ng], (g_exp["status"] != 0).astype(np.int64)), "golden file: out_sat differs"
        assert np.array_equal(out, exp["out"]), tsbench.report_mismatch("out", exp["out"], out, ins)
        flag = (exp["status"] != 0).astype(np.int64)
        assert np.array_equal(sat, flag), tsbench.report_mismatch("out_sat", flag[:, None], sat[:, None], ins)
        # float reference: the exact Hamilton product of the (quantised) inputs
        f = p["Q_F"]
        a = np.ldexp(ins["a"].astype(float), -f)
        b = np.ldexp(ins["b"].astype(float), -f)
        ref = np.stack([
            a[:, 0] * b[:, 0] - a[:, 1] * b[:, 1] - a[:, 2] * b[:, 2] - a[:, 3] * b[:, 3],
            a[:, 0] * b[:, 1] + a[:, 1] * b[:, 0] + a[:, 2] * b[:, 3] - a[:, 3] * b[:, 2],
            a[:, 0] * b[:, 2] - a[:, 1] * b[:, 3] + a[:, 2] * b[:, 0] + a[:, 3] * b[:, 1],
            a[:, 0] * b[:, 3] + a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1] + a[:, 3] * b[:, 0]], axis=1)
        ok = sat == 0
        err = np.abs(np.ldexp(out[ok].astype(float), -f) - ref[ok]) / np.ldexp(1.0, -f)
        dut._log.info("max |rtl - float| = %.4f LSB over %d unsaturated vectors; %d saturated",
                      err.max(), ok.sum(), (~ok).sum())
        assert err.max() <= TOL_LSB + 1e-6, f"float tolerance: {err.max()} LSB > {TOL_LSB}"
        assert (~ok).sum() > 0 and ok.sum() > 0, "both saturating and regular vectors must be covered"


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("cfg", tsbench.CONFIGS)
def test_ts_quat_mul(cfg, sim):
    tsbench.run_unit(MODULE, __file__, rtlparams.quat_mul(cfg, tsbench.target_for(sim)), cfg, sim)


@pytest.mark.parametrize("chain", (0, 1))
@pytest.mark.parametrize("fold", (2, 5))
@pytest.mark.parametrize("cfg", ["compact"])    # make test time; the default configuration is folded in the core (harness runs)
def test_ts_quat_mul_folded(cfg, fold, chain):
    """The folded form (16 / FOLD multipliers, II = FOLD), with a select or shift chains for the
    held operands: the same bits, the documented latency."""
    tsbench.run_unit(MODULE, __file__, dict(rtlparams.quat_mul(cfg, tsbench.target_for("verilator")), CHAIN=chain),
                     cfg, "verilator", fold=fold, nvec=2000)
