"""The chain JSON format (docs/chain-format.md): loading, defaults, tolerance rules, errors, round trip."""
import copy
import json

import numpy as np
import pytest

from tensor_servo import chain as ch
from tensor_servo.errors import InputError

MINIMAL = {
    "name": "two",
    "joints": [
        {"name": "a", "type": "revolute", "origin": {"xyz": [0, 0, 0.1], "quat_wxyz": [1, 0, 0, 0]},
         "axis": [0, 0, 1], "limits": {"lower": -1, "upper": 1, "velocity": 2}},
        {"name": "b", "type": "prismatic", "origin": {"xyz": [0.2, 0, 0], "quat_wxyz": [0, 1, 0, 0]},
         "axis": [1, 0, 0], "limits": {"lower": 0, "upper": 0.3}},
    ],
}


def variant(**edits):
    """MINIMAL with edits given as path=value, path like 'joints.0.axis' (value None deletes)."""
    d = copy.deepcopy(MINIMAL)
    for key, value in edits.items():
        *parents, last = key.split("__")
        node = d
        for p in parents:
            node = node[int(p)] if p.isdigit() else node[p]
        last = int(last) if last.isdigit() else last
        if value is None:
            del node[last]
        else:
            node[last] = value
    return d


def error_of(d) -> str:
    with pytest.raises(InputError) as e:
        ch.chain_from_dict(d)
    return str(e.value)


def test_minimal_chain_and_defaults():
    c = ch.chain_from_dict(MINIMAL)
    assert c.name == "two" and c.n == 2
    assert np.array_equal(c.base.matrix(), np.eye(4)) and np.array_equal(c.tool.matrix(), np.eye(4))
    assert c.joints[0].scale == 1.0 and c.joints[1].prismatic
    assert c.joints[1].limits.velocity is None
    # no limits at all: a continuous revolute joint
    d = variant(joints__0__limits=None)
    c = ch.chain_from_dict(d)
    assert not c.joints[0].limits.bounded and c.lower[0] == -np.inf


def test_quaternion_normalised_within_tolerance():
    q = [1.0005, 0.0, 0.0, 0.0]  # norm 1 + 5e-4, inside UNIT_TOL = 1e-3
    c = ch.chain_from_dict(variant(joints__0__origin__quat_wxyz=q))
    assert np.array_equal(c.joints[0].origin.quat_wxyz, [1.0, 0.0, 0.0, 0.0])
    q = [0.7072, 0.7072, 0, 0]  # norm 1.00013
    c = ch.chain_from_dict(variant(tool={"xyz": [0, 0, 0], "quat_wxyz": q}))
    assert abs(np.linalg.norm(c.tool.quat_wxyz) - 1.0) < 1e-15


@pytest.mark.parametrize("q", [[1.002, 0, 0, 0], [0.99, 0, 0, 0], [0, 0, 0, 0], [2, 0, 0, 0]])
def test_quaternion_rejected_beyond_tolerance(q):
    msg = error_of(variant(joints__1__origin__quat_wxyz=q))
    assert msg.startswith("joints[1].origin.quat_wxyz: quaternion norm")


def test_axis_normalised_if_nonzero():
    c = ch.chain_from_dict(variant(joints__0__axis=[0, 3, 4]))
    assert np.allclose(c.joints[0].axis, [0, 0.6, 0.8], rtol=0, atol=1e-16)
    assert error_of(variant(joints__0__axis=[0, 0, 0])) == "joints[0].axis: zero vector"
    assert error_of(variant(joints__0__axis=[0, 0, 1e-12])) == "joints[0].axis: zero vector"


@pytest.mark.parametrize("edits, expected", [
    ({"name": None}, "name: missing"),
    ({"name": ""}, "name: expected a non-empty string"),
    ({"joints": []}, "joints: expected a non-empty list"),
    ({"joints__0__axis": None}, "joints[0].axis: missing"),
    ({"joints__1__origin": None}, "joints[1].origin: missing"),
    ({"joints__1__origin__xyz": None}, "joints[1].origin.xyz: missing"),
    ({"joints__0__axis": [0, 1]}, "joints[0].axis: expected a list of 3 numbers"),
    ({"joints__0__axis": [0, "1", 0]}, "joints[0].axis: expected a list of 3 numbers"),
    ({"joints__0__axis": [0, True, 0]}, "joints[0].axis: expected a list of 3 numbers"),
    ({"joints__0__axis": [float("nan"), 0, 1]}, "joints[0].axis: not finite"),
    ({"joints__0__origin__xyz": [0, float("inf"), 0]}, "joints[0].origin.xyz: not finite"),
    ({"joints__0__type": "spherical"}, "joints[0].type: must be one of revolute, prismatic"),
    ({"joints__0__limits__lower": 2}, "joints[0].limits: lower 2 > upper 1"),
    ({"joints__0__limits__upper": None}, "joints[0].limits: give both lower and upper"),
    ({"joints__1__limits": {}}, "joints[1].limits: a prismatic joint needs lower and upper limits"),
    ({"joints__0__limits__velocity": 0}, "joints[0].limits.velocity: must be positive"),
    ({"joints__0__scale": 0}, "joints[0].scale: must be non-zero"),
    ({"joints__1__name": "a"}, "joints: duplicate joint name 'a'"),
    ({"units": {"length": "mm"}}, "units.length: only 'm' is supported"),
    ({"base": {"xyz": [0, 0, 0]}}, "base.quat_wxyz: missing"),
])
def test_errors_name_the_field(edits, expected):
    assert error_of(variant(**edits)).startswith(expected)


def test_equal_limits_allowed():
    c = ch.chain_from_dict(variant(joints__0__limits={"lower": 0.5, "upper": 0.5}))
    assert c.joints[0].limits.lower == c.joints[0].limits.upper == 0.5


def test_load_file_errors(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"name": "x", "joints": [}')
    with pytest.raises(InputError, match=r"bad\.json: malformed JSON at line 1 column 26"):
        ch.load(bad)
    with pytest.raises(InputError, match="no such file"):
        ch.load(tmp_path / "missing.json")
    nan = tmp_path / "nan.json"  # Python's json accepts NaN; the loader must not
    nan.write_text(json.dumps(MINIMAL).replace('"axis": [0, 0, 1]', '"axis": [NaN, 0, 1]'))
    with pytest.raises(InputError, match=r"joints\[0\]\.axis: not finite"):
        ch.load(nan)


def test_round_trip_unchanged(tmp_path):
    c = ch.canonical(ch.chain_from_dict(MINIMAL))
    p = tmp_path / "c.json"
    c.save(p)
    assert p.read_text() == c.to_json()
    assert ch.load(p).to_json() == c.to_json()


def test_canonical_makes_unit_vectors_exact_fixed_points():
    """Random rotations and axes: after canonical() the JSON reads back bit-identically.

    (With plain normalisation about 30 of these 100 chains would not: q / |q| is not idempotent in
    floating point for about 1 % of unit vectors.)"""
    rng = np.random.default_rng(7)
    for _ in range(100):
        joints = []
        for i in range(20):
            q = rng.normal(size=4)
            joints.append(ch.Joint(f"j{i}", "revolute", ch.Pose(rng.normal(size=3) * 0.1, q / np.linalg.norm(q)),
                                   rng.normal(size=3)))
        c = ch.canonical(ch.Chain("r", joints))
        text = c.to_json()
        assert ch.chain_from_dict(json.loads(text)).to_json() == text


def test_canonical_cleans_rounding_residue():
    quat = np.array([np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)])
    j = ch.Joint("a", "revolute", ch.Pose(np.array([1e-17, 0.0, 0.5]), quat), np.array([6e-17, 0.0, 1.0]))
    c = ch.canonical(ch.Chain("r", [j]))
    assert c.joints[0].origin.xyz[0] == 0.0 and c.joints[0].axis[0] == 0.0
    with pytest.raises(InputError, match=r"joints\[0\]\.axis: zero vector"):
        ch.canonical(ch.Chain("r", [ch.Joint("a", "revolute", ch.Pose(), np.zeros(3))]))


def test_reach():
    c = ch.chain_from_dict(variant(tool={"xyz": [0, 0.3, 0.4], "quat_wxyz": [1, 0, 0, 0]}))
    # |origins| 0.1 + 0.2, |tool| 0.5, prismatic stroke max(|0|, |0.3|)
    assert ch.reach(c) == pytest.approx(0.1 + 0.2 + 0.5 + 0.3, abs=1e-15)
    c.joints[1].scale = -2.0
    assert ch.reach(c) == pytest.approx(0.1 + 0.2 + 0.5 + 0.6, abs=1e-15)
