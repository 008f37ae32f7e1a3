"""Shared machinery of the tensor-servo RTL benches (pytest side and cocotb side).

pytest side: ``run_bench`` builds and runs one cocotb bench through ``cocotb_test.simulator.run``
(Icarus or Verilator), with build directories under ``build/cocotb/`` and the Verilator run-time
library compiled once and linked into every bench (it is identical for all of them and is most of a
Verilator build's time).

cocotb side: clock/reset, ``stream`` (one vector per cycle with random valid gaps, outputs collected
on ``out_valid``, latency checked for every vector), integer helpers and the mismatch report.

Seeds: every bench draws fresh random vectors; the seed is ``TS_SEED`` if set, otherwise a new one,
and is printed (pytest side) and logged (cocotb side) so a failure can be replayed with
``TS_SEED=<seed> pytest ...``.
"""
from __future__ import annotations

import fcntl
import json
import hashlib
import os
import shutil
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TB = ROOT / "tb"
RTL = ROOT / "rtl"
BUILD = ROOT / "build" / "cocotb"
GOLDEN = TB / "golden"
SIMS = ("verilator", "icarus")
CONFIGS = ("default", "compact")

# Verilator C++ optimisation: the generated model at -O1 (its speed hardly matters next to the
# Python side of cocotb), the rarely-run parts at -O0; the run-time library is built once.
VERILATOR_OPT = ["OPT_FAST=-O1", "OPT_SLOW=-O0", "OPT_GLOBAL=-O1"]
_VL_RUNTIME = ("verilated", "verilated_dpi", "verilated_vpi", "verilated_threads")


def target_for(sim: str) -> str:
    """Multiplier implementation a datapath bench uses on a simulator: the ECP5 variant (explicit
    MULT18X18D, simulated with tb/sim/MULT18X18D.v) on Verilator, the inferred one on Icarus, where
    the primitive's 72 single-bit ports make it ~20x slower.  tb/ts_mul checks both variants on both
    simulators, and no datapath module depends on TARGET other than through ts_mul."""
    return "ECP5" if sim == "verilator" else "GENERIC"


def fresh_seed() -> int:
    s = os.environ.get("TS_SEED")
    return int(s) if s else int.from_bytes(os.urandom(4), "little")


def _verilator_cmd_prefix(mdir: Path, top: str) -> list[str]:
    import cocotb
    lib_dir = os.path.join(os.path.dirname(cocotb.__file__), "libs")
    return ["perl", shutil.which("verilator"), "-cc", "--exe", "-Mdir", str(mdir), "-DCOCOTB_SIM=1",
            "--top-module", top, "--vpi", "--public-flat-rw", "--prefix", "Vtop", "-o", top,
            "-LDFLAGS", f"-Wl,-rpath,{lib_dir} -L{lib_dir} -lcocotbvpi_verilator"]


def verilator_runtime() -> list[str]:
    """Object files of the Verilator run-time library, compiled once per Verilator version and flags
    (under a file lock, so parallel pytest workers share one build)."""
    import cocotb
    ver = subprocess.run(["verilator", "--version"], capture_output=True, text=True).stdout.strip()
    key = hashlib.sha1(" ".join([ver, cocotb.__version__] + VERILATOR_OPT).encode()).hexdigest()[:12]
    d = BUILD / "_verilator_runtime" / key
    d.mkdir(parents=True, exist_ok=True)
    objs = [str(d / f"{n}.o") for n in _VL_RUNTIME]
    with open(d / ".lock", "w") as lk:
        fcntl.flock(lk, fcntl.LOCK_EX)
        if not (d / ".done").exists():
            top = d / "vl_runtime_top.v"
            top.write_text("module vl_runtime_top(input wire clk); endmodule\n")
            verilator_cpp = os.path.join(os.path.dirname(cocotb.__file__), "share", "lib", "verilator",
                                         "verilator.cpp")
            subprocess.run(_verilator_cmd_prefix(d, "vl_runtime_top") + ["-Wno-fatal", verilator_cpp, str(top)],
                           check=True, capture_output=True)
            subprocess.run(["make", "-C", str(d), "-f", "Vtop.mk"] + VERILATOR_OPT
                           + [f"{n}.o" for n in _VL_RUNTIME], check=True, capture_output=True)
            (d / ".done").write_text("ok\n")
    return objs


def _runners():
    from cocotb_test.simulator import Icarus, Verilator

    class _Verilator(Verilator):
        def __init__(self, vlt: str, **kw):
            self._vlt = vlt
            super().__init__(**kw)

        def build_command(self):
            cmds = super().build_command()
            cmd = [c for c in cmds[0] if c != "--public-flat-rw"]
            cmds[0] = cmd[:-len(self.verilog_sources_flat) - 1] + [self._vlt] + cmd[-len(self.verilog_sources_flat) - 1:]
            return cmds

    return _Verilator, Icarus


#: The primitives' benches stream 10,000 fresh random vectors per run on Verilator; Icarus is 10-50x
#: slower on them, so its runs take ICARUS_NVEC (the same code path, a second simulator's check)
#: unless TS_NVEC is set.  Keeps make test within its time budget on 2 cores.
ICARUS_NVEC = 2500
ICARUS_NVEC_MODULES = ("ts_quat_mul", "ts_quat_rotate", "ts_sincos", "ts_joint_quat", "ts_screw_transport",
                       "ts_round_sat", "ts_mul", "ts_delay", "ts_resize")


def run_bench(*, toplevel: str, test_file: str, sources: list[str], parameters: dict, sim: str,
              build_name: str, env: dict | None = None, includes: list[str] | None = None) -> None:
    """Build and run the cocotb bench in ``test_file`` (its own module) on ``toplevel``."""
    _Verilator, _Icarus = _runners()

    test_dir = str(Path(test_file).resolve().parent)
    module = Path(test_file).stem
    sim_build = BUILD / Path(test_dir).name / build_name
    extra = dict(env or {})
    extra.setdefault("TS_SEED", str(fresh_seed()))
    if sim == "icarus" and toplevel in ICARUS_NVEC_MODULES and "TS_NVEC" not in os.environ:
        extra.setdefault("TS_NVEC", str(ICARUS_NVEC))
    print(f"[{toplevel} {build_name}] TS_SEED={extra['TS_SEED']}")
    kw = {}
    if sim == "verilator":
        waves = bool(int(os.environ.get("WAVES", "0")))
        make_args = list(VERILATOR_OPT)
        if not waves:
            objs = verilator_runtime()
            make_args += ["VM_GLOBAL_FAST=", "VM_GLOBAL_SLOW=", "LOADLIBES=" + " ".join(objs)]
        kw["make_args"] = make_args
        kw["compile_args"] = ["-Wno-fatal", "-Wno-TIMESCALEMOD"]
    else:
        kw["force_compile"] = True
    if sim == "verilator":
        # Only the top level's ports need VPI access: a config file makes them public instead of
        # --public-flat-rw on every signal, which for the larger benches multiplied the generated
        # C++ (VPI symbol tables) by ten and dominated the build time.
        vlt = Path(sim_build) / "cocotb_public.vlt"
        vlt.parent.mkdir(parents=True, exist_ok=True)
        vlt.write_text("`verilator_config\n" + "".join(
            f'public_flat_rw -module "{toplevel}" -var "{pat}"\n' for pat in ("clk", "rst", "in_*", "out_*")))
        kw["vlt"] = str(vlt)
    runner = _Verilator if sim == "verilator" else _Icarus
    runner(
        verilog_sources=sources,
        toplevel=toplevel,
        module=module,
        python_search=[test_dir, str(TB)],
        includes=[str(RTL)] + list(includes or []),
        parameters={k: (f'"{v}"' if isinstance(v, str) and not v.startswith('"') else v)
                    for k, v in parameters.items()},
        sim_build=str(sim_build),
        extra_env=extra,
        timescale="1ns/1ps",
        **kw,
    ).run()


# ---- cocotb side -------------------------------------------------------------------------------
def run_unit(module: str, test_file: str, p: dict, cfg: str, sim: str, fold: int = 1, nvec: int | None = None) -> None:
    """One bench run of a datapath unit with parameters p; fold > 1 runs its folded form
    (parameter FOLD, build directory ...-fold<FOLD>), nvec sets TS_NVEC."""
    from rtlparams import sources
    target = target_for(sim)
    if fold > 1:
        p = dict(p, FOLD=fold)
    env = {"TS_CONFIG": cfg, "TS_PARAMS": json.dumps(p)}
    if nvec:
        env["TS_NVEC"] = str(nvec)
    run_bench(toplevel=module, test_file=test_file, sources=sources(module, target), parameters=p, sim=sim,
              build_name=f"{cfg}-{target}-" + (f"fold{fold}" if fold > 1 else sim)
              + (f"-chain{p['CHAIN']}" if p.get("CHAIN") else ""), env=env)


def to_signed(u: int, w: int) -> int:
    """Two's-complement value of a w-bit pattern; 1-bit signals (flags) read as 0/1."""
    if w == 1:
        return u
    return u - (1 << w) if u >> (w - 1) else u


class Stream:
    """Drives named input ports one vector per ``ii`` cycles at most (with random valid gaps) and collects the named
    output ports on ``out_valid``; checks that every vector comes out exactly ``latency`` cycles after
    it went in and that no output is X/Z from reset on."""

    def __init__(self, dut, inputs: list[str], outputs: list[str], latency: int, rng,
                 p_valid: float = 0.75, clk: str = "clk", rst: str = "rst", unsigned: tuple = (),
                 ii: int = 1):
        self.dut = dut
        self.clk = getattr(dut, clk)
        self.rst = getattr(dut, rst)
        self.in_valid = dut.in_valid
        self.out_valid = dut.out_valid
        self.ins = [getattr(dut, n) for n in inputs]
        self.in_masks = [(1 << len(h)) - 1 for h in self.ins]
        self.outs = [getattr(dut, n) for n in outputs]
        # widths; 0 marks an output read as unsigned
        self.out_w = [0 if n in unsigned else len(h) for n, h in zip(outputs, self.outs)]
        self.out_names = outputs
        self.latency = latency
        self.rng = rng
        self.p_valid = p_valid
        self.ii = ii          # initiation interval: cycles from one input vector to the next, at least

    async def reset(self, cycles: int = 4) -> None:
        import cocotb
        from cocotb.clock import Clock
        from cocotb.triggers import FallingEdge
        cocotb.start_soon(Clock(self.clk, 10, units="ns").start())
        self.rst.value = 1
        self.in_valid.value = 0
        for h in self.ins:
            h.value = 0
        for _ in range(cycles):
            await FallingEdge(self.clk)
        self.rst.value = 0
        await FallingEdge(self.clk)
        for h in [self.out_valid] + self.outs:
            assert h.value.is_resolvable, f"{h._name} is {h.value.binstr} after reset"
        assert int(self.out_valid.value) == 0, "out_valid set after reset"

    async def run(self, rows: list[tuple]) -> list[tuple]:
        """rows: per vector a tuple of Python ints (signed allowed), one per input port.  Returns one
        tuple of signed ints per vector, in order."""
        from cocotb.triggers import FallingEdge
        n = len(rows)
        valid_draw = self.rng.random(4 * n + 16) < self.p_valid
        got: list[tuple] = []
        in_cycle: list[int] = []
        out_cycle: list[int] = []
        k = 0
        cyc = 0
        idle = 0
        while len(got) < n:
            # At the falling edge: outputs of the last rising edge are stable; set the next inputs.
            if int(self.out_valid.value):
                vals = []
                for h, w in zip(self.outs, self.out_w):
                    v = h.value
                    if not v.is_resolvable:
                        raise AssertionError(f"{h._name} is {v.binstr} with out_valid = 1")
                    vals.append(to_signed(int(v), w) if w else int(v))
                got.append(tuple(vals))
                out_cycle.append(cyc)
                idle = 0
            else:
                idle += 1
                if idle > self.latency + 8 and k >= n:
                    raise AssertionError(f"only {len(got)} of {n} vectors came out")
            if k < n and valid_draw[cyc % len(valid_draw)] and (not in_cycle or cyc - in_cycle[-1] >= self.ii):
                self.in_valid.value = 1
                for h, m, v in zip(self.ins, self.in_masks, rows[k]):
                    h.value = int(v) & m
                in_cycle.append(cyc)
                k += 1
            else:
                self.in_valid.value = 0
            await FallingEdge(self.clk)
            cyc += 1
        lat = [o - i for i, o in zip(in_cycle, out_cycle)]
        bad = [j for j, l in enumerate(lat) if l != self.latency]
        assert not bad, (f"latency {lat[bad[0]]} cycles for vector {bad[0]} (documented {self.latency}); "
                         f"{len(bad)} vectors off")
        return got


def report_mismatch(name: str, expected, got, inputs: dict, limit: int = 5) -> str:
    """Readable first mismatches (expected from the model, got from the RTL)."""
    import numpy as np
    expected = np.asarray(expected)
    got = np.asarray(got)
    bad = np.nonzero(np.any((expected != got).reshape(len(expected), -1), axis=1))[0]
    lines = [f"{name}: {len(bad)} of {len(expected)} vectors differ from the model"]
    for i in bad[:limit]:
        ins = ", ".join(f"{k}={np.asarray(v)[i].tolist()}" for k, v in inputs.items())
        lines.append(f"  vector {i}: {ins}: model {expected[i].tolist()} rtl {got[i].tolist()}")
    return "\n".join(lines)
