"""Bench of rtl/ts_sincos.v: bit-exact with ts::sincos_turns (tensor_servo._model.prim_sincos) on the
golden vectors, the edge cases (every table index in every quadrant, with zero, half-way and largest
residual; quadrant boundaries) and fresh random angles; out_flags equal to the model's Status bits
(never raised by this function: no input can saturate); within TOL_LSB of numpy sin/cos.
"""
import json
import os

import numpy as np
import pytest

import rtlparams
import tsbench

MODULE = "ts_sincos"
N_RANDOM = int(os.environ.get("TS_NVEC", "10000"))
#: |rtl - sin/cos(2 pi u)| in quat_t LSB: 1/2 (final rounding) + 1/2 (table rounding) + internal
#: roundings and the truncated series (< 0.05): see docs/rtl/ts_sincos.md
TOL_LSB = 1.1

try:
    import cocotb
except ImportError:  # pragma: no cover
    cocotb = None

if cocotb is not None:
    @cocotb.test()
    async def sincos_bit_exact(dut):
        from tensor_servo import golden_prims as gp
        from tensor_servo.model import OVF_MASK
        cfg = os.environ["TS_CONFIG"]
        p = json.loads(os.environ["TS_PARAMS"])
        seed = int(os.environ["TS_SEED"])
        dut._log.info("config %s, params %s, seed %d, %d random vectors", cfg, p, seed, N_RANDOM)
        rng = np.random.default_rng(seed)
        g_in, g_exp = gp.load(tsbench.GOLDEN, "sincos", cfg)
        ng = len(g_in["u"])
        ins = gp.concat(g_in, gp.edge_inputs("sincos", cfg, rng), gp.random_inputs("sincos", cfg, rng, N_RANDOM))
        exp = gp.expected("sincos", cfg, ins)
        st = tsbench.Stream(dut, ["in_u"], ["out_sin", "out_cos", "out_flags"], rtlparams.latency(MODULE, p), rng)
        await st.reset()
        got = np.array(await st.run([(u,) for u in ins["u"].tolist()]), dtype=np.int64)
        # the flag word is read as a signed port: OVF_MASK gives back its bit pattern
        out, flags = got[:, :2], got[:, 2] & OVF_MASK
        assert np.array_equal(out[:ng], g_exp["out"]), tsbench.report_mismatch("golden file", g_exp["out"], out[:ng], g_in)
        assert np.array_equal(out, exp["out"]), tsbench.report_mismatch("out (sin, cos)", exp["out"], out, ins)
        flag = exp["status"].astype(np.int64) & OVF_MASK
        assert np.array_equal(flags, flag), tsbench.report_mismatch("out_flags", flag[:, None], flags[:, None], ins)
        a = 2.0 * np.pi * np.ldexp(ins["u"].astype(float), -p["U_W"])
        lsb = np.ldexp(1.0, -p["Q_F"])
        err = np.abs(np.ldexp(out.astype(float), -p["Q_F"]) - np.stack([np.sin(a), np.cos(a)], axis=1)) / lsb
        dut._log.info("max |rtl - numpy| = %.4f LSB (sin %.4f, cos %.4f)", err.max(), err[:, 0].max(), err[:, 1].max())
        assert err.max() <= TOL_LSB, f"float tolerance: {err.max()} LSB > {TOL_LSB}"


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("cfg", tsbench.CONFIGS)
def test_ts_sincos(cfg, sim):
    target = tsbench.target_for(sim)
    p = rtlparams.sincos(cfg, target, rom_path=str(rtlparams.rom_file(cfg)))
    tsbench.run_bench(toplevel=MODULE, test_file=__file__, sources=rtlparams.sources(MODULE, target),
                      parameters=p, sim=sim, build_name=f"{cfg}-{target}-{sim}",
                      env={"TS_CONFIG": cfg, "TS_PARAMS": json.dumps(p)})
