// Minimal test registry for the C++ model tests (no external framework needed).
#pragma once
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

namespace tscheck {
struct Case { const char* name; std::function<void()> fn; };
inline std::vector<Case>& registry() { static std::vector<Case> r; return r; }
inline int& failures() { static int f = 0; return f; }
struct Reg { Reg(const char* n, std::function<void()> f) { registry().push_back({n, std::move(f)}); } };
}  // namespace tscheck

#define TS_CAT2(a, b) a##b
#define TS_CAT(a, b) TS_CAT2(a, b)
#define TEST_CASE(name)                                                         \
  static void TS_CAT(test_fn_, __LINE__)();                                     \
  static tscheck::Reg TS_CAT(test_reg_, __LINE__)(name, TS_CAT(test_fn_, __LINE__)); \
  static void TS_CAT(test_fn_, __LINE__)()

#define CHECK(...)                                                                          \
  do {                                                                                      \
    if (!(__VA_ARGS__)) {                                                                   \
      ++tscheck::failures();                                                                \
      std::fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #__VA_ARGS__);   \
    }                                                                                       \
  } while (0)

#define CHECK_MSG(cond, ...)                                                                \
  do {                                                                                      \
    if (!(cond)) {                                                                          \
      ++tscheck::failures();                                                                \
      std::fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond);          \
      std::fprintf(stderr, __VA_ARGS__);                                                    \
      std::fprintf(stderr, "\n");                                                           \
    }                                                                                       \
  } while (0)
