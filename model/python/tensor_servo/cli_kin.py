"""``tservo fk``, ``tservo jacobian`` and ``tservo golden``.

    tservo jacobian CHAIN.json --q Q.npy [--model float|double|fixed] [--config default|compact]
                    [--basis base|tool] -o OUT.npz
    tservo fk CHAIN.json --q Q.npy [--model ...] [--config ...] -o OUT.npz
    tservo golden -o DIR

Q is (N, n).  OUT holds ``T`` (N,4,4), the tool pose in the root frame; ``J`` (N,6,n), rows
(omega; v), reference point = tool origin, axes of the requested basis; for ``fk`` also ``frames``
(N,n+2,4,4) (base, joint frames after motion, tool).  Models: ``float`` is the numpy reference
(the seed's construction), ``double`` the C++ model instantiated on double, ``fixed`` the
bit-accurate model (``--config``), whose results are converted to float64 and which adds
``overflow`` (N,) and ``flags`` (N,) and the raw integers (``*_raw``).
"""
from __future__ import annotations

import argparse

import numpy as np

from . import chain as chainmod
from .arrays import load_q, save_npz
from .errors import InputError

MODELS = ("float", "double", "fixed")


def _add_common(p: argparse.ArgumentParser) -> None:
    p.add_argument("chain", help="chain JSON file or embedded example name")
    p.add_argument("--q", required=True, help="joint values, .npy of shape (N, n)")
    p.add_argument("--model", choices=MODELS, default="fixed", help="float reference, C++ double, or fixed point")
    p.add_argument("--config", choices=("default", "compact"), default="default", help="fixed-point configuration")
    p.add_argument("-o", "--output", required=True, help="output .npz")


def register(sub) -> None:
    p = sub.add_parser("fk", help="forward kinematics of every frame")
    _add_common(p)
    p.set_defaults(func=cmd_fk)
    p = sub.add_parser("jacobian", help="tool pose and Jacobian (omega; v) at the tool origin")
    _add_common(p)
    p.add_argument("--basis", choices=("base", "tool"), default="base", help="axes the Jacobian is expressed in")
    p.set_defaults(func=cmd_jacobian)
    p = sub.add_parser("golden", help="write golden vectors (inputs and expected raw outputs)")
    p.add_argument("-o", "--output", required=True, help="output folder (e.g. tb/golden)")
    p.add_argument("--samples", type=int, default=64, help="configurations per chain and configuration")
    p.set_defaults(func=cmd_golden)


def _load(args):
    ch = chainmod.load(args.chain)
    q = load_q(args.q, ch.n)
    return ch, q


def _fixed_model(ch, q, config):
    from .model import Model, formats

    m = Model(ch, config)
    _, ok = m.quantize_q(q)
    if not ok.all():
        s = int(np.argmin(ok))
        W, I = formats(config)["angle_t"]
        lim = 2.0 ** (I - 1)
        j = int(np.argmax(np.abs(q[s]) >= lim - 2.0 ** (I - W)))
        raise InputError("--q", f"sample {s}, joint {j}: value {q[s, j]:g} outside the {config} joint-value "
                                f"format ap_fixed<{W},{I}> (|q| < {lim:g})")
    return m


def cmd_fk(args) -> int:
    ch, q = _load(args)
    out = {}
    if args.model == "float":
        from . import reference

        frames = np.array([reference.fk_frames(ch, qs) for qs in q]).reshape(len(q), ch.n + 2, 4, 4)
    else:
        m = _fixed_model(ch, q, args.config) if args.model == "fixed" else _model_double(ch)
        r = m.fk(q)
        frames = r.T
        if args.model == "fixed":
            out.update(overflow=r.overflow, flags=r.flags, quat_raw=r.quat_raw, pos_raw=r.pos_raw)
    out.update(T=frames[:, -1], frames=frames)
    save_npz(args.output, **out)
    return 0


def _model_double(ch):
    from .model import Model

    return Model(ch, "double")


def cmd_jacobian(args) -> int:
    ch, q = _load(args)
    out = {}
    if args.model == "float":
        from . import reference

        T = np.array([reference.fk_frames(ch, qs)[-1] for qs in q]).reshape(len(q), 4, 4)
        J = np.array([reference.jacobian(ch, qs, ref="tool", basis=args.basis) for qs in q]).reshape(len(q), 6, ch.n)
    else:
        m = _fixed_model(ch, q, args.config) if args.model == "fixed" else _model_double(ch)
        r = m.jacobian(q, ref="tool", basis=args.basis)
        T, J = r.T[:, -1], r.J
        if args.model == "fixed":
            out.update(overflow=r.overflow, flags=r.flags, J_raw=r.J_raw, quat_raw=r.quat_raw[:, -1], pos_raw=r.pos_raw[:, -1])
    out.update(T=T, J=J)
    save_npz(args.output, **out)
    return 0


def cmd_golden(args) -> int:
    from . import golden

    if args.samples < 1:
        raise InputError("--samples", "must be at least 1")
    for path in golden.write_all(args.output, samples=args.samples):
        print(path)
    return 0
