// tensor-servo: a Verilator driver of the whole servo core (rtl/ts_servo_core.v), spoken to over
// stdin/stdout one line per command, so that Python (tensor_servo.rtl_core) can run the Verilated
// core tick by tick at full Verilator speed, without a cocotb scheduler in between.
//
// Commands (decimal or 0x-hex integers; one answer line each, starting with "ok" or "err"):
//   reset                 rst high for 5 cycles          -> ok
//   w ADDR DATA           AXI4-Lite write                -> ok BRESP
//   r ADDR                AXI4-Lite read                 -> ok RDATA RRESP
//   t N W1 .. WN          one input packet (TLAST on WN), then run until the output packet's TLAST
//                                                        -> ok CYCLES M O1 .. OM
//                         CYCLES: clock cycles from the first input word's handshake to the last
//                         output word's (TREADY of the output is held high); O* signed 32-bit
//   c N                   N idle clock cycles            -> ok
//   q                     quit
// A handshake that does not complete within the timeout (TS_HARNESS_TIMEOUT cycles, default 10^6)
// answers "err timeout <what>" and the harness stays usable after a reset.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "Vts_servo_core.h"
#include "verilated.h"

namespace {

struct Harness {
  std::unique_ptr<VerilatedContext> ctx{new VerilatedContext};
  std::unique_ptr<Vts_servo_core> top;
  uint64_t timeout = 1000000;

  Harness() : top(new Vts_servo_core(ctx.get(), "core")) {
    if (const char* t = std::getenv("TS_HARNESS_TIMEOUT")) timeout = std::strtoull(t, nullptr, 0);
    top->clk = 0;
    top->rst = 1;
    top->s_axil_awvalid = top->s_axil_wvalid = top->s_axil_bready = 0;
    top->s_axil_arvalid = top->s_axil_rready = 0;
    top->s_axil_awprot = top->s_axil_arprot = 0;
    top->s_axil_wstrb = 0xF;
    top->s_axis_tvalid = top->s_axis_tlast = 0;
    top->s_axis_tdata = 0;
    top->m_axis_tready = 0;
    top->eval();
  }
  ~Harness() { top->final(); }

  // One rising edge: inputs were set and evaluated before; outputs settle after.
  void cycle() {
    top->clk = 1;
    top->eval();
    top->clk = 0;
    top->eval();
  }

  void reset() {
    top->rst = 1;
    top->s_axil_awvalid = top->s_axil_wvalid = top->s_axil_arvalid = 0;
    top->s_axis_tvalid = 0;
    top->m_axis_tready = 0;
    top->eval();
    for (int i = 0; i < 5; ++i) cycle();
    top->rst = 0;
    top->eval();
    cycle();
  }

  bool write(uint32_t addr, uint32_t data, int& resp) {
    top->s_axil_awaddr = addr;
    top->s_axil_wdata = data;
    top->s_axil_wstrb = 0xF;
    top->s_axil_awvalid = 1;
    top->s_axil_wvalid = 1;
    top->s_axil_bready = 1;
    top->eval();
    bool aw = false, w = false;
    for (uint64_t k = 0; k < timeout; ++k) {
      const bool aw_fire = !aw && top->s_axil_awready, w_fire = !w && top->s_axil_wready;
      const bool b_fire = top->s_axil_bvalid;
      if (b_fire && aw && w) {
        resp = top->s_axil_bresp;
        cycle();
        top->s_axil_bready = 0;
        top->eval();
        return true;
      }
      cycle();
      aw = aw || aw_fire;
      w = w || w_fire;
      if (aw) top->s_axil_awvalid = 0;
      if (w) top->s_axil_wvalid = 0;
      top->eval();
    }
    return false;
  }

  bool read(uint32_t addr, uint32_t& data, int& resp) {
    top->s_axil_araddr = addr;
    top->s_axil_arvalid = 1;
    top->s_axil_rready = 1;
    top->eval();
    bool ar = false;
    for (uint64_t k = 0; k < timeout; ++k) {
      const bool ar_fire = !ar && top->s_axil_arready;
      if (ar && top->s_axil_rvalid) {
        data = top->s_axil_rdata;
        resp = top->s_axil_rresp;
        cycle();
        top->s_axil_rready = 0;
        top->eval();
        return true;
      }
      cycle();
      ar = ar || ar_fire;
      if (ar) top->s_axil_arvalid = 0;
      top->eval();
    }
    return false;
  }

  // Send one packet and collect one answer; both streams run in the same cycles (the core may
  // start answering before the input ends: a malformed packet is answered at once).
  bool tick(const std::vector<uint32_t>& in, std::vector<int32_t>& out, uint64_t& cycles) {
    size_t i = 0;
    bool started = false, done = false;
    uint64_t start = 0, now = 0;
    out.clear();
    top->m_axis_tready = 1;
    for (uint64_t k = 0; k < timeout && !done; ++k, ++now) {
      if (i < in.size()) {
        top->s_axis_tvalid = 1;
        top->s_axis_tdata = in[i];
        top->s_axis_tlast = (i + 1 == in.size());
      } else {
        top->s_axis_tvalid = 0;
        top->s_axis_tlast = 0;
      }
      top->eval();
      const bool in_fire = top->s_axis_tvalid && top->s_axis_tready;
      const bool out_fire = top->m_axis_tvalid;
      if (out_fire) {
        out.push_back(static_cast<int32_t>(top->m_axis_tdata));
        if (top->m_axis_tlast) done = true;
      }
      if (in_fire) {
        if (!started) { started = true; start = now; }
        ++i;
      }
      cycle();
    }
    top->s_axis_tvalid = 0;
    top->s_axis_tlast = 0;
    top->m_axis_tready = 0;
    top->eval();
    cycles = now - start;
    return done && i == in.size();
  }
};

uint64_t num(const std::string& s) { return std::strtoull(s.c_str(), nullptr, 0); }

}  // namespace

int main(int argc, char** argv) {
  Verilated::commandArgs(argc, argv);
  Harness h;
  h.reset();
  std::string line;
  char buf[1 << 16];
  std::setvbuf(stdout, nullptr, _IOFBF, 1 << 16);
  while (std::fgets(buf, sizeof buf, stdin)) {
    std::istringstream in(buf);
    std::string cmd;
    if (!(in >> cmd)) continue;
    if (cmd == "q") break;
    if (cmd == "reset") {
      h.reset();
      std::printf("ok\n");
    } else if (cmd == "w") {
      std::string a, d;
      int resp = 0;
      if (!(in >> a >> d)) std::printf("err usage: w ADDR DATA\n");
      else if (!h.write(static_cast<uint32_t>(num(a)), static_cast<uint32_t>(num(d)), resp)) std::printf("err timeout write\n");
      else std::printf("ok %d\n", resp);
    } else if (cmd == "r") {
      std::string a;
      uint32_t data = 0;
      int resp = 0;
      if (!(in >> a)) std::printf("err usage: r ADDR\n");
      else if (!h.read(static_cast<uint32_t>(num(a)), data, resp)) std::printf("err timeout read\n");
      else std::printf("ok %u %d\n", data, resp);
    } else if (cmd == "t") {
      std::string s;
      in >> s;
      const uint64_t n = num(s);
      std::vector<uint32_t> words;
      for (uint64_t k = 0; k < n && in >> s; ++k) words.push_back(static_cast<uint32_t>(std::strtoll(s.c_str(), nullptr, 0)));
      std::vector<int32_t> out;
      uint64_t cyc = 0;
      if (words.size() != n || n == 0) std::printf("err usage: t N W1 .. WN\n");
      else if (!h.tick(words, out, cyc)) std::printf("err timeout tick\n");
      else {
        std::printf("ok %llu %zu", static_cast<unsigned long long>(cyc), out.size());
        for (int32_t v : out) std::printf(" %d", v);
        std::printf("\n");
      }
    } else if (cmd == "c") {
      std::string s;
      in >> s;
      for (uint64_t k = num(s); k > 0; --k) h.cycle();
      std::printf("ok\n");
    } else {
      std::printf("err unknown command %s\n", cmd.c_str());
    }
    std::fflush(stdout);
  }
  return 0;
}
