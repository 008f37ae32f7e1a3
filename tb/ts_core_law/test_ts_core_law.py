"""Bench of rtl/ts_core_law.v: the servo law of the front half (one task: the tool, setpoint in the
root frame) bit for bit against the model's task_error, through
tensor_servo._model.Servo(cfg, spec, params).tick_raw: the module is driven with the tool pose the
model computed (tool_quat_raw / tool_pos_raw) and the setpoint, and every output is compared with
the model: ep_raw, eo_raw, V_raw (omega; v), the Jacobian columns (mode B: rotated into the tool
basis by the column port; root-basis input columns from Model.jacobian; mode A: passed through)
and the status bits the servo law can raise (3 ovf_quat, 4 ovf_pos, 6 ovf_jac, 9 ovf_servo; the
forward kinematics raises none for these chains and the solver never raises them, both checked).

Parametrised over configuration x simulator; every run drives all three modes (A, B, error-only: A and B
alternately) one after the other, since the mode is an input of the module (TS_MODE=A,B,E selects).
Cases per mode (TS_NCASE, default 160 on Verilator, 40 on Icarus): PUMA 560, UR5, Panda, Stanford at
random joint values, gains from small to the top of gain_t, setpoints: zero error, the tool
quaternion with its sign flipped (q and -q), small and large random errors, 180-degree orientation
errors (error quaternion w = 0), full-range (saturating) positions, twists and quaternion components.
Seed printed; replay with TS_SEED=<seed>.  Also: no output X after reset, busy/done protocol, the
cycle count (logged, constant), the module's format localparams against the model's formats.
"""
import json
import math
import os

import numpy as np
import pytest

import rtlparams
import tsbench

MODULE = "ts_core_law"
CHAINS = ("puma560", "ur5", "panda", "stanford")
LAW_MASK = (1 << 3) | (1 << 4) | (1 << 6) | (1 << 9)
MODES = ("A", "B", "E")

try:
    import cocotb
except ImportError:  # pragma: no cover
    cocotb = None


def test_ts_core_law_formats():
    """The module's format localparams and port-width defaults equal the model's formats."""
    for cfg in tsbench.CONFIGS:
        rtlparams.check_module_formats(MODULE, cfg, 15, "ROTVEC_TABLE_BITS",
                                       [("Q_W", "quat_t"), ("P_W", "pos_t"), ("V_W", "vel_t"), ("G_W", "gain_t"),
                                        ("PE_W", "perr_t"), ("RO_W", "rot_t"), ("JW_W", "jw_t"), ("JV_W", "jv_t")])


# ---- cases (pure Python: model calls and the random setpoints) ------------------------------------
def _quat_mul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def _rand_unit(rng, k):
    v = rng.normal(size=k)
    return v / np.linalg.norm(v)


def _raw(x, wf):
    w, f = wf
    r = np.floor(np.ldexp(np.asarray(x, dtype=float), f) + 0.5).astype(np.int64)
    return np.clip(r, -(1 << (w - 1)), (1 << (w - 1)) - 1)


def _full(rng, wf, k):
    """k raw values over the whole range of a format, with the extremes often."""
    w, _ = wf
    lo, hi = -(1 << (w - 1)), (1 << (w - 1)) - 1
    r = rng.integers(lo, hi + 1, size=k)
    pick = rng.random(k)
    r[pick < 0.25] = lo
    r[(pick >= 0.25) & (pick < 0.5)] = hi
    return r.astype(np.int64)


def make_cases(cfg: str, mode: str, rng, ncase: int) -> list[dict]:
    from tensor_servo import _model, robots
    from tensor_servo.model import model_spec
    fq, fp, fv = rtlparams.fmt(cfg, "quat_t"), rtlparams.fmt(cfg, "pos_t"), rtlparams.fmt(cfg, "vel_t")
    gains = [(300.0, 300.0), (3000.0, 1000.0), (16000.0, 16000.0), (0.5, 2.0), (1000.0, 16383.0)]
    kinds = ["zero", "flip", "near", "far", "pi", "pi_exact", "sat_pos", "sat_vel", "sat_quat", "far_flip"]
    cases = []
    servos = {}
    specs = {name: model_spec(robots.load(name)) for name in CHAINS}
    models = {name: _model.Model(cfg, specs[name]) for name in CHAINS}
    for c in range(ncase):
        name = CHAINS[c % len(CHAINS)]
        sp, m = specs[name], models[name]
        n = m.n
        mode_b = mode == "B" or (mode == "E" and c % 2 == 1)
        ff = mode != "E"
        kp, ko = gains[rng.integers(len(gains))]
        key = (name, mode_b, ff, kp, ko)
        if key not in servos:
            p = {"L": 0.5, "kp": kp, "ko": ko, "dt": 1e-3, "klim": 500.0, "sweeps": 2, "mu": [1.5] * n,
                 "mode": "B" if mode_b else "A", "feedforward": ff, "controlled": [-1], "weights": [1.0],
                 "setpoint_frame": -1, "vlimits": True}
            servos[key] = _model.Servo(cfg, sp, p)
        s = servos[key]
        lo = np.array([j["lower"] if j["limited"] else -np.pi for j in sp["joints"]])
        hi = np.array([j["upper"] if j["limited"] else np.pi for j in sp["joints"]])
        d = m.quantize_q((lo + (hi - lo) * rng.random(n))[None, :])
        q = np.asarray(d["q_raw"], dtype=np.int64)[0]
        z3 = np.zeros((1, 3), dtype=np.int64)
        zn = np.zeros(n, dtype=np.int64)
        r0 = s.tick_raw(q, np.array([[1 << fq[1], 0, 0, 0]], dtype=np.int64), z3, z3, z3, zn)
        tq = np.asarray(r0["tool_quat_raw"], dtype=np.int64)
        tp = np.asarray(r0["tool_pos_raw"], dtype=np.int64)
        tqf = tq / 2.0 ** fq[1]
        tpf = tp / 2.0 ** fp[1]
        kind = kinds[c % len(kinds)]
        uw = _raw(rng.normal(scale=0.5, size=3), fv)
        uv = _raw(rng.normal(scale=0.3, size=3), fv)
        if kind == "zero":
            uq, up = tq.copy(), tp.copy()
            if rng.random() < 0.5:
                uw[:] = 0
                uv[:] = 0
        elif kind == "flip":
            uq, up = -tq, tp.copy()
        elif kind == "near":
            ax = _rand_unit(rng, 3)
            ang = rng.normal(scale=1e-3)
            dq = np.concatenate([[math.cos(ang / 2)], math.sin(ang / 2) * ax])
            uq = _raw(_quat_mul(dq, tqf), fq)
            up = _raw(tpf + rng.normal(scale=1e-3, size=3), fp)
        elif kind in ("far", "far_flip"):
            uq = _raw(_rand_unit(rng, 4), fq)
            if kind == "far_flip":
                uq = -uq
            up = _raw(tpf + rng.uniform(-2, 2, size=3), fp)
        elif kind in ("pi", "pi_exact"):
            ax = _rand_unit(rng, 3)
            dq = np.concatenate([[0.0], ax]) if kind == "pi_exact" else \
                np.concatenate([[rng.normal(scale=1e-4)], ax])
            uq = _raw(_quat_mul(dq, tqf) if rng.random() < 0.5 else _quat_mul(tqf, dq), fq)
            up = _raw(tpf + rng.normal(scale=0.1, size=3), fp)
        elif kind == "sat_pos":
            uq = _raw(_rand_unit(rng, 4), fq)
            up = _full(rng, fp, 3)
            uw, uv = _full(rng, fv, 3), _full(rng, fv, 3)
        elif kind == "sat_vel":
            uq = _raw(_quat_mul(np.concatenate([[0.9], 0.3 * _rand_unit(rng, 3)]), tqf), fq)
            up = _raw(tpf + rng.uniform(-5, 5, size=3), fp)
            uw, uv = _full(rng, fv, 3), _full(rng, fv, 3)
        else:  # sat_quat: components over the whole quat_t range (not unit)
            uq = _full(rng, fq, 4)
            up = _raw(tpf + rng.normal(scale=0.5, size=3), fp)
        uq = np.clip(uq, -(1 << (fq[0] - 1)), (1 << (fq[0] - 1)) - 1)
        r = s.tick_raw(q, uq[None, :], up[None, :], uw[None, :], uv[None, :], zn)
        assert np.array_equal(np.asarray(r["tool_quat_raw"]), tq)
        jr = m.jacobian(q[None, :], raw=True)
        fk_flags = int(np.asarray(jr["flags"])[0])
        cases.append({
            "name": name, "kind": kind, "mode_b": int(mode_b), "ff": int(ff), "n": n,
            "kp": int(s.params_raw()["kp"]), "ko": int(s.params_raw()["ko"]),
            "tq": tq.tolist(), "tp": tp.tolist(), "uq": uq.tolist(), "up": up.tolist(),
            "uw": uw.tolist(), "uv": uv.tolist(),
            "J_in": np.asarray(jr["J_raw"])[0].tolist(),
            "ep": np.asarray(r["ep_raw"])[0].tolist(), "eo": np.asarray(r["eo_raw"])[0].tolist(),
            "V": np.asarray(r["V_raw"])[0].tolist(), "J": np.asarray(r["J_raw"])[0].tolist(),
            "flags": int(r["flags"]), "fk_flags": fk_flags,
        })
    return cases


if cocotb is not None:
    async def clock_cycles(dut, n):
        from cocotb.triggers import FallingEdge
        for _ in range(n):
            await FallingEdge(dut.clk)

    @cocotb.test()
    async def core_law_bit_exact(dut):
        from cocotb.clock import Clock
        from cocotb.triggers import FallingEdge
        cfg = os.environ["TS_CONFIG"]
        modes = os.environ["TS_MODE"].split(",")
        fold = int(json.loads(os.environ["TS_PARAMS"]).get("FOLD", 1))
        seed = int(os.environ["TS_SEED"])
        ncase = int(os.environ.get("TS_NCASE", "160"))
        dut._log.info("config %s, modes %s, seed %d, %d cases per mode", cfg, modes, seed, ncase)
        rng = np.random.default_rng(seed)
        # the mode is an input of the module: one build runs every mode, one after the other
        cases = [c for mode in modes for c in make_cases(cfg, mode, rng, ncase)]

        cocotb.start_soon(Clock(dut.clk, 10, units="ns").start())
        in_names = (["start", "mode_b", "err_only", "kp", "ko", "col_valid"]
                    + [f"tool_q_{a}" for a in "wxyz"] + [f"tool_p_{a}" for a in "xyz"]
                    + [f"u_q_{a}" for a in "wxyz"] + [f"u_{g}_{a}" for g in "pwv" for a in "xyz"]
                    + [f"col_{g}_{a}" for g in "wv" for a in "xyz"])
        for nm in in_names:
            getattr(dut, f"in_{nm}").value = 0
        dut.rst.value = 1
        await clock_cycles(dut, 4)
        dut.rst.value = 0
        await FallingEdge(dut.clk)
        out_names = (["busy", "done", "flags", "col_valid", "col_sat"] + [f"ep_{a}" for a in "xyz"]
                     + [f"eo_{a}" for a in "xyz"] + [f"v{g}_{a}" for g in "wv" for a in "xyz"]
                     + [f"col_{g}_{a}" for g in "wv" for a in "xyz"])
        for nm in out_names:
            h = getattr(dut, f"out_{nm}")
            assert h.value.is_resolvable, f"out_{nm} is {h.value.binstr} after reset"
        assert int(dut.out_busy.value) == 0 and int(dut.out_done.value) == 0

        sg = tsbench.to_signed

        def setv(nm, v):
            h = getattr(dut, f"in_{nm}")
            h.value = int(v) & ((1 << len(h)) - 1)

        def getv(nm):
            h = getattr(dut, f"out_{nm}")
            return sg(int(h.value), len(h))

        problems = []
        cycles = {}      # per mode (B, feed-forward): the cycle count may depend on the mode, not on the data
        nflag = {"quat": 0, "pos": 0, "jac": 0, "servo": 0}
        for ci, c in enumerate(cases):
            n = c["n"]
            setv("mode_b", c["mode_b"])
            setv("err_only", 1 - c["ff"])
            setv("kp", c["kp"])
            setv("ko", c["ko"])
            for a, ax in enumerate("wxyz"):
                setv(f"tool_q_{ax}", c["tq"][a])
                setv(f"u_q_{ax}", c["uq"][a])
            for a, ax in enumerate("xyz"):
                setv(f"tool_p_{ax}", c["tp"][a])
                setv(f"u_p_{ax}", c["up"][a])
                setv(f"u_w_{ax}", c["uw"][a])
                setv(f"u_v_{ax}", c["uv"][a])
            setv("start", 1)
            await FallingEdge(dut.clk)
            setv("start", 0)
            # scramble the inputs: the module must have registered them
            for a, ax in enumerate("wxyz"):
                setv(f"tool_q_{ax}", int(rng.integers(-1000, 1000)))
                setv(f"u_q_{ax}", int(rng.integers(-1000, 1000)))
            setv("kp", 12345)
            setv("mode_b", 1 - c["mode_b"])
            setv("err_only", c["ff"])
            assert int(dut.out_busy.value) == 1
            # stream the root-basis columns while the law runs (some gaps)
            J_in = np.asarray(c["J_in"])
            cols_got = []
            k = 1
            col_i = 0
            done_at = None
            last_in = -fold
            while done_at is None or len(cols_got) < n:
                # at most one column per FOLD cycles (the column port's II)
                if col_i < n and k - last_in >= fold and rng.random() < 0.7:
                    last_in = k
                    setv("col_valid", 1)
                    for a, ax in enumerate("xyz"):
                        setv(f"col_w_{ax}", J_in[a, col_i])
                        setv(f"col_v_{ax}", J_in[a + 3, col_i])
                    col_i += 1
                else:
                    setv("col_valid", 0)
                await FallingEdge(dut.clk)
                k += 1
                if int(dut.out_col_valid.value):
                    cols_got.append([getv(f"col_w_{a}") for a in "xyz"] + [getv(f"col_v_{a}") for a in "xyz"])
                if done_at is None and int(dut.out_done.value):
                    done_at = k
                    assert int(dut.out_busy.value) == 0
                    got_ep = [getv(f"ep_{a}") for a in "xyz"]
                    got_eo = [getv(f"eo_{a}") for a in "xyz"]
                    got_V = [getv(f"vw_{a}") for a in "xyz"] + [getv(f"vv_{a}") for a in "xyz"]
                assert k < 2000, "no out_done / columns"
            setv("col_valid", 0)
            cycles.setdefault((c["mode_b"], c["ff"]), set()).add(done_at)
            flags = int(dut.out_flags.value)
            exp_flags = c["flags"] & LAW_MASK & ~c["fk_flags"]
            bad = []
            if c["fk_flags"] & LAW_MASK:
                dut._log.warning("case %d: forward kinematics raised %#x", ci, c["fk_flags"])
            if got_ep != c["ep"]:
                bad.append(f"ep model {c['ep']} rtl {got_ep}")
            if got_eo != c["eo"]:
                bad.append(f"eo model {c['eo']} rtl {got_eo}")
            if got_V != c["V"]:
                bad.append(f"V model {c['V']} rtl {got_V}")
            Jg = np.asarray(cols_got).T
            if not np.array_equal(Jg, np.asarray(c["J"])):
                cols = np.nonzero(np.any(Jg != np.asarray(c["J"]), axis=0))[0]
                bad.append(f"J columns {cols.tolist()} differ: model {np.asarray(c['J'])[:, cols].T.tolist()} "
                           f"rtl {Jg[:, cols].T.tolist()}")
            if (flags & ~c["fk_flags"]) != exp_flags:
                bad.append(f"flags rtl {flags:#x}, model {c['flags']:#x} (law bits {exp_flags:#x})")
            for b, nm in ((3, "quat"), (4, "pos"), (6, "jac"), (9, "servo")):
                if exp_flags >> b & 1:
                    nflag[nm] += 1
            if bad:
                problems.append(f"case {ci} {c['name']} {c['kind']} mode_b={c['mode_b']} ff={c['ff']} "
                                f"kp={c['kp']} ko={c['ko']} tq={c['tq']} tp={c['tp']} uq={c['uq']} up={c['up']} "
                                f"uw={c['uw']} uv={c['uv']}: " + "; ".join(bad))
            await FallingEdge(dut.clk)
        dut._log.info("%d cases, cycles from start to done %s, cases raising each flag %s", len(cases),
                      {f"B{m}ff{f}": sorted(v) for (m, f), v in sorted(cycles.items())}, nflag)
        assert all(len(v) == 1 for v in cycles.values()), f"cycle count not constant within a mode: {cycles}"
        assert nflag["servo"] > 0, "no case saturated"
        assert not problems, f"{len(problems)} of {len(cases)} cases differ:\n" + "\n".join(problems[:8])


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("cfg", tsbench.CONFIGS)
def test_ts_core_law(cfg, sim):
    # The ECP5 multiplier variant on Verilator only in the compact configuration: in the default one
    # its ~400 MULT18X18D models take about a minute to build (per run: the build is not reused),
    # which is over this bench's time budget.  ts_mul's own bench checks that both variants are
    # bit-identical on both simulators, and the lint jobs cover TARGET = "ECP5" for both configurations.
    target = tsbench.target_for(sim) if cfg == "compact" else "GENERIC"
    # FOLD: the servo core's (7) on Verilator, fully parallel (1) on Icarus: the bits must not change;
    # the default configuration's folded run holds its banks' operands in shift chains (CHAIN 1)
    p = {"CONFIG": 0 if cfg == "default" else 1, "ROM_FILE": str(rtlparams.RTL / f"ts_rotvec_rom_{cfg}.mem"),
         "TARGET": target, "FOLD": 7 if sim == "verilator" else 1,
         "CHAIN": 1 if (sim == "verilator" and cfg == "default") else 0}
    ncase = os.environ.get("TS_NCASE", "160" if sim == "verilator" else "40")   # per mode
    tsbench.run_bench(toplevel=MODULE, test_file=__file__, sources=rtlparams.sources(MODULE, target),
                      parameters=p, sim=sim, build_name=f"{cfg}-{target}-{sim}",
                      env={"TS_CONFIG": cfg, "TS_MODE": os.environ.get("TS_MODE", ",".join(MODES)),
                           "TS_PARAMS": json.dumps(p), "TS_NCASE": ncase})
