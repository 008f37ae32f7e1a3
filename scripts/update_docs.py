#!/usr/bin/env python3
"""Regenerate the generated sections of docs/numerics.md from the model.

    .venv/bin/python scripts/update_docs.py          # rewrite the sections in place
    .venv/bin/python scripts/update_docs.py --check  # exit 1 if a section is out of date

Sections are delimited by ``<!-- BEGIN name -->`` / ``<!-- END name -->``:
  formats       every signal of both fixed-point configurations (from the compiled model)
  accuracy      worst errors against Pinocchio on 10,000 random configurations per example chain
                (tensor_servo.accuracy, deterministic seeds) and the bounds the tests enforce
"""
from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "model" / "python"))

from tensor_servo import robots  # noqa: E402
from tensor_servo.accuracy import BOUNDS, SAMPLES, SEED, measure_example  # noqa: E402
from tensor_servo.model import FIXED_CONFIGS, formats  # noqa: E402

DOC = ROOT / "docs" / "numerics.md"

# Signal classes of formats.hpp: (name, meaning, range argument, multiplier operand?)
SIGNALS = [
    ("angle_t", "joint value q (input), joint units", "limits checked at configuration", True),
    ("kturn_t", "s/(4 pi): joint unit -> half-angle turns (derived at commit: s x 1/(4 pi))", "|s| checked", True),
    ("inv4pi_t", "constant 1/(4 pi) (derivation of kturn)", "constant", True),
    ("turn_t", "half angle in turns, modulo one turn (wraps by definition)", "wraps", False),
    ("scale_t", "joint scale s (constant)", "|s| checked", True),
    ("tab_t", "quarter-wave table entries sin/cos", "[0, 1]", True),
    ("delta_t", "residual angle d and sin d (rad)", "d < pi/2^(T+1) < 2^-7", True),
    ("dsq_t", "d^2 and d^2/6", "< 2^-14", True),
    ("trig_acc_t", "S h, C h, C sd, S sd before the final sum", "< 2^-6", False),
    ("quat_t", "unit quaternion and unit axis components, sin/cos", "|.| <= 1 + rounding", True),
    ("uvec_tmp_t", "t = 2 q_v x a (rotating a unit vector)", "|t| <= 2", True),
    ("len_t", "constant offsets: origin, base, tool translations (m)", "checked at configuration", True),
    ("len_tmp_t", "t = 2 q_v x p (rotating an offset)", "|t| <= 2 |p|", True),
    ("pos_t", "frame origins (m)", "|base| + reach, checked", False),
    ("lever_t", "r = p_ref - p_i, prismatic displacement s q (m)", "reach, checked", True),
    ("jw_t", "Jacobian omega rows", "|s|, checked", True),
    ("jv_t", "Jacobian v rows", "|s| reach, checked", True),
    ("jw_tmp_t", "t when rotating an omega column to another basis", "2 |s|", True),
    ("jv_tmp_t", "t when rotating a v column to another basis", "2 |s| reach", True),
    ("twopi_t", "constant 2 pi (sin/cos unit)", "constant", True),
    ("sixth_t", "constant 1/6 (sin/cos unit)", "constant", True),
    ("lchar_t", "characteristic length L (m/rad)", "checked", True),
    ("tw_t", "scaled target and residual (L omega; v)", "saturates, flagged", True),
    ("jsc_t", "scaled Jacobian column (L omega_i; v_i)", "L |s| and |s| reach", True),
    ("qd_t", "joint rates q' (joint units/s)", "clamped to the velocity box", True),
    ("gk_t", "<Js_i, r> 2^-k_i", "saturates, flagged", True),
    ("mant_t", "d_i 2^-k_i (truncated)", "[1, 2)", True),
    ("recip_t", "1/mant (table + one Newton step)", "(1/2, 1]", True),
    ("mu_t", "per-joint multiplier (relaxation)", "[0, 2)", True),
    ("step_t", "mu_i / mant_i", "[0, 2)", True),
    ("bfm_t", "IK refinement (offline, not in the core): block-floating mantissa of a vector or scalar", "|.| <= 1 by construction", True),
    ("cgy_t", "IK refinement: 1/|A p|^2 mantissa after a second Newton step", "[1, 2]", True),
    ("cge_t", "IK refinement: Newton error 1 - m y", "< 2^-12", True),
    ("cgx_t", "IK refinement: increment of q', relative to the residual's exponent", "|x_ls| / |r0| < 2^29 (1/sigma_min); saturates, flagged", False),
    ("cgr_t", "IK refinement: residual of the recurrence, relative to its first exponent", "|r| never grows: < sqrt(rows) < 8", False),
    ("klim_t", "limit-approach gain (1/s)", "checked", True),
    ("qdiff_t", "limit minus q, operand of the limit-approach product", "< 16 (default exact)", True),
    ("gain_t", "servo gains K_p, K_o (1/s)", "checked", True),
    ("dt_t", "tick period (s)", "checked", True),
    ("vel_t", "setpoint twist U' and command V", "saturates, flagged", True),
    ("perr_t", "position error (m)", "saturates, flagged", True),
    ("rot_t", "orientation error, rotation vector (rad)", "|.| <= pi", True),
    ("rvf_t", "phi/sin(phi) table and interpolation (rotation vector)", "[1, pi/2]", True),
    ("tacc_t", "exact accumulator of the solver residual", "exact, n <= 64", False),
    ("weight_t", "per-task row weight (trees of chains)", "[0, 4)", True),
]

METRIC_LABELS = [("pos", "position (m)"), ("rot", "orientation (rad)"), ("jac", "J element, root axes"),
                 ("jac_tool", "J element, tool axes")]


def fmt_sif(W: int, I: int) -> str:
    return f"(1,{I - 1},{W - I})"


def formats_section() -> str:
    fd = {c: formats(c) for c in FIXED_CONFIGS}
    lines = ["| signal | meaning | range | default `ap_fixed<W,I>` (S,I,F) LSB | compact `ap_fixed<W,I>` (S,I,F) LSB | mult. operand |",
             "|---|---|---|---|---|---|"]
    for name, meaning, rng, operand in SIGNALS:
        cells = []
        for c in FIXED_CONFIGS:
            W, I = fd[c][name]
            cells.append(f"`<{W},{I}>` {fmt_sif(W, I)} 2^-{W - I}")
        lines.append(f"| `{name}` | {meaning} | {rng} | {cells[0]} | {cells[1]} | {'yes' if operand else 'no'} |")
    return "\n".join(lines)


def accuracy_section() -> str:
    lines = [f"Worst error over {SAMPLES:,} random configurations per chain (seed {SEED}), "
             "model vs Pinocchio at the same quantised joint values. Bound = what `make test` enforces.", ""]
    head = "| chain | config | " + " | ".join(f"{lab} measured / bound" for _, lab in METRIC_LABELS) + " | max abs(norm(Q)-1) |"
    lines += [head, "|---|---|" + "---|" * len(METRIC_LABELS) + "---|"]
    for name in robots.names():
        for c in FIXED_CONFIGS:
            e = measure_example(name, c)
            cells = [f"{e[k]:.2e} / {BOUNDS[c][k]:.0e}" for k, _ in METRIC_LABELS]
            lines.append(f"| {name} | {c} | " + " | ".join(cells) + f" | {e['qnorm']:.1e} |")
    return "\n".join(lines)


SECTIONS = {"formats": formats_section, "accuracy": accuracy_section}


def render(text: str, only: list[str] | None = None) -> str:
    for name, fn in SECTIONS.items():
        if only and name not in only:
            continue
        pat = re.compile(rf"(<!-- BEGIN {name} -->).*?(<!-- END {name} -->)", re.S)
        if not pat.search(text):
            raise SystemExit(f"update_docs: section {name!r} missing in {DOC}")
        body = fn()
        text = pat.sub(lambda m: m.group(1) + "\n" + body + "\n" + m.group(2), text)
    return text


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--only", nargs="*", choices=list(SECTIONS))
    a = ap.parse_args()
    old = DOC.read_text()
    new = render(old, a.only)
    if a.check:
        if new != old:
            print("update_docs: docs/numerics.md is out of date; run scripts/update_docs.py", file=sys.stderr)
            return 1
        return 0
    DOC.write_text(new)
    return 0


if __name__ == "__main__":
    sys.exit(main())
