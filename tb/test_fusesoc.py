"""The FuseSoC package (tensor-servo.core): every target runs through fusesoc and does its job.

lint / lint_core / lint_regs: verilator --lint-only -Wall through edalize (a primitive, the whole
core, the register block); sim / sim_compact: the self-checking
golden-vector bench of ts_quat_mul in Icarus (tb/fusesoc/tb_ts_quat_mul_golden.v) prints PASS; the
same bench stops with a non-zero exit on a corrupted expected word; synth: yosys synth_ecp5 maps the
compact quaternion product to at most 16 MULT18X18D (the issue's goal).
sim_core / sim_core_compact: the whole core's self-checking bench (tb/fusesoc/tb_ts_servo_core_golden.v,
its script of register accesses and tick packets with the model's expected words from
scripts/gen_rtl_data.py) prints PASS in Icarus and in Verilator; it fails on a corrupted expected
output word and on a wrong BRESP expectation. synth_core: the compact core through yosys synth_ecp5
takes at most 72 MULT18X18D (the issue's LFE5U-45F budget)."""
import re
import subprocess
import sys
from pathlib import Path

import pytest

import rtlparams

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
from gen_rtl_data import CORE_OPS  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
VLNV = "tensor-servo:servo:tensor-servo"
FUSESOC = str(Path(sys.executable).parent / "fusesoc")


def fusesoc(target: str, build_root: Path, tool: str | None = None) -> subprocess.CompletedProcess:
    """`fusesoc run` of one target of the package (tool: the target's own when None)."""
    return subprocess.run([FUSESOC, "--cores-root", str(ROOT), "run", "--build-root", str(build_root),
                           "--target", target, *(["--tool", tool] if tool else []), VLNV],
                          cwd=ROOT, capture_output=True, text=True, timeout=900)


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


def synth_cells(target: str, tmp_path: Path) -> dict[str, int]:
    """Run a yosys target: the cell counts of the last `stat` in its log (the mapped design)."""
    p = fusesoc(target, tmp_path)
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-3000:]
    log = next(tmp_path.glob(f"*/{target}-yosys/yosys.log")).read_text()
    assert "Number of cells:" in log, "no stat in the yosys log"
    last = log[log.rindex("Number of cells:"):].split("\n\n", 1)[0]
    return {name: int(k) for name, k in re.findall(r"^\s+(\w+)\s+(\d+)\s*$", last, re.M)}


def test_synth_target_maps_compact_quat_mul_to_16_dsp(tmp_path):
    cells = synth_cells("synth", tmp_path)
    assert 0 < cells.get("MULT18X18D", 0) <= 16
    assert cells.get("TRELLIS_FF", 0) > 0


CORE_PASS = r"PASS \d+ operations, 17 output packets \(340 words\) equal to the model \(CONFIG={c}, NMAX=8\)"


@pytest.mark.parametrize("target,config,tool", [("sim_core", 0, "icarus"), ("sim_core_compact", 1, "icarus"),
                                                ("sim_core_compact", 1, "verilator")])
def test_sim_core_targets_match_the_model(target, config, tool, tmp_path):
    p = fusesoc(target, tmp_path, tool)
    out = p.stdout + p.stderr
    assert p.returncode == 0, out[-3000:]
    assert re.search(CORE_PASS.format(c=config), out), out[-3000:]


def _corrupt_core_script(kind: str) -> tuple[list[str], int]:
    """The compact core script with one operation made wrong: 'word' flips bit 3 of the 30th expected
    output word, 'bresp' expects OKAY from the write the core must refuse. -> lines, the op index."""
    src = (ROOT / "tb" / "fusesoc" / "core_puma560_compact.hex").read_text().splitlines()
    ops = [i for i, line in enumerate(src) if not line.startswith("//")]
    op = {name: format(code, "x") for name, code in CORE_OPS.items()}      # a line's first hex digit
    if kind == "word":
        recv = [i for i in ops if src[i][0] == op["RECV"]]
        k = recv[29]
        src[k] = src[k][:-1] + format(int(src[k][-1], 16) ^ 0x8, "x")
    else:
        k = next(i for i in ops if src[i][0] == op["WRITE_ERR"])
        src[k] = op["WRITE"] + src[k][1:]
    return src, ops.index(k)


@pytest.mark.parametrize("kind", ["word", "bresp"])
def test_core_bench_fails_on_a_wrong_expectation(kind, tmp_path):
    src, op = _corrupt_core_script(kind)
    (tmp_path / "bad.hex").write_text("\n".join(src) + "\n")
    for rom in (ROOT / "rtl").glob("*_compact.mem"):
        (tmp_path / rom.name).write_text(rom.read_text())
    top = "tb_ts_servo_core_golden"
    files = [str(ROOT / "tb" / "fusesoc" / f"{top}.v")] + rtlparams.sources("ts_servo_core", "GENERIC")
    vvp = tmp_path / "tb.vvp"
    subprocess.run(["iverilog", "-g2005", f"-I{ROOT / 'rtl'}", "-o", str(vvp), "-s", top, f"-P{top}.CONFIG=1",
                    f'-P{top}.SCRIPT="bad.hex"', *files], check=True)
    p = subprocess.run(["vvp", "-n", str(vvp)], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert p.returncode != 0, p.stdout[-2000:]
    assert f"FAIL op {op}" in p.stdout and "PASS" not in p.stdout, p.stdout[-2000:]
    assert ("got 0x" in p.stdout) if kind == "word" else ("answered BRESP 2" in p.stdout), p.stdout[-2000:]


def test_synth_core_target_fits_the_compact_budget(tmp_path):
    cells = synth_cells("synth_core", tmp_path)
    assert 0 < cells.get("MULT18X18D", 0) <= 72
    assert cells.get("DP16KD", 0) >= 1      # the register block's joint mirror
