"""Golden vectors of the RTL datapath primitives, from the bit-accurate model.

For each hardware primitive (rtl/ts_<module>.v) this module draws input vectors -- edge cases and
seeded random ones -- and computes the expected outputs with the C++ model through its bindings
(``tensor_servo._model.prim_*``), all as raw two's-complement integers of the model's formats
(value = raw * 2^-F).  The RTL benches (tb/) use the same generators for their fresh random vectors
and replay the committed files ``tb/golden/prim_<module>_<config>.npz``.

    python -m tensor_servo.golden_prims -o tb/golden            # write both configurations
    python -m tensor_servo.golden_prims -o tb/golden --check    # compare with the committed files

Modules and arrays (N vectors; ``status`` is the model's sticky status word, non-zero = a saturation):
  quat_mul         a (N,4), b (N,4) -> out (N,4), status
  quat_rotate      q (N,4), v_<kind> (N,3) for kind in axis, offset, jw, jv
                   -> out_<kind>_<fwd|inv> (N,3), status_<kind>_<fwd|inv>
  sincos           u (N,) -> out (N,2) = (sin, cos), status
  joint_quat       angle (N,), kturn (N,), axis (N,3) -> out (N,4), status
  screw_transport  q (N,4), axis (N,3), prismatic (N,), s (N,), p_ref (N,3), p_i (N,3)
                   -> z (N,3), w (N,3), v (N,3), status  (rotate 'axis' by q, then screw_column)
"""
from __future__ import annotations

import argparse
import math
import sys
import zlib
from pathlib import Path

import numpy as np

from . import _model

MODULES = ("quat_mul", "quat_rotate", "sincos", "joint_quat", "screw_transport")
CONFIGS = ("default", "compact")
#: rotate kinds: (vector, tmp, out) formats (model/bindings/module.cpp prim_rotate)
KINDS = {
    "axis": ("quat_t", "uvec_tmp_t", "quat_t"),
    "offset": ("len_t", "len_tmp_t", "pos_t"),
    "jw": ("jw_t", "jw_tmp_t", "jw_t"),
    "jv": ("jv_t", "jv_tmp_t", "jv_t"),
}


# ---- formats -------------------------------------------------------------------------------------
def fmt(cfg: str, name: str) -> tuple[int, int]:
    """(W, F) of a model format."""
    w, i = _model.formats(cfg)[name]
    return int(w), int(w - i)


def raw_max(w: int) -> int:
    return (1 << (w - 1)) - 1


def raw_min(w: int) -> int:
    return -(1 << (w - 1))


def to_raw(x, cfg: str, name: str) -> np.ndarray:
    """Quantise floats like fx::from_double (round half up, saturate)."""
    w, f = fmt(cfg, name)
    r = np.floor(np.ldexp(np.asarray(x, dtype=np.float64), f) + 0.5)
    return np.clip(r, raw_min(w), raw_max(w)).astype(np.int64)


def uniform_raw(rng, cfg: str, name: str, shape, frac: float = 1.0) -> np.ndarray:
    """Raw integers uniform over frac of the format's range."""
    w, _ = fmt(cfg, name)
    hi = max(1, int(frac * (1 << (w - 1))))
    return rng.integers(-hi, hi, size=shape, dtype=np.int64)


def unit_quats(rng, n: int) -> np.ndarray:
    g = rng.normal(size=(n, 4))
    return g / np.linalg.norm(g, axis=1, keepdims=True)


def unit_vecs(rng, n: int) -> np.ndarray:
    g = rng.normal(size=(n, 3))
    return g / np.linalg.norm(g, axis=1, keepdims=True)


def _mix(rng, n: int, parts: list[tuple[float, callable]]) -> np.ndarray:
    """n rows drawn from generators with the given weights, in random order."""
    counts = [int(round(w * n)) for w, _ in parts]
    counts[0] += n - sum(counts)
    rows = np.concatenate([g(c) for c, (_, g) in zip(counts, parts) if c > 0])
    return rows[rng.permutation(len(rows))]


def _cat(*arrays) -> np.ndarray:
    return np.concatenate([np.asarray(a, dtype=np.int64) for a in arrays])


# ---- quat_mul ------------------------------------------------------------------------------------
def _quat_mul_random(cfg, rng, n):
    def unit(c):
        return to_raw(unit_quats(rng, c), cfg, "quat_t")

    def raw(c):
        return uniform_raw(rng, cfg, "quat_t", (c, 4))

    def small(c):  # components well inside the range: products do not saturate, no unit norm
        return uniform_raw(rng, cfg, "quat_t", (c, 4), 0.25)
    a = _mix(rng, n, [(0.7, unit), (0.15, raw), (0.15, small)])
    b = _mix(rng, n, [(0.7, unit), (0.15, raw), (0.15, small)])
    return {"a": a, "b": b}


def _quat_mul_edges(cfg, rng):
    w, f = fmt(cfg, "quat_t")
    one, mx, mn = 1 << f, raw_max(w), raw_min(w)
    r = to_raw(unit_quats(rng, 8), cfg, "quat_t")
    ident = np.array([one, 0, 0, 0])
    conj = r * np.array([1, -1, -1, -1])
    pairs = [(np.zeros(4), np.zeros(4)), (ident, ident), (-ident, ident)]
    pairs += [(ident, x) for x in r[:3]] + [(x, ident) for x in r[3:6]]
    pairs += [(x, c) for x, c in zip(r, conj)]                         # q q* = identity (rounded)
    for k in range(1, 4):                                              # 180 degree rotations
        e = np.zeros(4, dtype=np.int64)
        e[k] = one
        pairs += [(e, e), (e, r[k]), (r[k], e)]
    pairs += [(r[0], r[0]), (r[1], r[1] + np.array([0, 1, -1, 1]))]     # parallel, nearly parallel
    full = [np.full(4, mx), np.full(4, mn), np.array([mx, mn, mx, mn]), np.array([mn, mx, mn, mx])]
    pairs += [(x, y) for x in full for y in full]                       # full scale: saturation
    half = 1 << (f - 1)                                                 # rounding ties (+-1/2, +-3/2 LSB)
    for x in (1, -1, 3, -3, 5, -5):
        pairs += [(np.array([x, 0, 0, 0]), np.array([half, 0, 0, 0])),
                  (np.array([0, x, 0, 0]), np.array([0, half, 0, 0]))]
    return {"a": np.array([p[0] for p in pairs], dtype=np.int64),
            "b": np.array([p[1] for p in pairs], dtype=np.int64)}


def _quat_mul_expected(cfg, ins):
    out, st = _model.prim_qmul(cfg, ins["a"], ins["b"])
    return {"out": np.asarray(out), "status": np.asarray(st)}


# ---- quat_rotate ---------------------------------------------------------------------------------
def _rotate_vec_random(cfg, kind, rng, n):
    vn = KINDS[kind][0]
    if kind == "axis":
        return _mix(rng, n, [(0.8, lambda c: to_raw(unit_vecs(rng, c), cfg, vn)),
                             (0.2, lambda c: uniform_raw(rng, cfg, vn, (c, 3)))])
    return _mix(rng, n, [(0.5, lambda c: uniform_raw(rng, cfg, vn, (c, 3), 0.5)),
                         (0.5, lambda c: uniform_raw(rng, cfg, vn, (c, 3)))])


def _quat_rotate_random(cfg, rng, n):
    q = _mix(rng, n, [(0.85, lambda c: to_raw(unit_quats(rng, c), cfg, "quat_t")),
                      (0.15, lambda c: uniform_raw(rng, cfg, "quat_t", (c, 4)))])
    d = {"q": q}
    for kind in KINDS:
        d[f"v_{kind}"] = _rotate_vec_random(cfg, kind, rng, n)
    return d


def _quat_rotate_edges(cfg, rng):
    qw, qf = fmt(cfg, "quat_t")
    one = 1 << qf
    qs = [np.array([one, 0, 0, 0]), np.array([-one, 0, 0, 0]), np.zeros(4, dtype=np.int64)]
    qs += [np.eye(4, dtype=np.int64)[k] * one for k in range(1, 4)]               # 180 degrees
    s = 1.0 / math.sqrt(2.0)
    qs += [to_raw([s, s, 0, 0], cfg, "quat_t"), to_raw([s, 0, 0, -s], cfg, "quat_t")]  # 90 degrees
    qs += [np.full(4, raw_max(qw)), np.full(4, raw_min(qw))]                      # full scale
    ru = to_raw(unit_quats(rng, 4), cfg, "quat_t")
    qs += list(ru)
    nq = len(qs)
    d = {}
    rows_q = []
    rows_v = {k: [] for k in KINDS}
    for kind in KINDS:
        vn = KINDS[kind][0]
        vw, vf = fmt(cfg, vn)
        unit = 1 << vf
        vs = [np.zeros(3, dtype=np.int64)] + [np.eye(3, dtype=np.int64)[k] * unit for k in range(3)]
        vs += [-np.eye(3, dtype=np.int64)[k] * unit for k in range(3)]
        vs += [np.full(3, raw_max(vw)), np.full(3, raw_min(vw)), np.array([raw_max(vw), raw_min(vw), raw_max(vw)])]
        rows_v[kind] = vs
    nv = len(rows_v["axis"])
    for i in range(nq):
        for j in range(nv):
            rows_q.append(qs[i])
    d["q"] = np.array(rows_q, dtype=np.int64)
    for kind in KINDS:
        d[f"v_{kind}"] = np.array([rows_v[kind][j] for i in range(nq) for j in range(nv)], dtype=np.int64)
    # v parallel and nearly parallel to the vector part of q (q_v x v = 0: t = 0)
    extra_q, extra_v = [], {k: [] for k in KINDS}
    for x in ru:
        for eps in (0, 1, -1):
            extra_q.append(x)
            for kind in KINDS:
                vn = KINDS[kind][0]
                _, vf = fmt(cfg, vn)
                vec = np.floor(np.ldexp(x[1:].astype(np.float64), vf - qf) + 0.5).astype(np.int64)
                extra_v[kind].append(vec + np.array([eps, 0, -eps]))
    d["q"] = _cat(d["q"], np.array(extra_q))
    for kind in KINDS:
        d[f"v_{kind}"] = _cat(d[f"v_{kind}"], np.array(extra_v[kind]))
    return d


def _quat_rotate_expected(cfg, ins):
    d = {}
    for kind in KINDS:
        for inv in (False, True):
            out, st = _model.prim_rotate(cfg, kind, inv, ins["q"], ins[f"v_{kind}"])
            tag = f"{kind}_{'inv' if inv else 'fwd'}"
            d[f"out_{tag}"] = np.asarray(out)
            d[f"status_{tag}"] = np.asarray(st)
    return d


# ---- sincos --------------------------------------------------------------------------------------
def sincos_fields(cfg: str) -> tuple[int, int, int]:
    """(turn width W_u, table bits T, residual bits R)."""
    wu, _ = fmt(cfg, "turn_t")
    t = int(_model.formats(cfg)["TRIG_TABLE_BITS"])
    return wu, t, wu - 2 - t


def _sincos_random(cfg, rng, n):
    wu, _, _ = sincos_fields(cfg)
    return {"u": rng.integers(0, 1 << wu, size=n, dtype=np.int64)}


def _sincos_edges(cfg, rng):
    wu, t, r = sincos_fields(cfg)
    us = [0, (1 << wu) - 1, 1]
    for qd in range(4):                                   # quadrant boundaries
        base = qd << (wu - 2)
        us += [(base + e) % (1 << wu) for e in (-1, 0, 1)]
    for qd in range(4):                                   # every table index, residual 0, in every quadrant
        for k in range(1 << t):
            us.append((qd << (wu - 2)) | (k << r))
    for k in range(1 << t):                               # every index with the largest residual
        us.append((k << r) | ((1 << r) - 1))
    us += [(k << r) | (1 << (r - 1)) for k in range(0, 1 << t, 17)]   # half-way residuals
    return {"u": np.array(us, dtype=np.int64)}


def _sincos_expected(cfg, ins):
    out, st = _model.prim_sincos(cfg, ins["u"])
    return {"out": np.asarray(out), "status": np.asarray(st)}


# ---- joint_quat ----------------------------------------------------------------------------------
def _joint_quat_random(cfg, rng, n):
    angle = uniform_raw(rng, cfg, "angle_t", n)
    kturn = uniform_raw(rng, cfg, "kturn_t", n)
    axis = _mix(rng, n, [(0.9, lambda c: to_raw(unit_vecs(rng, c), cfg, "quat_t")),
                         (0.1, lambda c: uniform_raw(rng, cfg, "quat_t", (c, 3)))])
    return {"angle": angle, "kturn": kturn, "axis": axis}


def _joint_quat_edges(cfg, rng):
    aw, af = fmt(cfg, "angle_t")
    kw, kf = fmt(cfg, "kturn_t")
    qw, qf = fmt(cfg, "quat_t")
    one = 1 << qf
    axes = [np.eye(3, dtype=np.int64)[k] * one for k in range(3)] + [-np.eye(3, dtype=np.int64)[2] * one]
    axes += list(to_raw(unit_vecs(rng, 2), cfg, "quat_t")) + [np.full(3, raw_max(qw)), np.full(3, raw_min(qw))]
    angles = [0, 1, -1, raw_max(aw), raw_min(aw), 1 << af, -(1 << af)]
    kturns = [0, raw_max(kw), raw_min(kw), to_raw(1.0 / (4 * math.pi), cfg, "kturn_t").item()]
    rows = [(a, k, x) for a in angles for k in kturns for x in axes[:3]]
    rows += [(1 << af, kturns[3], x) for x in axes]
    # kp: the largest power of two in the kturn format, 2^(kw-2-kf) turns per joint unit
    kp = 1 << (kw - 2)
    # near the wrap: q k = +-1/2 turn +- a little (q clipped to the joint-value format)
    q_half = min(1 << (af + kf - (kw - 2) - 1), raw_max(aw) - 2)
    for e in (-2, -1, 0, 1, 2):
        rows.append((q_half + e, kp, axes[2]))
        rows.append((-q_half + e, kp, axes[2]))
    # sin = -1 exactly (q k = -1/4 turn) times the most negative axis component saturates; +1 does not
    q_quarter = 1 << (af + kf - (kw - 2) - 2)
    for a in (-q_quarter, q_quarter):
        rows += [(a, kp, np.full(3, raw_min(qw))), (a, kp, np.full(3, raw_max(qw)))]
    return {"angle": np.array([r[0] for r in rows], dtype=np.int64),
            "kturn": np.array([r[1] for r in rows], dtype=np.int64),
            "axis": np.array([r[2] for r in rows], dtype=np.int64)}


def _joint_quat_expected(cfg, ins):
    out, st = _model.prim_joint_quat(cfg, ins["angle"], ins["kturn"], ins["axis"])
    return {"out": np.asarray(out), "status": np.asarray(st)}


# ---- screw_transport -----------------------------------------------------------------------------
def _screw_random(cfg, rng, n):
    lw, lf = fmt(cfg, "lever_t")
    lever_max = math.ldexp(raw_max(lw), -lf)
    pos_frac_small = lever_max / 2 / math.ldexp(1 << (fmt(cfg, "pos_t")[0] - 1), -fmt(cfg, "pos_t")[1])
    q = to_raw(unit_quats(rng, n), cfg, "quat_t")
    axis = to_raw(unit_vecs(rng, n), cfg, "quat_t")
    prismatic = rng.random(n) < 0.3
    s = _mix(rng, n, [(0.8, lambda c: to_raw(rng.uniform(-math.pi, math.pi, c), cfg, "scale_t")),
                      (0.2, lambda c: uniform_raw(rng, cfg, "scale_t", c))])
    p_ref = _mix(rng, n, [(0.7, lambda c: uniform_raw(rng, cfg, "pos_t", (c, 3), pos_frac_small)),
                          (0.3, lambda c: uniform_raw(rng, cfg, "pos_t", (c, 3)))])
    p_i = _mix(rng, n, [(0.7, lambda c: uniform_raw(rng, cfg, "pos_t", (c, 3), pos_frac_small)),
                        (0.3, lambda c: uniform_raw(rng, cfg, "pos_t", (c, 3)))])
    return {"q": q, "axis": axis, "prismatic": prismatic.astype(np.int64), "s": s, "p_ref": p_ref, "p_i": p_i}


def _screw_edges(cfg, rng):
    qw, qf = fmt(cfg, "quat_t")
    sw, sf = fmt(cfg, "scale_t")
    pw, pf = fmt(cfg, "pos_t")
    one = 1 << qf
    ident = np.array([one, 0, 0, 0])
    qs = [ident, np.array([0, one, 0, 0]), to_raw(unit_quats(rng, 1)[0], cfg, "quat_t")]
    axes = [np.eye(3, dtype=np.int64)[k] * one for k in range(3)] + [to_raw(unit_vecs(rng, 1)[0], cfg, "quat_t")]
    ss = [0, 1 << sf, -(1 << sf), raw_max(sw), raw_min(sw)]
    pr = to_raw(rng.uniform(-1, 1, 3), cfg, "pos_t")
    pairs = [(pr, pr), (np.zeros(3), pr), (np.full(3, raw_max(pw)), np.full(3, raw_min(pw))),
             (np.full(3, raw_min(pw)), np.full(3, raw_max(pw))), (to_raw([1.0, 0, 0], cfg, "pos_t"), np.zeros(3))]
    rows = []
    for q in qs:
        for a in axes:
            for s in ss:
                for pri in (0, 1):
                    for p in pairs[:3] if s in (ss[1], ss[3]) else pairs[:1]:
                        rows.append((q, a, pri, s, p[0], p[1]))
    for p in pairs:
        for pri in (0, 1):
            rows.append((ident, axes[2], pri, ss[1], p[0], p[1]))
    return {"q": np.array([r[0] for r in rows], dtype=np.int64),
            "axis": np.array([r[1] for r in rows], dtype=np.int64),
            "prismatic": np.array([r[2] for r in rows], dtype=np.int64),
            "s": np.array([r[3] for r in rows], dtype=np.int64),
            "p_ref": np.array([r[4] for r in rows], dtype=np.int64),
            "p_i": np.array([r[5] for r in rows], dtype=np.int64)}


def _screw_expected(cfg, ins):
    z, st1 = _model.prim_rotate(cfg, "axis", False, ins["q"], ins["axis"])
    w, v, st2 = _model.prim_screw(cfg, np.asarray(ins["prismatic"]).astype(bool), ins["s"], np.asarray(z),
                                  ins["p_ref"], ins["p_i"])
    return {"z": np.asarray(z), "w": np.asarray(w), "v": np.asarray(v),
            "status": np.asarray(st1) | np.asarray(st2)}


# ---- public API ----------------------------------------------------------------------------------
_GEN = {
    "quat_mul": (_quat_mul_random, _quat_mul_edges, _quat_mul_expected),
    "quat_rotate": (_quat_rotate_random, _quat_rotate_edges, _quat_rotate_expected),
    "sincos": (_sincos_random, _sincos_edges, _sincos_expected),
    "joint_quat": (_joint_quat_random, _joint_quat_edges, _joint_quat_expected),
    "screw_transport": (_screw_random, _screw_edges, _screw_expected),
}


#: format of every input array (the hardware port carries exactly these bits)
INPUT_FORMATS = {
    "quat_mul": {"a": "quat_t", "b": "quat_t"},
    "quat_rotate": {"q": "quat_t", **{f"v_{k}": KINDS[k][0] for k in KINDS}},
    "sincos": {"u": None},
    "joint_quat": {"angle": "angle_t", "kturn": "kturn_t", "axis": "quat_t"},
    "screw_transport": {"q": "quat_t", "axis": "quat_t", "prismatic": None, "s": "scale_t", "p_ref": "pos_t",
                        "p_i": "pos_t"},
}


def check_ranges(module: str, cfg: str, ins: dict[str, np.ndarray]) -> None:
    """Raise ValueError if an input lies outside its format (u: [0, 2^W_u); prismatic: 0/1)."""
    for k, name in INPUT_FORMATS[module].items():
        a = np.asarray(ins[k])
        if name is None:
            lo, hi = (0, (1 << sincos_fields(cfg)[0]) - 1) if k == "u" else (0, 1)
        else:
            w, _ = fmt(cfg, name)
            lo, hi = raw_min(w), raw_max(w)
        if a.size and (a.min() < lo or a.max() > hi):
            raise ValueError(f"{module}/{cfg}: input {k} outside its format [{lo}, {hi}]")


def random_inputs(module: str, cfg: str, rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    """n random input vectors of a module (raw integers)."""
    d = {k: np.asarray(v, dtype=np.int64) for k, v in _GEN[module][0](cfg, rng, n).items()}
    check_ranges(module, cfg, d)
    return d


def edge_inputs(module: str, cfg: str, rng: np.random.Generator | None = None) -> dict[str, np.ndarray]:
    """The edge-case input vectors of a module (some use a few random unit quaternions/vectors)."""
    rng = rng if rng is not None else np.random.default_rng(1)
    d = {k: np.asarray(v, dtype=np.int64) for k, v in _GEN[module][1](cfg, rng).items()}
    check_ranges(module, cfg, d)
    return d


def expected(module: str, cfg: str, inputs: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Expected outputs of the module from the C++ model (raw integers, status words)."""
    return _GEN[module][2](cfg, inputs)


def concat(*dicts: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    return {k: np.concatenate([d[k] for d in dicts]) for k in dicts[0]}


def golden_inputs(module: str, cfg: str, n: int = 256) -> dict[str, np.ndarray]:
    """Deterministic golden inputs: up to n/2 edge cases (evenly subsampled), random to n."""
    rng = np.random.default_rng(zlib.crc32(f"tensor-servo/{module}/{cfg}".encode()))
    edges = edge_inputs(module, cfg, rng)
    m = len(next(iter(edges.values())))
    keep = np.unique(np.linspace(0, m - 1, min(m, n // 2)).round().astype(int))
    edges = {k: v[keep] for k, v in edges.items()}
    return concat(edges, random_inputs(module, cfg, rng, n - len(keep)))


def golden(module: str, cfg: str, n: int = 256) -> dict[str, np.ndarray]:
    ins = golden_inputs(module, cfg, n)
    return {**{f"in_{k}": v for k, v in ins.items()}, **{f"exp_{k}": v for k, v in expected(module, cfg, ins).items()}}


def path(outdir, module: str, cfg: str) -> Path:
    return Path(outdir) / f"prim_{module}_{cfg}.npz"


def write(outdir, config: str, n: int = 256) -> list[Path]:
    """Write tb/golden/prim_<module>_<config>.npz for every module (deterministic content)."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    written = []
    for module in MODULES:
        p = path(outdir, module, config)
        np.savez_compressed(p, **golden(module, config, n))
        written.append(p)
    return written


def check(outdir, config: str, n: int = 256) -> list[str]:
    """Differences between the files in outdir and what the model generates now (empty = equal)."""
    problems = []
    for module in MODULES:
        p = path(outdir, module, config)
        if not p.exists():
            problems.append(f"{p}: missing")
            continue
        want = golden(module, config, n)
        with np.load(p) as f:
            have = {k: f[k] for k in f.files}
        if sorted(have) != sorted(want):
            problems.append(f"{p}: arrays {sorted(have)} != {sorted(want)}")
            continue
        for k in want:
            if have[k].shape != want[k].shape or not np.array_equal(have[k], want[k]):
                problems.append(f"{p}: array {k} differs")
    return problems


def load(outdir, module: str, cfg: str) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """(inputs, expected) of a committed golden file."""
    with np.load(path(outdir, module, cfg)) as f:
        ins = {k[3:]: f[k] for k in f.files if k.startswith("in_")}
        exp = {k[4:]: f[k] for k in f.files if k.startswith("exp_")}
    return ins, exp


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tensor_servo.golden_prims", description=__doc__.split("\n")[0])
    ap.add_argument("-o", "--outdir", default="tb/golden")
    ap.add_argument("-n", type=int, default=256, help="vectors per module (default 256)")
    ap.add_argument("--config", choices=CONFIGS, action="append")
    ap.add_argument("--check", action="store_true", help="compare instead of writing; exit 1 on a difference")
    a = ap.parse_args(argv)
    rc = 0
    for cfg in a.config or CONFIGS:
        if a.check:
            for msg in check(a.outdir, cfg, a.n):
                print(msg)
                rc = 1
        else:
            for p in write(a.outdir, cfg, a.n):
                print(p)
    return rc


if __name__ == "__main__":
    sys.exit(main())
