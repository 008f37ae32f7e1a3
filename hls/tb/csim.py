#!/usr/bin/env python3
"""Build and run the HLS C-simulation with plain g++ (no Vitis needed).

    python hls/tb/csim.py                      the full check: NMAX = 8 (100 000 random ticks per
                                               configuration, golden vectors, bindings sequences)
                                               and NMAX = 24 (chain20)
    python hls/tb/csim.py --nmax 8 --ticks 1000 --config default

The testbench (hls/tb/tb_hls.cpp) and the top functions (hls/ts_servo_top.cpp) are compiled
against model/include, hls/ and Xilinx's ap_types headers shipped in the hls4ml wheel.  Binaries
are cached under build/hls/ by a hash of every source they depend on and of the flags.
"""
from __future__ import annotations

import argparse
import fcntl
import hashlib
import importlib.util
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
HLS = ROOT / "hls"
BUILD = ROOT / "build" / "hls"
CXXFLAGS = ["-std=c++17", "-O2", "-Wall", "-Wextra", "-Wno-unknown-pragmas",
            # Xilinx's ap_types headers warn under -Wall (as in the top-level Makefile)
            "-Wno-uninitialized", "-Wno-maybe-uninitialized"]
ALL_CHAINS = "puma560,ur5,panda,stanford,chain20"


def ap_types_dir() -> str:
    spec = importlib.util.find_spec("hls4ml")
    if spec is None or not spec.submodule_search_locations:
        raise SystemExit("csim: the hls4ml package (Xilinx ap_types headers) is not installed")
    return os.path.join(spec.submodule_search_locations[0], "templates", "vivado", "ap_types")


def _sources() -> list[Path]:
    return sorted(list(HLS.glob("*.h")) + list(HLS.glob("*.cpp")) + [HLS / "tb" / "tb_hls.cpp"] +
                  list((ROOT / "model" / "include" / "tensor_servo").glob("*.hpp")))


def build(nmax: int, cxx: str | None = None) -> Path:
    """The testbench binary for a joint bound NMAX (compiled once per source state).  Builds for
    large NMAX (few ticks) use -O1: they compile faster and run long enough."""
    cxx = cxx or os.environ.get("CXX", "g++")
    ap = ap_types_dir()
    flags = CXXFLAGS + (["-O1"] if nmax > 16 else []) + [f"-DTS_NMAX={nmax}", f"-I{ROOT / 'model' / 'include'}", f"-I{HLS}", "-isystem", ap]
    h = hashlib.sha256(" ".join([cxx] + flags).encode())
    for f in _sources():
        h.update(f.name.encode() + f.read_bytes())
    BUILD.mkdir(parents=True, exist_ok=True)
    exe = BUILD / f"tb_hls_n{nmax}_{h.hexdigest()[:12]}"
    with open(BUILD / f".lock_n{nmax}", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # concurrent test workers build once
        if exe.exists():
            return exe
        with tempfile.TemporaryDirectory(dir=BUILD) as tmp:
            objs = [Path(tmp) / "top.o", Path(tmp) / "tb.o"]
            procs = [subprocess.Popen([cxx, *flags, "-c", str(src), "-o", str(o)], stderr=subprocess.PIPE, text=True)
                     for src, o in zip([HLS / "ts_servo_top.cpp", HLS / "tb" / "tb_hls.cpp"], objs)]
            errs = [p.communicate()[1] for p in procs]
            if any(p.returncode for p in procs):
                raise RuntimeError("csim: compilation failed\n" + "\n".join(errs))
            tmp_exe = Path(tmp) / "tb_hls"
            subprocess.run([cxx, *map(str, objs), "-o", str(tmp_exe)], check=True)
            os.replace(tmp_exe, exe)
        for old in BUILD.glob(f"tb_hls_n{nmax}_*"):  # binaries of earlier source states
            if old != exe:
                old.unlink(missing_ok=True)
    return exe


def make_vectors(outdir: Path, chains: str = ALL_CHAINS) -> Path:
    spec = importlib.util.spec_from_file_location("ts_make_vectors", HLS / "tb" / "make_vectors.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    mod.main([str(outdir), "--chains", chains])
    return outdir


def run(exe: Path, vectors: Path, ticks: int, chains: str = ALL_CHAINS, config: str = "both",
        seed: int = 1, fault: int = 0) -> subprocess.CompletedProcess:
    return subprocess.run([str(exe), str(vectors), "--ticks", str(ticks), "--chains", chains, "--config", config,
                           "--seed", str(seed), "--fault", str(fault)], capture_output=True, text=True)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nmax", type=int, action="append", help="joint bound of the build (default: 8 and 24)")
    ap.add_argument("--ticks", type=int, default=100000, help="random ticks per configuration (NMAX 8)")
    ap.add_argument("--config", default="both", choices=["default", "compact", "both"])
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        vec = make_vectors(Path(tmp))
        rc = 0
        for nmax in args.nmax or [8, 24]:
            exe = build(nmax)
            big = nmax < 20
            r = run(exe, vec, args.ticks if big else max(1, args.ticks // 25),
                    ALL_CHAINS if big else "chain20,puma560", args.config, args.seed)
            sys.stdout.write(r.stdout)
            sys.stderr.write(r.stderr)
            rc |= r.returncode
    return rc


if __name__ == "__main__":
    sys.exit(main())
