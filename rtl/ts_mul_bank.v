// SPDX-License-Identifier: Apache-2.0
// tensor-servo: a bank of N exact signed products p_k = a_k * b_k (A_W + B_W bits each), computed
// on L = ceil(N / FOLD) registered multipliers (ts_mul) over FOLD cycles.
//   FOLD = 1: N multipliers in parallel, latency ts_mul_lat(A_W, B_W), II = 1 (in_valid unused).
//   FOLD > 1: the operands are taken at in_valid (cycle 0) and held; in cycle c (0 <= c < FOLD)
//             multiplier l forms product c L + l; the products of the earlier phases are held in
//             registers until the last phase's come out, so every out_p slot is valid in the one
//             cycle ts_bank_lat(A_W, B_W, FOLD) = ts_mul_lat(A_W, B_W) + FOLD - 1 after in_valid.
//             II = FOLD: in_valid must not be set again within FOLD - 1 cycles of the last one.
// The products are exact, so a unit built on the bank gives the same bits at every FOLD; only
// its latency, its initiation interval and its multiplier count change (docs/rtl/shared.md).
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_mul_bank #(
  // Number of products
  parameter N = 4,
  // Products per multiplier (cycles per operation), >= 1
  parameter FOLD = 1,
  // Width of the a operands (signed)
  parameter A_W = 18,
  // Width of the b operands (signed)
  parameter B_W = 18,
  // Multiplier implementation: "GENERIC" or "ECP5" (see ts_mul)
  parameter TARGET = "GENERIC",
  // ECP5 wide products on three MULT18X18D (see ts_mul)
  parameter MUL3 = 0,
  // FOLD > 1: how the held operands reach the multipliers.  0: held once, a FOLD:1 select per
  // multiplier input; 1: shift chains per multiplier, for operands and products (more registers
  // and LUTs, shorter wires; docs/rtl/shared.md).  The bits and the latency never depend on it.
  parameter CHAIN = 0
) (
  input  wire                       clk,
  input  wire                       rst,
  input  wire                       in_valid,
  // operand k: in_a[k*A_W +: A_W], in_b[k*B_W +: B_W]
  input  wire [N*A_W-1:0]           in_a,
  input  wire [N*B_W-1:0]           in_b,
  // product k: out_p[k*(A_W+B_W) +: A_W+B_W]
  output wire [N*(A_W+B_W)-1:0]     out_p
);

  `include "ts_common.vh"

  localparam P_W = A_W + B_W;

  genvar l, c;
  generate
    if (FOLD < 1) begin : g_bad
      // Elaboration error: FOLD must be at least 1.
      ts_mul_bank_fold_must_be_positive u_error ();
    end

    if (FOLD == 1) begin : g_par
      for (l = 0; l < N; l = l + 1) begin : g_m
        ts_mul #(.A_W(A_W), .B_W(B_W), .TARGET(TARGET), .MUL3(MUL3)) u_m (
          .clk(clk), .rst(rst), .a(in_a[l*A_W +: A_W]), .b(in_b[l*B_W +: B_W]), .p(out_p[l*P_W +: P_W]));
      end
      wire unused_valid = in_valid;
    end else begin : g_fold
      localparam L = (N + FOLD - 1) / FOLD;       // multipliers
      localparam NP = L * FOLD;                   // slots, padded
      localparam PH_W = $clog2(FOLD);
      localparam ML = ts_mul_lat(A_W, B_W);
      localparam integer FOLD_M1 = FOLD - 1;
      localparam [PH_W-1:0] LAST = FOLD_M1[PH_W-1:0];

      // operands padded to NP slots (the padding slots multiply zeros and are never read)
      wire [NP*A_W-1:0] pa;
      wire [NP*B_W-1:0] pb;
      if (NP > N) begin : g_pad
        assign pa = {{((NP-N)*A_W){1'b0}}, in_a};
        assign pb = {{((NP-N)*B_W){1'b0}}, in_b};
      end else begin : g_nopad
        assign pa = in_a;
        assign pb = in_b;
      end
      // phase of this cycle's operands when not 0 (both forms)
      reg  [PH_W-1:0] ph;
      always @(posedge clk) begin
        if (rst) ph <= {PH_W{1'b0}};
        else if (in_valid) ph <= {{(PH_W-1){1'b0}}, 1'b1};
        else if (ph != {PH_W{1'b0}}) ph <= (ph == LAST) ? {PH_W{1'b0}} : ph + 1'b1;
      end
      wire act = in_valid | (ph != {PH_W{1'b0}});
      // held operands of phases 1 .. FOLD-1 (slot c of lane l at [((c-1)*L+l)*W]), loaded at
      // in_valid and reset to zero, so the products are defined before the first operation; with
      // CHAIN = 1 they shift down one slot per cycle (ha_sh), otherwise they stay (ha_sh = ha)
      reg  [(NP-L)*A_W-1:0] ha;
      reg  [(NP-L)*B_W-1:0] hb;
      wire [(NP-L)*A_W-1:0] ha_sh;
      wire [(NP-L)*B_W-1:0] hb_sh;
      if (CHAIN != 0 && FOLD > 2) begin : g_sh
        assign ha_sh = {{(L*A_W){1'b0}}, ha[(NP-L)*A_W-1:L*A_W]};
        assign hb_sh = {{(L*B_W){1'b0}}, hb[(NP-L)*B_W-1:L*B_W]};
      end else begin : g_hold
        assign ha_sh = ha;
        assign hb_sh = hb;
      end
      always @(posedge clk) begin
        if (rst) begin
          ha <= {((NP-L)*A_W){1'b0}};
          hb <= {((NP-L)*B_W){1'b0}};
        end else if (in_valid) begin
          ha <= pa[NP*A_W-1:L*A_W];
          hb <= pb[NP*B_W-1:L*B_W];
        end else if (ph != {PH_W{1'b0}}) begin
          ha <= ha_sh;
          hb <= hb_sh;
        end
      end
      if (CHAIN == 0) begin : g_select
        // one copy of the held operands, a FOLD:1 ts_sel per multiplier input; the products of the
        // phases before the last captured in a register per slot
        wire [PH_W-1:0] sel = in_valid ? {PH_W{1'b0}} : ph;

        // phase of the products at the multiplier outputs
        wire [PH_W:0] osel;
        ts_delay #(.W(PH_W+1), .DEPTH(ML)) u_od (.clk(clk), .rst(rst), .din({act, sel}), .dout(osel));
        wire            o_act = osel[PH_W];
        wire [PH_W-1:0] o_ph = osel[PH_W-1:0];

        for (l = 0; l < L; l = l + 1) begin : g_lane
          // candidates of this lane, one per phase: phase 0 from the inputs, the others held
          wire [FOLD*A_W-1:0] ca;
          wire [FOLD*B_W-1:0] cb;
          for (c = 0; c < FOLD; c = c + 1) begin : g_c
            if (c == 0) begin : g_in
              assign ca[c*A_W +: A_W] = pa[(c*L+l)*A_W +: A_W];
              assign cb[c*B_W +: B_W] = pb[(c*L+l)*B_W +: B_W];
            end else begin : g_held
              assign ca[c*A_W +: A_W] = ha[((c-1)*L+l)*A_W +: A_W];
              assign cb[c*B_W +: B_W] = hb[((c-1)*L+l)*B_W +: B_W];
            end
          end
          wire [A_W-1:0] a_l;
          wire [B_W-1:0] b_l;
          ts_sel #(.W(A_W), .N(FOLD), .IW(PH_W)) u_sa (.in_vec(ca), .in_idx(sel), .out_el(a_l));
          ts_sel #(.W(B_W), .N(FOLD), .IW(PH_W)) u_sb (.in_vec(cb), .in_idx(sel), .out_el(b_l));
          wire signed [P_W-1:0] p_l;
          ts_mul #(.A_W(A_W), .B_W(B_W), .TARGET(TARGET), .MUL3(MUL3)) u_m (
            .clk(clk), .rst(rst), .a(a_l), .b(b_l), .p(p_l));

          // products of the phases before the last are held; the last phase's pass through
          for (c = 0; c < FOLD; c = c + 1) begin : g_o
            if (c*L + l < N) begin : g_used
              if (c == FOLD - 1) begin : g_last
                assign out_p[(c*L+l)*P_W +: P_W] = p_l;
              end else begin : g_held
                localparam [PH_W-1:0] C = c;
                reg [P_W-1:0] cap;
                always @(posedge clk) begin
                  if (rst) cap <= {P_W{1'b0}};
                  else if (o_act && (o_ph == C)) cap <= p_l;
                end
                assign out_p[(c*L+l)*P_W +: P_W] = cap;
              end
            end else if (c == FOLD - 1) begin : g_pad
              wire unused_p = ^p_l;
            end
          end
        end
      end else begin : g_chains
        // shift chains for the held operands (ha, hb above) and products (CHAIN = 1): the
        // multiplier always reads the chain's head (or, in the in_valid cycle, the input).  A 2:1
        // multiplexer per held bit and one per multiplier operand bit, with wires between
        // neighbouring slots only, instead of a FOLD:1 multiplexer tree in front of each multiplier
        // (docs/rtl/shared.md).
        // at the multiplier outputs: a product of this operation (shift it in; the shift at the last
        // phase comes after the one cycle in which out_p is read)
        wire o_shift;
        ts_delay #(.W(1), .DEPTH(ML)) u_od (.clk(clk), .rst(rst), .din(act), .dout(o_shift));

        for (l = 0; l < L; l = l + 1) begin : g_lane
          // this cycle's operands: the input in the in_valid cycle, else the head of the chain
          wire [A_W-1:0] a_l = in_valid ? pa[l*A_W +: A_W] : ha[l*A_W +: A_W];
          wire [B_W-1:0] b_l = in_valid ? pb[l*B_W +: B_W] : hb[l*B_W +: B_W];
          wire signed [P_W-1:0] p_l;
          ts_mul #(.A_W(A_W), .B_W(B_W), .TARGET(TARGET), .MUL3(MUL3)) u_m (
            .clk(clk), .rst(rst), .a(a_l), .b(b_l), .p(p_l));

          // Products of the phases before the last, held in a shift chain (phase c at [c*P_W] in
          // the cycle the last phase's product is out, which passes straight through): each
          // product bit drives one register, not FOLD - 1.
          reg  [(FOLD-1)*P_W-1:0] hp;
          wire [(FOLD-1)*P_W-1:0] hp_sh;      // p_l shifted in (FOLD 2: one slot)
          if (FOLD > 2) begin : g_chain
            assign hp_sh = {p_l, hp[(FOLD-1)*P_W-1:P_W]};
          end else begin : g_one
            assign hp_sh = p_l;
          end
          always @(posedge clk) begin
            if (rst) hp <= {((FOLD-1)*P_W){1'b0}};
            else if (o_shift) hp <= hp_sh;
          end
          for (c = 0; c < FOLD; c = c + 1) begin : g_o
            if (c*L + l < N) begin : g_used
              if (c == FOLD - 1) begin : g_last
                assign out_p[(c*L+l)*P_W +: P_W] = p_l;
              end else begin : g_held
                assign out_p[(c*L+l)*P_W +: P_W] = hp[c*P_W +: P_W];
              end
            end
          end
        end
      end
    end
  endgenerate

endmodule

`default_nettype wire
