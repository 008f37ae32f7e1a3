"""Bench of rtl/ts_servo_regs.v (generated from rtl/ts_servo_regs.rdl), the servo core's AXI4-Lite
register block, alone: cocotbext-axi's AxiLiteMaster plus a cycle-exact hand driver (any WSTRB
pattern, AW/W in either order, same-cycle priority checks) against regmodel.RegModel, with an AXI
protocol monitor (no X after reset, VALID held and payload stable until READY) in every test.

Variants (pytest): simulator x (NMAX, configuration) = {verilator, icarus} x {(4, compact), (8, default)}.
"""
from __future__ import annotations

import logging
import os
import random

import pytest

import rtlparams
import tsbench

MODULE = "ts_servo_regs"
#: (NMAX, configuration) of the variants
VARIANTS = ((5, "compact"), (8, "default"))
#: rounds of random writes over every rw register
ROUNDS = int(os.environ.get("TS_REGS_ROUNDS", "2"))

try:
    import cocotb
except ImportError:  # pragma: no cover
    cocotb = None

if cocotb is not None:
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge, ReadOnly, RisingEdge, Timer
    from cocotbext.axi import AxiLiteBus, AxiLiteMaster

    from regmodel import ID_VALUE, VERSION, M32, RegModel, port_base
    from tensor_servo import regs

    AXI_OUT = ("awready", "wready", "bvalid", "bresp", "arready", "rvalid", "rdata", "rresp")
    AXI_IN = ("awaddr", "awprot", "awvalid", "wdata", "wstrb", "wvalid", "bready", "araddr", "arprot",
              "arvalid", "rready")
    #: sim-time limit of every test (a hang fails instead of blocking the suite)
    TIMEOUT_US = 400

    class TB:
        """Clock, reset, model, monitors; the AXI side is either AxiLiteMaster (self.axil) or the
        hand driver (raw_* methods), never both in one test (both would drive the bus)."""

        def __init__(self, dut, master: bool):
            self.dut = dut
            self.nmax = int(os.environ["TS_NMAX"])
            self.cfg = os.environ["TS_CONFIG"]
            self.rng = random.Random(int(os.environ["TS_SEED"]))
            self.model = RegModel(self.cfg, self.nmax)
            self.cycle = 0              # rising edges since the bench started
            self.errors: list[str] = []
            self.pulses: dict[str, list[int]] = {"out_ctrl_commit": [], "out_ctrl_clear": []}
            # Verilator 5.006 + cocotb 1.8: a port first found by iterating the scope (as
            # AxiLiteBus.from_prefix does through dir()) ignores writes; one first looked up by
            # name works, also afterwards.  So look every port up by name first.
            for n in ["clk", "rst"] + ["s_axil_" + s for s in AXI_OUT + AXI_IN] + self.model_ports():
                getattr(dut, n)
            cocotb.start_soon(Clock(dut.clk, 10, units="ns").start())
            self.axil = None
            if master:
                self.axil = AxiLiteMaster(AxiLiteBus.from_prefix(dut, "s_axil"), dut.clk, dut.rst)
                self.axil.write_if.log.setLevel(logging.WARNING)
                self.axil.read_if.log.setLevel(logging.WARNING)
            else:
                for s in ("awvalid", "wvalid", "bready", "arvalid", "rready", "awaddr", "wdata", "wstrb",
                          "araddr", "awprot", "arprot"):
                    getattr(dut, "s_axil_" + s).value = 0
            self.drive_inputs({})
            dut.in_flags_set.value = 0
            dut.in_joint_hold.value = 0

        def model_ports(self) -> list[str]:
            return list(self.model.outputs()) + ["in_flags_set", "in_joint_hold"] + [
                "in_" + port_base(r, f, False) for r in regs.GLOBAL.values() for f in r.fields if f.access == "ro"]

        # ---- set-up ------------------------------------------------------------------------------
        async def pulse_reset(self, edges: int = 4) -> None:
            """rst high for `edges` rising edges, released at a falling edge; the model reset too."""
            dut = self.dut
            dut.rst.value = 1
            for _ in range(edges):
                await RisingEdge(dut.clk)
            await FallingEdge(dut.clk)
            dut.rst.value = 0
            self.model.reset()

        async def reset(self) -> None:
            await self.pulse_reset()
            cocotb.start_soon(self._count())
            cocotb.start_soon(self._monitor())
            await FallingEdge(self.dut.clk)

        async def _count(self) -> None:
            while True:
                await RisingEdge(self.dut.clk)
                self.cycle += 1

        async def _monitor(self) -> None:
            """AXI4-Lite slave rules and strobe pulses, sampled 1 ns before every rising edge (what
            the edge sees; both drivers change their signals earlier in the cycle)."""
            dut = self.dut
            prev = None
            while True:
                await FallingEdge(dut.clk)
                await Timer(4, "ns")
                await ReadOnly()
                cur = {}
                for n in AXI_OUT + ("awvalid", "wvalid", "bready", "arvalid", "rready"):
                    v = getattr(dut, "s_axil_" + n).value
                    if not v.is_resolvable:
                        self.errors.append(f"cycle {self.cycle}: s_axil_{n} = {v.binstr}")
                        cur[n] = None
                    else:
                        cur[n] = int(v)
                for n in self.pulses:
                    v = getattr(dut, n).value
                    if not v.is_resolvable:
                        self.errors.append(f"cycle {self.cycle}: {n} = {v.binstr}")
                    elif int(v):
                        self.pulses[n].append(self.cycle)
                if prev is not None:
                    # B and R: once VALID is up it stays, with a stable payload, until READY.
                    if prev["bvalid"] and not prev["bready"]:
                        if not cur["bvalid"] or cur["bresp"] != prev["bresp"]:
                            self.errors.append(f"cycle {self.cycle}: B dropped or changed before BREADY")
                    if prev["rvalid"] and not prev["rready"]:
                        if not cur["rvalid"] or cur["rdata"] != prev["rdata"] or cur["rresp"] != prev["rresp"]:
                            self.errors.append(f"cycle {self.cycle}: R dropped or changed before RREADY")
                prev = cur

        def check_monitor(self) -> None:
            assert not self.errors, "AXI/port monitor: " + "; ".join(self.errors[:5])

        # ---- core side ---------------------------------------------------------------------------
        def drive_inputs(self, values: dict) -> None:
            """Set the ro inputs (in_ ports of ro fields); unspecified ones keep the model's value."""
            for r in regs.GLOBAL.values():
                for f in r.fields:
                    if f.access == "ro":
                        n = "in_" + port_base(r, f, False)
                        v = values.get(n, self.model.inputs.get(n, 0)) & ((1 << f.width) - 1)
                        self.model.inputs[n] = v
                        getattr(self.dut, n).value = v

        def random_inputs(self) -> dict:
            out = {}
            for r in regs.GLOBAL.values():
                for f in r.fields:
                    if f.access == "ro":
                        out["in_" + port_base(r, f, False)] = self.rng.getrandbits(f.width)
            return out

        def check_outputs(self, where: str) -> None:
            for n, want in self.model.outputs().items():
                h = getattr(self.dut, n)
                v = h.value
                assert v.is_resolvable, f"{where}: {n} = {v.binstr}"
                mask = (1 << len(h)) - 1
                assert int(v) & mask == want & mask, f"{where}: {n} = 0x{int(v) & mask:X}, expected 0x{want & mask:X}"

        # ---- AxiLiteMaster accesses --------------------------------------------------------------
        async def write(self, addr: int, data: int, strb: int = 0xF) -> None:
            """Write through AxiLiteMaster (contiguous strobes only), check the response and apply
            the write to the model."""
            lo = (strb & -strb).bit_length() - 1
            hi = strb.bit_length()
            assert strb == ((1 << hi) - 1) & ~((1 << lo) - 1), "AxiLiteMaster writes contiguous bytes"
            payload = ((data >> (8 * lo)) & ((1 << (8 * (hi - lo))) - 1)).to_bytes(hi - lo, "little")
            resp = await self.axil.write((addr & ~3) + lo, payload)
            self.expect_write(addr, data, strb, int(resp.resp))

        def expect_write(self, addr: int, data: int, strb: int, resp: int) -> dict:
            want, pulses = self.model.write(addr, data, strb)
            assert resp == want, f"write 0x{addr:03X} strb {strb:04b}: resp {resp}, expected {want}"
            if pulses.get("out_ctrl_clear"):
                self.model.clear_flags()
            return pulses

        async def read(self, addr: int) -> int:
            r = await self.axil.read(addr, 4)
            data = int.from_bytes(r.data, "little")
            self.expect_read(addr, data, int(r.resp))
            return data

        def expect_read(self, addr: int, data: int, resp: int) -> None:
            want, wresp = self.model.read(addr)
            assert resp == wresp, f"read 0x{addr:03X}: resp {resp}, expected {wresp}"
            assert data == want, f"read 0x{addr:03X}: 0x{data:08X}, expected 0x{want:08X}"

        async def check_all(self, where: str) -> None:
            """Read every mapped register and compare; compare every out_ port."""
            for a in self.model.mapped_addrs():
                await self.read(a)
            self.check_outputs(where)

        # ---- hand driver -------------------------------------------------------------------------
        async def _send(self, valid, ready, delay: int) -> int:
            """Hold VALID from `delay` falling edges on until the handshake; returns its edge.
            READY is sampled just after the falling edge (it may depend on VALID)."""
            for _ in range(delay):
                await FallingEdge(self.dut.clk)
            valid.value = 1
            while True:
                await Timer(1, "ns")
                r = int(ready.value)
                await FallingEdge(self.dut.clk)
                if r:
                    valid.value = 0
                    return self.cycle

        async def _recv(self, valid, ready, payload, delay: int) -> tuple[int, list[int]]:
            """Wait for VALID, raise READY `delay` cycles later; returns (edge after which VALID was
            first seen, payload values at the handshake)."""
            while True:
                await Timer(1, "ns")
                if int(valid.value):
                    break
                await FallingEdge(self.dut.clk)
            first = self.cycle
            for _ in range(delay):
                await FallingEdge(self.dut.clk)
                await Timer(1, "ns")
            ready.value = 1
            got = [int(h.value) for h in payload]
            await FallingEdge(self.dut.clk)
            ready.value = 0
            return first, got

        async def raw_write(self, addr: int, data: int, strb: int, aw_delay: int = 0, w_delay: int = 0,
                            b_delay: int = 0) -> tuple[int, int]:
            """Write with AW and W raised after their own delays (either order); returns (bresp,
            edge after which BVALID was high).  Starts and ends at a falling edge."""
            dut = self.dut
            dut.s_axil_awaddr.value = addr
            dut.s_axil_awprot.value = self.rng.getrandbits(3)
            dut.s_axil_wdata.value = data
            dut.s_axil_wstrb.value = strb
            aw = cocotb.start_soon(self._send(dut.s_axil_awvalid, dut.s_axil_awready, aw_delay))
            w = cocotb.start_soon(self._send(dut.s_axil_wvalid, dut.s_axil_wready, w_delay))
            b = cocotb.start_soon(self._recv(dut.s_axil_bvalid, dut.s_axil_bready, [dut.s_axil_bresp], b_delay))
            await aw
            await w
            first, (resp,) = await b
            return resp, first

        async def raw_read(self, addr: int, ar_delay: int = 0, r_delay: int = 0) -> tuple[int, int]:
            """Read; returns (rdata, rresp)."""
            dut = self.dut
            dut.s_axil_araddr.value = addr
            dut.s_axil_arprot.value = self.rng.getrandbits(3)
            ar = cocotb.start_soon(self._send(dut.s_axil_arvalid, dut.s_axil_arready, ar_delay))
            r = cocotb.start_soon(self._recv(dut.s_axil_rvalid, dut.s_axil_rready,
                                             [dut.s_axil_rdata, dut.s_axil_rresp], r_delay))
            await ar
            _, (rdata, rresp) = await r
            return rdata, rresp

    async def setup(dut, master: bool = True) -> TB:
        tb = TB(dut, master)
        await tb.reset()
        dut._log.info("NMAX %d, config %s, seed %s", tb.nmax, tb.cfg, os.environ["TS_SEED"])
        return tb

    def random_strb(rng) -> int:
        """Non-zero contiguous byte strobe."""
        lo = rng.randrange(4)
        hi = rng.randrange(lo + 1, 5)
        return ((1 << hi) - 1) & ~((1 << lo) - 1)

    # ---- tests -------------------------------------------------------------------------------------
    @cocotb.test(timeout_time=TIMEOUT_US, timeout_unit="us")
    async def reset_values(dut):
        """Every register and every out_ port holds its RDL reset value; ID, HWCFG literal."""
        tb = await setup(dut)
        tb.check_outputs("after reset")
        await tb.check_all("after reset")
        assert await tb.read(regs.ID) == ID_VALUE
        cfg_index = ("default", "compact").index(tb.cfg)
        assert await tb.read(regs.HWCFG) == tb.nmax | (cfg_index << 8) | (VERSION << 16)
        # independent of the generated map: identity base rotation, 10 sweeps
        assert await tb.read(0x040) == 1 << (regs.FORMATS[tb.cfg]["quat_t"][0] - regs.FORMATS[tb.cfg]["quat_t"][1])
        assert (await tb.read(0x024) >> 8) & 0xFF == 10
        tb.check_monitor()

    @cocotb.test(timeout_time=TIMEOUT_US, timeout_unit="us")
    async def rw_registers_random(dut):
        """Random data with random (contiguous) byte strobes into every rw register, in random
        order, read back at once; the out_ ports follow; a final sweep finds no cross-talk."""
        tb = await setup(dut)
        addrs = tb.model.rw_addrs()
        n = 0
        for rnd in range(ROUNDS):
            tb.rng.shuffle(addrs)
            for a in addrs:
                await tb.write(a, tb.rng.getrandbits(32), random_strb(tb.rng))
                await tb.read(a)
                n += 1
            tb.check_outputs(f"round {rnd}")
        # full words, incl. values with the sign bit of the format set and clear
        for a in addrs:
            await tb.write(a, tb.rng.choice([0x80000000, 0x7FFFFFFF, M32, 0, tb.rng.getrandbits(32)]))
        await tb.check_all("after the full-word pass")
        dut._log.info("%d random writes over %d rw registers", n, len(addrs))
        tb.check_monitor()

    @cocotb.test(timeout_time=TIMEOUT_US, timeout_unit="us")
    async def wstrb_patterns_and_aw_w_order(dut):
        """Hand driver: all 16 WSTRB patterns (0000 included) on random rw registers, with AW
        before W, W before AW and both together, random B back-pressure."""
        tb = await setup(dut, master=False)
        addrs = tb.model.rw_addrs()
        orders = {"aw first": 0, "w first": 0, "together": 0}
        for rep in range(6):
            for strb in range(16):
                a = tb.rng.choice(addrs)
                data = tb.rng.getrandbits(32)
                d_aw, d_w = tb.rng.randrange(4), tb.rng.randrange(4)
                orders["together" if d_aw == d_w else ("aw first" if d_aw < d_w else "w first")] += 1
                resp, _ = await tb.raw_write(a, data, strb, d_aw, d_w, tb.rng.randrange(3))
                tb.expect_write(a, data, strb, resp)
                rdata, rresp = await tb.raw_read(a | tb.rng.randrange(4), tb.rng.randrange(3), tb.rng.randrange(3))
                tb.expect_read(a, rdata, rresp)
                tb.check_outputs(f"strb {strb:04b} at 0x{a:03X}")
        assert all(orders.values()), orders
        tb.check_monitor()

    @cocotb.test(timeout_time=TIMEOUT_US, timeout_unit="us")
    async def ro_registers(dut):
        """ro registers show the core inputs at the time of the read; writes to ro and constant
        registers answer SLVERR and change nothing."""
        tb = await setup(dut)
        ro = [r for r in regs.GLOBAL.values() if not r.writable]
        assert {r.name for r in ro} == {"STATUS", "CFG_ERROR", "TICK_COUNT", "TICK_CYCLES", "ID", "HWCFG"}
        for _ in range(8):
            tb.drive_inputs(tb.random_inputs())
            for r in ro:
                await tb.read(r.offset)
        # every field of every ro register reaches its bit positions (walking ones)
        for r in regs.GLOBAL.values():
            for f in r.fields:
                if f.access == "ro":
                    n = "in_" + port_base(r, f, False)
                    for b in range(f.width):
                        tb.drive_inputs({n: 1 << b})
                        await tb.read(r.offset)
                    tb.drive_inputs({n: 0})
        # writes to ro / constant registers
        for r in ro:
            for strb in (0xF, 0x1, 0x8):
                await tb.write(r.offset, tb.rng.getrandbits(32), strb)
        await tb.check_all("after writes to ro registers")
        tb.check_monitor()

    @cocotb.test(timeout_time=TIMEOUT_US, timeout_unit="us")
    async def sticky_flags(dut):
        """Core pulses set FLAGS bits (holes ignored); writing 1 clears exactly those bits within
        the strobed bytes; CTRL.CLEAR clears all; out_flags follows."""
        tb = await setup(dut)
        fl = regs.GLOBAL["FLAGS"]
        flag_mask = sum(f.mask for f in fl.fields)
        nset = len(dut.in_flags_set)
        for _ in range(24):
            for _ in range(tb.rng.randrange(1, 4)):
                bits = tb.rng.getrandbits(nset)
                await FallingEdge(dut.clk)
                dut.in_flags_set.value = bits
                await FallingEdge(dut.clk)
                dut.in_flags_set.value = 0
                tb.model.set_flags(bits)
            await FallingEdge(dut.clk)
            tb.check_outputs("after set pulses")
            await tb.read(fl.offset)
            op = tb.rng.randrange(3)
            if op == 0:
                await tb.write(fl.offset, tb.rng.getrandbits(32) & flag_mask, random_strb(tb.rng))
            elif op == 1:
                await tb.write(fl.offset, M32, tb.rng.choice([0x1, 0x2, 0x4, 0x3, 0x6, 0xF]))
            else:
                await tb.write(regs.CTRL, regs.CTRL_CLEAR | (tb.model.words[regs.CTRL] & (regs.CTRL_RUN | regs.CTRL_VIRTUAL)))
            await FallingEdge(dut.clk)
            tb.check_outputs("after clear")
            await tb.read(fl.offset)
        # a held set input keeps the flag set
        dut.in_flags_set.value = regs.FLAGS_OVF_JAC
        await tb.write(fl.offset, M32)
        tb.model.set_flags(regs.FLAGS_OVF_JAC)
        await tb.read(fl.offset)
        assert tb.model.words[fl.offset] & regs.FLAGS_OVF_JAC
        dut.in_flags_set.value = 0
        tb.check_monitor()

    async def _flag_after(tb, kind: str, offset: int, first_edge: int | None) -> tuple[int, int]:
        """Write FLAGS=1 (w1c) or CTRL.CLEAR with the hand driver, AW and W together; pulse
        in_flags_set[OVF_POS] for the single cycle ending at edge first_edge + offset (no pulse if
        first_edge is None).  Returns (FLAGS.OVF_POS afterwards, edge of the clear)."""
        dut = tb.dut
        bit = regs.FLAGS_OVF_POS
        # set the flag, then clear it with the operation under test
        await FallingEdge(dut.clk)
        dut.in_flags_set.value = bit
        await FallingEdge(dut.clk)
        dut.in_flags_set.value = 0
        start = tb.cycle
        pulse = None
        if first_edge is not None:
            target = start + first_edge + offset

            async def pulser():
                while tb.cycle < target - 1:
                    await FallingEdge(dut.clk)
                dut.in_flags_set.value = bit       # sampled at edge `target`
                await RisingEdge(dut.clk)
                await FallingEdge(dut.clk)
                dut.in_flags_set.value = 0
            pulse = cocotb.start_soon(pulser())
        if kind == "w1c":
            resp, brise = await tb.raw_write(regs.FLAGS, bit, 0xF)
            clear_edge = brise                     # registers update where BVALID rises
        else:
            resp, brise = await tb.raw_write(regs.CTRL, regs.CTRL_CLEAR, 0xF)
            # FLAGS clear at the edge that ends the out_ctrl_clear pulse (seen first after `brise`)
            clear_edge = tb.pulses["out_ctrl_clear"][-1] + 1
        assert resp == regs.RESP_OKAY
        if pulse is not None:
            await pulse
        for _ in range(3):
            await FallingEdge(dut.clk)
        rdata, _ = await tb.raw_read(regs.FLAGS)
        return (rdata & bit) != 0, clear_edge - start

    @cocotb.test(timeout_time=TIMEOUT_US, timeout_unit="us")
    async def sticky_set_clear_priority(dut):
        """A core set in the same cycle as a write-1-to-clear (or the CTRL.CLEAR pulse) wins; one
        cycle earlier the clear wins, one cycle later the set."""
        tb = await setup(dut, master=False)
        for kind in ("w1c", "clear"):
            flag, edge = await _flag_after(tb, kind, 0, None)
            assert not flag, f"{kind}: the clear did not clear"
            res = {}
            for off in (-1, 0, 1):
                flag, edge2 = await _flag_after(tb, kind, off, edge)
                assert edge2 == edge, f"{kind}: clear edge moved ({edge} -> {edge2}); the bench assumes a fixed timing"
                res[off] = flag
            dut._log.info("%s at relative edge %d: set pulse at -1/0/+1 -> flag %s", kind, edge, res)
            assert res == {-1: False, 0: True, 1: True}, f"{kind}: {res} (set must win in the same cycle)"
        tb.check_monitor()

    @cocotb.test(timeout_time=TIMEOUT_US, timeout_unit="us")
    async def strobes_one_cycle(dut):
        """COMMIT and CLEAR give exactly one one-cycle pulse per write of 1 (none with the byte not
        strobed or with 0), at the edge where BVALID rises; they read as 0; RUN/VIRTUAL are
        written by the same word."""
        tb = await setup(dut, master=False)
        expect = {"out_ctrl_commit": 0, "out_ctrl_clear": 0}
        for i in range(40):
            data = tb.rng.getrandbits(4)
            strb = tb.rng.choice([0xF, 0x1, 0xE, 0x3, 0x0])
            before = {n: len(v) for n, v in tb.pulses.items()}
            resp, brise = await tb.raw_write(regs.CTRL, data, strb, tb.rng.randrange(3), tb.rng.randrange(3),
                                            tb.rng.randrange(2))
            pulses = tb.expect_write(regs.CTRL, data, strb, resp)
            for _ in range(3):
                await FallingEdge(dut.clk)
            for n in expect:
                new = tb.pulses[n][before[n]:]
                if pulses.get(n):
                    assert new == [brise], f"{n}: pulses at {new}, expected one at edge {brise}"
                    expect[n] += 1
                else:
                    assert not new, f"{n}: unexpected pulse at {new} (data {data:04b}, strb {strb:04b})"
            rdata, rresp = await tb.raw_read(regs.CTRL)
            tb.expect_read(regs.CTRL, rdata, rresp)
            assert rdata & (regs.CTRL_COMMIT | regs.CTRL_CLEAR) == 0
            tb.check_outputs(f"CTRL write {i}")
        assert expect["out_ctrl_commit"] > 0 and expect["out_ctrl_clear"] > 0
        # back to back: consecutive writes give consecutive pulses, one each
        n0 = len(tb.pulses["out_ctrl_commit"])
        for _ in range(5):
            resp, _ = await tb.raw_write(regs.CTRL, regs.CTRL_COMMIT, 0x1)
            tb.expect_write(regs.CTRL, regs.CTRL_COMMIT, 0x1, resp)
        await FallingEdge(dut.clk)
        edges = tb.pulses["out_ctrl_commit"][n0:]
        assert len(edges) == 5 and len(set(edges)) == 5, edges
        tb.check_monitor()

    @cocotb.test(timeout_time=TIMEOUT_US, timeout_unit="us")
    async def slverr_map(dut):
        """Every word of the 4 KiB window: mapped ones answer OKAY on reads, unmapped ones (holes,
        joint blocks >= NMAX) SLVERR with data 0 on reads and writes; nothing changes."""
        tb = await setup(dut)
        mapped = set(tb.model.mapped_addrs())
        n_err = 0
        for a in range(0, 1 << regs.ADDR_WIDTH, 4):
            await tb.read(a)
            if a not in mapped:
                await tb.write(a, tb.rng.getrandbits(32), random_strb(tb.rng))
                n_err += 1
        # joint blocks just above NMAX (the first unmapped block) and the last word of the window
        for a in (regs.JOINT_BASE + regs.JOINT_STRIDE * tb.nmax, 0xFFC):
            if a not in mapped:
                await tb.write(a, M32)
                assert (await tb.axil.read(a, 4)).resp == regs.RESP_SLVERR
        await tb.check_all("after writes to unmapped words")
        dut._log.info("%d mapped words, %d unmapped written", len(mapped), n_err)
        assert n_err == 1024 - len(mapped)
        tb.check_monitor()

    @cocotb.test(timeout_time=TIMEOUT_US, timeout_unit="us")
    async def joint_hold(dut):
        """in_joint_hold (the core raises it while its commit and loader read the joint registers):
        a write to a joint block waits, BVALID low and every out_ port unchanged, for as long as it
        is high, and completes right after it falls; global writes (CTRL included) are not held."""
        tb = await setup(dut, master=False)
        rw = tb.model.rw_addrs()
        jaddrs = [a for a in rw if a >= regs.JOINT_BASE]
        gaddrs = [a for a in rw if a < regs.JOINT_BASE]
        assert jaddrs and regs.CTRL in gaddrs
        for rep in range(12):
            dut.in_joint_hold.value = 1
            g = regs.CTRL if rep == 0 else tb.rng.choice(gaddrs)
            data = tb.rng.getrandbits(32)
            resp, _ = await tb.raw_write(g, data, 0xF, tb.rng.randrange(3), tb.rng.randrange(3))
            tb.expect_write(g, data, 0xF, resp)
            tb.check_outputs(f"global write 0x{g:03X} while held")
            a = tb.rng.choice(jaddrs)
            data = tb.rng.getrandbits(32)
            wr = cocotb.start_soon(tb.raw_write(a, data, 0xF, tb.rng.randrange(3), tb.rng.randrange(3)))
            for _ in range(tb.rng.randrange(4, 24)):
                await FallingEdge(dut.clk)
                assert not int(dut.s_axil_bvalid.value), f"write 0x{a:03X} answered while held"
                tb.check_outputs(f"joint write 0x{a:03X} held")
            released = tb.cycle
            dut.in_joint_hold.value = 0
            resp, first = await wr
            assert first <= released + 1, f"write 0x{a:03X}: B {first - released} cycles after the release"
            tb.expect_write(a, data, 0xF, resp)
            tb.check_outputs(f"joint write 0x{a:03X} released")
            rdata, rresp = await tb.raw_read(a)
            tb.expect_read(a, rdata, rresp)
        tb.check_monitor()

    @cocotb.test(timeout_time=TIMEOUT_US, timeout_unit="us")
    async def reset_after_writes(dut):
        """A reset in the middle of a run: every register reads its reset value again although the
        joint words' read-back RAM keeps what was written before; then the first write of each
        joint word with a partial strobe reads back the reset value in its unstrobed bytes."""
        tb = await setup(dut)
        rw = tb.model.rw_addrs()
        jaddrs = [a for a in rw if a >= regs.JOINT_BASE]
        for rnd in range(2):
            for a in rw:
                if a != regs.CTRL:
                    await tb.write(a, tb.rng.getrandbits(32) | 0x01010101, 0xF)
            await tb.check_all(f"round {rnd}, before the reset")
            await FallingEdge(dut.clk)
            await tb.pulse_reset(3)
            await FallingEdge(dut.clk)
            tb.check_outputs(f"round {rnd}, after the reset")
            await tb.check_all(f"round {rnd}, after the reset")
            tb.rng.shuffle(jaddrs)
            for a in jaddrs:
                strb = tb.rng.choice([0x1, 0x2, 0x4, 0x8, 0x3, 0xC, 0x6, 0x7, 0xE])
                await tb.write(a, tb.rng.getrandbits(32), strb)
                await tb.read(a)
            await tb.check_all(f"round {rnd}, first writes after the reset")
        tb.check_monitor()

    @cocotb.test(timeout_time=TIMEOUT_US, timeout_unit="us")
    async def read_write_same_word(dut):
        """Hand driver: a read of a joint word whose AR handshake is 2 cycles before .. 2 cycles
        after the AW/W handshake of a write to the same word reads the old word when it is not
        later than the write, the new one when it is (as one register would)."""
        tb = await setup(dut, master=False)
        jaddrs = [a for a in tb.model.rw_addrs() if a >= regs.JOINT_BASE]
        for rep in range(40):
            a = tb.rng.choice(jaddrs)
            old = tb.rng.getrandbits(32)
            resp, _ = await tb.raw_write(a, old, 0xF)
            tb.expect_write(a, old, 0xF, resp)
            want_old, _ = tb.model.read(a)
            new = tb.rng.getrandbits(32)
            d = rep % 5 - 2                      # AR handshake minus AW/W handshake, in cycles
            wd, rd = max(0, -d), max(0, d)
            wr = cocotb.start_soon(tb.raw_write(a, new, 0xF, wd, wd))
            rdata, rresp = await tb.raw_read(a, rd)
            resp, _ = await wr
            tb.expect_write(a, new, 0xF, resp)
            want_new, _ = tb.model.read(a)
            want = want_new if d > 0 else want_old
            assert rresp == 0 and rdata == want, (f"0x{a:03X}, read {d:+d} cycles from the write: "
                                                  f"0x{rdata:08X}, old 0x{want_old:08X}, new 0x{want_new:08X}")
            rdata, rresp = await tb.raw_read(a)
            tb.expect_read(a, rdata, rresp)
        tb.check_monitor()

    @cocotb.test(timeout_time=TIMEOUT_US, timeout_unit="us")
    async def back_to_back(dut):
        """Many queued AxiLiteMaster writes and reads at once (back to back, reads and writes
        interleaved), with random stalls on every channel (AW/W skew, B/R back-pressure)."""
        tb = await setup(dut)

        def pauses(p):
            while True:
                yield tb.rng.random() < p

        for p in (0.0, 0.3):
            if p:
                tb.axil.write_if.aw_channel.set_pause_generator(pauses(p))
                tb.axil.write_if.w_channel.set_pause_generator(pauses(p))
                tb.axil.write_if.b_channel.set_pause_generator(pauses(p))
                tb.axil.read_if.ar_channel.set_pause_generator(pauses(p))
                tb.axil.read_if.r_channel.set_pause_generator(pauses(p))
            rw = tb.model.rw_addrs()
            ro = [r.offset for r in regs.GLOBAL.values() if not r.writable]
            writes = []
            for _ in range(48):
                a = tb.rng.choice(rw)
                if a == regs.CTRL:
                    continue
                d = tb.rng.getrandbits(32)
                writes.append((a, d, tb.axil.init_write(a, d.to_bytes(4, "little"))))
            reads = [(a, tb.axil.init_read(a, 4)) for a in (tb.rng.choice(ro) for _ in range(32))]
            t0 = tb.cycle
            for a, d, ev in writes:
                await ev.wait()
                tb.expect_write(a, d, 0xF, int(ev.data.resp))
            for a, ev in reads:
                await ev.wait()
                tb.expect_read(a, int.from_bytes(ev.data.data, "little"), int(ev.data.resp))
            dut._log.info("pause %.1f: %d writes + %d reads in %d cycles", p, len(writes), len(reads),
                          tb.cycle - t0)
            await tb.check_all(f"after back-to-back (pause {p})")
        tb.check_monitor()


# ---- pytest ---------------------------------------------------------------------------------------
def sources(sim: str) -> list[str]:
    src = rtlparams.sources(MODULE)
    if sim == "verilator":
        # run_bench makes clk, rst, in_* and out_* visible to cocotb; the AXI ports too:
        src.append(str(tsbench.TB / MODULE / "public.vlt"))
    return src


@pytest.mark.parametrize("sim", tsbench.SIMS)
@pytest.mark.parametrize("nmax,cfg", VARIANTS, ids=[f"n{n}-{c}" for n, c in VARIANTS])
def test_ts_servo_regs(nmax, cfg, sim):
    tsbench.run_bench(toplevel=MODULE, test_file=__file__, sources=sources(sim),
                      parameters={"NMAX": nmax, "CONFIG": ("default", "compact").index(cfg)}, sim=sim,
                      build_name=f"n{nmax}-{cfg}-{sim}", env={"TS_NMAX": str(nmax), "TS_CONFIG": cfg})
