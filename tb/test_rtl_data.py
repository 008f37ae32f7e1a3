"""The committed generated files equal what the model generates now:
rtl/ts_trig_rom_<config>.mem and rtl/ts_cfg_<config>.vh (scripts/gen_rtl_data.py) and the golden
vectors tb/golden/prim_<module>_<config>.npz (tensor_servo.golden_prims)."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rtlparams

ROOT = Path(__file__).resolve().parents[1]


def test_rtl_data_files_match_the_model():
    p = subprocess.run([sys.executable, str(ROOT / "scripts" / "gen_rtl_data.py"), "--check"], cwd=ROOT,
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stdout + p.stderr


@pytest.mark.parametrize("cfg", rtlparams.CONFIGS)
def test_trig_rom_is_the_model_table(cfg):
    """Independent reading of the .mem file: word k = {S_k, C_k} of _model.trig_table."""
    from tensor_servo import _model
    w, _ = rtlparams.fmt(cfg, "tab_t")
    words = [int(l, 16) for l in rtlparams.rom_file(cfg).read_text().splitlines() if l and not l.startswith("//")]
    s, c = _model.trig_table(cfg)
    m = (1 << w) - 1
    assert len(words) == len(s) == 1 << int(_model.formats(cfg)["TRIG_TABLE_BITS"])
    assert [((x >> w) & m) for x in words] == [int(v) & m for v in s]
    assert [(x & m) for x in words] == [int(v) & m for v in c]


@pytest.mark.parametrize("cfg", rtlparams.CONFIGS)
def test_golden_vectors_match_the_model(cfg):
    from tensor_servo import golden_prims
    problems = golden_prims.check(ROOT / "tb" / "golden", cfg)
    assert not problems, "\n".join(problems) + "\n(regenerate: python -m tensor_servo.golden_prims -o tb/golden)"


@pytest.mark.parametrize("cfg", rtlparams.CONFIGS)
def test_golden_files_small_and_cover_saturation(cfg):
    from tensor_servo import golden_prims
    for m in golden_prims.MODULES:
        p = golden_prims.path(ROOT / "tb" / "golden", m, cfg)
        assert p.stat().st_size < 64 * 1024, f"{p} is {p.stat().st_size} bytes"
        ins, exp = golden_prims.load(ROOT / "tb" / "golden", m, cfg)
        n = len(next(iter(ins.values())))
        assert n == 256
        if m != "sincos":   # sin/cos cannot saturate
            st = np.concatenate([v for k, v in exp.items() if k.startswith("status")])
            assert (st != 0).any(), f"{m}: no saturating vector in the golden file"
