"""Virtual-mode IK (tensor_servo.ik): convergence, limits, honest flags, bad input.

Errors are recomputed independently with Pinocchio (oracle.PinChain), never taken from ik.
"""
import numpy as np
import pinocchio as pin
import pytest

from tensor_servo import ik, robots
from tensor_servo.errors import InputError
from tensor_servo.oracle import PinChain

CHAINS = ["puma560", "ur5", "panda", "stanford", "chain20"]
LOOSE = (1e-4, 1e-3)


def problems(name, n, seed, noise=0.1):
    ch = robots.load(name)
    pc = PinChain(ch)
    rng = np.random.default_rng(seed)
    qt = ch.random_q(rng, n)
    T = np.array([pc.tool_pose(q) for q in qt])
    q0 = np.clip(qt + rng.uniform(-noise, noise, qt.shape), ch.lower, ch.upper)
    return ch, pc, T, q0


def oracle_errors(pc, q, T):
    pe, re = [], []
    for qs, Ts in zip(q, T):
        P = pc.tool_pose(qs)
        pe.append(np.linalg.norm(P[:3, 3] - Ts[:3, 3]))
        re.append(np.linalg.norm(pin.log3(Ts[:3, :3].T @ P[:3, :3])))
    return np.array(pe), np.array(re)


def within_limits(ch, q):
    return np.all(np.isfinite(q)) and np.all((q >= ch.lower) & (q <= ch.upper))


def assert_honest(ch, pc, r, T, tol_pos, tol_rot):
    """ok, pos_err, rot_err agree with Pinocchio; q within the limits."""
    assert within_limits(ch, r.q)
    pe, re = oracle_errors(pc, r.q, T)
    np.testing.assert_allclose(r.pos_err, pe, rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(r.rot_err, re, rtol=1e-6, atol=1e-12)
    expect = (pe <= tol_pos) & (re <= tol_rot)
    edge = (np.abs(pe - tol_pos) < 1e-12) | (np.abs(re - tol_rot) < 1e-12)
    assert np.array_equal(r.ok[~edge], expect[~edge])


@pytest.mark.parametrize("name", CHAINS)
@pytest.mark.parametrize("model", ["float", "fixed"])
def test_near_seeds_converge(name, model):
    ch, pc, T, q0 = problems(name, 24, seed=5)
    r = ik.solve(ch, T, q0, model=model)
    assert_honest(ch, pc, r, T, 1e-6, 1e-5)
    pe, re = oracle_errors(pc, r.q, T)
    assert np.all((pe <= LOOSE[0]) & (re <= LOOSE[1])), (pe, re)
    assert r.ok.mean() >= 0.9, r.ok
    assert np.median(r.ticks) <= 20


@pytest.mark.parametrize("model", ["float", "fixed"])
def test_conjugate_refinement_finishes_ill_conditioned_targets(model):
    """UR5 targets with the wrist near its singularity (|q5| = 0.002-0.02 rad: condition numbers
    in the thousands): the sweeps alone crawl there, the polish's conjugate-direction refinement
    (solver.hpp solver_cg) reaches 1e-6 m / 1e-5 rad on every one (docs/ik.md)."""
    ch = robots.load("ur5")
    pc = PinChain(ch)
    rng = np.random.default_rng(3)
    N = 40
    qt = ch.random_q(rng, N)
    qt[:, 4] = rng.choice([-1, 1], N) * rng.uniform(0.002, 0.02, N)
    T = np.array([pc.tool_pose(q) for q in qt])
    q0 = np.clip(qt + rng.uniform(-0.1, 0.1, qt.shape), ch.lower, ch.upper)
    r = ik.solve(ch, T, q0, model=model)
    assert_honest(ch, pc, r, T, 1e-6, 1e-5)
    assert r.ok.all(), np.nonzero(~r.ok)[0]
    # the same search without the refinement leaves some of them short (the test has power)
    r0 = ik.solve(ch, T, q0, model=model, polish_cg=0)
    assert_honest(ch, pc, r0, T, 1e-6, 1e-5)
    assert r0.ok.mean() < 0.98, r0.ok.mean()


def test_refinement_steps_capped_on_long_chains():
    """A 40-joint chain: the polish's 2n refinement steps are capped at CG_MAX (the model refuses
    more), so the IK runs; answers stay within the limits."""
    from tensor_servo.randchain import random_chain

    rng = np.random.default_rng(4)
    ch = random_chain(rng, 40, offset=(0.02, 0.05))
    assert ik.polish_params(ik.IKParams(), ch.n).cg == ik.CG_MAX
    pc = PinChain(ch)
    qt = ch.random_q(rng, 3)
    T = np.array([pc.tool_pose(q) for q in qt])
    q0 = np.clip(qt + rng.uniform(-0.05, 0.05, qt.shape), ch.lower, ch.upper)
    r = ik.solve(ch, T, q0, model="float", max_ticks=120, polish_after=5)
    assert_honest(ch, pc, r, T, 1e-6, 1e-5)
    assert r.pos_err.max() < 1e-3, r.pos_err


@pytest.mark.parametrize("name", ["puma560", "panda"])
def test_compact_loose(name):
    ch, pc, T, q0 = problems(name, 16, seed=6)
    r = ik.solve(ch, T, q0, model="fixed", config="compact", tol_pos=1e-4, tol_rot=1e-3)
    assert_honest(ch, pc, r, T, 1e-4, 1e-3)
    assert r.ok.mean() >= 0.75  # its FK error alone is up to ~2e-4 m (docs/numerics.md)


@pytest.mark.parametrize("solver", ["pinv", "dls"])
def test_references_converge(solver):
    ch, pc, T, q0 = problems("puma560", 16, seed=7)
    r = ik.solve(ch, T, q0, model="float", solver=solver, max_ticks=200)
    assert_honest(ch, pc, r, T, 1e-6, 1e-5)
    pe, re = oracle_errors(pc, r.q, T)
    assert np.mean((pe <= LOOSE[0]) & (re <= LOOSE[1])) >= 0.9


@pytest.mark.parametrize("limits", ik.LIMITS)
@pytest.mark.parametrize("name", ["puma560", "ur5", "panda", "stanford", "chain20"])
def test_random_seeds_within_limits_and_honest(name, limits):
    ch, pc, T, _ = problems(name, 12, seed=8)
    q0 = ch.random_q(np.random.default_rng(9), 12)
    r = ik.solve(ch, T, q0, model="fixed", limits=limits, max_ticks=300)
    assert_honest(ch, pc, r, T, 1e-6, 1e-5)


@pytest.mark.parametrize("model,config,solver", [("float", "default", "cd"), ("fixed", "default", "cd"),
                                                  ("fixed", "compact", "cd"), ("float", "default", "pinv"),
                                                  ("float", "default", "dls")])
def test_unreachable_targets(model, config, solver):
    ch, pc, T, q0 = problems("puma560", 6, seed=10)
    T = T.copy()
    T[:3, :3, 3] += np.array([3.0, -2.0, 1.5])      # far outside the workspace
    T[3:] = T[3:] @ np.diag([1.0, -1.0, -1.0, 1.0])  # reachable position?  orientation flipped
    T[3:, 0, 3] += 2.0                              # ... and out of reach
    r = ik.solve(ch, T, q0, model=model, config=config, solver=solver, max_ticks=150)
    assert not r.ok.any()
    assert within_limits(ch, r.q)
    assert np.all(np.isfinite(r.pos_err)) and np.all(r.pos_err > 0.5)
    assert_honest(ch, pc, r, T, 1e-6, 1e-5)


def test_restarts_help_random_seeds_and_stay_honest():
    ch, pc, T, _ = problems("puma560", 40, seed=11)
    q0 = ch.random_q(np.random.default_rng(12), 40)
    r0 = ik.solve(ch, T, q0, model="fixed")
    r9 = ik.solve(ch, T, q0, model="fixed", restarts=9)
    assert_honest(ch, pc, r9, T, 1e-6, 1e-5)
    assert r9.ok.sum() >= r0.ok.sum()
    assert r9.ok.mean() >= 0.9
    assert np.all(r9.ticks <= 1000) and np.all(r9.attempts <= 10)
    # reproducible: the restarts' configurations come from the seed and the target index
    r9b = ik.solve(ch, T, q0, model="fixed", restarts=9)
    np.testing.assert_array_equal(r9b.q, r9.q)


def test_fixed_point_is_deterministic_and_max_ticks_zero():
    ch, pc, T, q0 = problems("ur5", 5, seed=13)
    a = ik.solve(ch, T, q0, model="fixed")
    b = ik.solve(ch, T, q0, model="fixed")
    np.testing.assert_array_equal(a.q, b.q)
    z = ik.solve(ch, T, q0, model="fixed", max_ticks=0)
    assert np.all(z.ticks == 0)
    np.testing.assert_allclose(z.q, q0, atol=1e-8)  # the seeds (quantised), nothing moved
    assert not z.ok.any()


def test_seed_broadcast_and_out_of_limit_seed():
    ch, pc, T, _ = problems("puma560", 4, seed=14)
    q0 = np.full(ch.n, 10.0)  # outside every limit (and outside the fixed-point range |q| < 8)
    r = ik.solve(ch, T, q0, model="fixed", max_ticks=200)
    assert r.q.shape == (4, ch.n)
    assert_honest(ch, pc, r, T, 1e-6, 1e-5)


def test_wrap_keeps_representatives_in_range():
    # UR5: every joint spans two turns; answers stay in [-2 pi, 2 pi] (after the search window)
    ch, pc, T, q0 = problems("ur5", 10, seed=15)
    r = ik.solve(ch, T, q0, model="fixed", limits="wrap")
    assert_honest(ch, pc, r, T, 1e-6, 1e-5)
    assert r.ok.mean() >= 0.9


def test_box_lsq_kkt():
    rng = np.random.default_rng(16)
    for _ in range(200):
        m, n = 6, int(rng.integers(3, 9))
        A = rng.normal(size=(m, n))
        if rng.random() < 0.3:
            A[:, -1] = A[:, 0]  # rank deficient
        b = rng.normal(size=m) * 3
        lo = -rng.uniform(0.0, 1.0, n)
        hi = rng.uniform(0.0, 1.0, n)
        x = ik.box_lsq(A, b, lo, hi)
        assert np.all(x >= lo - 1e-12) and np.all(x <= hi + 1e-12)
        g = A.T @ (b - A @ x)  # moving x_i up lowers the objective when g_i > 0
        tol = 1e-7 * (1 + np.abs(A).sum(axis=0) * np.linalg.norm(b))
        free = (x > lo + 1e-9) & (x < hi - 1e-9)
        assert np.all(np.abs(g[free]) <= tol[free])
        assert np.all(g[np.isclose(x, lo) & ~np.isclose(x, hi)] <= tol[np.isclose(x, lo) & ~np.isclose(x, hi)])
        assert np.all(g[np.isclose(x, hi) & ~np.isclose(x, lo)] >= -tol[np.isclose(x, hi) & ~np.isclose(x, lo)])


# ---- bad input -------------------------------------------------------------------------------------

def test_bad_targets():
    ch, pc, T, q0 = problems("puma560", 3, seed=17)
    with pytest.raises(InputError, match="non-finite"):
        Tn = T.copy(); Tn[1, 0, 3] = np.nan
        ik.solve(ch, Tn, q0)
    with pytest.raises(InputError, match="non-finite"):
        Tn = T.copy(); Tn[2, 2, 2] = np.inf
        ik.solve(ch, Tn, q0)
    with pytest.raises(InputError, match="shape"):
        ik.solve(ch, T[:, :3, :], q0)
    with pytest.raises(InputError, match="rigid"):
        Ts = T.copy(); Ts[0, :3, :3] *= 1.001
        ik.solve(ch, Ts, q0)
    with pytest.raises(InputError, match="rigid"):
        Tr = T.copy(); Tr[1, :3, 0] *= -1.0  # a reflection (det -1)
        ik.solve(ch, Tr, q0)
    with pytest.raises(InputError, match="last row"):
        Tl = T.copy(); Tl[0, 3, 0] = 0.5
        ik.solve(ch, Tl, q0)
    # within the rigidity tolerance: accepted
    Tok = T.copy(); Tok[0, :3, :3] *= 1 + 2e-7
    assert ik.solve(ch, Tok, q0, max_ticks=5).q.shape == (3, ch.n)


def test_bad_seeds_and_options():
    ch, pc, T, q0 = problems("puma560", 3, seed=18)
    with pytest.raises(InputError, match="non-finite"):
        qb = q0.copy(); qb[0, 1] = np.inf
        ik.solve(ch, T, qb)
    with pytest.raises(InputError, match="shape"):
        ik.solve(ch, T, q0[:2])
    with pytest.raises(InputError, match="shape"):
        ik.solve(ch, T, np.zeros(ch.n + 1))
    with pytest.raises(InputError, match="--tol-pos"):
        ik.solve(ch, T, q0, tol_pos=0.0)
    with pytest.raises(InputError, match="--tol-rot"):
        ik.solve(ch, T, q0, tol_rot=float("nan"))
    with pytest.raises(InputError, match="--max-ticks"):
        ik.solve(ch, T, q0, max_ticks=-1)
    with pytest.raises(InputError, match="--solver"):
        ik.solve(ch, T, q0, model="fixed", solver="pinv")
    with pytest.raises(InputError, match="mu"):
        ik.solve(ch, T, q0, mu=2.0)
    with pytest.raises(InputError, match="dt"):
        ik.solve(ch, T, q0, dt=0.1)
    with pytest.raises(InputError, match="polish_cg"):
        ik.solve(ch, T, q0, polish_cg=65)
    with pytest.raises(InputError, match="cg_below"):
        ik.solve(ch, T, q0, cg_below=0.0)
