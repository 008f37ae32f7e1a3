"""pytest configuration of the RTL benches: tb/ on sys.path (tsbench, rtlparams)."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

#: the longest runs of the suite (a Verilator build plus minutes of simulation each): started first,
#: so pytest-xdist spreads them over the workers instead of leaving them for the end
SLOW_FIRST = ("tb/ts_servo_core/", "tb/test_rtl_track.py", "tb/ts_core_law/", "tb/ts_core_solve/", "tb/ts_core_fk/",
              "tb/ts_core_commit/", "model/tests/test_hls")


def pytest_collection_modifyitems(session, config, items):
    def rank(item):
        nid = item.nodeid
        for k, pre in enumerate(SLOW_FIRST):
            if nid.startswith(pre):
                return k
        return len(SLOW_FIRST)
    items.sort(key=rank)   # stable: the order within each group is kept
