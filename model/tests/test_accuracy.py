"""The bit-accurate model against Pinocchio on every example chain: the published bounds hold,
the default configuration meets the accuracy goals, and docs/numerics.md is current."""
import importlib.util
from pathlib import Path

import pytest

from tensor_servo import robots
from tensor_servo.accuracy import BOUNDS, GOALS, measure_example
from tensor_servo.model import FIXED_CONFIGS

ROOT = Path(__file__).resolve().parents[2]


def _update_docs():
    spec = importlib.util.spec_from_file_location("update_docs", ROOT / "scripts" / "update_docs.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_default_bounds_meet_the_goals():
    for k, goal in GOALS.items():
        assert BOUNDS["default"][k] <= goal, k


@pytest.mark.parametrize("config", FIXED_CONFIGS)
@pytest.mark.parametrize("name", robots.names())
def test_errors_within_published_bounds(name, config):
    e = measure_example(name, config)
    assert e["overflow"] == 0
    for k, bound in BOUNDS[config].items():
        assert e[k] <= bound, f"{name} {config} {k}: {e[k]:.3g} > {bound:.3g}"


def test_numerics_doc_is_current():
    ud = _update_docs()
    text = ud.DOC.read_text()
    assert ud.render(text) == text, "docs/numerics.md is out of date: run scripts/update_docs.py"
