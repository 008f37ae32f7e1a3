"""The servo core's generated data files (formats header, solver and rotation-vector ROMs) are what
the model produces now (scripts/gen_core_data.py)."""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_core_data_files_are_current():
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "gen_core_data.py"), "--check"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_formats_header_matches_the_model():
    from tensor_servo import _model

    text = (ROOT / "rtl" / "ts_formats.vh").read_text()
    for cfg_idx, cfg in enumerate(("default", "compact")):
        for name, (w, i) in ((k, v) for k, v in _model.formats(cfg).items() if isinstance(v, tuple)):
            line = next(ln for ln in text.splitlines() if ln.startswith(f"localparam TS_{name[:-2].upper()}_W ="))
            vals = line.split("?")[1].split(";")[0].split(":")
            assert int(vals[cfg_idx]) == w, (cfg, name)
