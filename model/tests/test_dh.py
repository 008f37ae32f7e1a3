"""DH tables -> chain: FK equals roboticstoolbox-python's fkine for the same DH robot (both conventions)."""
import json
import math

import numpy as np
import pytest
import roboticstoolbox as rtb
from spatialmath import SE3

from tensor_servo import dh, robots
from tensor_servo.chain import Chain, Pose
from tensor_servo.errors import InputError

TOL = 1e-12


def fk(c: Chain, q: np.ndarray) -> np.ndarray:
    """T(q) = base * prod(origin_i * M_i(q_i)) * tool, from the chain's own matrices (Rodrigues)."""
    T = c.base.matrix()
    for j, qi in zip(c.joints, q):
        M = np.eye(4)
        th = j.scale * qi
        if j.prismatic:
            M[:3, 3] = th * j.axis
        else:
            x, y, z = j.axis
            K = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
            M[:3, :3] = np.eye(3) + math.sin(th) * K + (1 - math.cos(th)) * K @ K
        T = T @ j.origin.matrix() @ M
    return T @ c.tool.matrix()


def max_fk_error(c: Chain, robot, n: int = 200, seed: int = 0) -> float:
    rng = np.random.default_rng(seed)
    return max(np.abs(fk(c, q) - robot.fkine(q).A).max() for q in c.random_q(rng, n))


# ---- the embedded examples against roboticstoolbox's own models ---------------------------------

def rtb_model(name: str):
    if name == "puma560":
        return rtb.models.DH.Puma560()
    if name == "stanford":
        return rtb.models.DH.Stanford()
    if name == "ur5":
        r = rtb.models.DH.UR5()
        # rtb has d1 = 0.089459; Universal Robots publishes 0.089159 (our table): d1 is a translation
        # along the base z axis, so lowering rtb's base by the difference gives the same robot
        r.base = SE3.Tz(0.089159 - 0.089459)
        return r
    if name == "panda":
        r = rtb.models.DH.Panda()
        # rtb folds the flange (d = 0.107 along z7) into d7 and adds the Franka Hand as its tool;
        # our chain's tool is the flange
        r.tool = SE3()
        return r
    raise KeyError(name)


@pytest.mark.parametrize("name", ["puma560", "stanford", "ur5", "panda"])
def test_examples_match_rtb(name):
    table_chain = dh.load(robots.HERE / "dh" / f"{name}.json")
    embedded = robots.load(name)
    assert table_chain.to_json() == embedded.to_json()
    assert max_fk_error(embedded, rtb_model(name)) < TOL
    # joint limits are rtb's where rtb has them (UR5 has none in rtb)
    r = rtb_model(name)
    if r.links[0].qlim is not None:
        assert np.allclose(embedded.lower, r.qlim[0], rtol=0, atol=1e-12)
        assert np.allclose(embedded.upper, r.qlim[1], rtol=0, atol=1e-12)


def test_example_sanity():
    """Properties the rtb comparison would not notice if both were wrong the same way."""
    stanford = robots.load("stanford")
    assert [j.type for j in stanford.joints] == ["revolute"] * 2 + ["prismatic"] + ["revolute"] * 3
    panda = robots.load("panda")
    assert panda.n == 7
    assert np.array_equal(panda.tool.xyz, [0, 0, 0.107]) and np.array_equal(panda.tool.quat_wxyz, [1, 0, 0, 0])
    # the flange is 0.107 m beyond frame 7's origin, along joint 7's axis
    q = np.zeros(7)
    T = fk(panda, q)
    assert np.allclose(T[:3, 3], [0.088, 0, 0.333 + 0.316 + 0.384 - 0.107], atol=1e-12)


# ---- random tables in both conventions -----------------------------------------------------------

def random_table(convention: str, seed: int) -> dict:
    """A random DH table (rad) with prismatic joints, offsets, base and tool."""
    rng = np.random.default_rng(seed)
    joints = []
    types = ["revolute", "prismatic", "revolute", "revolute", "prismatic", "revolute", "revolute"]
    for i, t in enumerate(types):
        row = {"name": f"q{i}", "type": t, "a": float(rng.uniform(-0.3, 0.3)),
               "alpha": float(rng.uniform(-math.pi, math.pi)), "offset": float(rng.uniform(-1, 1))}
        if t == "revolute":
            row["d"] = float(rng.uniform(-0.3, 0.3))
            row["limits"] = {"lower": -2.5, "upper": 2.5}
        else:
            row["theta"] = float(rng.uniform(-math.pi, math.pi))
            row["offset"] *= 0.2
            row["limits"] = {"lower": -0.1, "upper": 0.4}
        joints.append(row)

    def pose():
        q = rng.normal(size=4)
        return {"xyz": [float(v) for v in rng.uniform(-0.5, 0.5, 3)], "quat_wxyz": [float(v) for v in q / np.linalg.norm(q)]}

    return {"name": f"random_{convention}", "convention": convention, "base": pose(), "tool": pose(), "joints": joints}


def rtb_robot(table: dict):
    links = []
    for r in table["joints"]:
        if table["convention"] == "standard":
            if r["type"] == "revolute":
                links.append(rtb.RevoluteDH(d=r["d"], a=r["a"], alpha=r["alpha"], offset=r["offset"]))
            else:
                links.append(rtb.PrismaticDH(theta=r["theta"], a=r["a"], alpha=r["alpha"], offset=r["offset"]))
        else:
            if r["type"] == "revolute":
                links.append(rtb.RevoluteMDH(d=r["d"], a=r["a"], alpha=r["alpha"], offset=r["offset"]))
            else:
                links.append(rtb.PrismaticMDH(theta=r["theta"], a=r["a"], alpha=r["alpha"], offset=r["offset"]))
    base = Pose(np.array(table["base"]["xyz"]), np.array(table["base"]["quat_wxyz"])).matrix()
    tool = Pose(np.array(table["tool"]["xyz"]), np.array(table["tool"]["quat_wxyz"])).matrix()
    return rtb.DHRobot(links, base=SE3(base, check=False), tool=SE3(tool, check=False))


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_random_tables_match_rtb(convention, seed):
    table = random_table(convention, seed)
    c = dh.to_chain(dh.table_from_dict(table))
    assert [j.type for j in c.joints] == [r["type"] for r in table["joints"]]
    assert max_fk_error(c, rtb_robot(table), n=100, seed=seed) < TOL


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_row_product_matches_chain(convention):
    """Independent of rtb: base * prod(A_i(q)) * tool with dh.row_matrix equals the chain's FK."""
    table = dh.table_from_dict(random_table(convention, 11))
    c = dh.to_chain(table)
    rng = np.random.default_rng(5)
    for q in c.random_q(rng, 50):
        T = table.base.matrix()
        for row, qi in zip(table.rows, q):
            T = T @ dh.row_matrix(row, convention, qi)
        assert np.abs(T @ table.tool.matrix() - fk(c, q)).max() < TOL


def test_degrees_equal_radians():
    rad = random_table("standard", 4)
    deg = json.loads(json.dumps(rad))
    deg["units"] = {"angle": "deg"}
    for r in deg["joints"]:
        r["alpha"] = math.degrees(r["alpha"])
        if r["type"] == "revolute":
            r["offset"] = math.degrees(r["offset"])
            r["limits"] = {"lower": math.degrees(-2.5), "upper": math.degrees(2.5), "velocity": math.degrees(1.0)}
        else:
            r["theta"] = math.degrees(r["theta"])
    a, b = dh.to_chain(dh.table_from_dict(rad)), dh.to_chain(dh.table_from_dict(deg))
    assert np.allclose(a.lower, b.lower, atol=1e-14) and np.allclose(a.upper, b.upper, atol=1e-14)
    assert b.joints[0].limits.velocity == pytest.approx(1.0, abs=1e-14)
    rng = np.random.default_rng(0)
    for q in a.random_q(rng, 20):
        assert np.abs(fk(a, q) - fk(b, q)).max() < TOL


def test_scale_and_unconverted_limits():
    """With a scale, the joint variable is scale*q + offset and limits stay in joint units."""
    t = {"name": "s", "convention": "standard", "units": {"angle": "deg"},
         "joints": [{"name": "j", "type": "revolute", "a": 0.1, "alpha": 90, "d": 0.2, "offset": 30,
                     "scale": math.pi / 180, "limits": {"lower": -90, "upper": 90}}]}
    table = dh.table_from_dict(t)
    c = dh.to_chain(table)
    assert (c.joints[0].limits.lower, c.joints[0].limits.upper) == (-90, 90)
    ref = dh.link_standard(math.radians(45 + 30), 0.2, 0.1, math.pi / 2)
    assert np.abs(fk(c, [45.0]) - ref).max() < TOL


@pytest.mark.parametrize("edit, expected", [
    (lambda t: t["joints"][1].pop("alpha"), "joints[1].alpha: missing"),
    (lambda t: t["joints"][0].pop("d"), "joints[0].d: missing"),
    (lambda t: t["joints"][1].pop("theta"), "joints[1].theta: missing"),
    (lambda t: t["joints"][0].update(theta=0.1), "joints[0].theta: is the joint variable of a revolute joint"),
    (lambda t: t["joints"][1].update(d=0.1), "joints[1].d: is the joint variable of a prismatic joint"),
    (lambda t: t["joints"][2].update(alfa=0.1), "joints[2].alfa: unknown key"),
    (lambda t: t["joints"][2]["limits"].update(min=0.1), "joints[2].limits.min: unknown key"),
    (lambda t: t.update(convention="craig"), "convention: must be one of standard, modified"),
    (lambda t: t.update(units={"angle": "grad"}), "units.angle: must be 'rad' or 'deg'"),
    (lambda t: t.pop("name"), "name: missing"),
    (lambda t: t.update(joints=[]), "joints: expected a non-empty list"),
    (lambda t: t["joints"][0].update(a=float("nan")), "joints[0].a: not finite"),
    (lambda t: t["joints"][0].update(a="0.1"), "joints[0].a: expected a number"),
    (lambda t: t["base"].update(quat_wxyz=[1.1, 0, 0, 0]), "base.quat_wxyz: quaternion norm"),
    (lambda t: t["joints"][0].update(type="helical"), "joints[0].type: must be one of revolute, prismatic"),
])
def test_table_errors_name_the_field(edit, expected):
    t = random_table("modified", 9)
    edit(t)
    with pytest.raises(InputError) as e:
        dh.to_chain(dh.table_from_dict(t))
    assert str(e.value).startswith(expected)


@pytest.mark.parametrize("limits, expected", [
    ({"lower": 0.4, "upper": -0.1}, "joints[1].limits: lower 0.4 > upper -0.1"),
    ({}, "joints[1].limits: a prismatic joint needs lower and upper limits"),
])
def test_limit_errors_from_the_chain_validation(limits, expected):
    t = random_table("standard", 9)
    t["joints"][1]["limits"] = limits
    with pytest.raises(InputError) as e:
        dh.to_chain(dh.table_from_dict(t))
    assert str(e.value).startswith(expected)


def test_malformed_table_file(tmp_path):
    p = tmp_path / "t.json"
    p.write_text('{"name": "x",\n "convention": standard}')
    with pytest.raises(InputError, match=r"t\.json: malformed JSON at line 2 column 16"):
        dh.load(p)
