#!/usr/bin/env python3
"""``make bench``: benchmark tables, peers measured in the same run.

    .venv/bin/python scripts/bench.py [--only kin ...] [--seconds S] [--no-write]

Sections (each prints a table and, unless --no-write, rewrites its section of docs/benchmarks.md):
  kin   FK of every frame + tool Jacobian per call: the C++ model (double, default, compact) vs
        Pinocchio C++ (computeFrameJacobian, LOCAL_WORLD_ALIGNED), same chains, same joint values
  ik    IK success and time on 1000 reachable targets per chain, near and random seeds: our servo
        (double, fixed) vs roboticstoolbox ik_LM, Pinocchio CLIK and ikpy (bench_ik.py; ~15 min)
  track steady tracking error of a circle and a figure-eight at 1 and 10 kHz, fixed vs float
        (bench_tracking.py)
  core  the servo core's tick (cycles of the Verilated core at its post-route Fmax) vs the same tick
        of the C++ model in double on one core of this machine (bench_tick.cpp)
"""
from __future__ import annotations

import argparse
import datetime
import os
import platform
import re
import subprocess
import sys
import sysconfig
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "model" / "python"))

from tensor_servo import robots  # noqa: E402
from tensor_servo.model import model_spec  # noqa: E402
from tensor_servo.rtl_core import tick_cycles  # noqa: E402

BUILD = ROOT / "build" / "bench"
DOC = ROOT / "docs" / "benchmarks.md"
KIN_CHAINS = ["puma560", "ur5", "stanford", "panda", "chain20"]


def cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def pin_prefix() -> Path:
    return Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix"


def build_bench(name: str, pinocchio: bool) -> Path:
    """Compile model/bench/<name>.cpp (-O3 -march=native) unless up to date."""
    exe = BUILD / name
    src = ROOT / "model" / "bench" / f"{name}.cpp"
    hdrs = [*(ROOT / "model" / "include" / "tensor_servo").glob("*.hpp"), *(ROOT / "model" / "bench").glob("*.hpp")]
    if exe.exists() and all(exe.stat().st_mtime > p.stat().st_mtime for p in [src, *hdrs]):
        return exe
    BUILD.mkdir(parents=True, exist_ok=True)
    cmd = ["g++", "-std=c++17", "-O3", "-march=native", "-DNDEBUG", "-w", "-I/usr/include/eigen3",
           f"-I{ROOT / 'model' / 'include'}"]
    if pinocchio:
        # Pinocchio header-only (its templates instantiated here, -O3 -march=native like ours);
        # the BOOST_MPL limits are the ones Pinocchio's CMake config exports.
        cmd += ["-DBOOST_MPL_LIMIT_LIST_SIZE=30", "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30",
                "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS", "-DBOOST_FUSION_INVOKE_MAX_ARITY=12",
                f"-I{pin_prefix() / 'include'}"]
    print("bench: compiling", exe.relative_to(ROOT), "(Pinocchio headers: about a minute)" if pinocchio else "", flush=True)
    subprocess.run(cmd + [str(src), "-o", str(exe)], check=True)
    return exe


def build_bench_kin() -> Path:
    return build_bench("bench_kin", pinocchio=True)


def write_spec_txt(name: str, path: Path) -> None:
    s = model_spec(robots.load(name))
    f = lambda v: " ".join(repr(float(x)) for x in v)  # noqa: E731
    lines = [str(len(s["joints"])), f(s["base_quat"]) + " " + f(s["base_xyz"]), f(s["tool_quat"]) + " " + f(s["tool_xyz"])]
    for j in s["joints"]:
        lines.append(" ".join([str(int(j["prismatic"])), f(j["origin_quat"]), f(j["origin_xyz"]), f(j["axis"]),
                               repr(j["scale"]), str(int(j["limited"])), repr(j["lower"]), repr(j["upper"])]))
    path.write_text("\n".join(lines) + "\n")


def bench_kin(seconds: float) -> str:
    exe = build_bench_kin()
    rows = []
    for name in KIN_CHAINS:
        spec = BUILD / f"{name}.txt"
        write_spec_txt(name, spec)
        out = subprocess.run([str(exe), str(spec), str(seconds)], check=True, capture_output=True, text=True).stdout
        res = {}
        for line in out.splitlines():
            parts = line.split()
            if len(parts) >= 3:
                res[parts[0]] = float(parts[1])  # min over 7 repeats, ns per call
        n = robots.load(name).n
        rows.append((name, n, res))
    hdr = ("| chain | DOF | Pinocchio ns/call | tservo double ns/call | double / Pinocchio | "
           "tservo default ns/call (calls/s) | tservo compact ns/call (calls/s) |")
    lines = [hdr, "|---|---|---|---|---|---|---|"]
    for name, n, r in rows:
        p, d, fd, fc = r["pinocchio"], r["tservo-double"], r["tservo-default"], r["tservo-compact"]
        lines.append(f"| {name} | {n} | {p:.0f} | {d:.0f} | {d / p:.2f} | {fd:.0f} ({1e9 / fd:,.0f}) | {fc:.0f} ({1e9 / fc:,.0f}) |")
    table = "\n".join(lines)
    ratios = [r["tservo-double"] / r["pinocchio"] for nm, _, r in rows if nm in ("puma560", "panda", "chain20")]
    six = [r for nm, n, r in rows if n == 6]
    verdict = [
        f"- Goal: the double model within 1.5x of Pinocchio (PUMA 560, Panda, chain20): worst ratio "
        f"{max(ratios):.2f} -> {'met' if max(ratios) <= 1.5 else 'NOT met'}.",
        f"- Goal: fixed-point model >= 500,000 FK+Jacobian per second for 6 DOF on one core: slowest 6-DOF "
        f"default {min(1e9 / r['tservo-default'] for r in six):,.0f}/s -> "
        f"{'met' if min(1e9 / r['tservo-default'] for r in six) >= 5e5 else 'NOT met'}.",
    ]
    return table + "\n\n" + "\n".join(verdict)


def bench_ik_section(seconds: float) -> str:
    from tensor_servo.bench_ik import bench_ik

    table, verdict = bench_ik(n_targets=int(os.environ.get("TS_BENCH_IK_TARGETS", "1000")))
    return table + "\n\n" + verdict


def bench_track_section(seconds: float) -> str:
    from tensor_servo.bench_tracking import bench_tracking

    return bench_tracking()


CORE_CHAINS = ["puma560", "panda"]     # 6 and 7 joints
CORE_SWEEPS = 2
CORE_GOAL_NS = 1000.0


CORE_RESULTS = ROOT / "build" / "synth" / "core_results.json"
RESOURCES = ROOT / "docs" / "resources.md"
#: a 6-joint tick line of docs/resources.md's generated core section (scripts/synth_core.py)
TICK_LINE = re.compile(r"^6-joint tick: (\d+) ns per tick \((\d+) cycles at [\d.]+ MHz, (LFE5U-\d+F) -6"
                       r"(, post-placement estimate)?[^)]*\), (\w+) configuration", re.M)
#: docs/resources.md's generated core section, the date of its run and the RTL it measured
#: (synth_core.rtl_note; sections written before it have no RTL)
SECTION = re.compile(r"<!-- BEGIN GENERATED core\b.*?-->(.*?)<!-- END GENERATED core -->", re.S)
SECTION_RUN = re.compile(r", run (\d{4}-\d\d-\d\d)(?:\.|, (RTL of commit [^.]+)\.)")


def core_fmax(results: Path = CORE_RESULTS, resources: Path = RESOURCES) -> tuple[dict, str]:
    """Fmax of the whole core per configuration, {cfg: (MHz, device text) or None}, and where it came
    from.  The results of a scripts/synth_core.py run on this machine (`results`) come first; without
    them (a fresh clone) the figures recorded in docs/resources.md's generated core section, whose
    6-joint tick lines give the Fmax to the precision of their ns (cycles / ns)."""
    import json

    out: dict = {"default": None, "compact": None}
    if results.exists():
        res = json.loads(results.read_text())
        for cfg in out:
            r = res.get(cfg) or {}
            if r.get("fmax"):
                out[cfg] = (min(r["fmax"]), r["device"] + " -6")
            elif r.get("fmax_placed"):     # routing did not finish: nextpnr's post-placement estimate
                out[cfg] = (r["fmax_placed"], r["device"] + " -6, post-placement estimate")
        where = results.relative_to(ROOT) if results.is_relative_to(ROOT) else results
        return out, f"{where}, a `scripts/synth_core.py` run on this machine"
    m = SECTION.search(resources.read_text()) if resources.exists() else None
    section = m.group(1) if m else ""
    for ns, cycles, dev, est, cfg in TICK_LINE.findall(section):
        if cfg in out and int(ns) > 0:
            out[cfg] = (int(cycles) / int(ns) * 1e3, dev + " -6" + (", post-placement estimate" if est else ""))
    run = SECTION_RUN.search(section)
    when = f" (run {run.group(1)}{', ' + run.group(2) if run.group(2) else ''})" if run else ""
    return out, f"docs/resources.md's generated core section{when}"


def bench_core(seconds: float) -> str:
    """The servo core's tick (cycles measured on the Verilated core in this run, at the post-route
    Fmax of scripts/synth_core.py) against the same tick of the C++ model in double on one core."""
    exe = build_bench("bench_tick", pinocchio=False)
    fmax, source = core_fmax()
    lines = [f"Tick: FK, Jacobian, servo law (A, feed-forward), {CORE_SWEEPS} descent sweeps. Core: cycles per tick "
             "(TICK_CYCLES) of the Verilated core measured in this run, at the worst-seed post-route Fmax of the "
             f"whole core from `scripts/synth_core.py` ({source}; not re-run by make bench), or "
             "nextpnr's post-placement estimate where routing did not finish. "
             "Peer: `model/bench/bench_tick.cpp`, the model's `servo_tick` in double, -O3 -march=native, one core, "
             "min / median ns over 7 repetitions.", "",
             "| config | chain | joints | core cycles/tick | core Fmax | core ns/tick | C++ double ns/tick (min / median) "
             "| core / double |", "|---|---|---|---|---|---|---|---|"]
    verdict = []
    for name in CORE_CHAINS:
        spec = BUILD / f"{name}.txt"
        write_spec_txt(name, spec)
        out = subprocess.run([str(exe), str(spec), str(CORE_SWEEPS), str(seconds)], check=True, capture_output=True,
                             text=True).stdout
        t = {p[0]: (float(p[1]), float(p[2])) for p in (ln.split() for ln in out.splitlines()) if len(p) >= 3}
        d_min, d_med = t["tick-double"]
        n = robots.load(name).n
        for cfg in ("default", "compact"):
            c = tick_cycles(robots.load(name), cfg, CORE_SWEEPS)
            fm = fmax[cfg]
            if fm is None:
                lines.append(f"| {cfg} | {name} | {n} | {c} | not placed | - | {d_min:.0f} / {d_med:.0f} | - |")
                if n == 6:
                    verdict.append(f"- Goal: 6-joint tick <= {CORE_GOAL_NS:.0f} ns in {cfg}: no post-route Fmax "
                                   f"(see docs/resources.md); {c} cycles would need {c / CORE_GOAL_NS * 1e3:.0f} MHz.")
                continue
            ns = c / fm[0] * 1e3
            lines.append(f"| {cfg} | {name} | {n} | {c} | {fm[0]:.1f} MHz ({fm[1]}) | {ns:.0f} | {d_min:.0f} / "
                         f"{d_med:.0f} | {ns / d_min:.2f} |")
            if n == 6:
                verdict.append(f"- Goal: 6-joint tick <= {CORE_GOAL_NS:.0f} ns ({cfg}, {fm[1]}): {ns:.0f} ns -> "
                               f"{'met' if ns <= CORE_GOAL_NS else 'MISSED'}; against double on this CPU: "
                               f"{ns / d_min:.2f}x its time -> {'faster' if ns < d_min else 'slower'}.")
    return "\n".join(lines) + "\n\n" + "\n".join(verdict)


SECTIONS = {"kin": bench_kin, "ik": bench_ik_section, "track": bench_track_section, "core": bench_core}


def replace_section(text: str, name: str, body: str) -> str:
    pat = re.compile(rf"(<!-- BEGIN {name} -->).*?(<!-- END {name} -->)", re.S)
    if not pat.search(text):
        return text.rstrip() + f"\n\n<!-- BEGIN {name} -->\n{body}\n<!-- END {name} -->\n"
    return pat.sub(lambda m: m.group(1) + "\n" + body + "\n" + m.group(2), text)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", nargs="*", choices=list(SECTIONS), default=list(SECTIONS))
    ap.add_argument("--seconds", type=float, default=1.0, help="time per measured case")
    ap.add_argument("--no-write", action="store_true", help="print only, leave docs/benchmarks.md alone")
    a = ap.parse_args()
    stamp = (f"Measured {datetime.date.today().isoformat()} on {cpu_name()} ({os.cpu_count()} cores), "
             f"command `make bench` (`.venv/bin/python scripts/bench.py`).")
    text = DOC.read_text() if DOC.exists() else "# Benchmarks\n"
    for name in a.only:
        body = stamp + "\n\n" + SECTIONS[name](a.seconds)
        print(f"\n== {name} ==\n{body}\n", flush=True)
        text = replace_section(text, name, body)
    if not a.no_write:
        DOC.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
