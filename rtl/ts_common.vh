// tensor-servo: constant functions shared by the datapath modules (included inside module bodies).
// Language: Verilog 2005
//
// Lint: Verilator 5.006 reports VARHIDDEN on these functions in one elaboration of the whole core with
// TARGET "GENERIC" (the ts_quat_mul parameterisation that ts_core_fk and ts_core_law share: the
// function of the instance "hides" the same function of an enclosing module).  Every copy is this
// file's, so nothing is hidden that differs; the waiver covers this file only.
/* verilator lint_off VARHIDDEN */

// Latency of ts_mul in clock cycles for operand widths aw x bw, for every TARGET: 3 register
// stages (input, product, output); with an operand wider than 18 bits one more for the fabric
// register after the ECP5 partial products and one adder level per wide operand (the GENERIC
// target pads with registers to the same latency).
function integer ts_mul_lat;
  input integer aw;
  input integer bw;
  begin
    ts_mul_lat = 3 + (((aw > 18) || (bw > 18)) ? 1 : 0) + ((aw > 18) ? 1 : 0) + ((bw > 18) ? 1 : 0);
  end
endfunction

// Latency of ts_mul_bank (products a x b of widths aw x bw, FOLD fold): every product out in one
// cycle, the last phase's fold - 1 cycles after the first's.
function integer ts_bank_lat;
  input integer aw;
  input integer bw;
  input integer fold;
  begin
    ts_bank_lat = ts_mul_lat(aw, bw) + fold - 1;
  end
endfunction

// Latency of ts_quat_rotate (q of width qw, vector vw, intermediate t tw; fold as its FOLD): stage A
// products, a registered difference and the rounding of t, then stage B products, two adder
// levels and the output rounding.  The law's own rotation has the same pipeline.
function integer ts_rotate_lat;
  input integer qw;
  input integer vw;
  input integer tw;
  input integer fold;
  begin
    ts_rotate_lat = ts_bank_lat(qw, vw, fold) + 1 + ts_round_lat(1) + ts_bank_lat(qw, tw, fold) + 2 +
                    ts_round_lat(1);
  end
endfunction

function integer ts_max;
  input integer x;
  input integer y;
  begin
    ts_max = (x > y) ? x : y;
  end
endfunction

// Latency of ts_round_sat in clock cycles (for either mode sat = 1 / 0).
function integer ts_round_lat;
  input integer sat;
  begin
    ts_round_lat = (sat >= 0) ? 2 : 2;
  end
endfunction
/* verilator lint_on VARHIDDEN */
