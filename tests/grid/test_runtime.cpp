// The runtime's floating-point mode: subnormal numbers flushed to zero on every thread
// (runtime.cpp), so that their microcode assists cannot slow a step down.
#include <gtest/gtest.h>

#include <limits>

#include "runtime.hpp"

namespace efsi {
namespace {

// Through memory, so that the compiler cannot fold the arithmetic at build time.
double product(double a, double b) {
  volatile double x = a;
  return x * b;
}
double sum(double a, double b) {
  volatile double x = a;
  return x + b;
}

TEST(Runtime, EveryThreadFlushesSubnormals) {
#if defined(__SSE3__)
  const double tiny = std::numeric_limits<double>::min();  // the smallest normal number
  int flushed = 0, zero_result = 0, zero_operand = 0, threads = 0;
#pragma omp parallel num_threads(2) reduction(+ : flushed, zero_result, zero_operand, threads)
  {
    threads += 1;
    flushed += subnormals_flushed() ? 1 : 0;
    zero_result += product(tiny, 0.25) == 0.0 ? 1 : 0;  // would be subnormal: FTZ
    // A subnormal operand (the smallest one): DAZ reads it as 0.
    const double sub = std::numeric_limits<double>::denorm_min();
    zero_operand += sum(sub, 0.0) == 0.0 && sum(sub, tiny) == tiny ? 1 : 0;
  }
  EXPECT_EQ(flushed, threads);
  EXPECT_EQ(zero_result, threads);
  EXPECT_EQ(zero_operand, threads);
  EXPECT_EQ(threads, 2);
#else
  GTEST_SKIP() << "the subnormal mode is set on x86 only";
#endif
}

// A normal result just above the threshold is kept: only subnormals go.
TEST(Runtime, NormalNumbersAreKept) {
  const double tiny = std::numeric_limits<double>::min();
  EXPECT_EQ(product(tiny, 2.0), 2.0 * std::numeric_limits<double>::min());
  EXPECT_GT(product(tiny, 1.0), 0.0);
}

}  // namespace
}  // namespace efsi
