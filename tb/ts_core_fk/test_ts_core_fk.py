"""Bench of rtl/ts_core_fk.v: forward kinematics and the screw-transport Jacobian (root basis, reference
point the tool origin: what the servo uses for error choice A) bit for bit against the model
(tensor_servo._model.Model(cfg, spec).jacobian(q, raw=True)): the tool pose, every joint frame's
origin and every Jacobian column, and the Status bits (out_flags = the model's flags), for
PUMA 560, UR5, Panda, the Stanford arm (prismatic joint), PUMA 560 with a rotated and offset base
and tool, and the first 8 joints of chain20 (NMAX joints, one prismatic), at fresh random joint
values within the limits (seed printed; replay with TS_SEED=<seed>; TS_NQ = vectors per chain).
Three more chains saturate, so that the flags and the saturated values are checked too. The model
builds them without the core's configuration checks, which refuse them (Model(..., checked=False)),
and their joint values are anywhere in (-7.5, 7.5) after fixed first vectors (`first_rows`) that
saturate whatever the seed:
- puma560_reach: PUMA 560 with offsets (3.5, -3.5, 3.5) m and scale 3 (compact 1.5); in the
  default configuration without its origin rotations, so that at q = 0 the offsets add up to 21 m,
  beyond pos_t's 16 m. Positions, lever arms and Jacobian entries saturate;
- stanford_stroke: the Stanford arm with a prismatic scale of 3.9 (d = s q saturates);
- stanford_pp: the Stanford arm's first three joints with long offsets along z and the same
  prismatic scale, whose first vector saturates only the prismatic origin p_3 = pF + d z.
Also: no output is X after reset, busy/done protocol, the cycle count of each evaluation (logged;
constant for a chain), and that the width localparams of the module equal the model's formats.
"""
import json
import os
import re
from pathlib import Path

import numpy as np
import pytest

import rtlparams
import tsbench

MODULE = "ts_core_fk"
NMAX = 8
JI_W = 3
CHAINS = ("puma560", "ur5", "panda", "stanford", "puma560_frames", "chain20_8", "puma560_reach",
          "stanford_stroke", "stanford_pp")
#: chains past the core's configuration checks: |q| range of their random joint values
SATURATING = {"puma560_reach": 7.5, "stanford_stroke": 7.5, "stanford_pp": 7.5}

try:
    import cocotb
except ImportError:  # pragma: no cover
    cocotb = None


def chain_spec(name: str, cfg: str = "default") -> dict:
    from tensor_servo import robots
    from tensor_servo.model import model_spec
    if name == "puma560_frames":
        sp = model_spec(robots.load("puma560"))
        qb = np.array([0.9, 0.1, -0.3, 0.2]); qb /= np.linalg.norm(qb)
        qt = np.array([0.5, -0.5, 0.5, 0.5])
        sp["base_quat"], sp["base_xyz"] = qb.tolist(), [0.1, -0.25, 0.4]
        sp["tool_quat"], sp["tool_xyz"] = qt.tolist(), [0.03, -0.02, 0.12]
        return sp
    if name == "chain20_8":
        sp = model_spec(robots.load("chain20"))
        sp["joints"] = sp["joints"][:NMAX]
        return sp
    if name == "puma560_reach":
        sp = model_spec(robots.load("puma560"))
        for j in sp["joints"]:
            # revolute scales near the limit of kturn_t = s / (4 pi): |s| < pi (compact pi / 2)
            j["origin_xyz"], j["scale"] = [3.5, -3.5, 3.5], (3.0 if cfg == "default" else 1.5)
            if cfg == "default":  # the offsets add up at q = 0: 21 m > 16 m (pos_t)
                j["origin_quat"] = [1.0, 0.0, 0.0, 0.0]
        return sp
    if name == "stanford_stroke":
        sp = model_spec(robots.load("stanford"))
        for j in sp["joints"]:
            if j["prismatic"]:
                j["scale"] = 3.9
        return sp
    if name == "stanford_pp":
        # the first three joints, offsets along z adding up to 8.4 m (compact 4.35 m) at frame 3's
        # origin before the prismatic stroke: d z takes it past pos_t (16 m, compact 8 m), while no
        # other sum saturates (the tool sits on frame 3)
        sp = model_spec(robots.load("stanford"))
        sp["joints"] = sp["joints"][:3]
        big = 1.0 if cfg == "default" else 0.5
        sp["base_xyz"] = [0.0, 0.0, 3.9 * big]
        sp["joints"][0]["origin_xyz"] = [0.0, 0.0, 3.5 * big]
        sp["joints"][1]["origin_xyz"] = [0.0, 0.0, 1.0 if cfg == "default" else 0.7]
        sp["joints"][2]["scale"] = 3.9
        return sp
    return model_spec(robots.load(name))


def first_rows(name: str, cfg: str, n: int) -> list:
    """Fixed joint values (joint units) that the vectors of a saturating chain start with."""
    qmax = SATURATING[name]
    if name == "puma560_reach":
        return [np.full(n, 0.95 * qmax), np.zeros(n)]
    if name == "stanford_stroke":
        return [np.full(n, 0.95 * qmax)]
    # stanford_pp at q = 0: frame 3's z axis is the root's; d = 7.8 m (compact 3.98 m) along it
    return [np.array([0.0, 0.0, 2.0 if cfg == "default" else 1.02])]


def random_q(m, spec: dict, rng, nq: int, qmax: float | None = None, first: list = ()) -> np.ndarray:
    """Raw joint values within the limits, or anywhere in (-qmax, qmax) after the rows first."""
    if qmax is not None:
        lo, hi = np.full(m.n, -qmax), np.full(m.n, qmax)
    else:
        lo = np.array([j["lower"] if j["limited"] else -np.pi for j in spec["joints"]])
        hi = np.array([j["upper"] if j["limited"] else np.pi for j in spec["joints"]])
    q = lo + (hi - lo) * rng.random((nq, len(lo)))
    for r, row in enumerate(first[:nq]):
        q[r] = row
    d = m.quantize_q(q)
    assert np.asarray(d["ok"]).all()
    return np.asarray(d["q_raw"], dtype=np.int64)


def cfg_words(c: dict) -> list[tuple[int, int]]:
    """(address, raw value) of the configuration: address {global, joint, field}."""
    words = []
    n = len(c["scale"])
    for j in range(n):
        base = j << 4
        words += [(base + a, int(c["origin_quat"][j][a])) for a in range(4)]
        words += [(base + 4 + a, int(c["origin_xyz"][j][a])) for a in range(3)]
        words += [(base + 8 + a, int(c["axis"][j][a])) for a in range(3)]
        words += [(base + 12, int(c["scale"][j])), (base + 13, int(c["kturn"][j])),
                  (base + 14, int(bool(c["prismatic"][j])))]
    g = 1 << (JI_W + 4)
    words += [(g + a, int(c["base_quat"][a])) for a in range(4)]
    words += [(g + 4 + a, int(c["base_xyz"][a])) for a in range(3)]
    words += [(g + 8 + a, int(c["tool_quat"][a])) for a in range(4)]
    words += [(g + 12 + a, int(c["tool_xyz"][a])) for a in range(3)]
    words += [(g + 15, n)]
    return words


def test_ts_core_fk_formats():
    """The module's format localparams (and port-width parameter defaults) equal the model's."""
    text = (rtlparams.RTL / f"{MODULE}.v").read_text()
    for cfg in tsbench.CONFIGS:
        rtlparams.check_module_formats(MODULE, cfg, 20, "TRIG_TABLE_BITS",
                                       [("ANG_W", "angle_t"), ("Q_W", "quat_t"), ("P_W", "pos_t"),
                                        ("JW_W", "jw_t"), ("JV_W", "jv_t")])
        ci = 0 if cfg == "default" else 1
        sc = rtlparams.sincos(cfg)
        m = re.search(r"localparam TWOPI = \(CONFIG == 0\) \? (\d+) : (\d+);", text)
        assert int(m.group(1 + ci)) == sc["TWOPI"]
        m = re.search(r"localparam SIXTH = (\d+);", text)
        assert int(m.group(1)) == sc["SIXTH"]


if cocotb is not None:
    async def clock_cycles(dut, n):
        from cocotb.triggers import FallingEdge
        for _ in range(n):
            await FallingEdge(dut.clk)

    @cocotb.test()
    async def core_fk_bit_exact(dut):
        from cocotb.clock import Clock
        from cocotb.triggers import FallingEdge
        from tensor_servo import _model
        from tensor_servo.model import OVF_MASK, STATUS_BITS
        cfg = os.environ["TS_CONFIG"]
        seed = int(os.environ["TS_SEED"])
        nq = int(os.environ.get("TS_NQ", "12"))
        dut._log.info("config %s, seed %d, %d joint vectors per chain", cfg, seed, nq)
        rng = np.random.default_rng(seed)

        cocotb.start_soon(Clock(dut.clk, 10, units="ns").start())
        for h in (dut.in_cfg_we, dut.in_cfg_addr, dut.in_cfg_data, dut.in_q_we, dut.in_q_addr, dut.in_q_data,
                  dut.in_start, dut.in_col_addr):
            h.value = 0
        dut.rst.value = 1
        await clock_cycles(dut, 4)
        dut.rst.value = 0
        await FallingEdge(dut.clk)
        outs = [getattr(dut, f"out_{x}") for x in ["busy", "done", "flags"] + [f"tool_q_{a}" for a in "wxyz"]
                + [f"tool_p_{a}" for a in "xyz"] + [f"col_{g}_{a}" for g in "wvp" for a in "xyz"]]
        for h in outs:
            assert h.value.is_resolvable, f"{h._name} is {h.value.binstr} after reset"
        assert int(dut.out_busy.value) == 0 and int(dut.out_done.value) == 0

        qw = len(dut.in_q_data)
        cw = len(dut.in_cfg_data)
        w = {n: len(getattr(dut, n)) for n in ("out_tool_q_w", "out_tool_p_x", "out_col_w_x", "out_col_v_x")}
        sg = tsbench.to_signed
        problems = []
        cycles_log = {}
        raised = {name: 0 for name in CHAINS}
        for name in CHAINS:
            spec = chain_spec(name, cfg)
            m = _model.Model(cfg, spec, checked=name not in SATURATING)
            n = m.n
            c = m.constants()
            for addr, val in cfg_words(c):
                dut.in_cfg_we.value = 1
                dut.in_cfg_addr.value = addr
                dut.in_cfg_data.value = val & ((1 << cw) - 1)
                await FallingEdge(dut.clk)
            dut.in_cfg_we.value = 0
            q = random_q(m, spec, rng, nq, SATURATING.get(name),
                         first_rows(name, cfg, n) if name in SATURATING else ())
            ref = m.jacobian(q, raw=True)
            cyc = []
            for s in range(nq):
                for j in range(n):
                    dut.in_q_we.value = 1
                    dut.in_q_addr.value = j
                    dut.in_q_data.value = int(q[s, j]) & ((1 << qw) - 1)
                    await FallingEdge(dut.clk)
                dut.in_q_we.value = 0
                dut.in_start.value = 1
                await FallingEdge(dut.clk)
                dut.in_start.value = 0
                k = 1
                assert int(dut.out_busy.value) == 1
                while not int(dut.out_done.value):
                    await FallingEdge(dut.clk)
                    k += 1
                    assert k < 5000, "no out_done"
                assert int(dut.out_busy.value) == 0
                cyc.append(k)
                got_q = [sg(int(getattr(dut, f"out_tool_q_{a}").value), w["out_tool_q_w"]) for a in "wxyz"]
                got_p = [sg(int(getattr(dut, f"out_tool_p_{a}").value), w["out_tool_p_x"]) for a in "xyz"]
                got_flags = int(dut.out_flags.value)
                J = np.zeros((6, n), dtype=np.int64)
                P = np.zeros((n, 3), dtype=np.int64)
                for col in range(n):
                    # the address is sampled at the next rising edge, the column is out after it
                    dut.in_col_addr.value = col
                    await FallingEdge(dut.clk)
                    for a, ax in enumerate("xyz"):
                        J[a, col] = sg(int(getattr(dut, f"out_col_w_{ax}").value), w["out_col_w_x"])
                        J[a + 3, col] = sg(int(getattr(dut, f"out_col_v_{ax}").value), w["out_col_v_x"])
                        P[col, a] = sg(int(getattr(dut, f"out_col_p_{ax}").value), w["out_tool_p_x"])
                exp_q = np.asarray(ref["quat_raw"])[s, n + 1]
                exp_p = np.asarray(ref["pos_raw"])[s, n + 1]
                exp_P = np.asarray(ref["pos_raw"])[s, 1:n + 1]
                exp_J = np.asarray(ref["J_raw"])[s]
                exp_flags = int(ref["flags"][s]) & OVF_MASK
                raised[name] |= exp_flags
                bad = []
                if not np.array_equal(got_q, exp_q):
                    bad.append(f"tool quat model {exp_q.tolist()} rtl {got_q}")
                if not np.array_equal(got_p, exp_p):
                    bad.append(f"tool pos model {exp_p.tolist()} rtl {got_p}")
                if not np.array_equal(P, exp_P):
                    rows = np.nonzero(np.any(P != exp_P, axis=1))[0]
                    bad.append(f"frame origins {rows.tolist()} differ: model {exp_P[rows].tolist()} rtl {P[rows].tolist()}")
                if not np.array_equal(J, exp_J):
                    cols = np.nonzero(np.any(J != exp_J, axis=0))[0]
                    bad.append(f"J columns {cols.tolist()} differ: model {exp_J[:, cols].T.tolist()} rtl {J[:, cols].T.tolist()}")
                if got_flags != exp_flags:
                    bad.append(f"out_flags {got_flags:#x}, model flags {exp_flags:#x}")
                if bad:
                    problems.append(f"{name} vector {s} q_raw={q[s].tolist()}: " + "; ".join(bad))
            cycles_log[name] = (n, sorted(set(cyc)))
            dut._log.info("%s (n = %d, prismatic %s): cycles from start to done %s", name, n,
                          np.nonzero(c["prismatic"])[0].tolist(), sorted(set(cyc)))
            if len(set(cyc)) != 1:
                problems.append(f"{name}: cycle count not constant: {sorted(set(cyc))}")
        dut._log.info("cycles per chain: %s", cycles_log)
        dut._log.info("Status bits raised per chain: %s", {k: hex(v) for k, v in raised.items()})
        for name in CHAINS:
            if (raised[name] != 0) != (name in SATURATING):
                problems.append(f"{name}: Status bits {raised[name]:#x} raised over its vectors")
        sat_bits = STATUS_BITS["ovf_pos"] | STATUS_BITS["ovf_lever"] | STATUS_BITS["ovf_jac"]
        got_bits = raised["puma560_reach"] | raised["stanford_stroke"]
        if not raised["stanford_pp"] & STATUS_BITS["ovf_pos"]:
            problems.append(f"stanford_pp raised {raised['stanford_pp']:#x}: its prismatic origin must saturate")
        if got_bits & sat_bits != sat_bits:
            problems.append(f"the saturating chains raised {got_bits:#x}: POS, LEVER and JAC must all be covered")
        out_file = os.environ.get("TS_CYCLES_FILE")
        if out_file:
            Path(out_file).write_text(json.dumps(cycles_log))
        assert not problems, f"{len(problems)} mismatches:\n" + "\n".join(problems[:10])


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("cfg", tsbench.CONFIGS)
def test_ts_core_fk(cfg, sim):
    target = tsbench.target_for(sim)
    # FOLD: the servo core's (7) on Verilator, fully parallel (1) on Icarus: the bits must not change;
    # the default configuration's folded run holds its banks' operands in shift chains (CHAIN 1) and
    # takes its wide ECP5 products on three MULT18X18D each (MUL3 1; the primitives' benches run MUL3 0)
    variant = sim == "verilator" and cfg == "default"
    p = {"NMAX": NMAX, "CONFIG": 0 if cfg == "default" else 1, "ROM_FILE": str(rtlparams.rom_file(cfg)),
         "TARGET": target, "FOLD": 7 if sim == "verilator" else 1,
         "CHAIN": 1 if variant else 0, "MUL3": 1 if variant else 0}
    nq = os.environ.get("TS_NQ", "12" if sim == "verilator" else "3")
    tsbench.run_bench(toplevel=MODULE, test_file=__file__, sources=rtlparams.sources(MODULE, target),
                      parameters=p, sim=sim, build_name=f"{cfg}-{target}-{sim}",
                      env={"TS_CONFIG": cfg, "TS_PARAMS": json.dumps(p), "TS_NQ": nq})
