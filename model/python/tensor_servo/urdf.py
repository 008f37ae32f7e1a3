"""URDF -> Chain: the serial path between two links of a URDF robot (docs/chain-format.md).

    tservo chain from-urdf ROBOT.urdf --base LINK --tip LINK -o CHAIN.json

Rules:
  * the root frame of the chain is the ``--base`` link (``base`` = identity); ``--base`` must be an
    ancestor of ``--tip`` (default base: the root link; default tip: the only leaf below the base);
  * fixed joints are folded into the origin of the next moving joint; trailing fixed joints form the
    tool;
  * ``revolute`` and ``prismatic`` joints need ``<limit lower upper>``; ``continuous`` joints become
    revolute joints without position limits; a ``velocity`` limit of 0 (a common placeholder) or no
    velocity attribute means "no velocity limit";
  * ``floating`` and ``planar`` joints, mimic joints, unknown links and missing paths are rejected;
  * visuals, collisions, inertials, transmissions and everything off the path are ignored.

The file is parsed by yourdfpy (a maintained URDF parser).  Before that, lxml reads it strictly:
yourdfpy silently "recovers" malformed XML, and it fails with bare KeyError/ValueError on missing
attributes or bad numbers; the strict pass turns both into one-line errors that name the element.
"""
from __future__ import annotations

import contextlib
import logging
import math
import os
from pathlib import Path

import numpy as np

from .chain import Chain, Joint, Limits, Pose, canonical
from .errors import InputError

MOVING = ("revolute", "continuous", "prismatic")
URDF_TYPES = MOVING + ("fixed", "floating", "planar")
XACRO_NS = "http://www.ros.org/wiki/xacro"


# ---- strict XML pass -------------------------------------------------------------------------------

def _parse_xml(path: Path):
    from lxml import etree

    parser = etree.XMLParser(remove_blank_text=True, resolve_entities=False, no_network=True)
    try:
        root = etree.parse(str(path), parser).getroot()
    except etree.XMLSyntaxError as e:
        line, col = e.position if e.position else (e.lineno, 0)
        msg = " ".join(str(e.msg).split())
        raise InputError(str(path), f"malformed XML at line {line} column {col}: {msg}") from None
    except OSError as e:
        raise InputError(str(path), f"cannot read: {e.strerror or e}") from None
    if root.tag != "robot":
        raise InputError(str(path), f"root element is <{root.tag}>, expected <robot>")
    for el in root.iter():
        if isinstance(el.tag, str) and el.tag.startswith("{" + XACRO_NS + "}"):
            raise InputError(str(path), f"contains xacro macros (<xacro:{el.tag.split('}')[1]}> at line "
                                        f"{el.sourceline}); expand it first: xacro FILE.xacro > FILE.urdf")
    return root


def _numbers(el, attr: str, n: int | None, where: str) -> None:
    """Check that an attribute holds n finite numbers (n None: one number)."""
    text = el.get(attr)
    if text is None:
        return
    parts = text.split()
    try:
        vals = [float(p) for p in parts]
    except ValueError:
        vals = None
    if vals is None or len(vals) != (n or 1):
        want = f"{n} numbers" if n else "a number"
        raise InputError(f"{where} <{el.tag} {attr}>", f"expected {want} (got {text!r})")
    if not all(math.isfinite(v) for v in vals):
        raise InputError(f"{where} <{el.tag} {attr}>", f"not finite (got {text!r})")


def _check_structure(root, path: Path) -> None:
    """The structure yourdfpy assumes: named links, joints with type, parent and child links that
    exist, numeric attributes that parse; unique names; each link the child of at most one joint."""
    links: set[str] = set()
    for el in root.findall("link"):
        name = el.get("name")
        if not name:
            raise InputError(f"{path.name}: <link> at line {el.sourceline}", "missing name attribute")
        if name in links:
            raise InputError(f"link '{name}'", "defined twice")
        links.add(name)
    joints: set[str] = set()
    child_of: dict[str, str] = {}
    for el in root.findall("joint"):
        name = el.get("name")
        if not name:
            raise InputError(f"{path.name}: <joint> at line {el.sourceline}", "missing name attribute")
        where = f"joint '{name}'"
        if name in joints:
            raise InputError(where, "defined twice")
        joints.add(name)
        if not el.get("type"):
            raise InputError(where, "missing type attribute")
        for tag in ("parent", "child"):
            sub = el.find(tag)
            if sub is None or not sub.get("link"):
                raise InputError(where, f"missing <{tag} link=\"...\"/>")
            if sub.get("link") not in links:
                raise InputError(where, f"{tag} link '{sub.get('link')}' is not defined")
        child = el.find("child").get("link")
        if child in child_of:
            raise InputError(where, f"link '{child}' is already the child of joint '{child_of[child]}' "
                                    f"(a URDF must be a tree)")
        child_of[child] = name
        for tag, attrs in (("origin", {"xyz": 3, "rpy": 3}), ("axis", {"xyz": 3}),
                           ("limit", {"lower": None, "upper": None, "velocity": None, "effort": None}),
                           ("mimic", {"multiplier": None, "offset": None})):
            sub = el.find(tag)
            if sub is not None:
                for attr, n in attrs.items():
                    _numbers(sub, attr, n, where)
        mimic = el.find("mimic")
        if mimic is not None and not mimic.get("joint"):
            raise InputError(f"{where} <mimic>", "missing joint attribute")


# ---- yourdfpy model --------------------------------------------------------------------------------

@contextlib.contextmanager
def _quiet(logger_name: str):
    """Silence a library's logger (its warnings would be extra lines on stderr)."""
    log = logging.getLogger(logger_name)
    old = log.level
    log.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        log.setLevel(old)


def _load_model(path: Path):
    with _quiet("yourdfpy"):
        import yourdfpy

        try:
            return yourdfpy.URDF.load(str(path), load_meshes=False, build_scene_graph=False,
                                      build_collision_scene_graph=False, load_collision_meshes=False)
        except Exception as e:  # the structure was checked; anything left is reported in one line
            msg = " ".join(str(e).split())
            raise InputError(str(path), f"cannot parse URDF ({type(e).__name__}: {msg})") from None


def _default_links(model, parent_joint: dict, base: str | None, tip: str | None, path: Path) -> tuple[str, str]:
    links = list(model.link_map)
    if base is None:
        roots = [ln for ln in links if ln not in parent_joint]
        if len(roots) != 1:
            raise InputError("--base", f"required: {path.name} has {len(roots)} root links ({', '.join(roots[:8])})")
        base = roots[0]
    if tip is None:
        parents = {j.parent for j in model.joint_map.values()}
        below = [ln for ln in links if ln not in parents and base in _ancestors(ln, parent_joint, model)]
        if len(below) != 1:
            raise InputError("--tip", f"required: link '{base}' has {len(below)} leaf links below it "
                                      f"({', '.join(below[:8])})")
        tip = below[0]
    return base, tip


def _ancestors(link: str, parent_joint: dict, model) -> list[str]:
    out, seen = [], {link}
    while link in parent_joint:
        link = model.joint_map[parent_joint[link]].parent
        if link in seen:
            break
        seen.add(link)
        out.append(link)
    return out


def _serial_path(model, parent_joint: dict, base: str, tip: str) -> list:
    """Joints from base to tip (base must be an ancestor of tip)."""
    if base == tip:
        raise InputError("--tip", f"is the same link as --base ('{base}')")
    joints, link, seen = [], tip, {tip}
    while link != base:
        if link not in parent_joint:
            raise InputError("--base", f"link '{base}' is not an ancestor of link '{tip}' (no serial path "
                                       f"from '{base}' to '{tip}')")
        j = model.joint_map[parent_joint[link]]
        joints.append(j)
        link = j.parent
        if link in seen:
            raise InputError(f"joint '{j.name}'", f"closes a kinematic loop through link '{link}'")
        seen.add(link)
    return joints[::-1]


def _velocity(lim, where: str) -> float | None:
    v = None if lim is None else lim.velocity
    if v is None or v == 0.0:
        return None
    if v < 0:
        raise InputError(f"{where} <limit velocity>", f"must not be negative (got {v:g})")
    return float(v)


def _joint(j) -> Joint:
    where = f"joint '{j.name}'"
    axis = np.asarray(j.axis if j.axis is not None else [1.0, 0.0, 0.0], dtype=float)
    if float(np.linalg.norm(axis)) < 1e-9:
        raise InputError(f"{where} <axis xyz>", "zero vector")
    lim = j.limit
    if j.type == "continuous":
        limits = Limits(None, None, _velocity(lim, where))
        jtype = "revolute"
    else:
        if lim is None or lim.lower is None or lim.upper is None:
            raise InputError(where, f"a {j.type} joint needs <limit lower=\"...\" upper=\"...\"/> "
                                    f"(use type=\"continuous\" for an unlimited revolute joint)")
        if lim.lower > lim.upper:
            raise InputError(f"{where} <limit>", f"lower {lim.lower:g} > upper {lim.upper:g}")
        limits = Limits(float(lim.lower), float(lim.upper), _velocity(lim, where))
        jtype = j.type
    return Joint(j.name, jtype, Pose(), axis / np.linalg.norm(axis), limits)


def from_urdf(path: str | os.PathLike, base: str | None = None, tip: str | None = None,
              name: str | None = None) -> Chain:
    """The chain from link ``base`` to link ``tip`` of a URDF file (see the module docstring)."""
    path = Path(path)
    if not path.is_file():
        raise InputError(str(path), "no such file")
    root = _parse_xml(path)
    _check_structure(root, path)
    model = _load_model(path)
    for arg, link in (("--base", base), ("--tip", tip)):
        if link is not None and link not in model.link_map:
            raise InputError(arg, f"no link named '{link}' in {path.name}")
    parent_joint = {j.child: j.name for j in model.joint_map.values()}
    base, tip = _default_links(model, parent_joint, base, tip, path)

    joints: list[Joint] = []
    acc = np.eye(4)  # fixed transforms since the last moving joint
    for j in _serial_path(model, parent_joint, base, tip):
        if j.type not in URDF_TYPES:
            raise InputError(f"joint '{j.name}'", f"unknown type '{j.type}' (URDF types: {', '.join(URDF_TYPES)})")
        if j.type in ("floating", "planar"):
            raise InputError(f"joint '{j.name}'", f"type '{j.type}' is not supported (on the path from "
                                                  f"'{base}' to '{tip}'; only 1-DOF and fixed joints are)")
        if j.mimic is not None and j.type != "fixed":
            raise InputError(f"joint '{j.name}'", f"mimic joints are not supported (it mimics joint "
                                                  f"'{j.mimic.joint}')")
        origin = np.eye(4) if j.origin is None else np.asarray(j.origin, dtype=float)
        acc = acc @ origin
        if j.type == "fixed":
            continue
        joint = _joint(j)
        joint.origin = Pose.from_matrix(acc)
        joints.append(joint)
        acc = np.eye(4)
    if not joints:
        raise InputError("--tip", f"no movable joint between '{base}' and '{tip}'")
    chain_name = name or model.robot.name or path.stem
    return canonical(Chain(chain_name, joints, Pose(), Pose.from_matrix(acc)))
