"""HLS C++ (hls/): bit-exact with the model in C-simulation, synthesisable subset, generated tables.

The C-simulation (hls/tb/tb_hls.cpp, plain g++ against Xilinx's ap_types headers) compares every
output word of the six top functions with the bit-accurate model (fx) on the committed golden
vectors, on servo sequences computed through the Python bindings, and on 100 000 random ticks per
configuration (in-range, limit, singular and saturating stress ticks); its exit status is 0 only
when every word matched and every coverage requirement held.
"""
import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("ts_csim", ROOT / "hls" / "tb" / "csim.py")
csim = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(csim)

_mv_spec = importlib.util.spec_from_file_location("ts_make_vectors", ROOT / "hls" / "tb" / "make_vectors.py")
_mv = importlib.util.module_from_spec(_mv_spec)
_mv_spec.loader.exec_module(_mv)
VARIANTS = _mv.VARIANTS  # servo set-ups of the bindings sequences

TICKS = 100_000
CHAINS8 = ["puma560", "ur5", "panda", "stanford"]


@pytest.fixture(scope="module")
def vectors(tmp_path_factory):
    return csim.make_vectors(tmp_path_factory.mktemp("hls_vectors"))


def ok_lines(out: str) -> list[str]:
    return [ln.strip() for ln in out.splitlines() if ln.startswith("  ok")]


def check_run(r: subprocess.CompletedProcess, configs: list[str], chains: list[str], ticks: int):
    out = r.stdout
    assert r.returncode == 0, out[-4000:] + r.stderr[-2000:]
    m = re.search(r"summary: (\d+) packets compared, (\d+) mismatches, (\d+) failed requirements", out)
    assert m and int(m.group(1)) > 0 and m.group(2) == "0" and m.group(3) == "0", out[-3000:]
    oks = ok_lines(out)
    for cfg in configs:
        assert any(f"tables {cfg}:" in ln for ln in oks)
        for ch in chains:
            assert any(ln.startswith(f"ok    golden {ch} {cfg}: 64 samples") for ln in oks), (ch, cfg)
            seq = 30 * len(VARIANTS)  # make_vectors' default --servo-ticks per set-up
            assert any(ln.startswith(f"ok    bindings {ch} {cfg}: {seq} servo ticks") for ln in oks), (ch, cfg)
        assert any(ln.startswith(f"ok    random {cfg}: {ticks} ticks x 3 kernels bit-exact") for ln in oks), cfg
        for req in ("saturation coverage", "limit coverage", "singular coverage", "refusals"):
            assert any(ln.startswith(f"ok    {req} {cfg}") for ln in oks), (req, cfg)


@pytest.mark.slow
@pytest.mark.parametrize("config", ["default", "compact"])
def test_csim_bit_exact_nmax8(vectors, config):
    """ts_{kin,solve,servo}_top[_compact] (NMAX = 8) equal the model word for word."""
    exe = csim.build(8)
    check_run(csim.run(exe, vectors, TICKS, ",".join(CHAINS8 + ["chain20"]), config), [config], CHAINS8, TICKS)


@pytest.mark.slow
def test_csim_bit_exact_nmax24_chain20(vectors):
    """A 24-joint build runs the 20-joint example (golden vectors, bindings sequences, random ticks)."""
    exe = csim.build(24)
    check_run(csim.run(exe, vectors, 3000, "chain20,puma560", "both"), ["default", "compact"], ["chain20", "puma560"], 3000)


def test_csim_comparisons_can_fail(vectors, tmp_path):
    """The comparisons can fail: a corrupted expected word, or a model that sees another chain."""
    exe = csim.build(8)
    r = csim.run(exe, vectors, 200, "puma560", "default", fault=50)
    assert r.returncode == 1 and "FAIL  random default: 200 ticks" in r.stdout, r.stdout[-2000:]
    assert "summary: " in r.stdout and " 12 mismatches" in r.stdout  # 4 faulty ticks x 3 kernels
    bad = tmp_path / "vectors"
    bad.mkdir()
    for f in vectors.iterdir():
        text = f.read_text()
        if f.name == "chain_puma560_default.txt":  # one raw constant off by one LSB
            text = re.sub(r"^(scale 6 )(-?\d+)", lambda m: m.group(1) + str(int(m.group(2)) + 1), text, flags=re.M)
        (bad / f.name).write_text(text)
    r = csim.run(exe, bad, 200, "puma560", "default")
    # the bindings sequences were computed by the real model: they must now disagree with the
    # kernels fed the altered chain (the random ticks feed both sides the same altered chain)
    assert r.returncode == 1 and "FAIL  bindings puma560 default" in r.stdout, r.stdout[-2000:]
    assert "ok    random default: 200 ticks" in r.stdout


def test_tables_are_generated_from_the_model():
    r = subprocess.run([sys.executable, str(ROOT / "hls" / "gen_tables.py"), "--check"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_lint_clean():
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "hls_lint.py")], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    m = re.search(r"clean \(.*; (\d+) project functions reachable, (\d+) loops checked\)", r.stdout)
    assert m and int(m.group(1)) > 30 and int(m.group(2)) > 30, r.stdout


def test_lint_reports_every_violation_kind():
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "hls_lint.py"), "--source",
                        str(ROOT / "hls" / "tb" / "lint_bad.cpp"), "--top", "bad_top"], capture_output=True, text=True)
    assert r.returncode == 1, r.stdout + r.stderr
    for kind in ("dynamic-memory", "std-library", "math-library", "runtime-static", "indirect-call", "recursion",
                 "loop-bound", "source-token"):
        assert re.search(rf"^{kind}: ", r.stdout, re.M), (kind, r.stdout)
    assert "'while' loop" in r.stdout and "loop bound 'i < n'" in r.stdout
