"""``make demo`` (tensor_servo.demo): the Verilated core on PUMA 560, a short run in compact."""
from __future__ import annotations

import subprocess
import sys


def test_demo_runs_the_core_and_writes_a_png(tmp_path):
    png = tmp_path / "err.png"
    r = subprocess.run([sys.executable, "-m", "tensor_servo.demo", "--config", "compact", "--seconds", "0.1",
                        "-o", str(png)], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "core vs model: bit-identical over 100 ticks" in r.stdout, r.stdout
    assert "cycles per tick (TICK_CYCLES, 10 sweeps): " in r.stdout
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_demo_bad_argument_is_one_line(tmp_path):
    r = subprocess.run([sys.executable, "-m", "tensor_servo.demo", "--seconds", "0", "-o", str(tmp_path / "x.png")],
                       capture_output=True, text=True)
    assert r.returncode == 2
    assert r.stderr.strip().splitlines() == ["demo: error: --seconds: must be 0.01..60 (got 0)"]
    assert not (tmp_path / "x.png").exists()
