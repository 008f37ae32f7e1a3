"""Golden vectors: inputs and expected raw outputs of the bit-accurate model, written
deterministically (fixed seeds, PCG64) so the committed files under ``tb/golden/`` can be
regenerated bit for bit and replayed by the RTL and HLS benches.

Per example chain and fixed-point configuration, ``kin_<chain>_<config>.npz`` holds:
    q_raw (N, n)                joint values (angle_t raw), within the limits (continuous: +-pi)
    quat_raw (N, n+2, 4)        every frame's quaternion (quat_t raw); frames 0 base .. n+1 tool
    pos_raw (N, n+2, 3)         every frame's origin (pos_t raw)
    axis_raw (N, n, 3)          joint axes in the root frame (quat_t raw)
    J_raw (N, 6, n)             Jacobian at the tool origin, root axes, rows (omega; v)
    J_tool_raw (N, 6, n)        the same in the tool frame's axes
    flags (N,)                  sticky status
    const_* ...                 the chain's quantised constants (raw)
"""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from . import robots
from .chain import write_atomic
from .model import FIXED_CONFIGS, Model

SEED = 20261122


def kin_vectors(name: str, config: str, samples: int) -> dict[str, np.ndarray]:
    ch = robots.load(name)
    m = Model(ch, config)
    rng = np.random.Generator(np.random.PCG64([SEED, sum(map(ord, name)), FIXED_CONFIGS.index(config)]))
    q = ch.random_q(rng, samples)
    q_raw, ok = m.quantize_q(q)
    assert ok.all()
    fk = m.fk(q_raw, raw=True)
    jb = m.jacobian(q_raw, ref="tool", basis="base", raw=True)
    jt = m.jacobian(q_raw, ref="tool", basis="tool", raw=True)
    out = {
        "q_raw": q_raw, "quat_raw": fk.quat_raw, "pos_raw": fk.pos_raw, "axis_raw": fk.axis_raw,
        "J_raw": jb.J_raw, "J_tool_raw": jt.J_raw, "flags": fk.flags | jb.flags | jt.flags,
    }
    out.update({f"const_{k}": v for k, v in m.constants().items()})
    return out


def _npz_bytes(arrays: dict[str, np.ndarray]) -> bytes:
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    return buf.getvalue()


def write_all(outdir: str | Path, samples: int = 64) -> list[Path]:
    outdir = Path(outdir)
    written = []
    for name in robots.names():
        for cfg in FIXED_CONFIGS:
            p = outdir / f"kin_{name}_{cfg}.npz"
            write_atomic(p, _npz_bytes(kin_vectors(name, cfg, samples)))
            written.append(p)
    return written
