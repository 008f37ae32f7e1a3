"""cocotb bench of ts_servo_core, the servo core top: configuration over AXI4-Lite, commit, and
closed-loop ticks over AXI4-Stream compared word for word with the model's tick
(tensor_servo._model.commit_raw(cfg, raw, NMAX) -> Servo holding the committed state, .tick_raw).

Tests (every one starts from reset; fresh seed per run, TS_SEED replays):
- closed loop per robot (PUMA 560, UR5, Panda, Stanford arm; Panda in error choice B, UR5 in
  error-only mode): the plant integrates q' exactly (the next measured q is the tick's q_next),
  the setpoint moves on a small circle around the start tool pose with its velocity as
  feed-forward; the warm start is the previous tick's q' (the model's solver applies the leak),
  zero after the commit and on COLD ticks; virtual mode with LOAD_Q on the first tick;
- back-to-back packets with random tvalid/tready gaps (no tick lost or duplicated);
- a bad configuration (axis not unit) refused with its CFG_ERROR code/joint and TREADY low;
- malformed packets (TLAST early / late) answered with status bit 30, no state change;
- reset in the middle of a tick, then reconfigure and run;
- cycles per tick (TICK_CYCLES) of PUMA 560 at 10 and 2 sweeps, without gaps (logged and
  written to TS_CYCLES_FILE);
- CTRL.COMMIT during a tick;
- a joint-register write during a commit (it waits until the loader is done);
- FLAGS against the OR of the packets' status flags (set by a far setpoint, cleared by writing 1
  and by CTRL.CLEAR), and CTRL.VIRTUAL switched between ticks with the packet's q off the core's.
"""
from __future__ import annotations

import json
import math
import os
import random

import numpy as np
import pytest

import rtlparams
import tsbench

MODULE = "ts_servo_core"
NMAX = 8
ROBOTS = ("puma560", "ur5", "panda", "stanford")
SERVO = {"kp": ("gain_t", 20.0), "ko": ("gain_t", 20.0), "lchar": ("lchar_t", 0.5),
         "klim": ("klim_t", 500.0), "dt": ("dt_t", 0.001)}
STATUS_MALFORMED = 1 << 30


def fw(cfg, name):
    return rtlparams.fmt(cfg, name)


qz = rtlparams.quantize_const


def raw_from_chain(chain, cfg: str, mode: int = 0, sweeps: int = 10, leak: int = 5) -> dict:
    """Register words of a chain (rtlparams.core_raw, as tb/ts_core_commit), this bench's gains."""
    return rtlparams.core_raw(chain, cfg, NMAX, SERVO, mode=mode, sweeps=sweeps, leak=leak)


def start_q(chain, cfg: str, rng) -> list[int]:
    out = []
    for j in chain.joints:
        lim = j.limits
        lo, hi = (lim.lower, lim.upper) if lim.bounded else (-1.0, 1.0)
        out.append(qz(lo + (hi - lo) * (0.3 + 0.4 * rng.random()), cfg, "angle_t"))
    return out


def sext(v: int, w: int = 32) -> int:
    v &= (1 << w) - 1
    return v - (1 << w) if v >> (w - 1) else v


class Path:
    """Setpoint on a circle of radius r (m) around the start tool position, constant orientation
    (the start tool quaternion), velocity feed-forward; raw words of each tick."""

    def __init__(self, cfg, quat_raw, pos_raw, dt, r=0.01, period=0.2):
        self.cfg = cfg
        _, qf = fw(cfg, "quat_t")
        _, pf = fw(cfg, "pos_t")
        self.p0 = np.array(pos_raw, dtype=float) / 2.0 ** pf
        self.quat = [int(x) for x in quat_raw]
        self.dt, self.r, self.om = dt, r, 2 * math.pi / period

    def at(self, k):
        t = k * self.dt
        c, s = math.cos(self.om * t), math.sin(self.om * t)
        p = self.p0 + self.r * np.array([c - 1.0, s, 0.3 * s])
        v = self.r * self.om * np.array([-s, c, 0.3 * c])
        w = np.array([0.05 * c, 0.0, -0.05 * s])
        up = [qz(x, self.cfg, "pos_t") for x in p]
        uw = [qz(x, self.cfg, "vel_t") for x in w]
        uv = [qz(x, self.cfg, "vel_t") for x in v]
        return self.quat, up, uw, uv


# ---- cocotb side ----------------------------------------------------------------------------------
if os.environ.get("COCOTB_SIM") or os.environ.get("TOPLEVEL"):
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge, with_timeout
    from cocotbext.axi import (AxiLiteBus, AxiLiteMaster, AxiStreamBus, AxiStreamFrame, AxiStreamSink,
                               AxiStreamSource)
    import logging

    from tensor_servo import _model, regs, robots
    from tensor_servo.rtl_core import register_writes

    class TB:
        def __init__(self, dut):
            self.dut = dut
            self.cfg = os.environ["TS_CONFIG"]
            self.rng = random.Random(int(os.environ["TS_SEED"]))
            self.nrng = np.random.default_rng(int(os.environ["TS_SEED"]))
            # Verilator 5.006 + cocotb 1.8: look every port up by name before from_prefix iterates.
            for n in ["clk", "rst"] + [f"s_axil_{s}" for s in ("awaddr", "awprot", "awvalid", "awready", "wdata",
                      "wstrb", "wvalid", "wready", "bresp", "bvalid", "bready", "araddr", "arprot", "arvalid",
                      "arready", "rdata", "rresp", "rvalid", "rready")] + \
                    [f"s_axis_{s}" for s in ("tdata", "tvalid", "tready", "tlast")] + \
                    [f"m_axis_{s}" for s in ("tdata", "tvalid", "tready", "tlast")]:
                getattr(dut, n)
            cocotb.start_soon(Clock(dut.clk, 10, units="ns").start())
            self.axil = AxiLiteMaster(AxiLiteBus.from_prefix(dut, "s_axil"), dut.clk, dut.rst)
            self.src = AxiStreamSource(AxiStreamBus.from_prefix(dut, "s_axis"), dut.clk, dut.rst, byte_size=32)
            self.snk = AxiStreamSink(AxiStreamBus.from_prefix(dut, "m_axis"), dut.clk, dut.rst, byte_size=32)
            for x in (self.axil.write_if, self.axil.read_if, self.src, self.snk):
                x.log.setLevel(logging.WARNING)
            self.ticks = 0
            self.errors = []

        def gaps(self, on: bool):
            if on:
                def gen(p):
                    while True:
                        yield self.rng.random() < p
                self.src.set_pause_generator(gen(0.3))
                self.snk.set_pause_generator(gen(0.3))
            else:
                self.src.clear_pause_generator()
                self.snk.clear_pause_generator()

        async def reset(self):
            self.dut.rst.value = 1
            for _ in range(5):
                await RisingEdge(self.dut.clk)
            self.dut.rst.value = 0
            await RisingEdge(self.dut.clk)

        async def wr(self, addr, data):
            r = await self.axil.write_dword(addr, data & 0xFFFFFFFF)
            return r

        async def rd(self, addr):
            return await self.axil.read_dword(addr)

        async def configure(self, raw: dict):
            for addr, word in register_writes(raw, NMAX):
                await self.wr(addr, word)

        async def commit(self, ctrl_after: int):
            await self.wr(regs.CTRL, regs.CTRL_COMMIT)
            for _ in range(10000):
                st = await self.rd(regs.STATUS)
                if not st & regs.STATUS_CFG_BUSY:
                    break
            else:
                raise AssertionError("CFG_BUSY never fell")
            err = await self.rd(regs.CFG_ERROR)
            await self.wr(regs.CTRL, ctrl_after | regs.CTRL_CLEAR)
            return st, err & 0xFF, (err >> 8) & 0xFF

        async def tick_io(self, words):
            await self.src.send(AxiStreamFrame(tdata=[w & 0xFFFFFFFF for w in words]))
            fr = await with_timeout(self.snk.recv(), 2000, "us")
            return [sext(w) for w in fr.tdata]

    class Loop:
        """Model side of the closed loop: the committed Servo, the plant q, the warm start."""

        def __init__(self, tb: TB, robot: str, raw: dict, virtual: bool = False):
            res, self.servo = _model.commit_raw(tb.cfg, raw, NMAX)
            assert res["code"] == 0, res
            self.tb, self.robot, self.cfg, self.n = tb, robot, tb.cfg, raw["n"]
            chain = robots.load(robot)
            self.q = start_q(chain, tb.cfg, tb.rng)
            self.warm = [0] * self.n
            self.q_int = [0] * self.n          # the core's q in virtual mode
            self.virtual = virtual
            z3 = np.zeros((1, 3), dtype=np.int64)
            one = qz(1.0, tb.cfg, "quat_t")
            o = self.servo.tick_raw(np.array(self.q, dtype=np.int64), np.array([[one, 0, 0, 0]], dtype=np.int64),
                                    z3, z3, z3, np.zeros(self.n, dtype=np.int64))
            _, dtf = fw(tb.cfg, "dt_t")
            self.path = Path(tb.cfg, o["tool_quat_raw"], o["tool_pos_raw"], raw["dt"] / 2.0 ** dtf)
            self.k = 0

        def packet(self, cold=False, load_q=False):
            uq, up, uw, uv = self.path.at(self.k)
            ctl = (1 if cold else 0) | (2 if load_q else 0)
            return [ctl] + list(self.q) + list(uq) + list(up) + list(uw) + list(uv), (uq, up, uw, uv)

        def expect(self, sp, cold=False, load_q=False):
            uq, up, uw, uv = sp
            qin = self.q_int if (self.virtual and not load_q) else self.q
            w = [0] * self.n if cold else self.warm
            a = lambda x: np.array([x], dtype=np.int64)  # noqa: E731
            o = self.servo.tick_raw(np.array(qin, dtype=np.int64), a(uq), a(up), a(uw), a(uv),
                                    np.array(w, dtype=np.int64))
            self.tb.ticks += 1
            qd = [int(x) for x in o["qd_raw"]]
            qn = [int(x) for x in o["q_next_raw"]]
            exp = qd + qn + [int(x) for x in np.ravel(o["ep_raw"])] + [int(x) for x in np.ravel(o["eo_raw"])] + \
                [int(o["flags"]), self.tb.ticks]
            self.warm = qd
            self.q_int = qn
            self.q = qn                        # plant: exact integration
            self.k += 1
            return exp

    def compare(tb, what, exp, got):
        if [sext(e) for e in exp] != got:
            bad = [i for i, (e, g) in enumerate(zip(exp, got)) if sext(e) != g]
            msg = f"{what}: words {bad} differ: model {exp} rtl {got}" if len(exp) == len(got) else \
                f"{what}: {len(got)} words, expected {len(exp)}"
            tb.errors.append(msg)
            tb.dut._log.error(msg)

    async def setup(dut):
        tb = TB(dut)
        await tb.reset()
        return tb

    async def bring_up(tb, robot, mode=0, sweeps=10, leak=5, virtual=False):
        raw = raw_from_chain(robots.load(robot), tb.cfg, mode=mode, sweeps=sweeps, leak=leak)
        await tb.configure(raw)
        ctrl = regs.CTRL_RUN | (regs.CTRL_VIRTUAL if virtual else 0)
        st, code, joint = await tb.commit(ctrl)
        assert st & regs.STATUS_CFG_OK and code == 0, (robot, hex(st), code, joint)
        tb.ticks = 0
        return Loop(tb, robot, raw, virtual)

    async def closed_loop(tb, lp, nt, cold_at=(), load_at=(0,)):
        for k in range(nt):
            cold, load_q = k in cold_at, k in load_at
            words, sp = lp.packet(cold, load_q)
            got = await tb.tick_io(words)
            compare(tb, f"{lp.robot} tick {k}", lp.expect(sp, cold, load_q), got)

    NT = int(os.environ.get("TS_NT", "15"))
    QUICK = os.environ.get("TS_QUICK", "0") == "1"      # Icarus: 2 sweeps in the loops, no cycle test
    SW_LOOP = 2 if QUICK else 10

    @cocotb.test()
    async def robots_closed_loop(dut):
        """Every robot in closed loop, random gaps; Panda in mode B, UR5 error-only, Stanford virtual."""
        tb = await setup(dut)
        tb.gaps(True)
        modes = {"puma560": 0, "ur5": regs.MODE_ERROR_ONLY, "panda": regs.MODE_ERR_B, "stanford": 0}
        for robot in ROBOTS:
            lp = await bring_up(tb, robot, mode=modes[robot], sweeps=SW_LOOP, virtual=(robot == "stanford"))
            await closed_loop(tb, lp, NT, cold_at=(NT // 2,))
            cnt = await tb.rd(regs.TICK_COUNT)
            assert cnt == NT, (robot, cnt)
            dut._log.info(f"{robot} mode {modes[robot]}: {NT} ticks")
        assert not tb.errors, f"{len(tb.errors)} mismatches, first: {tb.errors[0]}"

    @cocotb.test()
    async def back_to_back(dut):
        """Packets queued back to back (random tvalid/tready gaps): one answer per packet, in order.
        Open loop (the q sequence is the model's), so the packets can be sent before the answers."""
        tb = await setup(dut)
        tb.gaps(True)
        lp = await bring_up(tb, "puma560", sweeps=2)
        nt = max(3, NT // 3)
        exp, sent = [], []
        for k in range(nt):
            words, sp = lp.packet()
            sent.append(words)
            exp.append(lp.expect(sp))
        for w in sent:
            await tb.src.send(AxiStreamFrame(tdata=[x & 0xFFFFFFFF for x in w]))
        for k in range(nt):
            fr = await with_timeout(tb.snk.recv(), 4000, "us")
            compare(tb, f"back-to-back {k}", exp[k], [sext(x) for x in fr.tdata])
        await ClockCycles(dut.clk, 200)
        assert tb.snk.empty(), "extra output packet"
        assert await tb.rd(regs.TICK_COUNT) == nt
        assert not tb.errors, f"{len(tb.errors)} mismatches, first: {tb.errors[0]}"

    @cocotb.test()
    async def bad_config_and_malformed(dut):
        tb = await setup(dut)
        raw = raw_from_chain(robots.load("puma560"), tb.cfg)
        raw["joints"][2]["axis"][0] += 1 << (fw(tb.cfg, "quat_t")[1] - 4)   # not a unit vector
        res, _ = _model.commit_raw(tb.cfg, raw, NMAX)
        await tb.configure(raw)
        st, code, joint = await tb.commit(regs.CTRL_RUN)
        assert (code, joint) == (res["code"], res["joint"]) == (2, 2), (code, joint, res)
        assert st & regs.STATUS_CFG_ERR and not st & regs.STATUS_CFG_OK, hex(st)
        # TREADY stays low with RUN = 1 and a packet waiting
        lp_words = [0] + [0] * 6 + [0] * 13
        cocotb.start_soon(tb.src.send(AxiStreamFrame(tdata=lp_words)))
        for _ in range(300):
            await RisingEdge(dut.clk)
            assert not int(dut.s_axis_tready.value), "TREADY high without a valid configuration"
        # NJOINTS above NMAX: code 1
        raw2 = raw_from_chain(robots.load("puma560"), tb.cfg)
        raw2["n"] = NMAX + 1
        await tb.wr(regs.NJOINTS, NMAX + 1)
        st, code, joint = await tb.commit(regs.CTRL_RUN)
        assert (code, joint) == (1, 0xFF), (code, joint)
        await tb.reset()
        tb.src.clear()
        # malformed packets between good ticks: no state change, one answer each
        tb.gaps(True)
        lp = await bring_up(tb, "ur5", sweeps=2)
        await closed_loop(tb, lp, min(3, NT))
        for short in (True, False, True):
            words, _ = lp.packet()
            words = words[:-1] if short else words + [0x1234, 0x5678]
            got = await tb.tick_io(words)
            exp = [0] * (2 * lp.n + 6) + [STATUS_MALFORMED, tb.ticks]
            compare(tb, f"malformed ({'short' if short else 'long'})", exp, got)
        got = await tb.tick_io([0])   # one word with TLAST
        compare(tb, "malformed (1 word)", [0] * (2 * lp.n + 6) + [STATUS_MALFORMED, tb.ticks], got)
        await closed_loop(tb, lp, min(3, NT), load_at=())
        assert await tb.rd(regs.TICK_COUNT) == tb.ticks
        assert not tb.errors, f"{len(tb.errors)} mismatches, first: {tb.errors[0]}"

    @cocotb.test()
    async def reset_mid_tick(dut):
        tb = await setup(dut)
        lp = await bring_up(tb, "panda")
        words, _ = lp.packet()
        cocotb.start_soon(tb.src.send(AxiStreamFrame(tdata=[w & 0xFFFFFFFF for w in words])))
        for _ in range(400):
            await RisingEdge(dut.clk)
        assert int(dut.u_regs.in_status_busy.value) if hasattr(dut, "u_regs") else True
        await tb.reset()
        tb.src.clear()
        tb.snk.clear()
        st = await tb.rd(regs.STATUS)
        assert st == 0 and await tb.rd(regs.TICK_COUNT) == 0, hex(st)
        tb.gaps(False)
        lp = await bring_up(tb, "panda", sweeps=2)
        await closed_loop(tb, lp, min(5, NT))
        assert not tb.errors, f"{len(tb.errors)} mismatches, first: {tb.errors[0]}"

    @cocotb.test(skip=QUICK)       # Icarus: reported as skipped (too slow for 3 more runs)
    async def cycles_per_tick(dut):
        """TICK_CYCLES of PUMA 560 without gaps, 10 and 2 sweeps (first input word to last output word)."""
        tb = await setup(dut)
        tb.gaps(False)
        out = {}
        for sweeps in (10, 2):
            lp = await bring_up(tb, "puma560", sweeps=sweeps)
            cyc = set()
            for k in range(3):
                words, sp = lp.packet(load_q=False)
                got = await tb.tick_io(words)
                compare(tb, f"cycles sweeps {sweeps} tick {k}", lp.expect(sp), got)
                cyc.add(await tb.rd(regs.TICK_CYCLES))
            out[sweeps] = sorted(cyc)
            dut._log.info(f"PUMA 560, {sweeps} sweeps: TICK_CYCLES {sorted(cyc)}")
        f = os.environ.get("TS_CYCLES_FILE")
        if f:
            with open(f, "w") as fh:
                json.dump(out, fh)
        assert not tb.errors, f"{len(tb.errors)} mismatches, first: {tb.errors[0]}"

    @cocotb.test(skip=QUICK)       # Icarus: reported as skipped (too slow for 3 more runs)
    async def commit_during_tick(dut):
        """CTRL.COMMIT written while a tick runs: the tick ends with the old state (its answer matches
        the model), the commit runs after it (CFG_BUSY meanwhile), then warm start and virtual q are
        zero and the ticks match again."""
        tb = await setup(dut)
        tb.gaps(False)
        lp = await bring_up(tb, "puma560", sweeps=2)
        await closed_loop(tb, lp, 2)
        words, sp = lp.packet()
        await tb.src.send(AxiStreamFrame(tdata=[w & 0xFFFFFFFF for w in words]))
        for _ in range(60):
            await RisingEdge(dut.clk)
        await tb.wr(regs.CTRL, regs.CTRL_RUN | regs.CTRL_COMMIT)
        st = await tb.rd(regs.STATUS)
        assert st & regs.STATUS_BUSY and st & regs.STATUS_CFG_BUSY, hex(st)
        fr = await with_timeout(tb.snk.recv(), 2000, "us")
        compare(tb, "tick during the commit request", lp.expect(sp), [sext(x) for x in fr.tdata])
        for _ in range(2000):
            st = await tb.rd(regs.STATUS)
            if not st & regs.STATUS_CFG_BUSY:
                break
        assert st & regs.STATUS_CFG_OK, hex(st)
        lp.warm = [0] * lp.n
        lp.q_int = [0] * lp.n
        await closed_loop(tb, lp, 3, load_at=())
        assert not tb.errors, f"{len(tb.errors)} mismatches, first: {tb.errors[0]}"

    @cocotb.test()
    async def joint_write_during_commit(dut):
        """A joint-register write issued while a commit runs waits until the loader is done (the
        commit engine reads the register block's joint words directly, without a shadow): the
        commit succeeds with the words of its start and the ticks match the model's committed
        state; the register then reads the new word, and the next commit refuses it."""
        tb = await setup(dut)
        tb.gaps(False)
        raw = raw_from_chain(robots.load("puma560"), tb.cfg, sweeps=2)
        lp = await bring_up(tb, "puma560", sweeps=2)
        await closed_loop(tb, lp, 1)
        # joint 0's axis no longer a unit vector: the commit would refuse it (code 2, joint 0)
        bad = json.loads(json.dumps(raw))
        bad["joints"][0]["axis"][0] += 1 << (fw(tb.cfg, "quat_t")[1] - 4)
        res_bad, _ = _model.commit_raw(tb.cfg, bad, NMAX)
        assert (res_bad["code"], res_bad["joint"]) == (2, 0), res_bad
        addr = regs.joint_addr(0, "AXIS_X")
        word = bad["joints"][0]["axis"][0] & 0xFFFFFFFF
        await tb.wr(regs.CTRL, regs.CTRL_RUN | regs.CTRL_COMMIT)
        ev = tb.axil.init_write(addr, word.to_bytes(4, "little"))
        busy_while_pending = 0
        for _ in range(10000):
            st = await tb.rd(regs.STATUS)
            if ev.is_set():
                break
            busy_while_pending += bool(st & regs.STATUS_CFG_BUSY)
        else:
            raise AssertionError("the joint write never completed")
        assert int(ev.data.resp) == regs.RESP_OKAY
        st_answer = await tb.rd(regs.STATUS)
        st = st_answer
        while st & regs.STATUS_CFG_BUSY:
            st = await tb.rd(regs.STATUS)
        assert await tb.rd(addr) == word
        # the commit zeroes the warm start and the virtual q; its state is the old words'
        lp.warm = [0] * lp.n
        lp.q_int = [0] * lp.n
        tb.ticks = await tb.rd(regs.TICK_COUNT)
        if st & regs.STATUS_CFG_OK:
            await closed_loop(tb, lp, 2, load_at=())
        assert not tb.errors, f"ticks after the commit: {len(tb.errors)} mismatches, first: {tb.errors[0]}"
        assert st & regs.STATUS_CFG_OK, f"STATUS {st:#x} after the commit (CFG_OK expected)"
        assert not st_answer & regs.STATUS_CFG_BUSY, f"the joint write was answered during the commit ({st_answer:#x})"
        assert busy_while_pending, "the joint write did not meet the commit (CFG_BUSY never seen)"
        dut._log.info("joint write waited over %d STATUS reads with CFG_BUSY", busy_while_pending)
        st, code, joint = await tb.commit(regs.CTRL_RUN)
        assert (code, joint) == (2, 0) and st & regs.STATUS_CFG_ERR, (hex(st), code, joint)
        assert not tb.errors, f"{len(tb.errors)} mismatches, first: {tb.errors[0]}"

    #: the FLAGS register's bits (the model's status bits 0-9, 16, 17)
    FLAG_BITS = sum(f.mask for f in regs.GLOBAL["FLAGS"].fields)

    @cocotb.test()
    async def flags_and_virtual_switch(dut):
        """FLAGS against the packets' status words: after ticks, FLAGS is the OR of their flag
        bits; a far setpoint (0.2 m off the path) makes the model's limit flags rise, a fast one
        (31 m/s) its servo saturation flag; writing 1 clears flags, CTRL.CLEAR all.  CTRL.VIRTUAL
        switched between ticks (no commit): with the packet's q moved off the core's own q, each
        tick must take the q of its mode."""
        tb = await setup(dut)
        tb.gaps(False)
        lp = await bring_up(tb, "puma560", sweeps=2)
        n, seen = lp.n, 0

        async def tick(far=False, fast=False):
            """far: the setpoint 0.2 m off the path in x; fast: its linear velocity 31 m/s in x,
            so that U' + Kp E leaves vel_t (the law saturates the command)."""
            nonlocal seen
            words, sp = lp.packet()
            uq, up, uw, uv = sp
            if far:
                up = [up[0] + qz(0.2, tb.cfg, "pos_t")] + list(up[1:])
            if fast:
                uv = [qz(31.0, tb.cfg, "vel_t")] + list(uv[1:])
            sp = (uq, up, uw, uv)
            words = words[:1 + n] + list(uq) + list(up) + list(uw) + list(uv)
            exp = lp.expect(sp)
            got = await tb.tick_io(words)
            compare(tb, f"flags tick {lp.k - 1}{' (far)' if far else ''}{' (fast)' if fast else ''}", exp, got)
            flags = exp[2 * n + 6] & FLAG_BITS
            seen |= flags
            return flags

        for _ in range(2):
            await tick()
        assert await tb.rd(regs.FLAGS) == seen, (hex(await tb.rd(regs.FLAGS)), hex(seen))
        far = await tick(far=True)
        assert far & (regs.FLAGS_LIMIT_ACTIVE | regs.FLAGS_VLIMIT_ACTIVE), \
            f"the far setpoint should raise a limit flag in the model: {far:#x}"
        got = await tb.rd(regs.FLAGS)
        assert got == seen and got & far == far, (hex(got), hex(seen))
        await tb.wr(regs.FLAGS, far)                       # write 1 to clear those bits only
        assert await tb.rd(regs.FLAGS) == seen & ~far, hex(await tb.rd(regs.FLAGS))
        seen &= ~far
        fast = await tick(far=True, fast=True)
        assert fast & regs.FLAGS_OVF_SERVO, f"the fast setpoint should saturate the command in the model: {fast:#x}"
        assert await tb.rd(regs.FLAGS) == seen, (hex(await tb.rd(regs.FLAGS)), hex(seen))
        await tb.wr(regs.CTRL, regs.CTRL_RUN | regs.CTRL_CLEAR)
        assert await tb.rd(regs.FLAGS) == 0 and await tb.rd(regs.TICK_COUNT) == 0
        tb.ticks, seen = 0, 0
        # virtual on and off between ticks; the packet's q is moved off q_next by a few steps
        off = qz(0.002, tb.cfg, "angle_t")
        for virtual in (True, True, False, True, False):
            ctrl = regs.CTRL_RUN | (regs.CTRL_VIRTUAL if virtual else 0)
            await tb.wr(regs.CTRL, ctrl)
            assert await tb.rd(regs.CTRL) & regs.CTRL_VIRTUAL == (regs.CTRL_VIRTUAL if virtual else 0)
            lp.virtual = virtual
            lp.q = [x + off for x in lp.q]
            await tick()
        assert await tb.rd(regs.FLAGS) == seen and await tb.rd(regs.TICK_COUNT) == tb.ticks
        assert not tb.errors, f"{len(tb.errors)} mismatches, first: {tb.errors[0]}"


# ---- pytest side ------------------------------------------------------------------------------------
def sources(target: str, sim: str) -> list[str]:
    fs = [str(rtlparams.RTL / "ts_servo_core.v"), str(rtlparams.RTL / "ts_servo_regs.v")]
    for m in ("ts_core_commit", "ts_core_fk", "ts_core_law", "ts_core_solve"):
        for f in rtlparams.sources(m, target):
            if f not in fs:
                fs.append(f)
    if sim == "verilator":
        fs.append(str(tsbench.TB / MODULE / "public.vlt"))
    return fs


# make test runs the whole core under cocotb in the compact configuration (Verilator and Icarus,
# about 3 minutes each): the default configuration differs in widths only; its engines run on both
# simulators in their own benches (tb/ts_core_*), and the whole default core runs every make test
# in closed loop through the Verilator harness (tb/test_rtl_track.py, 5 chains, every output word
# compared with the model; make soak: 10,000 ticks each).  TS_CORE_DEFAULT=1 adds the default
# configuration on Verilator here (about 3 more minutes), as it ran until the harness tests came.
# The third run builds the compact core with its folded banks' operands in shift chains (CHAIN 1,
# the same bits and cycles) and runs fewer ticks.
CORE_RUNS = [("compact", "verilator", 0), ("compact", "icarus", 0), ("compact", "verilator", 1)]
if os.environ.get("TS_CORE_DEFAULT") == "1":
    CORE_RUNS.insert(0, ("default", "verilator", 0))


@pytest.mark.parametrize("cfg,sim,chain", CORE_RUNS)
def test_ts_servo_core(cfg, sim, chain):
    target = tsbench.target_for(sim) if cfg == "compact" else "GENERIC"
    p = {"NMAX": NMAX, "CONFIG": tsbench.CONFIGS.index(cfg), "TARGET": target,
         "TRIG_ROM": str(rtlparams.RTL / f"ts_trig_rom_{cfg}.mem"),
         "RECIP_ROM": str(rtlparams.RTL / f"ts_recip_rom_{cfg}.mem"),
         "ROTVEC_ROM": str(rtlparams.RTL / f"ts_rotvec_rom_{cfg}.mem"), "CHAIN": chain}
    build = f"{cfg}-{target}-{sim}" + ("-chain1" if chain else "")
    cyc_file = tsbench.BUILD / MODULE / f"cycles-{build}.json"
    cyc_file.parent.mkdir(parents=True, exist_ok=True)
    # ticks per robot: the simulators run about 10-40 kcycles/s (Verilator) and 2 kcycles/s (Icarus)
    nt = os.environ.get("TS_NT", "1" if sim == "icarus" else "2" if chain else "6")
    tsbench.run_bench(toplevel=MODULE, test_file=__file__, sources=sources(target, sim), parameters=p,
                      sim=sim, build_name=build,
                      env={"TS_CONFIG": cfg, "TS_NT": nt, "TS_CYCLES_FILE": str(cyc_file),
                           "TS_QUICK": "1" if sim == "icarus" else "0"})
    if cyc_file.exists():
        print(f"[{MODULE} {build}] PUMA 560 cycles per tick by sweeps: {cyc_file.read_text()}")
