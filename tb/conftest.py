"""pytest configuration of the RTL benches: tb/ on sys.path (tsbench, rtlparams)."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
