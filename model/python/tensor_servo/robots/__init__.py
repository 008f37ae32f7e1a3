"""Embedded example chains (JSON files in this folder; sources in docs/chain-format.md).

    names()      -> ['chain20', 'panda', 'puma560', 'stanford', 'ur5']
    load(name)   -> Chain
    path(name)   -> Path of the JSON file

The files are generated, not edited by hand: ``python -m tensor_servo.robots.regenerate`` rebuilds
them from the DH tables in ``dh/`` (puma560, ur5, panda, stanford) and from the synthetic recipe of
``chain20``; ``--check`` tells whether they are up to date.  Anywhere a chain file is accepted
(``chain.load``, the ``tservo`` commands) one of these names is accepted too.
"""
from __future__ import annotations

import json
from pathlib import Path

from ..chain import Chain, chain_from_dict
from ..errors import InputError

HERE = Path(__file__).resolve().parent


def names() -> list[str]:
    """Names of the embedded serial-chain examples, sorted."""
    return sorted(p.stem for p in HERE.glob("*.json"))


def tree_names() -> list[str]:
    """Names of the embedded trees of chains (several tips; seed section 12), in ``trees/``."""
    return sorted(p.stem for p in (HERE / "trees").glob("*.json"))


def path(name: str) -> Path:
    """The JSON file of an embedded example; InputError for an unknown name."""
    if name in tree_names():
        return HERE / "trees" / f"{name}.json"
    if name not in names():
        raise InputError(str(name), f"no such file or embedded example (examples: {', '.join(names() + tree_names())})")
    return HERE / f"{name}.json"


def load(name: str) -> Chain:
    """Load and validate an embedded example."""
    p = path(name)
    try:
        return chain_from_dict(json.loads(p.read_text()))
    except InputError as e:  # a broken embedded file is a packaging bug; say which file
        raise InputError(f"{p.name}: {e.field}", e.problem) from None
