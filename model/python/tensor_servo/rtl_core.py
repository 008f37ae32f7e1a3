"""The Verilated servo core (rtl/ts_servo_core.v) as a tick back end: ``tservo track --model rtl``.

The core is compiled by Verilator together with a small C++ driver (tb/harness/
ts_servo_core_harness.cpp) that speaks a line protocol on stdin/stdout (AXI4-Lite writes and
reads, one AXI4-Stream packet in and one out per tick).  This module builds that program once per
(configuration, NMAX) under ``build/vcore/`` (about a minute; rebuilt when an RTL file changes),
configures the core over its registers exactly as a host would (docs/programmers_guide.md), and
runs ticks:

    core = RtlServo(chain, "default", dt=1e-3, **servo_params)   # builds, configures, commits
    out = core.tick(q, U, V, qd_warm)   # -> servo.TickOut; out.raw["cycles"] is TICK_CYCLES
    core.close()

What the core is told is what the bit-accurate model ticks with: the register words are the
model's own quantised chain and parameters (``Servo.config_raw``), and each input packet holds the
model's quantisation of the float inputs (``Servo.inputs_raw``), so ``--model rtl`` and
``--model fixed`` give identical outputs (tb/test_rtl_track.py checks it).  The core keeps its
own warm start (its previous command, with the leak of MODE.WARM_LEAK); the back end checks that
the loop's warm start is that one, and sends COLD when the loop asks for none.
"""
from __future__ import annotations

import fcntl
import hashlib
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np

from . import _model, regs
from .chain import Chain
from .errors import InputError
from .model import formats
from .servo import Servo, TickOut, pose_to_quat_pos

ROOT = Path(__file__).resolve().parents[3]
RTL = ROOT / "rtl"
HARNESS = ROOT / "tb" / "harness" / "ts_servo_core_harness.cpp"
BUILD = ROOT / "build" / "vcore"
CONFIG_INDEX = {"default": 0, "compact": 1}
NMAX_DEFAULT = 8
NMAX_LIMIT = 60                 # joint blocks of the register map (0x100 + 0x40 j < 4 KiB)
LEAK_MAX = regs.MODE_WARM_LEAK_MASK >> regs.MODE_WARM_LEAK_SHIFT     # 4-bit field
SWEEPS_MAX = regs.MODE_SWEEPS_MASK >> regs.MODE_SWEEPS_SHIFT         # 8-bit field
IN_COLD = 1                     # input packet control word: bit 0 COLD (bit 1 LOAD_Q: virtual mode, unused here)


def core_nmax(n: int) -> int:
    """The NMAX the core is built with for an n-joint chain: 8 (the core's default) or n."""
    return max(NMAX_DEFAULT, n)


# ---- building the Verilated program ----------------------------------------------------------------

def _sources() -> list[Path]:
    return sorted([*RTL.glob("*.v"), *RTL.glob("*.vh"), *RTL.glob("*.mem"), HARNESS])


def _build_key(config: str, nmax: int, verilator: str) -> str:
    h = hashlib.sha1()
    ver = subprocess.run([verilator, "--version"], capture_output=True, text=True).stdout
    h.update(f"{config} {nmax} {ver}".encode())
    for f in _sources():
        h.update(f.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:12]


def harness_binary(config: str, nmax: int) -> Path:
    """Path of the Verilated core driver for (config, NMAX), built if missing (locked, so that
    parallel test workers build it once)."""
    if config not in CONFIG_INDEX:
        raise InputError("--config", f"unknown configuration {config!r} (default, compact)")
    if not (RTL / "ts_servo_core.v").exists() or not HARNESS.exists():
        raise InputError("--model rtl", f"the RTL sources are not in {ROOT} (the rtl model needs a source checkout)")
    verilator = shutil.which("verilator")
    if verilator is None:
        raise InputError("--model rtl", "verilator not found (make setup installs it)")
    key = _build_key(config, nmax, verilator)
    out = BUILD / f"{config}-n{nmax}-{key}"
    exe = out / "Vharness"
    BUILD.mkdir(parents=True, exist_ok=True)
    with open(BUILD / f".lock-{config}-n{nmax}", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if exe.exists():
            return exe
        roms = {p: RTL / f"ts_{n}_rom_{config}.mem" for p, n in
                (("TRIG_ROM", "trig"), ("RECIP_ROM", "recip"), ("ROTVEC_ROM", "rotvec"))}
        tmp = out.with_name(out.name + ".tmp")
        shutil.rmtree(tmp, ignore_errors=True)
        cmd = [verilator, "--cc", "--exe", "--build", "-j", str(os.cpu_count() or 2), "-O3", "--x-assign", "fast",
               "--x-initial", "fast", "-Wno-fatal",
               "-Wno-lint", "-Wno-style", "--top-module", "ts_servo_core", f"-I{RTL}", "-y", str(RTL),
               f"-GNMAX={nmax}", f"-GCONFIG={CONFIG_INDEX[config]}", '-GTARGET="GENERIC"',
               *[f'-G{p}="{f}"' for p, f in roms.items()], "-CFLAGS", "-O2", "-Mdir", str(tmp),
               "-o", "Vharness", str(RTL / "ts_servo_core.v"), str(HARNESS)]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0 or not (tmp / "Vharness").exists():
            last = (r.stderr or r.stdout).strip().splitlines()[-1:] or ["no output"]
            raise InputError("--model rtl", f"Verilator build failed: {last[0]}")
        shutil.rmtree(out, ignore_errors=True)
        tmp.rename(out)
    return exe


# ---- the running core ----------------------------------------------------------------------------

class CoreSim:
    """One Verilated core process: register access and ticks (the harness's line protocol)."""

    def __init__(self, config: str, nmax: int):
        self.config, self.nmax = config, nmax
        self.p = subprocess.Popen([str(harness_binary(config, nmax))], stdin=subprocess.PIPE,
                                  stdout=subprocess.PIPE, text=True, bufsize=1)

    def _cmd(self, line: str) -> list[str]:
        assert self.p.stdin and self.p.stdout
        self.p.stdin.write(line + "\n")
        self.p.stdin.flush()
        ans = self.p.stdout.readline().split()
        if not ans or ans[0] != "ok":
            raise InputError("--model rtl", f"core simulation: {' '.join(ans[1:]) or 'no answer'} ({line.split()[0]})")
        return ans[1:]

    def reset(self) -> None:
        self._cmd("reset")

    def write(self, addr: int, data: int) -> None:
        resp = int(self._cmd(f"w {addr} {data & 0xFFFFFFFF}")[0])
        if resp != 0:
            raise InputError("--model rtl", f"register write at {addr:#x} answered {['OKAY', 'EXOKAY', 'SLVERR', 'DECERR'][resp]}")

    def read(self, addr: int) -> int:
        return int(self._cmd(f"r {addr}")[0])

    def cycles(self, n: int) -> None:
        self._cmd(f"c {n}")

    def packet(self, words) -> tuple[int, list[int]]:
        """One input packet; the output packet's words (signed) and the cycles it took."""
        a = self._cmd(f"t {len(words)} " + " ".join(str(int(w) & 0xFFFFFFFF) for w in words))
        return int(a[0]), [int(x) for x in a[2:]]

    def close(self) -> None:
        if self.p.poll() is None:
            try:
                assert self.p.stdin
                self.p.stdin.write("q\n")
                self.p.stdin.close()
                self.p.wait(timeout=10)
            except (OSError, subprocess.TimeoutExpired):
                self.p.kill()


def register_writes(raw: dict, nmax: int) -> list[tuple[int, int]]:
    """The (address, word) writes that load a raw configuration (``commit_raw``'s dict) into the
    core, unused joint blocks left at their reset values; CTRL.COMMIT not included."""
    w = [(regs.NJOINTS, raw["n"]),
         (regs.MODE, raw["mode"] | (raw["sweeps"] << regs.MODE_SWEEPS_SHIFT)
          | (raw["warm_leak"] << regs.MODE_WARM_LEAK_SHIFT))]
    w += [(getattr(regs, k.upper()), raw[k]) for k in ("kp", "ko", "lchar", "klim", "dt")]
    for part in ("base", "tool"):
        w += [(getattr(regs, f"{part.upper()}_Q{c}"), raw[f"{part}_q"][i]) for i, c in enumerate("WXYZ")]
        w += [(getattr(regs, f"{part.upper()}_P{c}"), raw[f"{part}_p"][i]) for i, c in enumerate("XYZ")]
    for j, jd in enumerate(raw["joints"][:nmax]):
        a = lambda f: regs.joint_addr(j, f)  # noqa: E731
        w.append((a("JCFG"), jd["jcfg"]))
        w += [(a("ORIGIN_Q" + c), jd["qo"][i]) for i, c in enumerate("WXYZ")]
        w += [(a("ORIGIN_P" + c), jd["po"][i]) for i, c in enumerate("XYZ")]
        w += [(a("AXIS_" + c), jd["axis"][i]) for i, c in enumerate("XYZ")]
        w += [(a(f.upper()), jd[f]) for f in ("scale", "lower", "upper", "vmax", "mu")]
    return [(a, v & 0xFFFFFFFF) for a, v in w]


class RtlServo:
    """The servo tick of one chain run by the Verilated core (same contract as servo.Servo.tick,
    one task, setpoints in the root frame)."""

    def __init__(self, chain: Chain, config: str = "default", dt: float = 1e-3, nmax: int | None = None, **params):
        """nmax: the core's NMAX parameter, the joints it is built for (n..NMAX_LIMIT; None: core_nmax(n),
        the core's default 8 or n); each (config, NMAX) is Verilated once under build/vcore/."""
        if nmax is not None and not chain.n <= int(nmax) <= NMAX_LIMIT:
            raise InputError("--nmax", f"the core is built for NMAX joints, {chain.n} (this chain) to {NMAX_LIMIT} "
                                       f"(got {nmax})")
        if config not in CONFIG_INDEX:
            raise InputError("--config", f"the rtl model runs default or compact (got {config!r})")
        if params.get("setpoint_frame", -1) not in (-1, None):
            raise InputError("--setpoint-frame", "the core takes setpoints in the root frame (-1)")
        sw = params.get("sweeps")
        if sw is not None and not 1 <= int(sw) <= SWEEPS_MAX:
            raise InputError("--sweeps", f"the core runs 1..{SWEEPS_MAX} sweeps per tick (got {sw})")
        if int(params.get("warm_leak", 0)) > LEAK_MAX:
            raise InputError("--warm", f"the core's warm-start leak is 0..{LEAK_MAX}")
        if int(params.get("cg", 0)) != 0:
            raise InputError("cg", "the core has no conjugate-direction refinement (an offline IK option): use cg = 0")
        self.model = Servo(chain, config, dt=dt, **params)   # quantisation and config words
        try:
            self.raw = self.model._s.config_raw()
        except ValueError as e:
            raise InputError("--model rtl", str(e)) from None
        self.chain, self.config, self.n = chain, config, chain.n
        self.nmax = core_nmax(chain.n) if nmax is None else int(nmax)
        f = formats(config)
        self.lsb = {k: 2.0 ** (f[k][1] - f[k][0]) for k in ("qd_t", "angle_t", "perr_t", "rot_t")}
        self.sim = CoreSim(config, self.nmax)
        self.cold_policy = False
        self.cycles: list[int] = []
        self.commit()

    # -- configuration ---------------------------------------------------------------------------
    def set_warm(self, policy) -> None:
        """The loop's warm-start policy (track.warm_start): 'prev' (leak 0), 'zero' (COLD every
        tick) or a leak shift s; recommits the core if the leak changes."""
        if policy == "zero":
            self.cold_policy = True
            return
        s = 0 if policy == "prev" else int(policy)
        if not 0 <= s <= LEAK_MAX:
            raise InputError("--warm", f"the core's warm-start leak is 0..{LEAK_MAX} (got {s})")
        self.cold_policy = False
        if s != self.raw["warm_leak"]:
            self.raw["warm_leak"] = s
            self.commit()

    def commit(self) -> None:
        for a, v in register_writes(self.raw, self.nmax):
            self.sim.write(a, v)
        self.sim.write(regs.CTRL, regs.CTRL_COMMIT)
        for _ in range(1000):
            st = self.sim.read(regs.STATUS)
            if not st & regs.STATUS_CFG_BUSY:
                break
            self.sim.cycles(100)
        else:
            raise InputError("--model rtl", "the core's commit did not finish (CFG_BUSY stuck)")
        if not st & regs.STATUS_CFG_OK:
            e = self.sim.read(regs.CFG_ERROR)
            code, joint = e & 0xFF, (e >> 8) & 0xFF
            where = "" if joint == 0xFF else f" at joint {joint}"
            # the model's commit step on the same words names the field (the same checks, in order)
            res, _ = _model.commit_raw(self.config, self.raw, self.nmax)
            why = f"{res['field']}: {res['message']}" if res["code"] else "the model accepts these words"
            raise InputError("chain", f"the core refused the configuration: CFG_ERROR {code}{where} ({why})")
        self.sim.write(regs.CTRL, regs.CTRL_RUN | regs.CTRL_CLEAR)
        self.prev_qd = np.zeros(self.n, dtype=np.int64)

    # -- ticks ---------------------------------------------------------------------------------------
    def expected_warm(self) -> np.ndarray:
        s = self.raw["warm_leak"]
        return self.prev_qd - (self.prev_qd >> s) if s else self.prev_qd.copy()

    def tick(self, q, U, V=None, qd_warm=None) -> TickOut:
        n = self.n
        uq, up = pose_to_quat_pos(np.asarray(U, dtype=float))
        V = np.zeros(6) if V is None else np.asarray(V, dtype=float).reshape(6)
        w = np.zeros(n) if qd_warm is None else np.asarray(qd_warm, dtype=float)
        try:
            ir = self.model._s.inputs_raw(np.asarray(q, dtype=float), uq[None], up[None], V[None, :3].copy(),
                                          V[None, 3:].copy(), w)
        except ValueError as e:
            raise InputError("tick", str(e)) from None
        warm = np.asarray(ir["warm"], dtype=np.int64)
        cold = self.cold_policy or (not warm.any() and self.prev_qd.any())
        if not cold and not np.array_equal(warm, self.expected_warm()):
            raise InputError("qd_warm", "the core's warm start is its previous command with the committed "
                                        f"leak (MODE.WARM_LEAK = {self.raw['warm_leak']}); got another one")
        words = [IN_COLD if cold else 0, *ir["q"], *np.ravel(ir["uq"]), *np.ravel(ir["up"]),
                 *np.ravel(ir["uw"]), *np.ravel(ir["uv"])]
        cyc, out = self.sim.packet(words)
        if len(out) != 2 * n + 8:
            raise InputError("--model rtl", f"the core answered {len(out)} words, expected {2 * n + 8}")
        qd = np.array(out[:n], dtype=np.int64)
        qn = np.array(out[n:2 * n], dtype=np.int64)
        ep = np.array(out[2 * n:2 * n + 3], dtype=np.int64)
        eo = np.array(out[2 * n + 3:2 * n + 6], dtype=np.int64)
        status = out[2 * n + 6] & 0xFFFFFFFF
        self.prev_qd = qd
        self.cycles.append(cyc)
        raw = {"qd": qd, "q_next": qn, "ep": ep, "eo": eo, "status": status, "tick_count": out[2 * n + 7],
               "cycles": cyc}
        return TickOut(qd * self.lsb["qd_t"], qn * self.lsb["angle_t"], ep * self.lsb["perr_t"],
                       eo * self.lsb["rot_t"], np.zeros(0), status | int(ir["flags"]), raw)

    def close(self) -> None:
        self.sim.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def tick_cycles(chain: Chain, config: str, sweeps: int, ticks: int = 5) -> int:
    """TICK_CYCLES of the Verilated core for a chain (median over a few ticks from a mid-range
    configuration towards a pose 0.02 rad away in every joint; the sequencer's cycle count depends
    on n and the sweeps only)."""
    from .track import relative_poses

    lo = np.where(np.isfinite(chain.lower), chain.lower, -1.0)
    hi = np.where(np.isfinite(chain.upper), chain.upper, 1.0)
    q = 0.5 * (lo + hi) + 0.1 * (hi - lo)
    U = relative_poses(chain, (q + 0.02)[None])[0]
    with RtlServo(chain, config, dt=1e-3, sweeps=sweeps) as core:
        return int(np.median([core.tick(q, U, np.zeros(6), None).raw["cycles"] for _ in range(ticks)]))
