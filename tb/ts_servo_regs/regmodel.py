"""Reference model of the servo core's register block (rtl/ts_servo_regs.v) for the cocotb bench,
written from the documented behaviour (docs/registers.md) on top of the generated map
(tensor_servo.regs): what a read returns, what a write does and which core-side ports it changes.

Addresses are byte addresses; bits [1:0] are ignored.  A word is "mapped" when it is a global
register or a register of a joint block j < NMAX; everything else answers SLVERR (read data 0).
"""
from __future__ import annotations

from tensor_servo import regs

ID_VALUE = 0x54535256      # "TSRV", from the issue (independent of the generated map)
VERSION = 0x0001           # HWCFG.VERSION (0.1)
M32 = 0xFFFFFFFF


def byte_mask(strb: int) -> int:
    return sum(0xFF << (8 * i) for i in range(4) if (strb >> i) & 1)


def port_base(reg: regs.Reg, f: regs.Field, joint: bool) -> str:
    """Core-side port name (without in_/out_) of a field: <reg>[_<field>], joint_ prefix."""
    b = reg.name.lower() if (len(reg.fields) == 1 and reg.fields[0].name == "VALUE") else f"{reg.name}_{f.name}".lower()
    return ("joint_" + b) if joint else b


class RegModel:
    """Register contents (read words of the storage registers) and core-side inputs."""

    def __init__(self, cfg: str, nmax: int):
        self.cfg = cfg
        self.nmax = nmax
        self.cfg_index = regs.CONFIGS.index(cfg)
        self.inputs: dict[str, int] = {}      # in_ port -> value (ro fields)
        self.words: dict[int, int] = {}       # word address -> stored read word (rw / rw1c parts)
        self.reset()

    # ---- addressing ------------------------------------------------------------------------------
    def decode(self, addr: int):
        """(Reg, joint index or None) of a byte address, or None when unmapped."""
        a = addr & 0xFFC
        if a < regs.JOINT_BASE:
            for r in regs.GLOBAL.values():
                if r.offset == a:
                    return r, None
            return None
        j, off = divmod(a - regs.JOINT_BASE, regs.JOINT_STRIDE)
        if j >= self.nmax:
            return None
        for r in regs.JOINT.values():
            if r.offset == off:
                return r, j
        return None

    def mapped_addrs(self) -> list[int]:
        out = [r.offset for r in regs.GLOBAL.values()]
        out += [regs.joint_addr(j, n) for j in range(self.nmax) for n in regs.JOINT]
        return sorted(out)

    def rw_addrs(self) -> list[int]:
        """Addresses of registers with rw fields (not FLAGS/CTRL strobes only)."""
        return [a for a in self.mapped_addrs() if any(f.access == "rw" for f in self.decode(a)[0].fields)]

    # ---- state -----------------------------------------------------------------------------------
    def field_reset(self, f: regs.Field) -> int:
        """Reset of a field as bits of the 32-bit read word."""
        v = f.reset[self.cfg]
        if f.fmt:
            return regs.stored(v, self.cfg, f.fmt)
        return (v << f.lsb) & f.mask

    def reset(self) -> None:
        self.words = {}
        for a in self.mapped_addrs():
            r, _ = self.decode(a)
            w = 0
            for f in r.fields:
                if f.access in ("rw", "rw1c"):
                    w |= self.field_reset(f)
            self.words[a] = w

    def read(self, addr: int) -> tuple[int, int]:
        """(data, resp) of a read."""
        d = self.decode(addr)
        if d is None:
            return 0, regs.RESP_SLVERR
        r, j = d
        a = addr & 0xFFC
        w = 0
        for f in r.fields:
            if f.access in ("rw", "rw1c"):
                w |= self.words[a] & (M32 if f.fmt else f.mask)
            elif f.access == "ro":
                w |= (self.inputs.get("in_" + port_base(r, f, False), 0) << f.lsb) & f.mask
            elif f.access == "const":
                w |= (self.const_value(r, f) << f.lsb) & f.mask
        return w, regs.RESP_OKAY

    def const_value(self, r: regs.Reg, f: regs.Field) -> int:
        if r.name == "HWCFG":
            return {"NMAX": self.nmax, "CONFIG": self.cfg_index}.get(f.name, f.reset[self.cfg])
        return f.reset[self.cfg]

    def write(self, addr: int, data: int, strb: int) -> tuple[int, dict]:
        """(resp, pulses) of a write; pulses: strobe port -> value pulsed for one cycle."""
        d = self.decode(addr)
        if d is None:
            return regs.RESP_SLVERR, {}
        r, j = d
        if not r.writable:
            return regs.RESP_SLVERR, {}
        a = addr & 0xFFC
        m = byte_mask(strb)
        old = self.words[a]
        merged = (old & ~m) | (data & m)
        new = 0
        pulses = {}
        for f in r.fields:
            if f.access == "rw":
                new |= regs.stored(merged, self.cfg, f.fmt) if f.fmt else merged & f.mask
            elif f.access == "rw1c":
                new |= old & f.mask & ~(data & m)
            elif f.access == "strobe":
                pulses["out_" + port_base(r, f, False)] = ((data & m) & f.mask) >> f.lsb
        self.words[a] = new
        return regs.RESP_OKAY, pulses

    def set_flags(self, bits: int) -> None:
        """Core set pulses on in_flags_set (bits without a flag are ignored)."""
        fl = regs.GLOBAL["FLAGS"]
        mask = sum(f.mask for f in fl.fields)
        self.words[fl.offset] |= bits & mask

    def clear_flags(self) -> None:
        self.words[regs.GLOBAL["FLAGS"].offset] = 0

    # ---- core-side outputs -----------------------------------------------------------------------
    def outputs(self) -> dict[str, int]:
        """Expected value of every level out_ port (rw fields, flags); strobes are 0 when idle."""
        out: dict[str, int] = {}
        for r in regs.GLOBAL.values():
            for f in r.fields:
                if f.access == "rw":
                    w = regs.width(self.cfg, f.fmt) if f.fmt else f.width
                    out["out_" + port_base(r, f, False)] = (self.words[r.offset] >> f.lsb) & ((1 << w) - 1)
                elif f.access == "strobe":
                    out["out_" + port_base(r, f, False)] = 0
        fl = regs.GLOBAL["FLAGS"]
        out["out_flags"] = self.words[fl.offset]
        for r in regs.JOINT.values():
            for f in r.fields:
                w = regs.width(self.cfg, f.fmt) if f.fmt else f.width
                v = 0
                for j in range(self.nmax):
                    fv = (self.words[regs.joint_addr(j, r.name)] >> f.lsb) & ((1 << w) - 1)
                    v |= fv << (j * w)
                out["out_" + port_base(r, f, True)] = v
        return out
