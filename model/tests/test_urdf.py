"""URDF -> chain: tool pose equals Pinocchio's own URDF parser; every rejected input names its element."""
import importlib.util
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from tensor_servo import urdf
from tensor_servo.errors import InputError
from tensor_servo.oracle import PinChain

DATA = Path(__file__).parent / "data"
RTBDATA = Path(importlib.util.find_spec("rtbdata").submodule_search_locations[0])
TOL = 1e-12


def pinocchio_pose(model, data, chain, q, base: str, tip: str) -> np.ndarray:
    """Pose of link ``tip`` in link ``base`` from Pinocchio's URDF model, our joints set to q (others
    neutral; continuous joints have nq = 2: cos, sin)."""
    qp = pin.neutral(model)
    for j, qi in zip(chain.joints, q):
        jid = model.getJointId(j.name)
        iq = model.idx_qs[jid]
        if model.nqs[jid] == 2:
            qp[iq:iq + 2] = [np.cos(qi), np.sin(qi)]
        else:
            assert model.nqs[jid] == 1
            qp[iq] = qi
    pin.framesForwardKinematics(model, data, qp)
    T_base = data.oMf[model.getFrameId(base, pin.FrameType.BODY)]
    T_tip = data.oMf[model.getFrameId(tip, pin.FrameType.BODY)]
    return (T_base.inverse() * T_tip).homogeneous


def check_against_pinocchio(path: Path, base: str, tip: str, n: int = 100):
    chain = urdf.from_urdf(path, base, tip)
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    ours = PinChain(chain)
    rng = np.random.default_rng(3)
    err = max(np.abs(ours.tool_pose(q) - pinocchio_pose(model, data, chain, q, base, tip)).max()
              for q in chain.random_q(rng, n))
    assert err < TOL
    return chain


@pytest.mark.parametrize("rel, base, tip, n", [
    ("xacro/unimation_puma560_description/urdf/puma560_robot.urdf", "link1", "link7", 6),
    ("xacro/abb_irb140_description/urdf/irb140.urdf", "base_link", "tool0", 6),
    ("xacro/kuka_description/kuka_lbr_iiwa/urdf/lbr_iiwa_14_r820.urdf", "base_link", "tool0", 7),
    ("xacro/kuka_description/kuka_kr210/urdf/kr210l150.urdf", "base_link", "tool0", 6),
    ("xacro/kuka_description/kuka_kr210/urdf/kr210l150.urdf", "link_2", "link_5", 3),
])
def test_rtbdata_urdfs_match_pinocchio(rel, base, tip, n):
    chain = check_against_pinocchio(RTBDATA / rel, base, tip)
    assert chain.n == n
    assert np.array_equal(chain.base.matrix(), np.eye(4))


def test_rtbdata_limits_and_velocity():
    chain = urdf.from_urdf(RTBDATA / "xacro/kuka_description/kuka_lbr_iiwa/urdf/lbr_iiwa_14_r820.urdf", "base_link", "tool0")
    j = chain.joints[1]
    assert (j.limits.lower, j.limits.upper, j.limits.velocity) == (-2.0942, 2.0942, 1.4834)
    # the trailing fixed joint (0.126 m along z, axis "0 0 0" which fixed joints may have) is the tool
    assert np.allclose(chain.tool.xyz, [0, 0, 0.126], atol=1e-15)
    puma = urdf.from_urdf(RTBDATA / "xacro/unimation_puma560_description/urdf/puma560_robot.urdf")
    assert puma.n == 6 and all(j.limits.velocity is None for j in puma.joints)  # velocity="0": not given


@pytest.mark.parametrize("base, tip, n", [
    ("world", "tcp", 4), ("base_link", "flange", 4), ("link1", "link4", 3), ("bracket", "slider", 2),
    ("world", "link1", 1),
])
def test_fixture_matches_pinocchio(base, tip, n):
    chain = check_against_pinocchio(DATA / "serial_fixed.urdf", base, tip)
    assert chain.n == n


def test_fixture_folding_and_joint_mapping():
    c = urdf.from_urdf(DATA / "serial_fixed.urdf", "world", "tcp")
    assert c.name == "fixture_arm"
    assert [j.name for j in c.joints] == ["j1", "j2", "j3", "j4"]  # 4 fixed joints folded away
    assert [j.type for j in c.joints] == ["revolute", "revolute", "prismatic", "revolute"]
    assert [j.limits.bounded for j in c.joints] == [True, True, True, False]  # j4 is continuous
    assert [j.limits.velocity for j in c.joints] == [2.0, None, 0.5, 3.0]  # velocity="0": not given
    assert np.allclose(c.joints[1].axis, np.array([0.3, 0.4, 0.866]) / np.linalg.norm([0.3, 0.4, 0.866]), atol=1e-15)
    # leading fixed joint (world -> base_link) folded into j1's origin: translation 0.1 0.2 0.05 plus
    # Rz(0.5) applied to j1's own 0 0 0.3
    assert np.allclose(c.joints[0].origin.xyz, [0.1, 0.2, 0.35], atol=1e-15)
    # trailing fixed joints (0 0 0.08, then 0.01 0 0.12) form the tool
    assert np.allclose(c.tool.xyz, [0.01, 0, 0.2], atol=1e-15)
    # the name option
    assert urdf.from_urdf(DATA / "serial_fixed.urdf", "world", "tcp", name="arm").name == "arm"


def test_default_base_and_tip():
    c = urdf.from_urdf(RTBDATA / "xacro/unimation_puma560_description/urdf/puma560_robot.urdf")
    assert [j.name for j in c.joints] == ["j1", "j2", "j3", "j4", "j5", "j6"]
    c = urdf.from_urdf(DATA / "floating.urdf", base="body")  # the only leaf below body is arm
    assert [j.name for j in c.joints] == ["shoulder"]


def test_default_tip_needs_a_single_leaf():
    with pytest.raises(InputError, match=r"^--tip: required: link 'world' has 4 leaf links"):
        urdf.from_urdf(DATA / "serial_fixed.urdf")
    with pytest.raises(InputError, match=r"^--base: required: disconnected.urdf has 2 root links \(a, c\)"):
        urdf.from_urdf(DATA / "disconnected.urdf")


@pytest.mark.parametrize("fixture, base, tip, expected", [
    ("malformed.urdf", None, None,
     r"malformed\.urdf: malformed XML at line 10 column 9: Opening and ending tag mismatch: joint line 6"),
    ("floating.urdf", "world", "arm", r"^joint 'free_flyer': type 'floating' is not supported"),
    ("planar.urdf", "floor", "arm", r"^joint 'cart_plane': type 'planar' is not supported"),
    ("mimic.urdf", "base", "l2", r"^joint 'follower': mimic joints are not supported \(it mimics joint 'drive'\)"),
    ("disconnected.urdf", "a", "d", r"^--base: link 'a' is not an ancestor of link 'd'"),
    ("disconnected.urdf", "b", "a", r"^--base: link 'b' is not an ancestor of link 'a'"),
    ("disconnected.urdf", "a", "zzz", r"^--tip: no link named 'zzz' in disconnected\.urdf"),
    ("disconnected.urdf", "nope", "b", r"^--base: no link named 'nope' in disconnected\.urdf"),
    ("disconnected.urdf", "a", "a", r"^--tip: is the same link as --base"),
    ("missing_limit.urdf", None, None, r"^joint 'elbow': a revolute joint needs <limit"),
    ("zero_axis.urdf", None, None, r"^joint 'wrist' <axis xyz>: zero vector"),
    ("bad_limits.urdf", None, None, r"^joint 'slide' <limit>: lower 0\.5 > upper 0\.1"),
    ("bad_number.urdf", None, None, r"^joint 'hip' <origin xyz>: expected 3 numbers \(got '0 0 zero'\)"),
    ("undefined_link.urdf", None, None, r"^joint 'knee': child link 'ghost' is not defined"),
    ("macro.urdf.xacro", None, None, r"contains xacro macros \(<xacro:property> at line 4\)"),
    ("only_fixed.urdf", "a", "c", r"^--tip: no movable joint between 'a' and 'c'"),
    ("does_not_exist.urdf", None, None, r"does_not_exist\.urdf: no such file"),
])
def test_rejected_inputs_name_the_element(fixture, base, tip, expected):
    with pytest.raises(InputError, match=expected) as e:
        urdf.from_urdf(DATA / fixture, base, tip)
    assert "\n" not in str(e.value)


def test_off_path_elements_are_ignored():
    """Floating/planar/mimic joints off the path do not matter: only the path is checked."""
    c = urdf.from_urdf(DATA / "floating.urdf", "body", "arm")
    assert [j.name for j in c.joints] == ["shoulder"]
    c = urdf.from_urdf(DATA / "mimic.urdf", "base", "l1")
    assert [j.name for j in c.joints] == ["drive"]


@pytest.mark.parametrize("xml, expected", [
    ('<robot name="r"><link name="a"/><link name="a"/></robot>', r"^link 'a': defined twice"),
    ('<robot name="r"><link/></robot>', r"<link> at line 1: missing name attribute"),
    ('<robot name="r"><link name="a"/><link name="b"/><joint name="j"><parent link="a"/><child link="b"/></joint></robot>',
     r"^joint 'j': missing type attribute"),
    ('<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="revolute"><child link="b"/></joint></robot>',
     r"^joint 'j': missing <parent link"),
    ('<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
     '<joint name="j" type="fixed"><parent link="a"/><child link="c"/></joint>'
     '<joint name="k" type="fixed"><parent link="b"/><child link="c"/></joint></robot>',
     r"^joint 'k': link 'c' is already the child of joint 'j'"),
    ('<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
     '<limit lower="-1" upper="nan" velocity="1" effort="1"/></joint></robot>',
     r"^joint 'j' <limit upper>: not finite"),
    ('<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="screw"><parent link="a"/><child link="b"/>'
     '</joint></robot>', r"^joint 'j': unknown type 'screw'"),
    ('<model name="r"/>', r"root element is <model>, expected <robot>"),
])
def test_structure_errors(tmp_path, xml, expected):
    p = tmp_path / "r.urdf"
    p.write_text(xml)
    with pytest.raises(InputError, match=expected):
        urdf.from_urdf(p, "a", "b")
