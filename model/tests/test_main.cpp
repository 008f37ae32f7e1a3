#include <cstring>

#include "check.hpp"

int main(int argc, char** argv) {
  int run = 0;
  for (const auto& c : tscheck::registry()) {
    if (argc > 1 && std::strstr(c.name, argv[1]) == nullptr) continue;
    const int before = tscheck::failures();
    c.fn();
    ++run;
    std::printf("%-60s %s\n", c.name, tscheck::failures() == before ? "ok" : "FAILED");
  }
  std::printf("%d test cases, %d failed checks\n", run, tscheck::failures());
  return tscheck::failures() == 0 && run > 0 ? 0 : 1;
}
