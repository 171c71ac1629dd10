// The floor under a spring's cost: how fast this core takes the square root and the
// division every spring needs (`len = sqrt(d.d)`, `1 / len`), eight independent chains
// of each width at once, so that the figure is throughput, not latency. Built without
// fused multiply-adds, as Hooke's kernels are. See README.md.
#include <immintrin.h>
#include <stdio.h>
#include <time.h>

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + t.tv_nsec * 1e-9;
}

int main(void) {
  const long n = 100000000;  // square roots (and divisions) per width
  __m512d a[8];
  __m256d b[8];
  for (int i = 0; i < 8; i++) {
    a[i] = _mm512_set1_pd(1.0 + i * 0.1);
    b[i] = _mm256_set1_pd(1.0 + i * 0.1);
  }
  const __m512d one8 = _mm512_set1_pd(1.0);
  const __m256d one4 = _mm256_set1_pd(1.0);
  double t = now();
  for (long k = 0; k < n / 8; k++)
    for (int i = 0; i < 8; i++)
      a[i] = _mm512_add_pd(_mm512_div_pd(one8, _mm512_sqrt_pd(a[i])), one8);
  double zmm = now() - t;
  t = now();
  for (long k = 0; k < n / 8; k++)
    for (int i = 0; i < 8; i++)
      b[i] = _mm256_add_pd(_mm256_div_pd(one4, _mm256_sqrt_pd(b[i])), one4);
  double ymm = now() - t;
  double sink = 0.0, lanes[4];
  for (int i = 0; i < 8; i++) {
    sink += _mm512_reduce_add_pd(a[i]);
    _mm256_storeu_pd(lanes, b[i]);
    sink += lanes[0];
  }
  printf("{\"zmm_ns_per_lane\": %.3f, \"ymm_ns_per_lane\": %.3f, \"sink\": %g}\n",
         zmm / n * 1e9 / 8, ymm / n * 1e9 / 4, sink);
  return 0;
}
