"""Bench of rtl/ts_core_solve.v: the back half of the servo tick (scaled columns and target, step
factors, bounds, warm start with its leak, coordinate-descent sweeps, integration) bit for bit against
the model (tensor_servo._model.Servo(cfg, spec, params).solve_raw(J, V, q, warm)): every q', q_next,
the residual r and the status word.

Cases (fresh random, seed printed; replay with TS_SEED=<seed>; TS_NCASE scales the count):
  - real ticks: J_raw and V_raw of Servo.tick (PUMA 560, UR5, Panda, Stanford arm) at random joint
    values and setpoints near the current pose, warm start from the tick before;
  - random raw J / V / q / warm on the same chains and on truncated chains (n = 1, 2, 3) and 8 joints
    of chain20, with different L, klim, sweeps (1, 2, 3, 10), mu (0, 1, 1.9, random), warm_leak;
  - joints at, near and beyond their limits, zero (singular) columns, saturating V and warm start.
TS_NMAX=<N> builds the module with NMAX = N (default 8; the chain20 cases then use min(N, 20) joints).
Also: no output is X after reset, the busy/done protocol, the cycles per solve (equal to the
documented count, whatever the data), and that the
format localparams of the module equal the model's formats.
"""
import json
import os
import re
from pathlib import Path

import numpy as np
import pytest

import rtlparams
import tsbench

MODULE = "ts_core_solve"
NMAX = int(os.environ.get("TS_NMAX", "8"))   # TS_NMAX: one-off runs at another NMAX (chain20 gives n <= 20)
JI_W = max(1, (NMAX - 1).bit_length())
ROBOTS = ("puma560", "ur5", "panda", "stanford")

try:
    import cocotb
except ImportError:  # pragma: no cover
    cocotb = None


def test_ts_core_solve_formats():
    """The module's format localparams and port-width parameter defaults equal the model's formats."""
    text = (rtlparams.RTL / f"{MODULE}.v").read_text()
    for cfg in tsbench.CONFIGS:
        rtlparams.check_module_formats(MODULE, cfg, 30, "RECIP_TABLE_BITS",
                                       [("ANG_W", "angle_t"), ("QD_W", "qd_t"), ("TW_W", "tw_t")])
        ci = 0 if cfg == "default" else 1
        m = re.search(r"parameter CD_W = \(CONFIG == 0\) \? (\d+) : (\d+)", text)
        widest = max(rtlparams.fmt(cfg, n)[0] for n in ("angle_t", "qd_t", "jw_t", "jv_t", "vel_t", "lchar_t",
                                                         "klim_t", "dt_t", "mu_t"))
        assert int(m.group(1 + ci)) == widest


# ---- case generation (simulator side) ----------------------------------------------------------------
def qraw(x, cfg: str, name: str) -> np.ndarray:
    """Raw values as fx::from_double (floor(x 2^F + 1/2), saturated)."""
    w, f = rtlparams.fmt(cfg, name)
    r = np.floor(np.ldexp(np.asarray(x, dtype=float), f) + 0.5)
    return np.clip(r, -(1 << (w - 1)), (1 << (w - 1)) - 1).astype(np.int64)


def chain_spec(name: str, nj: int | None = None) -> dict:
    from tensor_servo import robots
    from tensor_servo.model import model_spec
    sp = model_spec(robots.load(name))
    if nj is not None:
        sp["joints"] = sp["joints"][:nj]
    return sp


def servo_params(n: int, rng, dt: float = 1e-3, **kw) -> dict:
    p = {"L": 0.5, "kp": 0.3 / dt, "ko": 0.3 / dt, "dt": dt, "klim": 0.5 / dt, "sweeps": 10,
         "mu": [1.5] * n, "mode": "A", "feedforward": True, "controlled": [-1], "setpoint_frame": -1,
         "vlimits": True, "weights": [1.0], "warm_leak": 0}
    p.update(kw)
    return p


def random_params(n: int, rng, sweeps: int) -> dict:
    mu_kind = rng.integers(4)
    if mu_kind == 0:
        mu = [1.5] * n
    elif mu_kind == 1:
        mu = list(rng.choice([0.0, 1.0, 1.9], size=n))
    else:
        mu = list(rng.uniform(0.2, 1.95, size=n))
    dt = float(rng.choice([1e-3, 4e-3, 0.05]))
    return servo_params(n, rng, dt=dt, L=float(rng.choice([0.05, 0.5, 1.0, 3.5])),
                        klim=float(rng.choice([0.5 / dt, 1.0 / dt, 20.0])), sweeps=sweeps, mu=mu,
                        vlimits=bool(rng.random() < 0.8), warm_leak=int(rng.choice([0, 0, 1, 3, 8])))


def random_raw_case(cfg: str, pr: dict, n: int, rng, kind: str):
    """Random raw (J, V, q, warm) of one of several kinds."""
    jw_w = rtlparams.fmt(cfg, "jw_t")[0]
    jv_w = rtlparams.fmt(cfg, "jv_t")[0]
    vel_w, vel_f = rtlparams.fmt(cfg, "vel_t")
    qd_w, qd_f = rtlparams.fmt(cfg, "qd_t")
    ang_w, ang_f = rtlparams.fmt(cfg, "angle_t")

    def rint(bits, shape):
        return rng.integers(-(1 << (bits - 1)), 1 << (bits - 1), size=shape, dtype=np.int64)

    # magnitudes: full range, or typical (entries ~ 1 rad/m, V ~ 0.1 .. 2)
    if kind == "full":
        J = np.vstack([rint(jw_w, (3, n)), rint(jv_w, (3, n))])
        V = rint(vel_w, 6)
    else:
        J = np.vstack([qraw(rng.uniform(-1, 1, (3, n)), cfg, "jw_t"), qraw(rng.uniform(-1.2, 1.2, (3, n)), cfg, "jv_t")])
        V = qraw(rng.normal(0, float(rng.choice([0.01, 0.3, 2.0])), 6), cfg, "vel_t")
    lo, hi, lim = np.asarray(pr["lo"]), np.asarray(pr["hi"]), np.asarray(pr["limited"])
    span = np.where(lim, hi - lo, 1 << (ang_f + 2))
    base = np.where(lim, lo, -(1 << (ang_f + 1)))
    q = base + (rng.random(n) * span).astype(np.int64)
    warm = qraw(rng.normal(0, 0.5, n), cfg, "qd_t")
    if kind == "limits":
        # joints exactly at, a few LSB inside / outside, or well beyond a limit
        for i in range(n):
            if not lim[i]:
                continue
            c = rng.integers(6)
            off = int(rng.integers(1, 50))
            q[i] = [lo[i], hi[i], lo[i] + off, hi[i] - off, lo[i] - off, hi[i] + (1 << (ang_f - 2))][c]
        warm = qraw(rng.normal(0, 3.0, n), cfg, "qd_t")
    elif kind == "singular":
        for i in rng.choice(n, size=max(1, n // 2), replace=False):
            J[:, i] = 0
        if n > 1 and rng.random() < 0.5:
            J[:, 0] = J[:, 1]  # two equal columns
    elif kind == "saturate":
        V = np.where(rng.random(6) < 0.5, (1 << (vel_w - 1)) - 1, -(1 << (vel_w - 1))).astype(np.int64)
        warm = np.where(rng.random(n) < 0.5, (1 << (qd_w - 1)) - 1, -(1 << (qd_w - 1))).astype(np.int64)
        J = np.vstack([rint(jw_w, (3, n)), rint(jv_w, (3, n))])
        # joint values at the edge of angle_t: q + q' dt saturates (ST_OVF_ANGLE)
        for i in range(n):
            if rng.random() < 0.5:
                edge = (1 << (ang_w - 1)) - 1 - int(rng.integers(0, 1000))
                q[i] = edge if rng.random() < 0.5 else -edge
    q = np.clip(q, -(1 << (ang_w - 1)), (1 << (ang_w - 1)) - 1).astype(np.int64)
    return J.astype(np.int64), V.astype(np.int64), q, warm.astype(np.int64)


def make_groups(cfg: str, rng, scale: float):
    """Groups of cases sharing one configuration: (name, params_raw, [(J, V, q, warm, expected)])."""
    from tensor_servo import _model
    from tensor_servo import robots
    from tensor_servo.reference import fk_frames
    from tensor_servo.servo import Servo
    groups = []
    cnt = lambda k: max(1, int(round(k * scale)))  # noqa: E731

    # real ticks: J and V from Servo.tick at random q / setpoints, warm start from the tick before
    for name in ROBOTS:
        ch = robots.load(name)
        for sweeps in (2, 10):
            s = Servo(ch, cfg, dt=1e-3, sweeps=sweeps, warm_leak=int(rng.choice([0, 2])))
            pr = s._s.params_raw()
            cases = []
            spec = chain_spec(name)
            lo = np.array([j["lower"] if j["limited"] else -np.pi for j in spec["joints"]])
            hi = np.array([j["upper"] if j["limited"] else np.pi for j in spec["joints"]])
            for _ in range(cnt(6)):
                q = lo + (hi - lo) * rng.uniform(0.02, 0.98, ch.n)
                q2 = q + rng.normal(0, 0.05, ch.n)
                T = fk_frames(ch, q2)[ch.n + 1]  # the setpoint: the tool pose at q2
                Ud = rng.normal(0, 0.05, 6)
                warm = rng.normal(0, 0.2, ch.n)
                out = s.tick(q, T, Ud, warm)
                J = np.asarray(out.raw["J"])[0].astype(np.int64)
                V = np.asarray(out.raw["V"])[0].astype(np.int64)
                q_r = qraw(q, cfg, "angle_t")
                w_r = qraw(warm, cfg, "qd_t")
                exp = s._s.solve_raw(J, V, q_r, w_r)
                # the solve alone reproduces the tick's back half
                assert np.array_equal(exp["qd_raw"], out.raw["qd"]), "solve_raw differs from tick"
                cases.append((J, V, q_r, w_r, exp))
            groups.append((f"{name} tick sweeps={sweeps}", pr, cases))

    # random raw cases on full and truncated chains
    chains = [(r, None) for r in ROBOTS] + [("puma560", 1), ("ur5", 2), ("stanford", 3), ("chain20", min(NMAX, 20))]
    if scale < 0.5:  # the short run (Icarus): half of the chains, still n = 2, 6, 7 and NMAX
        chains = [("puma560", None), ("panda", None), ("ur5", 2), ("chain20", min(NMAX, 20))]
    for name, nj in chains:
        spec = chain_spec(name, nj)
        n = len(spec["joints"])
        # some joints without position limits (continuous joints: q + q' dt may saturate angle_t)
        for j in spec["joints"]:
            if not j["prismatic"] and rng.random() < 0.25:
                j["limited"] = False
        for sweeps in (int(rng.choice([1, 2, 3])), 10):
            p = random_params(n, rng, sweeps)
            s = _model.Servo(cfg, spec, p)
            pr = s.params_raw()
            cases = []
            for kind in ("typical", "full", "limits", "singular", "saturate"):
                for _ in range(cnt(2 if kind == "typical" else 1)):
                    J, V, q, warm = random_raw_case(cfg, pr, n, rng, kind)
                    cases.append((J, V, q, warm, s.solve_raw(J, V, q, warm)))
            groups.append((f"{name}[{n}] raw sweeps={sweeps} leak={p['warm_leak']} L={p['L']}", pr, cases))
    return groups


def cfg_words(pr: dict) -> list[tuple[int, int]]:
    n = len(pr["mu"])
    words = []
    for j in range(n):
        b = j << 4
        words += [(b + 0, int(pr["lo"][j])), (b + 1, int(pr["hi"][j])), (b + 2, int(pr["vmax"][j])),
                  (b + 3, int(pr["mu"][j])), (b + 4, int(bool(pr["limited"][j])))]
    g = 1 << (JI_W + 4)
    words += [(g + 0, int(pr["L"])), (g + 1, int(pr["klim"])), (g + 2, int(pr["dt"])),
              (g + 3, int(pr["sweeps"])), (g + 4, int(pr["warm_leak"]))]
    return words


def x_words(J, V, q, warm) -> list[tuple[int, int]]:
    n = J.shape[1]
    words = []
    for j in range(n):
        b = j << 4
        words += [(b + a, int(J[a, j])) for a in range(6)]
        words += [(b + 6, int(q[j])), (b + 7, int(warm[j]))]
    g = 1 << (JI_W + 4)
    words += [(g + a, int(V[a])) for a in range(6)]
    return words


def solve_cycles(cfg: str, n: int, sweeps: int) -> int:
    """Cycles per solve, as docs/rtl/ts_core_solve.md states them: MLAT is the shared multiplier's
    latency (operands as wide as the widest a and b operand of the configuration), every joint
    costs 24 cycles of preparation streams and integration, every coordinate step 3 MLAT + 24;
    independent of the data (zero columns, limits)."""
    wa = max(rtlparams.fmt(cfg, t)[0] for t in ("lchar_t", "jsc_t", "mant_t", "recip_t", "mu_t", "klim_t",
                                                  "gk_t", "qd_t"))
    wb = max(rtlparams.fmt(cfg, t)[0] for t in ("jw_t", "vel_t", "jsc_t", "recip_t", "qdiff_t", "qd_t",
                                                  "tw_t", "step_t", "dt_t"))
    mlat = rtlparams.mul_lat(wa, wb)
    return 50 + 9 * mlat + 24 * n + sweeps * n * (3 * mlat + 24)


if cocotb is not None:
    async def clock_cycles(dut, n):
        from cocotb.triggers import FallingEdge
        for _ in range(n):
            await FallingEdge(dut.clk)

    async def write(dut, we, addr, data, words, mask):
        from cocotb.triggers import FallingEdge
        for a, v in words:
            we.value = 1
            addr.value = a
            data.value = v & mask
            await FallingEdge(dut.clk)
        we.value = 0

    @cocotb.test()
    async def core_solve_bit_exact(dut):
        from cocotb.clock import Clock
        from cocotb.triggers import FallingEdge, RisingEdge
        from cocotb.utils import get_sim_time
        cfg = os.environ["TS_CONFIG"]
        seed = int(os.environ["TS_SEED"])
        scale = float(os.environ.get("TS_NCASE", "1"))
        dut._log.info("config %s, seed %d, case scale %g", cfg, seed, scale)
        rng = np.random.default_rng(seed)
        groups = make_groups(cfg, rng, scale)
        ncase = sum(len(c) for _, _, c in groups)
        dut._log.info("%d groups, %d solves", len(groups), ncase)
        fl = {}
        for _, _, cs in groups:
            for c in cs:
                fl[int(c[4]["flags"])] = fl.get(int(c[4]["flags"]), 0) + 1
        dut._log.info("model status words of the cases (value: count): %s",
                      {f"{k:#x}": v for k, v in sorted(fl.items())})

        cocotb.start_soon(Clock(dut.clk, 10, units="ns").start())
        for h in (dut.in_cfg_we, dut.in_cfg_addr, dut.in_cfg_data, dut.in_x_we, dut.in_x_addr, dut.in_x_data,
                  dut.in_start, dut.in_n):
            h.value = 0
        dut.rst.value = 1
        await clock_cycles(dut, 4)
        dut.rst.value = 0
        await FallingEdge(dut.clk)
        for h in (dut.out_busy, dut.out_done, dut.out_qd, dut.out_q_next, dut.out_r, dut.out_flags):
            assert h.value.is_resolvable, f"{h._name} is {h.value.binstr} after reset"
        assert int(dut.out_busy.value) == 0 and int(dut.out_done.value) == 0

        cd_mask = (1 << len(dut.in_cfg_data)) - 1
        qd_w = rtlparams.fmt(cfg, "qd_t")[0]
        ang_w = rtlparams.fmt(cfg, "angle_t")[0]
        tw_w = rtlparams.fmt(cfg, "tw_t")[0]
        sg = tsbench.to_signed
        problems = []
        cycles = {}
        done_cases = 0
        for gname, pr, cases in groups:
            await write(dut, dut.in_cfg_we, dut.in_cfg_addr, dut.in_cfg_data, cfg_words(pr), cd_mask)
            n = len(pr["mu"])
            for ci, (J, V, q, warm, exp) in enumerate(cases):
                await write(dut, dut.in_x_we, dut.in_x_addr, dut.in_x_data, x_words(J, V, q, warm), cd_mask)
                dut.in_n.value = n
                dut.in_start.value = 1
                t0 = get_sim_time("ns")
                await FallingEdge(dut.clk)
                dut.in_start.value = 0
                assert int(dut.out_busy.value) == 1
                await RisingEdge(dut.out_done)
                await FallingEdge(dut.clk)
                k = int(round((get_sim_time("ns") - t0) / 10))
                assert int(dut.out_busy.value) == 0 and int(dut.out_done.value) == 1
                cycles.setdefault((n, int(pr["sweeps"])), set()).add(k)
                if k != solve_cycles(cfg, n, int(pr["sweeps"])):
                    problems.append(f"{gname} case {ci}: {k} cycles, documented {solve_cycles(cfg, n, int(pr['sweeps']))}")
                vq = int(dut.out_qd.value)
                vn = int(dut.out_q_next.value)
                vr = int(dut.out_r.value)
                got_qd = [sg((vq >> (i * qd_w)) & ((1 << qd_w) - 1), qd_w) for i in range(n)]
                got_qn = [sg((vn >> (i * ang_w)) & ((1 << ang_w) - 1), ang_w) for i in range(n)]
                got_r = [sg((vr >> (a * tw_w)) & ((1 << tw_w) - 1), tw_w) for a in range(6)]
                got_f = int(dut.out_flags.value)
                bad = []
                for key, got in (("qd_raw", got_qd), ("q_next_raw", got_qn), ("r_raw", got_r)):
                    e = np.asarray(exp[key]).tolist()
                    if e != got:
                        bad.append(f"{key}: model {e} rtl {got}")
                if got_f != int(exp["flags"]):
                    bad.append(f"flags: model {int(exp['flags']):#x} rtl {got_f:#x}")
                if bad:
                    problems.append(f"{gname} case {ci}: J={J.tolist()} V={V.tolist()} q={q.tolist()} "
                                    f"warm={warm.tolist()}: " + "; ".join(bad))
                done_cases += 1
        log = {f"n={n} sweeps={s}": sorted(v) for (n, s), v in sorted(cycles.items())}
        dut._log.info("cycles per solve (start to done): %s", log)
        out_file = os.environ.get("TS_CYCLES_FILE")
        if out_file:
            Path(out_file).write_text(json.dumps(log))
        dut._log.info("%d solves compared, %d mismatches", done_cases, len(problems))
        assert not problems, f"{len(problems)} of {done_cases} solves differ:\n" + "\n".join(problems[:6])


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("cfg", tsbench.CONFIGS)
def test_ts_core_solve(cfg, sim):
    target = tsbench.target_for(sim)
    p = {"NMAX": NMAX, "CONFIG": 0 if cfg == "default" else 1,
         "ROM_FILE": str(rtlparams.RTL / f"ts_recip_rom_{cfg}.mem"), "TARGET": target}
    scale = os.environ.get("TS_NCASE", "1" if sim == "verilator" else "0.2")
    tsbench.run_bench(toplevel=MODULE, test_file=__file__, sources=rtlparams.sources(MODULE, target),
                      parameters=p, sim=sim, build_name=f"{cfg}-{target}-{sim}" + ("" if NMAX == 8 else f"-nmax{NMAX}"),
                      env={"TS_CONFIG": cfg, "TS_NCASE": scale, "TS_NMAX": str(NMAX)})
