"""The embedded example chains: load, validate, round-trip, fit every configuration, are up to date."""
import json
import math

import numpy as np
import pytest

from tensor_servo import chain as ch
from tensor_servo import model, robots
from tensor_servo.errors import InputError
from tensor_servo.robots import regenerate

REQUIRED = ["puma560", "ur5", "panda", "stanford", "chain20"]


def test_names():
    assert set(REQUIRED) <= set(robots.names())
    assert robots.names() == sorted(robots.names())
    assert all(robots.path(n).is_file() for n in robots.names())


@pytest.mark.parametrize("name", REQUIRED)
def test_example_loads_round_trips_and_fits(name):
    text = robots.path(name).read_text()
    c = robots.load(name)
    assert c.name == name
    assert c.to_json() == text  # loading changes nothing (no re-normalisation drift)
    assert ch.chain_from_dict(json.loads(c.to_json())).to_json() == text
    assert ch.load(name).to_json() == text  # chain.load accepts example names
    assert model.check_config(c) == {cfg: None for cfg in model.CONFIGS}
    assert set(model.CONFIGS) == {"double", "default", "compact"}


@pytest.mark.parametrize("name", REQUIRED)
def test_example_limits_are_set(name):
    c = robots.load(name)
    for j in c.joints:
        if j.prismatic or name != "chain20":
            assert j.limits.bounded, j.name  # only chain20 has continuous joints
        if name != "stanford":  # no citable velocity limits for the Stanford arm (docs/chain-format.md)
            assert j.limits.velocity is not None and j.limits.velocity > 0, j.name


def test_files_are_up_to_date():
    """The JSON files are what the generator makes from robots/dh/*.json and the chain20 recipe."""
    built = regenerate.build()
    assert set(built) == set(robots.names())
    for name, text in built.items():
        assert regenerate.up_to_date(robots.path(name).read_text(), text), name
    assert regenerate.main(["--check"]) == 0


def test_up_to_date_tolerates_the_last_bits_only():
    """The files are compared with a few units in the last place (BLAS kernels differ per CPU), but
    a real change of a number, a key, a string or an integer still makes a file stale."""
    text = robots.path("chain20").read_text()
    axis = json.loads(text)["joints"][3]["axis"]

    def with_axis0(v):
        d = json.loads(text)
        d["joints"][3]["axis"][0] = v
        return json.dumps(d, indent=2)

    assert regenerate.up_to_date(text, with_axis0(math.nextafter(axis[0], 1.0)))
    assert not regenerate.up_to_date(text, with_axis0(axis[0] + 1e-12))
    assert not regenerate.up_to_date(text, text.replace('"j4"', '"j5"', 1))
    assert not regenerate.up_to_date(text, text.replace('"revolute"', '"prismatic"', 1))
    d = json.loads(text)
    d["joints"].pop()
    assert not regenerate.up_to_date(text, json.dumps(d, indent=2))


def test_chain20_properties():
    c = robots.load("chain20")
    assert c.n == 20
    prismatic = [i for i, j in enumerate(c.joints) if j.prismatic]
    continuous = [i for i, j in enumerate(c.joints) if not j.prismatic and not j.limits.bounded]
    assert len(prismatic) >= 2 and 2 <= len(continuous) <= 5
    for j in c.joints:
        assert np.count_nonzero(np.abs(j.axis) > 0.04) == 3, j.name  # oblique: not along x, y or z
        assert abs(j.origin.quat_wxyz[0]) < 1 - 1e-4, j.name  # rotated origin
    assert abs(c.base.quat_wxyz[0]) < 1 - 1e-4 and abs(c.tool.quat_wxyz[0]) < 1 - 1e-4
    r = ch.reach(c)
    assert r < 3.0
    # the same sum, spelled out
    total = sum(np.linalg.norm(j.origin.xyz) for j in c.joints) + np.linalg.norm(c.tool.xyz)
    total += sum(max(abs(j.limits.lower), abs(j.limits.upper)) for j in c.joints if j.prismatic)
    assert r == pytest.approx(total, abs=1e-12)


def test_unknown_example():
    with pytest.raises(InputError, match="no such file or embedded example"):
        robots.load("puma")
    with pytest.raises(InputError, match="puma: no such file"):
        ch.load("puma")
