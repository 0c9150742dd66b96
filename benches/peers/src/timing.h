/* The timing protocol shared by the three drivers (driver.c, pin_numeric.cpp, and, in Rust, the
 * kanegen bench's main.rs, which implements the same steps):
 *
 *   1. warm-up: call the function, cycling over the K states, until ROUND_US microseconds have
 *      passed (at least 2 calls); est = elapsed / calls;
 *   2. calls per round c = clamp(ROUND_US * 1000 / est, 10, CALLS): up to CALLS calls, fewer for
 *      slow functions so that a round lasts about ROUND_US;
 *   3. ROUNDS rounds of c calls, each timed with the thread's CPU clock
 *      (CLOCK_THREAD_CPUTIME_ID) and with the monotonic wall clock; report the median round and
 *      the fastest round in CPU time (ns per call), the timed calls, and the median round in wall
 *      time. CPU time leaves out the time slices the process loses to other processes on a
 *      shared machine (which double a wall-clock round when another process is runnable on the
 *      same CPU); what such a neighbour does to the caches still counts.
 *
 * One output element per call (cycling over the elements) is summed into a checksum, which is
 * printed, so no call can be dropped.
 */
#ifndef PEERS_TIMING_H
#define PEERS_TIMING_H

#include <stdlib.h>
#include <time.h>

static double peers_now_ns(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

static double peers_cpu_ns(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

static int peers_cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static long peers_calls_per_round(double est_ns, double round_us, long max_calls) {
  double c = round_us * 1000.0 / (est_ns > 1e-3 ? est_ns : 1e-3);
  if (c > (double)max_calls) c = (double)max_calls;
  if (c < 10.0) c = 10.0;
  return (long)c;
}

#endif
