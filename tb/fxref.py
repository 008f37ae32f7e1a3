"""Python statement of the model's narrowing (model/include/tensor_servo/fixed.hpp), for the benches of
the shared pieces (ts_round_sat): round half up (AP_RND: add half an output LSB, arithmetic shift),
then saturate (AP_SAT, flag) or wrap (AP_WRAP).  tb/ts_round_sat checks this statement against the
C++ model's cvt (through prim_qmul) before using it."""
from __future__ import annotations


def round_raw(x: int, shift: int) -> int:
    """detail::round_raw: fraction bits reduced by `shift` (> 0: round half up; <= 0: exact)."""
    if shift > 0:
        return (x + (1 << (shift - 1))) >> shift
    return x << (-shift)


def cvt(x: int, shift: int, out_w: int) -> tuple[int, int]:
    """cvt<Dst>: (value, saturated)."""
    r = round_raw(x, shift)
    hi, lo = (1 << (out_w - 1)) - 1, -(1 << (out_w - 1))
    if r > hi:
        return hi, 1
    if r < lo:
        return lo, 1
    return r, 0


def wrap(x: int, shift: int, out_w: int) -> int:
    """wrap<Dst>: rounded, low out_w bits, two's complement."""
    r = round_raw(x, shift) & ((1 << out_w) - 1)
    return r - (1 << out_w) if r >> (out_w - 1) else r
