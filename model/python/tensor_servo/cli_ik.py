"""``tservo ik``: inverse kinematics by the servo in virtual mode (docs/ik.md).

    tservo ik CHAIN.json --targets T.npy --q0 Q0.npy [--model float|fixed] [--config default|compact]
              [--solver cd|pinv|dls] [--limits free|wrap|clip] [--restarts R] [--seed S]
              [--max-ticks N] [--tol-pos M] [--tol-rot R] -o OUT.npz

T is (N, 4, 4) tool poses in the root frame (rigid transforms), Q0 (n,) (one seed for every
target) or (N, n).  OUT holds ``q`` (N, n), always within the joint limits; ``ok`` (N,) the float
errors of the returned q are within --tol-pos / --tol-rot; ``ticks`` (N,) ticks spent;
``pos_err`` (N,) m and ``rot_err`` (N,) rad, measured in float (reference.py) on the returned q;
``converged`` (N,) the model's own test passed; ``attempts`` (N,).  ``--model float`` is the double
configuration of the same C++ servo, ``fixed`` the bit-accurate fixed-point model (``--config``);
``--solver pinv|dls`` are double-precision references (``--model float`` only).
"""
from __future__ import annotations

import numpy as np

from . import chain as chainmod
from . import ik
from .arrays import load_array, save_npz
from .errors import InputError


def register(sub) -> None:
    p = sub.add_parser("ik", help="inverse kinematics: the servo in virtual mode from seeds to target poses")
    p.add_argument("chain", help="chain JSON file or embedded example name")
    p.add_argument("--targets", required=True, help="target tool poses, .npy of shape (N, 4, 4)")
    p.add_argument("--q0", required=True, help="seeds, .npy of shape (n,) or (N, n)")
    p.add_argument("--model", choices=ik.MODELS, default="fixed", help="C++ servo in double (float) or fixed point")
    p.add_argument("--config", choices=("default", "compact"), default="default", help="fixed-point configuration")
    p.add_argument("--solver", choices=ik.SOLVERS, default="cd",
                   help="cd: the servo's coordinate descent; pinv, dls: double-precision references")
    p.add_argument("--limits", choices=ik.LIMITS, default="free",
                   help="joint limits during the search (answers are always within the limits)")
    p.add_argument("--restarts", type=int, default=0, help="further attempts from pseudo-random configurations")
    p.add_argument("--seed", type=int, default=0, help="seed of the restarts' configurations")
    p.add_argument("--max-ticks", type=int, default=1000, help="tick budget per target (all attempts)")
    p.add_argument("--tol-pos", type=float, default=1e-6, help="position tolerance (m)")
    p.add_argument("--tol-rot", type=float, default=1e-5, help="orientation tolerance (rad)")
    p.add_argument("-o", "--output", required=True, help="output .npz")
    p.set_defaults(func=cmd_ik)


def cmd_ik(args) -> int:
    ch = chainmod.load(args.chain)
    T = ik.check_targets(load_array(args.targets, "--targets"))
    q0 = ik.check_q0(ch, load_array(args.q0, "--q0"), len(T))
    if args.model == "fixed" and args.solver != "cd":
        raise InputError("--solver", f"{args.solver} is a double-precision reference: use --model float")
    r = ik.solve(ch, T, q0, model=args.model, config=args.config, solver=args.solver, limits=args.limits,
                 max_ticks=args.max_ticks, tol_pos=args.tol_pos, tol_rot=args.tol_rot,
                 restarts=args.restarts, seed=args.seed)
    save_npz(args.output, q=r.q, ok=r.ok, ticks=r.ticks, pos_err=r.pos_err, rot_err=r.rot_err,
             converged=r.converged, attempts=r.attempts)
    print(f"{int(r.ok.sum())}/{len(r.ok)} within {args.tol_pos:g} m / {args.tol_rot:g} rad; "
          f"median {int(np.median(r.ticks))} ticks; wrote {args.output}")
    return 0
