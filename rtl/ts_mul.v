// SPDX-License-Identifier: Apache-2.0
// tensor-servo: registered signed multiplier p = a * b (exact, A_W + B_W bits), fixed latency
// ts_mul_lat(A_W, B_W) cycles (3; with an operand wider than 18 bits 1 + (A_W > 18) + (B_W > 18)
// more), II = 1, for every TARGET:
//   "GENERIC"  inferred product: input registers, product register, output register (+ padding);
//              maps onto DSP48E1 AREG/BREG/MREG/PREG on 7-series.
//   "ECP5"     explicit MULT18X18D instances with input, pipeline and output registers enabled
//              (yosys infers ECP5 multipliers as combinational cells).  An operand wider than 18
//              bits is split into an unsigned low 17-bit part and a signed high part (<= 18 bits),
//              so A_W, B_W <= 35; the 2 or 4 partial products are registered in the fabric (the
//              route from a DSP block to the adders limited Fmax) and summed by a registered tree.
//              MUL3 = 1 (both operands 19..33 bits): a Karatsuba form on three MULT18X18D instead of
//              four (16-bit split, the pre-adds in front of the DSP input registers), the same
//              product and latency; a shape outside that range keeps its 1, 2 or 4 instances.
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_mul #(
  // Width of operand a (signed); <= 35 for TARGET "ECP5"
  parameter A_W = 18,
  // Width of operand b (signed); <= 35 for TARGET "ECP5"
  parameter B_W = 18,
  // Implementation: "GENERIC" (inferred) or "ECP5" (MULT18X18D instances)
  parameter TARGET = "GENERIC",
  // ECP5, both operands 19..33 bits: 1 = three MULT18X18D (Karatsuba, 16-bit split) instead of
  // four; the same product and latency.  Ignored otherwise.
  parameter MUL3 = 0
) (
  input  wire                      clk,
  input  wire                      rst,
  input  wire signed [A_W-1:0]     a,
  input  wire signed [B_W-1:0]     b,
  output wire signed [A_W+B_W-1:0] p
);

  `include "ts_common.vh"

  localparam P_W = A_W + B_W;
  localparam LAT = ts_mul_lat(A_W, B_W);

  generate
    if (TARGET == "ECP5") begin : g_ecp5
      if ((A_W > 35) || (B_W > 35)) begin : g_bad
        // Elaboration error: operand too wide for the two-part ECP5 decomposition.
        ts_mul_ecp5_operand_wider_than_35_bits u_error ();
      end

      localparam NA = (A_W > 18) ? 2 : 1;
      localparam NB = (B_W > 18) ? 2 : 1;

      localparam K3 = (MUL3 != 0) && (A_W > 18) && (B_W > 18) && (A_W <= 33) && (B_W <= 33);

      if (K3) begin : g_k3
        // Karatsuba: a = a1 2^16 + a0, b = b1 2^16 + b0 with a0, b0 unsigned 16-bit and a1, b1
        // signed (<= 17 bits).  a0 + a1 and b0 + b1 fit 18-bit signed (A_W, B_W <= 33), so
        //   a b = a1 b1 2^32 + ((a0 + a1)(b0 + b1) - a0 b0 - a1 b1) 2^16 + a0 b0
        // on three MULT18X18D; the pre-adds feed the DSP input registers.
        wire signed [17:0] a0 = {2'b00, a[15:0]};
        wire signed [17:0] b0 = {2'b00, b[15:0]};
        wire signed [17:0] a1, b1;
        ts_resize #(.IN_W(A_W-16), .LSH(0), .OUT_W(18)) u_a1 (.in(a[A_W-1:16]), .out(a1));
        ts_resize #(.IN_W(B_W-16), .LSH(0), .OUT_W(18)) u_b1 (.in(b[B_W-1:16]), .out(b1));
        wire signed [17:0] a_s = a0 + a1;
        wire signed [17:0] b_s = b0 + b1;
        wire signed [35:0] k00, k11, kss;
        ts_ecp5_mult18 u_m00 (.clk(clk), .rst(rst), .a(a0), .b(b0), .p(k00));
        ts_ecp5_mult18 u_m11 (.clk(clk), .rst(rst), .a(a1), .b(b1), .p(k11));
        ts_ecp5_mult18 u_mss (.clk(clk), .rst(rst), .a(a_s), .b(b_s), .p(kss));
        reg signed [35:0] q00, q11, qss;
        always @(posedge clk) begin
          if (rst) begin
            q00 <= 36'sd0; q11 <= 36'sd0; qss <= 36'sd0;
          end else begin
            q00 <= k00; q11 <= k11; qss <= kss;
          end
        end
        // Level 1: the middle term (a0 b1 + a1 b0, modulo 2^(P_W-16)) and the concatenation of the
        // high and low products (a0 b0 < 2^32).  Level 2: one add.  Modulo 2^P_W throughout.
        wire signed [P_W-17:0] m00, m11, mss;
        ts_resize #(.IN_W(36), .LSH(0), .OUT_W(P_W-16)) u_r00 (.in(q00), .out(m00));
        ts_resize #(.IN_W(36), .LSH(0), .OUT_W(P_W-16)) u_r11 (.in(q11), .out(m11));
        ts_resize #(.IN_W(36), .LSH(0), .OUT_W(P_W-16)) u_rss (.in(qss), .out(mss));
        wire signed [P_W-1:0] cat;
        ts_resize #(.IN_W(68), .LSH(0), .OUT_W(P_W)) u_cat (.in({q11, q00[31:0]}), .out(cat));
        reg signed [P_W-17:0] mid_r;
        reg signed [P_W-1:0]  cat_r;
        reg signed [P_W-1:0]  sum_r;
        always @(posedge clk) begin
          if (rst) begin
            mid_r <= {(P_W-16){1'b0}};
            cat_r <= {P_W{1'b0}};
            sum_r <= {P_W{1'b0}};
          end else begin
            mid_r <= mss - m00 - m11;
            cat_r <= cat;
            sum_r <= cat_r + {mid_r, 16'd0};
          end
        end
        assign p = sum_r;
      end else begin : g_k4
        // Operand parts as 18-bit signed multiplier inputs: [0] low (or whole), [1] high.
        wire signed [17:0] ap [0:1];
        wire signed [17:0] bp [0:1];
        if (NA == 1) begin : g_a1
          ts_resize #(.IN_W(A_W), .LSH(0), .OUT_W(18)) u_a0 (.in(a), .out(ap[0]));
          assign ap[1] = 18'sd0;
        end else begin : g_a2
          assign ap[0] = {1'b0, a[16:0]};
          ts_resize #(.IN_W(A_W-17), .LSH(0), .OUT_W(18)) u_a1 (.in(a[A_W-1:17]), .out(ap[1]));
        end
        if (NB == 1) begin : g_b1
          ts_resize #(.IN_W(B_W), .LSH(0), .OUT_W(18)) u_b0 (.in(b), .out(bp[0]));
          assign bp[1] = 18'sd0;
        end else begin : g_b2
          assign bp[0] = {1'b0, b[16:0]};
          ts_resize #(.IN_W(B_W-17), .LSH(0), .OUT_W(18)) u_b1 (.in(b[B_W-1:17]), .out(bp[1]));
        end

        // Partial products pp[i][j] = ap[i] * bp[j], weight 2^(17 (i + j)).
        wire signed [35:0] pp00, pp01, pp10, pp11;
        ts_ecp5_mult18 u_m00 (.clk(clk), .rst(rst), .a(ap[0]), .b(bp[0]), .p(pp00));
        if (NB == 2) begin : g_m01
          ts_ecp5_mult18 u_m01 (.clk(clk), .rst(rst), .a(ap[0]), .b(bp[1]), .p(pp01));
        end else begin : g_n01
          assign pp01 = 36'sd0;
        end
        if (NA == 2) begin : g_m10
          ts_ecp5_mult18 u_m10 (.clk(clk), .rst(rst), .a(ap[1]), .b(bp[0]), .p(pp10));
        end else begin : g_n10
          assign pp10 = 36'sd0;
        end
        if ((NA == 2) && (NB == 2)) begin : g_m11
          ts_ecp5_mult18 u_m11 (.clk(clk), .rst(rst), .a(ap[1]), .b(bp[1]), .p(pp11));
        end else begin : g_n11
          assign pp11 = 36'sd0;
        end

        if ((NA == 1) && (NB == 1)) begin : g_sum1
          // One product: the DSP output register is the module output.
          ts_resize #(.IN_W(36), .LSH(0), .OUT_W(P_W)) u_p (.in(pp00), .out(p));
          wire unused_pp = ^{pp01, pp10, pp11};
        end else if ((NA == 2) && (NB == 2)) begin : g_sum4
          // Level 1: the two middle products (weight 2^17) are added; low (unsigned, < 2^34) and
          // high (weight 2^34) products are concatenated, no adder needed.
          // Level 2: one add.  All sums are modulo 2^P_W (the exact product fits P_W bits).
          reg signed [35:0] q00, q01, q10, q11;
          always @(posedge clk) begin
            if (rst) begin
              q00 <= 36'sd0; q01 <= 36'sd0; q10 <= 36'sd0; q11 <= 36'sd0;
            end else begin
              q00 <= pp00; q01 <= pp01; q10 <= pp10; q11 <= pp11;
            end
          end
          wire signed [P_W-18:0] m01, m10;
          ts_resize #(.IN_W(36), .LSH(0), .OUT_W(P_W-17)) u_r01 (.in(q01), .out(m01));
          ts_resize #(.IN_W(36), .LSH(0), .OUT_W(P_W-17)) u_r10 (.in(q10), .out(m10));
          wire signed [P_W-1:0] cat;
          ts_resize #(.IN_W(70), .LSH(0), .OUT_W(P_W)) u_cat (.in({q11, q00[33:0]}), .out(cat));
          wire unused_pp00 = ^q00[35:34];
          reg signed [P_W-18:0] mid_r;
          reg signed [P_W-1:0]  cat_r;
          reg signed [P_W-1:0]  sum_r;
          always @(posedge clk) begin
            if (rst) begin
              mid_r <= {(P_W-17){1'b0}};
              cat_r <= {P_W{1'b0}};
              sum_r <= {P_W{1'b0}};
            end else begin
              mid_r <= m01 + m10;
              cat_r <= cat;
              sum_r <= cat_r + {mid_r, 17'd0};
            end
          end
          assign p = sum_r;
        end else begin : g_sum2
          // Two products: low part (weight 1) + high part (weight 2^17).
          reg signed [35:0] q_lo, q_hi;
          always @(posedge clk) begin
            if (rst) begin
              q_lo <= 36'sd0; q_hi <= 36'sd0;
            end else begin
              q_lo <= pp00; q_hi <= (NA == 2) ? pp10 : pp01;
            end
          end
          wire signed [P_W-1:0] lo_e;
          wire signed [P_W-18:0] hi_e;
          ts_resize #(.IN_W(36), .LSH(0), .OUT_W(P_W)) u_lo (.in(q_lo), .out(lo_e));
          ts_resize #(.IN_W(36), .LSH(0), .OUT_W(P_W-17)) u_hi (.in(q_hi), .out(hi_e));
          wire unused_pp11 = ^pp11;
          reg signed [P_W-1:0] sum_r;
          always @(posedge clk) begin
            if (rst) sum_r <= {P_W{1'b0}};
            else     sum_r <= lo_e + {hi_e, 17'd0};
          end
          assign p = sum_r;
        end
      end
    end else begin : g_generic
      reg signed [A_W-1:0] a_r;
      reg signed [B_W-1:0] b_r;
      reg signed [P_W-1:0] m_r;
      always @(posedge clk) begin
        if (rst) begin
          a_r <= {A_W{1'b0}};
          b_r <= {B_W{1'b0}};
          m_r <= {P_W{1'b0}};
        end else begin
          a_r <= a;
          b_r <= b;
          m_r <= a_r * b_r;
        end
      end
      // Output register plus padding to the common latency.
      ts_delay #(.W(P_W), .DEPTH(LAT - 2)) u_out (.clk(clk), .rst(rst), .din(m_r), .dout(p));
    end
  endgenerate

endmodule

`default_nettype wire
