"""Bench of rtl/ts_joint_quat.v: bit-exact with ts::joint_quat (tensor_servo._model.prim_joint_quat) on
the golden vectors, the edge cases (zero and full-scale joint values and constants, axis-aligned and
full-scale axes, angles at the wrap of the half turn, sin = -1 times the most negative axis component,
which saturates: ST_OVF_QUAT) and fresh random vectors; out_flags equal to the model's Status bits;
within the documented bound of float math.
"""
import json
import os

import numpy as np
import pytest

import rtlparams
import tsbench

MODULE = "ts_joint_quat"
N_RANDOM = int(os.environ.get("TS_NVEC", "10000"))
#: sincos bound (LSB of quat_t), see tb/ts_sincos
SINCOS_TOL_LSB = 1.1

try:
    import cocotb
except ImportError:  # pragma: no cover
    cocotb = None


def angle_tol_lsb(p):
    """Half an LSB of the binary angle, as a sin/cos error in quat_t LSB."""
    return 2.0 * np.pi * np.ldexp(0.5, -p["U_W"]) / np.ldexp(1.0, -p["Q_F"])


if cocotb is not None:
    @cocotb.test()
    async def joint_quat_bit_exact(dut):
        from tensor_servo import golden_prims as gp
        from tensor_servo.model import OVF_MASK, STATUS_BITS
        cfg = os.environ["TS_CONFIG"]
        p = json.loads(os.environ["TS_PARAMS"])
        seed = int(os.environ["TS_SEED"])
        dut._log.info("config %s, params %s, seed %d, %d random vectors", cfg, p, seed, N_RANDOM)
        rng = np.random.default_rng(seed)
        g_in, g_exp = gp.load(tsbench.GOLDEN, "joint_quat", cfg)
        ng = len(g_in["angle"])
        ins = gp.concat(g_in, gp.edge_inputs("joint_quat", cfg, rng),
                        gp.random_inputs("joint_quat", cfg, rng, N_RANDOM))
        exp = gp.expected("joint_quat", cfg, ins)
        rows = [tuple(r) for r in np.concatenate([ins["angle"][:, None], ins["kturn"][:, None], ins["axis"]],
                                                 axis=1).tolist()]
        st = tsbench.Stream(dut, ["in_angle", "in_kturn", "in_axis_x", "in_axis_y", "in_axis_z"],
                            ["out_w", "out_x", "out_y", "out_z", "out_flags"], rtlparams.latency(MODULE, p), rng)
        await st.reset()
        got = np.array(await st.run(rows), dtype=np.int64)
        # the flag word is read as a signed port: OVF_MASK gives back its bit pattern
        out, flags = got[:, :4], got[:, 4] & OVF_MASK
        assert np.array_equal(out[:ng], g_exp["out"]), tsbench.report_mismatch("golden file", g_exp["out"], out[:ng], g_in)
        assert np.array_equal(out, exp["out"]), tsbench.report_mismatch("out", exp["out"], out, ins)
        flag = exp["status"].astype(np.int64) & OVF_MASK
        assert np.array_equal(flags, flag), tsbench.report_mismatch("out_flags", flag[:, None], flags[:, None], ins)
        assert (flag == STATUS_BITS["ovf_quat"]).any(), "the saturating edge case (ST_OVF_QUAT) must be covered"
        # float reference: half angle in turns = angle * kturn (exact inputs), (cos, sin * axis)
        u = np.ldexp(ins["angle"].astype(float), -p["ANG_F"]) * np.ldexp(ins["kturn"].astype(float), -p["KT_F"])
        axis = np.ldexp(ins["axis"].astype(float), -p["Q_F"])
        ref = np.concatenate([np.cos(2 * np.pi * u)[:, None], np.sin(2 * np.pi * u)[:, None] * axis], axis=1)
        lsb = np.ldexp(1.0, -p["Q_F"])
        err = np.abs(np.ldexp(out.astype(float), -p["Q_F"]) - ref) / lsb
        tsc = SINCOS_TOL_LSB + angle_tol_lsb(p)
        bound = np.concatenate([np.full((len(u), 1), tsc), 0.5 + tsc * np.abs(axis)], axis=1) + 1e-6
        ok = flags == 0
        ratio = (err / bound)[ok]
        dut._log.info("max |rtl - float| / bound = %.3f (w: %.4f LSB, bound %.4f)", ratio.max(), err[ok, 0].max(), tsc)
        assert ratio.max() <= 1.0, f"float tolerance exceeded: {ratio.max():.3f} x bound"


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("cfg", tsbench.CONFIGS)
def test_ts_joint_quat(cfg, sim):
    target = tsbench.target_for(sim)
    p = rtlparams.joint_quat(cfg, target, rom_path=str(rtlparams.rom_file(cfg)))
    tsbench.run_bench(toplevel=MODULE, test_file=__file__, sources=rtlparams.sources(MODULE, target),
                      parameters=p, sim=sim, build_name=f"{cfg}-{target}-{sim}",
                      env={"TS_CONFIG": cfg, "TS_PARAMS": json.dumps(p)})
