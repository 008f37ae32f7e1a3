"""IK benchmark: the servo in virtual mode against peers, same targets, same seeds, one run.

    table, verdict = bench_ik(n_targets=1000)

For each chain (PUMA 560, UR5, Panda, Stanford arm, chain20): ``n_targets`` reachable targets, the
tool poses (float reference) of uniformly random configurations within the limits, and two kinds
of seeds: *near* = the target's configuration + U(-0.1, 0.1) rad on every joint, clipped to the
limits; *random* = a uniformly random configuration.  Every solver's answer is checked the same
way: revolute joints outside their range are shifted by whole turns (same pose) and the answer
must then lie within the limits; position error |p - p_t| and orientation error angle(R_t^T R) by
the float reference, against 1e-4 m / 1e-3 rad ("loose") and 1e-6 m / 1e-5 rad ("tight").

Solvers (each stops on the tight tolerance, or tighter, and is scored at both):
  tservo CD double    ``ik.solve(model="float")``: the C++ servo in the double configuration
  tservo CD default   ``ik.solve(model="fixed", config="default")``: bit-accurate fixed point
  tservo CD compact   ``config="compact"``, run and scored at the loose tolerance only (its FK
                      error is ~0.2 mm)
  rtb ik_LM           roboticstoolbox ``ETS.ik_LM`` on an ETS built from the chain (FK checked
                      against ours), ``slimit=1`` (seed only), ``ilimit=30`` (default),
                      ``tol=5e-13`` (E = e^T e / 2: both errors < 1e-6), ``joint_limits=False``
                      (the limits are checked on the answer, after whole-turn shifts, as for
                      everyone: with ``True`` and ``slimit=1`` a search that ends out of limits
                      returns a meaningless q)
  Pinocchio CLIK      the loop of Pinocchio's inverse-kinematics example on the tool frame:
                      err = log6(oMtool^-1 oMdes), J = -Jlog6(...) J_frame,
                      q = integrate(q, -J^T (J J^T + 1e-12 I)^-1 err * 0.1), stop when
                      |err| < 1e-7 or after 1000 iterations; limits checked at the end
  ikpy                an ikpy Chain built from the chain's links (FK checked against ours),
                      ``inverse_kinematics_frame(..., orientation_mode="all", tol=1e-12)``
                      (scipy least_squares with bounds); "iterations" = FK evaluations

Times: peers per call from Python (wall clock, median over the targets).  tservo: the C++ model's
time per tick on this CPU (measured separately, FK + Jacobian + servo law + sweeps) times the ticks
of the target, plus one final test tick; the Python driver that batches the targets is not
counted.  Slow peers (Python loops) get a time budget per chain and seed kind; when it runs out,
the row reports the targets it reached (column n).
"""
from __future__ import annotations

import dataclasses
import datetime
import math
import os
import platform
import time
import warnings

import numpy as np

from . import ik, reference, robots
from .chain import Chain, matrix_to_quat

ROBOTS = ["puma560", "ur5", "panda", "stanford", "chain20"]
LOOSE = (1e-4, 1e-3)
TIGHT = (1e-6, 1e-5)


# ---- peers' models of our chains ------------------------------------------------------------------

def _align_z(a: np.ndarray) -> np.ndarray:
    """A rotation R with R e_z = a (unit vector)."""
    a = np.asarray(a, dtype=float)
    c = float(a[2])
    if c > 1 - 1e-15:
        return np.eye(3)
    if c < -1 + 1e-15:
        return np.diag([1.0, -1.0, -1.0])
    v = np.cross([0.0, 0.0, 1.0], a)
    s = float(np.linalg.norm(v))
    return reference.rotation(v / s, math.atan2(s, c))


def rtb_ets(chain: Chain):
    """roboticstoolbox ETS of the chain: constant SE3 + Rz/tz per joint (the joint axis is turned
    onto z and back).  Joint variable = scale * q."""
    import roboticstoolbox as rtb

    ets = []
    pre = chain.base.matrix()
    for j in chain.joints:
        R = np.eye(4)
        R[:3, :3] = _align_z(j.axis)
        M = pre @ j.origin.matrix() @ R
        if not np.array_equal(M, np.eye(4)):
            ets.append(rtb.ET.SE3(M))
        qlim = None if j.limits.lower is None else np.sort([j.scale * j.limits.lower, j.scale * j.limits.upper])
        ets.append(rtb.ET.tz(qlim=qlim) if j.prismatic else rtb.ET.Rz(qlim=qlim))
        pre = np.eye(4)
        pre[:3, :3] = R[:3, :3].T
    ets.append(rtb.ET.SE3(pre @ chain.tool.matrix()))
    return rtb.ETS(ets)


def _rpy(R: np.ndarray) -> np.ndarray:
    """(roll, pitch, yaw) with R = Rz(yaw) Ry(pitch) Rx(roll) (ikpy's convention)."""
    p = math.asin(-max(-1.0, min(1.0, R[2, 0])))
    if abs(math.cos(p)) > 1e-9:
        return np.array([math.atan2(R[2, 1], R[2, 2]), p, math.atan2(R[1, 0], R[0, 0])])
    return np.array([math.atan2(-R[1, 2], R[1, 1]), p, 0.0])


def ikpy_chain(chain: Chain):
    """ikpy Chain: origin link, one URDFLink per joint (base folded into the first origin), the tool
    as a fixed link.  Joint variable = scale * q."""
    from ikpy.chain import Chain as IChain
    from ikpy.link import OriginLink, URDFLink

    links = [OriginLink()]
    pre = chain.base.matrix()
    for j in chain.joints:
        M = pre @ j.origin.matrix()
        b = (-np.inf, np.inf) if j.limits.lower is None else tuple(np.sort([j.scale * j.limits.lower, j.scale * j.limits.upper]))
        kw = {"translation": np.asarray(j.axis), "joint_type": "prismatic"} if j.prismatic else {"rotation": np.asarray(j.axis)}
        links.append(URDFLink(j.name, M[:3, 3], _rpy(M[:3, :3]), bounds=b, **kw))
        pre = np.eye(4)
    M = chain.tool.matrix()
    links.append(URDFLink("tool", M[:3, 3], _rpy(M[:3, :3]), joint_type="fixed"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return IChain(links, active_links_mask=[False] + [True] * chain.n + [False])


def check_peer_fk(chain: Chain, rng: np.random.Generator, samples: int = 20) -> dict[str, float]:
    """Largest |T_peer - T_ours| over random configurations, per peer model."""
    from .oracle import PinChain

    s = chain.scales
    ets, ic, pc = rtb_ets(chain), ikpy_chain(chain), PinChain(chain)
    err = {"rtb": 0.0, "ikpy": 0.0, "pinocchio": 0.0}
    for q in chain.random_q(rng, samples):
        T = reference.fk_frames(chain, q)[chain.n + 1]
        err["rtb"] = max(err["rtb"], float(np.abs(ets.fkine(s * q).A - T).max()))
        err["ikpy"] = max(err["ikpy"], float(np.abs(ic.forward_kinematics(np.r_[0.0, s * q, 0.0]) - T).max()))
        err["pinocchio"] = max(err["pinocchio"], float(np.abs(pc.tool_pose(q) - T).max()))
    return err


# ---- runners: (q (m, n), iterations (m,), seconds (m,)) for the first m targets -----------------

def run_rtb(chain, T, Q0, budget):
    ets = rtb_ets(chain)
    s = chain.scales
    Q, its, tm = [], [], []
    t_start = time.perf_counter()
    for q0, Tt in zip(Q0, T):
        t0 = time.perf_counter()
        sol = ets.ik_LM(Tt, q0=s * q0, ilimit=30, slimit=1, tol=5e-13, joint_limits=False)
        tm.append(time.perf_counter() - t0)
        Q.append(np.asarray(sol.q, dtype=float) / s)
        its.append(int(sol.iterations))
        if time.perf_counter() - t_start > budget:
            break
    return np.array(Q), np.array(its), np.array(tm)


def run_clik(chain, T, Q0, budget, eps=1e-7, it_max=1000, DT=1e-1, damp=1e-12):
    import pinocchio as pin

    from .oracle import PinChain

    pc = PinChain(chain)
    model, data, fid = pc.model, pc.data, pc.tool_id
    s = chain.scales
    Q, its, tm = [], [], []
    t_start = time.perf_counter()
    for q0, Tt in zip(Q0, T):
        oMdes = pin.SE3(Tt[:3, :3].copy(), Tt[:3, 3].copy())
        t0 = time.perf_counter()
        q = s * q0
        i = 0
        while True:
            pin.framesForwardKinematics(model, data, q)
            iMd = data.oMf[fid].actInv(oMdes)
            err = pin.log(iMd).vector
            if np.linalg.norm(err) < eps or i >= it_max:
                break
            J = pin.computeFrameJacobian(model, data, q, fid)
            J = -np.dot(pin.Jlog6(iMd.inverse()), J)
            v = -J.T.dot(np.linalg.solve(J.dot(J.T) + damp * np.eye(6), err))
            q = pin.integrate(model, q, v * DT)
            i += 1
        tm.append(time.perf_counter() - t0)
        Q.append(np.asarray(q) / s)
        its.append(i)
        if time.perf_counter() - t_start > budget:
            break
    return np.array(Q), np.array(its), np.array(tm)


def run_ikpy(chain, T, Q0, budget):
    ic = ikpy_chain(chain)
    s = chain.scales
    calls = [0]
    fk = ic.forward_kinematics

    def counted(*a, **k):
        calls[0] += 1
        return fk(*a, **k)

    ic.forward_kinematics = counted
    Q, its, tm = [], [], []
    t_start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for q0, Tt in zip(Q0, T):
            calls[0] = 0
            t0 = time.perf_counter()
            x = ic.inverse_kinematics_frame(Tt, initial_position=np.r_[0.0, s * q0, 0.0], orientation_mode="all", tol=1e-12)
            tm.append(time.perf_counter() - t0)
            Q.append(np.asarray(x[1:-1], dtype=float) / s)
            its.append(calls[0])
            if time.perf_counter() - t_start > budget:
                break
    return np.array(Q), np.array(its), np.array(tm)


_TICK_CACHE: dict = {}


def tick_seconds(chain: Chain, model: str, config: str, params: ik.IKParams, samples: int = 64, ticks: int = 10) -> float:
    """Time of one servo tick of the C++ model (FK, Jacobian, servo law, sweeps) on this CPU: the
    fastest of three runs of ``samples`` x ``ticks + 1`` ticks that never converge."""
    cfg = "double" if model == "float" else config
    key = (chain.name, chain.n, cfg, params.sweeps, params.mu)
    if key in _TICK_CACHE:
        return _TICK_CACHE[key]
    eng = ik._CDEngine(chain, cfg, params)
    rng = np.random.default_rng(7)
    q = chain.random_q(rng, samples)
    qt = chain.random_q(rng, samples)
    T = np.array([reference.fk_frames(chain, x)[chain.n + 1] for x in qt])
    quat = np.array([matrix_to_quat(t[:3, :3]) for t in T])
    pos = np.ascontiguousarray(T[:, :3, 3])
    best = math.inf
    for _ in range(3):
        t0 = time.perf_counter()
        eng.servo._s.ik(q, quat, pos, ticks, 0.0, 0.0)
        best = min(best, (time.perf_counter() - t0) / (samples * (ticks + 1)))
    _TICK_CACHE[key] = best
    return best


def run_servo(chain, T, Q0, model, config, tol, params, max_ticks):
    r = ik.solve(chain, T, Q0, model=model, config=config, tol_pos=tol[0], tol_rot=tol[1], max_ticks=max_ticks, params=params)
    t_base = tick_seconds(chain, model, config, params)
    t_pol = tick_seconds(chain, model, config, ik.polish_params(params, chain.n)) if params.polish_after is not None else t_base
    pt = r.polish_ticks if r.polish_ticks is not None else np.zeros_like(r.ticks)
    return r.q, r.ticks, (r.ticks - pt + 1) * t_base + pt * t_pol


# ---- scoring and the table ---------------------------------------------------------------------------

def score(chain: Chain, T: np.ndarray, Q: np.ndarray) -> dict[str, np.ndarray]:
    """Success flags at both tolerances, after whole-turn shifts, limits checked."""
    Q = ik.wrap_into_limits(chain, Q)
    pe, re = ik.pose_errors(chain, Q, T[: len(Q)])
    inside = np.all((Q >= chain.lower) & (Q <= chain.upper), axis=1)
    return {"loose": inside & (pe <= LOOSE[0]) & (re <= LOOSE[1]),
            "tight": inside & (pe <= TIGHT[0]) & (re <= TIGHT[1]), "inside": inside}


def problems(chain: Chain, n: int, seed: int):
    rng = np.random.default_rng(seed)
    qt = chain.random_q(rng, n)
    T = np.array([reference.fk_frames(chain, q)[chain.n + 1] for q in qt])
    near = np.clip(qt + rng.uniform(-0.1, 0.1, qt.shape), chain.lower, chain.upper)
    far = chain.random_q(rng, n)
    return T, {"near": near, "random": far}


def _pct(x: np.ndarray) -> str:
    return f"{100.0 * x.mean():.1f} %"


def bench_ik(n_targets: int = 1000, chains: list[str] | None = None, seed: int = 2026, peer_budget: float = 20.0,
             max_ticks: int = 1000, restarts: int = 9, peers: bool = True, progress=None) -> tuple[str, str]:
    """Run the benchmark; returns (markdown table with its header lines, verdict lines).
    ``peer_budget``: seconds per slow peer (Pinocchio CLIK, ikpy) per chain and seed kind."""
    say = progress or (lambda *a: None)
    chains = chains or ROBOTS
    params = ik.IKParams()
    rows = []
    res = {}  # (chain, seeds, solver) -> dict
    fk_check = {}
    t_all = time.perf_counter()
    for name in chains:
        ch = robots.load(name)
        T, seeds = problems(ch, n_targets, seed)
        if peers:
            fk_check[name] = check_peer_fk(ch, np.random.default_rng(seed + 1))
        for kind, Q0 in seeds.items():
            runs = [
                ("tservo CD double", lambda: run_servo(ch, T, Q0, "float", "double", TIGHT, params, max_ticks), True),
                ("tservo CD fixed default", lambda: run_servo(ch, T, Q0, "fixed", "default", TIGHT, params, max_ticks), True),
                ("tservo CD fixed compact", lambda: run_servo(ch, T, Q0, "fixed", "compact", LOOSE, params, max_ticks), False),
            ]
            if restarts and kind == "random":
                rp = dataclasses.replace(params, restarts=restarts)
                runs.append((f"tservo CD fixed default, restarts={restarts}",  # noqa: B023
                             lambda: run_servo(ch, T, Q0, "fixed", "default", TIGHT, rp, max_ticks), True))
            if peers:
                runs += [
                    ("rtb ik_LM (slimit=1)", lambda: run_rtb(ch, T, Q0, math.inf), True),
                    ("Pinocchio CLIK", lambda: run_clik(ch, T, Q0, peer_budget), True),
                    ("ikpy", lambda: run_ikpy(ch, T, Q0, peer_budget), True),
                ]
            for label, fn, tight in runs:
                t0 = time.perf_counter()
                Q, its, tm = fn()
                sc = score(ch, T, Q)
                d = {"loose": sc["loose"].mean(), "tight": sc["tight"].mean() if tight else math.nan,
                     "time": float(np.median(tm)), "its": float(np.median(its)), "m": len(Q)}
                res[(name, kind, label)] = d
                rows.append((name, kind, label, d, tight))
                say(f"  {name:9s} {kind:6s} {label:24s} loose {100 * d['loose']:5.1f} % tight "
                    f"{100 * d['tight']:5.1f} % med {d['its']:g} it {1e3 * d['time']:.3f} ms n={d['m']} "
                    f"({time.perf_counter() - t0:.1f} s)")
    elapsed = time.perf_counter() - t_all

    cpu = _cpu()
    head = [
        f"Measured {datetime.date.today().isoformat()} on {cpu} ({os.cpu_count()} cores), {n_targets} targets per chain "
        f"and seed kind (seed {seed}), whole run {elapsed / 60:.1f} min.",
        "",
        "| chain | seeds | solver | success 1e-4 m / 1e-3 rad | success 1e-6 m / 1e-5 rad | median time (ms) | median iterations | n |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, kind, label, d, tight in rows:
        t = f"{100 * d['tight']:.1f} %" if tight else "–"
        it = f"{d['its']:g}" + (" FK evals" if label == "ikpy" else (" ticks" if label.startswith("tservo") else ""))
        head.append(f"| {name} | {kind} | {label} | {100 * d['loose']:.1f} % | {t} | {1e3 * d['time']:.3f} | {it} | {d['m']} |")
    if fk_check:
        worst = {k: max(v[k] for v in fk_check.values()) for k in ("rtb", "ikpy", "pinocchio")}
        head += ["", "Peer models of the chains agree with the float reference: largest |T_peer - T| = " +
                 ", ".join(f"{k} {v:.1e}" for k, v in worst.items()) + "."]
    table = "\n".join(head)
    return table, verdict(res, chains)


def verdict(res: dict, chains: list[str]) -> str:
    lines = []
    for label in ("tservo CD double", "tservo CD fixed default"):
        for tol in ("loose", "tight"):
            vals = {c: res[(c, "near", label)][tol] for c in chains if (c, "near", label) in res}
            if not vals:
                continue
            w = min(vals.values())
            where = ", ".join(c for c, v in vals.items() if v == w) if w < max(vals.values()) else "every chain"
            met = "met" if w >= 0.999 else "MISSED"
            lines.append(f"- Goal near seeds >= 99.9 % ({label}, {tol}): worst {100 * w:.1f} % ({where}) -> {met}.")
    peer = "rtb ik_LM (slimit=1)"
    for label in ("tservo CD double", "tservo CD fixed default"):
        for tol in ("loose", "tight"):
            cmp = []
            for c in chains:
                a, b = res.get((c, "random", label)), res.get((c, "random", peer))
                if a and b:
                    cmp.append((a[tol] - b[tol], c, a[tol], b[tol]))
            if cmp:
                bad = [x for x in cmp if x[0] < 0]
                if bad:
                    s = ", ".join(f"{c} {100 * a:.1f} vs {100 * b:.1f} %" for _, c, a, b in bad)
                    lines.append(f"- Goal random seeds >= ik_LM ({label}, {tol}): MISSED on {s}.")
                else:
                    lines.append(f"- Goal random seeds >= ik_LM ({label}, {tol}): met on every chain.")
    for label, kind, tol in (("tservo CD fixed compact", "near", "loose"), ("tservo CD fixed default, restarts=9", "random", "tight")):
        vals = {k[0]: res[k][tol] for k in res if k[1] == kind and k[2] == label}
        if vals:
            w = min(vals.values())
            where = ", ".join(c for c, v in vals.items() if v == w)
            lines.append(f"- For information: {label}, {kind} seeds, {tol}: worst {100 * w:.1f} % ({where}).")
    return "\n".join(lines)


STUDY_VARIANTS = [
    ("**default** (free, clip phase from the seed, polish, stall test)", {}),
    ("limits = clip (the core's rule during the search)", {"limits": "clip"}),
    ("limits = wrap (full-turn joints only)", {"limits": "wrap"}),
    ("free, clip phase from the clamped answer", {"clip_from_seed": False}),
    ("no polish (30 sweeps, mu 1.6 throughout)", {"polish_after": None}),
    ("polish without the conjugate-direction refinement", {"polish_cg": 0}),
    ("refinement from 1e-3 m (cg_below)", {"cg_below": 1e-3}),
    ("no stall test", {"stall_window": None}),
    ("dt = 1/32 (K = 32: V and q' saturate on far seeds)", {"dt": 1 / 32}),
    ("L = 0.5 m", {"L": 0.5}),
    ("10 sweeps, mu 1.5 (tracking defaults), no polish", {"sweeps": 10, "mu": 1.5, "polish_after": None}),
]


def _solve_cell(ch: Chain, T: np.ndarray, Q0: np.ndarray, model: str, kw: dict):
    """ik.solve with overrides kw; (result, "success loose / tight" in %)."""
    r = ik.solve(ch, T, Q0, model=model, **kw)
    sc = score(ch, T, r.q)
    return r, f"{100 * sc['loose'].mean():.1f} / {100 * sc['tight'].mean():.1f}"


def study(n_targets: int = 500, chains: list[str] | None = None, seed: int = 11, model: str = "fixed",
          progress=None) -> str:
    """The parameter / limit-strategy study of docs/ik.md: one markdown row per chain and variant,
    cells = success loose / tight (%) and median ticks for near and random seeds."""
    say = progress or (lambda *a: None)
    out = ["| chain | variant | near: loose / tight | ticks | random: loose / tight | ticks |",
           "|---|---|---|---|---|---|"]
    for name in chains or ["puma560", "ur5", "panda", "stanford"]:
        ch = robots.load(name)
        T, seeds = problems(ch, n_targets, seed)
        for label, kw in STUDY_VARIANTS:
            cells = []
            for kind in ("near", "random"):
                r, cell = _solve_cell(ch, T, seeds[kind], model, kw)
                cells.append(f"{cell} | {np.median(r.ticks):g}")
            out.append(f"| {name} | {label} | " + " | ".join(cells) + " |")
            say(out[-1])
    return "\n".join(out)


GATE_THRESHOLDS = (1e-3, 1e-2, 3e-2, 1e-1, 3e-1)


def gate_study(n_targets: int = 1000, chains: list[str] | None = None, seed: int = 2026, progress=None) -> str:
    """The refinement's gate (docs/ik.md, "Ill-conditioned targets"): success loose / tight (%) on
    the benchmark's problems without the refinement and with it from each ``cg_below`` threshold,
    in double and default fixed point."""
    say = progress or (lambda *a: None)
    cols = [("none", {"polish_cg": 0})] + [(f"{t:g}", {"cg_below": t}) for t in GATE_THRESHOLDS]
    out = ["| chain, number type, seeds | " + " | ".join(c for c, _ in cols) + " |",
           "|---|" + "---|" * len(cols)]
    for name in chains or ["ur5", "panda"]:
        ch = robots.load(name)
        T, seeds = problems(ch, n_targets, seed)
        for model in ("float", "fixed"):
            for kind in ("near", "random"):
                cells = [_solve_cell(ch, T, seeds[kind], model, kw)[1] for _, kw in cols]
                out.append(f"| {name}, {'double' if model == 'float' else 'fixed'}, {kind} | " + " | ".join(cells) + " |")
                say(out[-1])
    return "\n".join(out)


def _cpu() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


if __name__ == "__main__":  # python -m tensor_servo.bench_ik [N] | ... study [N] | ... gate [N]
    import sys

    if len(sys.argv) > 1 and sys.argv[1] == "study":
        study(int(sys.argv[2]) if len(sys.argv) > 2 else 500, progress=print)
    elif len(sys.argv) > 1 and sys.argv[1] == "gate":
        print(gate_study(int(sys.argv[2]) if len(sys.argv) > 2 else 1000, progress=print))
    else:
        n = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
        table, v = bench_ik(n, progress=print)
        print(table)
        print()
        print(v)
