"""Array input/output for the CLI: validated loading and atomic saving."""
from __future__ import annotations

import io
import os
from pathlib import Path

import numpy as np

from .chain import write_atomic
from .errors import InputError


def load_array(path: str | os.PathLike, name: str) -> np.ndarray:
    """Load a .npy array (or one array from a .npz by ``file.npz:key``), as float64."""
    spath = str(path)
    key = None
    if ".npz:" in spath:
        spath, key = spath.rsplit(":", 1)
    p = Path(spath)
    if not p.exists():
        raise InputError(name, f"{spath}: no such file")
    try:
        obj = np.load(p, allow_pickle=False)
    except Exception as e:  # numpy raises several types for corrupt files
        raise InputError(name, f"{spath}: not a readable .npy/.npz file ({type(e).__name__})") from None
    if isinstance(obj, np.lib.npyio.NpzFile):
        if key is None:
            raise InputError(name, f"{spath}: an .npz needs a key, e.g. {spath}:q")
        if key not in obj.files:
            raise InputError(name, f"{spath}: no array {key!r} (has {', '.join(obj.files)})")
        arr = obj[key]
    else:
        arr = obj
    if arr.dtype.kind not in "fiu":
        raise InputError(name, f"expected a numeric array, got dtype {arr.dtype}")
    return np.asarray(arr, dtype=np.float64)


def check_shape(arr: np.ndarray, name: str, shape: tuple) -> np.ndarray:
    """Check an array against a shape pattern (None = any size); also rejects NaN/inf."""
    if arr.ndim != len(shape) or any(s is not None and s != a for s, a in zip(shape, arr.shape)):
        want = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ")"
        raise InputError(name, f"shape {tuple(arr.shape)} does not match {want}")
    if not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))[0]
        raise InputError(name, f"non-finite value at index {tuple(int(i) for i in bad)}")
    return arr


def load_q(path: str | os.PathLike, n: int, name: str = "--q") -> np.ndarray:
    """Joint values, (N, n) (a single (n,) vector is accepted as N = 1)."""
    q = load_array(path, name)
    if q.ndim == 1 and q.shape[0] == n:
        q = q[None, :]
    return check_shape(q, name, (None, n))


def save_npz(path: str | os.PathLike, **arrays: np.ndarray) -> None:
    """Save arrays to an .npz atomically (nothing half-written on failure)."""
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    write_atomic(path, buf.getvalue())
