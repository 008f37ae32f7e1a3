"""Bench of rtl/ts_quat_rotate.v: all four kinds (axis, offset, jw, jv) forward and inverse, eight
instances in parallel (tb_ts_quat_rotate.v), bit-exact with ts::rotate (tensor_servo._model.prim_rotate)
on the golden vectors, the edge cases and fresh random vectors; out_sat exactly when the model flags;
within the documented bound of float math when not saturated.
"""
import json
import os

import numpy as np
import pytest

import rtlparams
import tsbench

MODULE = "ts_quat_rotate"
N_RANDOM = int(os.environ.get("TS_NVEC", "10000"))
KINDS = ("axis", "offset", "jw", "jv")
SLOT = 32


def float_bound(q, lsb_t, lsb_o):
    """Per-component bound on |rtl - float formula| (t rounded once, out rounded once):
    1/2 LSB(out) + 1/2 LSB(tmp) (|w| + |q_j| + |q_k|), j, k the two other axes."""
    aq = np.abs(q)
    s = np.stack([aq[:, 0] + aq[:, 2] + aq[:, 3], aq[:, 0] + aq[:, 1] + aq[:, 3], aq[:, 0] + aq[:, 1] + aq[:, 2]], axis=1)
    return 0.5 * lsb_o + 0.5 * lsb_t * s


def float_rotate(q, v, inverse):
    w = q[:, :1]
    qv = -q[:, 1:] if inverse else q[:, 1:]
    t = 2.0 * np.cross(qv, v)
    return v + w * t + np.cross(qv, t)


try:
    import cocotb
except ImportError:  # pragma: no cover
    cocotb = None

if cocotb is not None:
    @cocotb.test()
    async def quat_rotate_bit_exact(dut):
        from tensor_servo import golden_prims as gp
        cfg = os.environ["TS_CONFIG"]
        pk = json.loads(os.environ["TS_PARAMS"])   # per kind
        seed = int(os.environ["TS_SEED"])
        dut._log.info("config %s, seed %d, %d random vectors per kind and direction", cfg, seed, N_RANDOM)
        rng = np.random.default_rng(seed)
        g_in, g_exp = gp.load(tsbench.GOLDEN, "quat_rotate", cfg)
        ng = len(g_in["q"])
        ins = gp.concat(g_in, gp.edge_inputs("quat_rotate", cfg, rng),
                        gp.random_inputs("quat_rotate", cfg, rng, N_RANDOM))
        exp = gp.expected("quat_rotate", cfg, ins)
        n = len(ins["q"])
        m32 = (1 << SLOT) - 1
        cols = [ins["q"][:, c] for c in range(4)] + [ins[f"v_{k}"][:, c] for k in KINDS for c in range(3)]
        rows = []
        for r in zip(*[c.tolist() for c in cols]):
            word = 0
            for s, x in enumerate(r):
                word |= (x & m32) << (SLOT * s)
            rows.append((word,))
        st = tsbench.Stream(dut, ["in_bus"], ["out_bus"], rtlparams.latency(MODULE, pk["axis"]), rng,
                            ii=pk["axis"].get("FOLD", 1))
        await st.reset()
        got = await st.run(rows)
        busw = 24 * SLOT + 16
        words = [g[0] & ((1 << busw) - 1) for g in got]
        vals = np.array([[tsbench.to_signed((w >> (SLOT * s)) & m32, SLOT) for s in range(24)] for w in words],
                        dtype=np.int64)
        sats = np.array([(w >> (24 * SLOT)) & 0xFF for w in words])
        valids = np.array([(w >> (24 * SLOT + 8)) & 0xFF for w in words])
        assert np.all(valids == 0xFF), "instances disagree on out_valid (latency differs between kinds)"
        problems = []
        for ki, kind in enumerate(KINDS):
            p = pk[kind]
            for inv in (0, 1):
                m = 2 * ki + inv
                tag = f"{kind}_{'inv' if inv else 'fwd'}"
                out = vals[:, 3 * m:3 * m + 3]
                sat = (sats >> m) & 1
                e_out, e_st = exp[f"out_{tag}"], exp[f"status_{tag}"]
                if not np.array_equal(out[:ng], g_exp[f"out_{tag}"]):
                    problems.append(tsbench.report_mismatch(f"{tag} golden file", g_exp[f"out_{tag}"], out[:ng], g_in))
                if not np.array_equal(out, e_out):
                    problems.append(tsbench.report_mismatch(f"{tag} out", e_out, out, {"q": ins["q"], "v": ins[f"v_{kind}"]}))
                flag = (e_st != 0).astype(np.int64)
                if not np.array_equal(sat, flag):
                    problems.append(tsbench.report_mismatch(f"{tag} out_sat", flag[:, None], sat[:, None],
                                                            {"q": ins["q"], "v": ins[f"v_{kind}"]}))
                # float reference: the same formula on the quantised inputs, without rounding
                q = np.ldexp(ins["q"].astype(float), -p["Q_F"])
                v = np.ldexp(ins[f"v_{kind}"].astype(float), -p["V_F"])
                ref = float_rotate(q, v, inv)
                ok = sat == 0
                err = np.abs(np.ldexp(out.astype(float), -p["O_F"]) - ref)
                bound = float_bound(q, np.ldexp(1.0, -p["T_F"]), np.ldexp(1.0, -p["O_F"])) + 1e-12
                ratio = (err / bound)[ok]
                dut._log.info("%s: max |rtl - float| / bound = %.3f over %d unsaturated vectors, %d saturated",
                              tag, ratio.max(), ok.sum(), (~ok).sum())
                if ratio.max() > 1.0:
                    problems.append(f"{tag}: float tolerance exceeded ({ratio.max():.3f} x bound)")
                if ok.sum() == 0 or (~ok).sum() == 0:
                    problems.append(f"{tag}: saturating and regular vectors must both be covered")
        assert not problems, "\n".join(problems)


# Icarus (about 100 s per run: eight instances) in the compact configuration only, for make test's time;
# the default configuration runs on Verilator.  The folded rotation is checked inside the folded
# screw transport's bench (its axis rotation) and, every kind, in the core's engines.
@pytest.mark.parametrize("cfg,sim", [(c, s) for c in tsbench.CONFIGS for s in tsbench.SIMS
                                     if not (s == "icarus" and c == "default")])
def test_ts_quat_rotate(cfg, sim):
    run_rotate(cfg, sim, 1)


def run_rotate(cfg, sim, fold, nvec=None):
    target = tsbench.target_for(sim)
    pk = {k: dict(rtlparams.quat_rotate(cfg, k, False, target), FOLD=fold) for k in KINDS}
    params = {"Q_W": pk["axis"]["Q_W"], "Q_F": pk["axis"]["Q_F"], "TARGET": target, "FOLD": fold}
    for k, pre in zip(KINDS, ("AX", "OF", "JW", "JV")):
        for key in ("V_W", "V_F", "T_W", "T_F", "O_W", "O_F"):
            params[f"{pre}_{key}"] = pk[k][key]
    here = os.path.dirname(os.path.abspath(__file__))
    tsbench.run_bench(toplevel="tb_ts_quat_rotate", test_file=__file__,
                      sources=[os.path.join(here, "tb_ts_quat_rotate.v")] + rtlparams.sources(MODULE, target),
                      parameters=params, sim=sim, build_name=f"{cfg}-{target}-{sim}" + (f"-fold{fold}" if fold > 1 else ""),
                      env=dict({"TS_CONFIG": cfg, "TS_PARAMS": json.dumps(pk)}, **({"TS_NVEC": str(nvec)} if nvec else {})))
