"""scripts/lint_rtl.sh: every RTL module, with every parameter set it is used with, is clean under
verilator --lint-only -Wall and iverilog -g2005 -Wall."""
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_lint_rtl():
    p = subprocess.run(["bash", str(ROOT / "scripts" / "lint_rtl.sh"), "-j", "1"], cwd=ROOT,
                       capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stdout[-6000:] + p.stderr[-2000:]
    assert "jobs clean" in p.stdout
