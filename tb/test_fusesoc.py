"""The FuseSoC package (tensor-servo.core): every target runs through fusesoc and does its job.

lint / lint_core / lint_regs: verilator --lint-only -Wall through edalize (a primitive, the whole
core, the register block); sim / sim_compact: the self-checking
golden-vector bench of ts_quat_mul in Icarus (tb/fusesoc/tb_ts_quat_mul_golden.v) prints PASS; the
same bench stops with a non-zero exit on a corrupted expected word; synth: yosys synth_ecp5 maps the
compact quaternion product to at most 16 MULT18X18D (the issue's goal)."""
import re
import subprocess
import sys
from pathlib import Path

import pytest

import rtlparams

ROOT = Path(__file__).resolve().parents[1]
VLNV = "tensor-servo:servo:tensor-servo"
FUSESOC = str(Path(sys.executable).parent / "fusesoc")


def fusesoc(target: str, build_root: Path) -> subprocess.CompletedProcess:
    return subprocess.run([FUSESOC, "--cores-root", str(ROOT), "run", "--build-root", str(build_root),
                           "--target", target, VLNV], cwd=ROOT, capture_output=True, text=True, timeout=900)


@pytest.mark.parametrize("target", ["lint", "lint_core", "lint_regs"])
def test_lint_targets(target, tmp_path):
    p = fusesoc(target, tmp_path)
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-3000:]
    # the edalize verilator back end was really told -Wall and lint-only
    eda = next(tmp_path.glob(f"*/{target}-verilator/*.eda.yml")).read_text()
    assert "-Wall" in eda and "lint-only" in eda


@pytest.mark.parametrize("target,qw", [("sim", 27), ("sim_compact", 18)])
def test_sim_targets_pass_golden_vectors(target, qw, tmp_path):
    p = fusesoc(target, tmp_path)
    out = p.stdout + p.stderr
    assert p.returncode == 0, out[-3000:]
    assert re.search(rf"PASS 256 vectors \(Q_W={qw},", out), out[-3000:]


def test_golden_bench_fails_on_a_wrong_expected_word(tmp_path):
    src = (ROOT / "tb" / "fusesoc" / "quat_mul_compact.hex").read_text().splitlines()
    k = next(i for i, line in enumerate(src) if not line.startswith("//")) + 20
    last = src[k][-1]
    src[k] = src[k][:-1] + format(int(last, 16) ^ 0x2, "x")   # flip bit 1: the last bit of exp_z
    bad = tmp_path / "bad.hex"
    bad.write_text("\n".join(src) + "\n")
    files = [str(ROOT / "tb" / "fusesoc" / "tb_ts_quat_mul_golden.v")] + rtlparams.sources("ts_quat_mul", "GENERIC")
    vvp = tmp_path / "tb.vvp"
    top = "tb_ts_quat_mul_golden"
    subprocess.run(["iverilog", "-g2005", f"-I{ROOT / 'rtl'}", "-o", str(vvp), f"-P{top}.Q_W=18", f"-P{top}.Q_F=16",
                    f'-P{top}.VEC_FILE="{bad}"', *files], check=True)
    p = subprocess.run(["vvp", "-n", str(vvp)], capture_output=True, text=True, timeout=300)
    assert p.returncode != 0
    assert "FAIL vector 20" in p.stdout


def test_synth_target_maps_compact_quat_mul_to_16_dsp(tmp_path):
    p = fusesoc("synth", tmp_path)
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-3000:]
    log = next(tmp_path.glob("*/synth-yosys/yosys.log")).read_text()
    counts = re.findall(r"^\s+MULT18X18D\s+(\d+)\s*$", log, re.M)
    assert counts, "no MULT18X18D count in the yosys log"
    assert int(counts[-1]) <= 16
    assert re.search(r"^\s+TRELLIS_FF\s+\d+", log, re.M)
