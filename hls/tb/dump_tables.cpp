// Prints the model's constant tables (raw values) for hls/gen_tables.py:
//     <config> <table> <count> <raw values...>
// one line per table, from the model's own TrigTable / RecipTable / RotvecTable (fx).
#include <cstdio>

#include "tensor_servo/servo.hpp"

using namespace ts;

namespace {
template <class T>
void line(const char* cfg, const char* name, const T* v, int n) {
  std::printf("%s %s %d", cfg, name, n);
  for (int i = 0; i < n; ++i) std::printf(" %lld", static_cast<long long>(raw_of(v[i])));
  std::printf("\n");
}

template <class Fmt>
void dump(const char* cfg) {
  const auto& tt = TrigTable<Fmt>::get();
  line(cfg, "trig_sin", tt.s, tt.N);
  line(cfg, "trig_cos", tt.c, tt.N);
  line(cfg, "two_pi", &tt.twopi_value, 1);
  line(cfg, "sixth", &tt.sixth_value, 1);
  const auto& rt = RecipTable<Fmt>::get();
  line(cfg, "recip", rt.y, rt.N);
  const auto& vt = RotvecTable<Fmt>::get();
  line(cfg, "rotvec_f", vt.f, vt.N + 1);
  line(cfg, "rotvec_df", vt.df, vt.N + 1);
}
}  // namespace

int main() {
  dump<FmtDefault>("default");
  dump<FmtCompact>("compact");
  return 0;
}
