"""``tservo chain``: create, check and export chain descriptions (docs/chain-format.md).

    tservo chain from-urdf ROBOT.urdf [--base LINK] [--tip LINK] [--name NAME] -o CHAIN.json
    tservo chain from-dh TABLE.json -o CHAIN.json
    tservo chain validate CHAIN.json|NAME
    tservo chain export NAME -o CHAIN.json

``-o -`` writes to standard output.  Output files are written atomically and only after the whole
input has been read and validated: on an error nothing is created and an existing file is left as
it was.  The importers are imported lazily (yourdfpy takes a second or two to import).
"""
from __future__ import annotations

import argparse
import math
import sys

from . import chain as chain_mod
from . import robots
from .chain import Chain
from .errors import InputError


def _write(c: Chain, out: str) -> None:
    if out == "-":
        sys.stdout.write(c.to_json())
    else:
        c.save(out)
        print(f"wrote {out}: chain '{c.name}', {c.n} joints")


def _fmt_limit(v: float | None, unit: str) -> str:
    return "-" if v is None else f"{v:.4g} {unit}"


def summary(c: Chain, fits: dict[str, str | None]) -> str:
    """Human-readable summary: name, joint table, reach, and whether each configuration fits."""
    lines = [f"chain '{c.name}': {c.n} joints, {sum(j.prismatic for j in c.joints)} prismatic"]
    w = max(4, max(len(j.name) for j in c.joints))
    lines.append(f"  {'#':>2}  {'name':<{w}}  {'type':<9}  {'axis':<24}  {'lower':>11}  {'upper':>11}  "
                 f"{'velocity':>12}  scale")
    for i, j in enumerate(c.joints):
        u = "m" if j.prismatic else "rad"
        kind = j.type if j.prismatic or j.limits.bounded else "revolute*"
        axis = "[" + ", ".join(f"{a:+.3f}" for a in j.axis) + "]"
        lines.append(f"  {i:>2}  {j.name:<{w}}  {kind:<9}  {axis:<24}  {_fmt_limit(j.limits.lower, u):>11}  "
                     f"{_fmt_limit(j.limits.upper, u):>11}  {_fmt_limit(j.limits.velocity, u + '/s'):>12}  "
                     f"{j.scale:g}")
    if any(not j.prismatic and not j.limits.bounded for j in c.joints):
        lines.append("  (* continuous: no position limits)")
    base_d = math.hypot(*c.base.xyz)
    lines.append(f"reach: {chain_mod.reach(c):.4f} m (origins + tool + prismatic strokes; base offset "
                 f"{base_d:.4f} m)")
    lines.append("configurations:")
    for cfg, why in fits.items():
        lines.append(f"  {cfg:<8} {'fits' if why is None else 'does not fit: ' + why}")
    return "\n".join(lines)


# ---- commands ------------------------------------------------------------------------------------

def cmd_from_urdf(args: argparse.Namespace) -> int:
    from . import urdf

    _write(urdf.from_urdf(args.urdf, base=args.base, tip=args.tip, name=args.name), args.output)
    return 0


def cmd_from_dh(args: argparse.Namespace) -> int:
    from . import dh

    _write(dh.load(args.table), args.output)
    return 0


def cmd_validate(args: argparse.Namespace) -> int:
    from . import model

    c = chain_mod.load(args.chain)
    print(summary(c, model.check_config(c)))
    return 0


def cmd_export(args: argparse.Namespace) -> int:
    if args.name not in robots.names():
        raise InputError("NAME", f"unknown example '{args.name}' (examples: {', '.join(robots.names())})")
    _write(robots.load(args.name), args.output)
    return 0


def register(subparsers) -> None:
    p = subparsers.add_parser("chain", help="create, check and export chain descriptions",
                              description="Chain descriptions (JSON): import from URDF or DH tables, "
                                          "validate, export the embedded examples.")
    sub = p.add_subparsers(dest="chain_command", metavar="SUBCOMMAND")
    sub.required = True
    out_help = "output chain JSON ('-' for standard output)"

    s = sub.add_parser("from-urdf", help="import the serial path between two links of a URDF",
                       description="Import the serial path from --base to --tip of a URDF file. Fixed "
                                   "joints are folded, continuous joints become unlimited revolute joints.")
    s.add_argument("urdf", metavar="ROBOT.urdf")
    s.add_argument("--base", metavar="LINK", help="root link of the chain (default: the URDF's root link)")
    s.add_argument("--tip", metavar="LINK", help="last link (default: the only leaf below --base)")
    s.add_argument("--name", help="chain name (default: the URDF robot name)")
    s.add_argument("-o", "--output", required=True, metavar="CHAIN.json", help=out_help)
    s.set_defaults(func=cmd_from_urdf)

    s = sub.add_parser("from-dh", help="convert a DH table (standard or modified)",
                       description="Convert a Denavit-Hartenberg table file (docs/chain-format.md) to a chain.")
    s.add_argument("table", metavar="TABLE.json")
    s.add_argument("-o", "--output", required=True, metavar="CHAIN.json", help=out_help)
    s.set_defaults(func=cmd_from_dh)

    s = sub.add_parser("validate", help="check a chain file and summarise it",
                       description="Validate a chain file (or embedded example) and print its joints, "
                                   "reach and whether it fits each number configuration. Exit 0 if valid.")
    s.add_argument("chain", metavar="CHAIN.json|NAME")
    s.set_defaults(func=cmd_validate)

    s = sub.add_parser("export", help="write an embedded example chain",
                       description="Write one of the embedded example chains to a file.")
    s.add_argument("name", metavar="NAME", help=f"one of {', '.join(robots.names())}")
    s.add_argument("-o", "--output", required=True, metavar="CHAIN.json", help=out_help)
    s.set_defaults(func=cmd_export)
