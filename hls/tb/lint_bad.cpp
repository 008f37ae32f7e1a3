// A deliberately non-synthesisable top function: scripts/hls_lint.py must report every kind of
// violation here (model/tests/test_hls.py checks it does).  Not part of any build.
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

namespace bad {
int fact(int n) { return n <= 1 ? 1 : n * fact(n - 1); }                        // recursion
struct Table { double v[8]; Table() { for (int i = 0; i < 8; ++i) v[i] = std::sin(i); } };  // math
const Table& table() { static const Table t; return t; }                         // run-time static
int twice(int x) { return 2 * x; }
}  // namespace bad

int bad_top(int n, int x) {
  int* p = static_cast<int*>(std::malloc(4 * sizeof(int)));                     // dynamic memory
  std::vector<int> v(3, x);                                                        // STL container
  int (*f)(int) = bad::twice;
  int s = f(x);                                                                    // indirect call
  for (int i = 0; i < n; ++i) s += i;                                              // run-time bound
  while (s > 100) s -= 7;                                                          // while loop
  std::free(p);
  return s + bad::fact(x) + static_cast<int>(bad::table().v[1]) + static_cast<int>(v.size());
}
