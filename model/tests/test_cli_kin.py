"""tservo fk / jacobian / golden through the real console script."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tensor_servo import reference, robots
from tensor_servo.oracle import PinChain

TSERVO = str(Path(sys.executable).with_name("tservo"))
ROOT = Path(__file__).resolve().parents[2]


def run(*args):
    return subprocess.run([TSERVO, *map(str, args)], capture_output=True, text=True)


def one_line_error(r, *words):
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("tservo: error:"), r.stderr
    assert "Traceback" not in r.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])


@pytest.fixture
def qfile(tmp_path):
    ch = robots.load("puma560")
    q = ch.random_q(np.random.default_rng(3), 20)
    p = tmp_path / "q.npy"
    np.save(p, q)
    return ch, q, p


@pytest.mark.parametrize("model", ["float", "double", "fixed"])
@pytest.mark.parametrize("basis", ["base", "tool"])
def test_jacobian_matches_pinocchio(tmp_path, qfile, model, basis):
    ch, q, p = qfile
    out = tmp_path / "out.npz"
    r = run("jacobian", "puma560", "--q", p, "--model", model, "--basis", basis, "-o", out)
    assert r.returncode == 0, r.stderr
    d = np.load(out)
    assert d["T"].shape == (20, 4, 4) and d["J"].shape == (20, 6, 6)
    pc = PinChain(ch)
    tol = 1e-12 if model != "fixed" else 5e-6
    for s in range(20):
        assert np.abs(d["T"][s] - pc.tool_pose(q[s])).max() < tol
        assert np.abs(d["J"][s] - pc.jacobian(q[s], basis)).max() < tol
    if model == "fixed":
        assert d["overflow"].shape == (20,) and not d["overflow"].any()
        assert d["J_raw"].dtype == np.int64


def test_fk_every_frame(tmp_path, qfile):
    ch, q, p = qfile
    out = tmp_path / "fk.npz"
    assert run("fk", "puma560", "--q", p, "--model", "fixed", "--config", "compact", "-o", out).returncode == 0
    d = np.load(out)
    assert d["frames"].shape == (20, ch.n + 2, 4, 4)
    for s in range(20):
        ref = reference.fk_frames(ch, q[s])
        assert np.abs(d["frames"][s][:, :3, 3] - ref[:, :3, 3]).max() < 1e-3  # compact bound
    assert np.array_equal(d["T"], d["frames"][:, -1])


def test_bad_q_inputs(tmp_path, qfile):
    ch, q, p = qfile
    out = tmp_path / "out.npz"
    bad = tmp_path / "bad.npy"
    np.save(bad, q[:, :5])
    one_line_error(run("jacobian", "puma560", "--q", bad, "-o", out), "--q", "shape")
    q2 = q.copy()
    q2[4, 2] = np.nan
    np.save(bad, q2)
    one_line_error(run("jacobian", "puma560", "--q", bad, "-o", out), "--q", "non-finite")
    q2 = q.copy()
    q2[7, 1] = 9.0  # outside ap_fixed<32,4> (|q| < 8)
    np.save(bad, q2)
    one_line_error(run("jacobian", "puma560", "--q", bad, "--model", "fixed", "-o", out), "sample 7, joint 1")
    one_line_error(run("fk", "puma560", "--q", tmp_path / "missing.npy", "-o", out), "no such file")
    (tmp_path / "junk.npy").write_bytes(b"not numpy")
    one_line_error(run("fk", "puma560", "--q", tmp_path / "junk.npy", "-o", out), "--q")
    one_line_error(run("fk", "nosuchrobot", "--q", p, "-o", out), "nosuchrobot")
    assert not out.exists()


def test_failed_run_leaves_existing_output_untouched(tmp_path, qfile):
    ch, q, p = qfile
    out = tmp_path / "out.npz"
    out.write_bytes(b"previous")
    bad = tmp_path / "bad.npy"
    np.save(bad, np.full((3, 6), np.inf))
    one_line_error(run("fk", "puma560", "--q", bad, "-o", out))
    assert out.read_bytes() == b"previous"


def test_golden_vectors_are_reproducible(tmp_path):
    """The committed tb/golden/kin_* files are exactly what the model writes today."""
    r = run("golden", "-o", tmp_path)
    assert r.returncode == 0, r.stderr
    files = sorted(tmp_path.glob("kin_*.npz"))
    assert len(files) == 2 * len(robots.names())
    for f in files:
        committed = ROOT / "tb" / "golden" / f.name
        assert committed.exists(), f"{committed} missing: run make golden"
        a, b = np.load(f), np.load(committed)
        assert sorted(a.files) == sorted(b.files)
        for k in a.files:
            assert np.array_equal(a[k], b[k]), f"{f.name}:{k} differs: the model changed; run make golden"
