// SPDX-License-Identifier: Apache-2.0
// tensor-servo formal harness: ts_quat_mul (TARGET "GENERIC") against a straightforward reference --
// each component one expression of four exact products, rounded half up and saturated, written
// directly from ts::qmul -- delayed by the module latency.  Whenever out_valid is set the outputs
// and the flag must equal the reference of the vector that entered LATENCY cycles earlier.
// Reset is tied low and every register starts at zero (the state reset leaves); the reset itself is
// checked by the cocotb bench.  Used by tb/test_formal_qmul.py: unrolled from that state over
// LATENCY + 1 cycles, which for this feed-forward pipeline covers every input vector.  TIE_DOWN = 1 makes the reference round
// ties toward -inf (a deliberately wrong reference: the proof must fail).
`default_nettype none

module formal_qmul #(
  parameter Q_W = 6,
  parameter Q_F = 4,
  parameter LATENCY = 7,
  parameter TIE_DOWN = 0
) (
  input  wire                  clk,
  input  wire                  in_valid,
  input  wire signed [Q_W-1:0] aw, ax, ay, az, bw, bx, by, bz
);

  wire                  out_valid, out_sat;
  wire signed [Q_W-1:0] ow, ox, oy, oz;
  ts_quat_mul #(.Q_W(Q_W), .Q_F(Q_F), .TARGET("GENERIC")) dut (
    .clk(clk), .rst(1'b0), .in_valid(in_valid),
    .in_a_w(aw), .in_a_x(ax), .in_a_y(ay), .in_a_z(az),
    .in_b_w(bw), .in_b_x(bx), .in_b_y(by), .in_b_z(bz),
    .out_valid(out_valid), .out_w(ow), .out_x(ox), .out_y(oy), .out_z(oz), .out_sat(out_sat));

  // the 16 products at their natural width, then each component as one expression
  localparam P_W = 2 * Q_W;
  localparam E_W = 2 * Q_W + 3;
  wire signed [P_W-1:0] p00 = aw * bw, p01 = aw * bx, p02 = aw * by, p03 = aw * bz;
  wire signed [P_W-1:0] p10 = ax * bw, p11 = ax * bx, p12 = ax * by, p13 = ax * bz;
  wire signed [P_W-1:0] p20 = ay * bw, p21 = ay * bx, p22 = ay * by, p23 = ay * bz;
  wire signed [P_W-1:0] p30 = az * bw, p31 = az * bx, p32 = az * by, p33 = az * bz;
  wire signed [E_W-1:0] e0 = p00 - p11 - p22 - p33;
  wire signed [E_W-1:0] e1 = p01 + p10 + p23 - p32;
  wire signed [E_W-1:0] e2 = p02 - p13 + p20 + p31;
  wire signed [E_W-1:0] e3 = p03 + p12 - p21 + p30;

  localparam signed [E_W-1:0] HALF = (TIE_DOWN != 0) ? ((1 << (Q_F - 1)) - 1) : (1 << (Q_F - 1));
  localparam signed [E_W-1:0] MAXV = (1 << (Q_W - 1)) - 1;
  localparam signed [E_W-1:0] MINV = -(1 << (Q_W - 1));

  function [Q_W:0] cvt;   // {saturated, value}
    input signed [E_W-1:0] e;
    reg signed [E_W-1:0] r;
    begin
      r = (e + HALF) >>> Q_F;
      if (r > MAXV)      cvt = {1'b1, MAXV[Q_W-1:0]};
      else if (r < MINV) cvt = {1'b1, MINV[Q_W-1:0]};
      else               cvt = {1'b0, r[Q_W-1:0]};
    end
  endfunction

  wire [Q_W:0] c0 = cvt(e0), c1 = cvt(e1), c2 = cvt(e2), c3 = cvt(e3);
  wire [4*Q_W:0] ref_now = {c0[Q_W] | c1[Q_W] | c2[Q_W] | c3[Q_W],
                            c3[Q_W-1:0], c2[Q_W-1:0], c1[Q_W-1:0], c0[Q_W-1:0]};

  reg [4*Q_W:0] ref_pipe [0:LATENCY-1];
  integer i;
  always @(posedge clk) begin
    ref_pipe[0] <= ref_now;
    for (i = 1; i < LATENCY; i = i + 1) ref_pipe[i] <= ref_pipe[i-1];
  end
  wire [4*Q_W:0] r = ref_pipe[LATENCY-1];

  always @(*) begin
    if (out_valid) begin
      assert (ow == r[Q_W-1:0]);
      assert (ox == r[2*Q_W-1:Q_W]);
      assert (oy == r[3*Q_W-1:2*Q_W]);
      assert (oz == r[4*Q_W-1:3*Q_W]);
      assert (out_sat == r[4*Q_W]);
    end
  end

endmodule

`default_nettype wire
