/* Timing and dump driver for the C code CasADi generated from Pinocchio's algorithms
 * (adapted from the shared harness peers/casadi/src/driver.c: rnea added, the timing protocol of
 * timing.h, four vectors per state).
 *
 * Built once per model and label: gcc -O3 -march=native -I gen/MODEL/VARIANT, linked with
 * gen/MODEL/VARIANT/casadi_gen.o (compiled separately, as a user would: no LTO, so every
 * call goes through CasADi's standard entry point f(arg, res, iw, w, mem)).
 * -DPEERS_WORLD=1 when the generated file has M_world and aba_world; -DPEERS_DERIVS=1 when it has
 * rnea_derivs, rnea_jac, aba_derivs, aba_jac and minv.
 *
 * usage: driver STATES.txt LABEL MODEL time ROUNDS CALLS ROUND_US
 *        driver STATES.txt LABEL MODEL dump
 *
 * STATES.txt: "K n", then per state one line q (n), v (n), tau (n), a (n)
 *   (tau = rnea(q, v, a), so aba(q, v, tau) = a).
 * time: per function the protocol of timing.h; prints
 *       "casadi,LABEL,MODEL,FUNC,median_ns,min_ns,calls,checksum,wall_median_ns" (ns per call;
 *       median and min in thread CPU time).
 *       A last row, "sincos_n", times n calls of glibc's sincos(q_j) (gcc turns the generated
 *       sin/cos pairs into sincos calls), for scale.
 * dump: JSON with every output at every state (for tools/validate.py).
 */
#define _GNU_SOURCE /* sincos */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "casadi_gen.h"
#include "timing.h"

/* The side the rows and the dump name: CasADi's C, or kanegen's C output behind the same entry
 * points (src/kanegen_c, -DPEERS_SIDE="\"kanegen\""). */
#ifndef PEERS_SIDE
#define PEERS_SIDE "casadi"
#endif

typedef int (*fn_t)(const casadi_real **, casadi_real **, casadi_int *, casadi_real *, int);
typedef int (*work_t)(casadi_int *, casadi_int *, casadi_int *, casadi_int *);

enum { IN_Q = 1, IN_QV = 2, IN_QVTAU = 3, IN_QVA = 4 };

/* Outputs: `nmat` dense n x n matrices (column-major, as CasADi writes them), then `nvec`
 * vectors of n. The dump names the first output after the function and the others
 * "NAME.OUTPUT" (out[i]), as M_nle's second output is "M_nle.nle". */
#define MAX_MAT 3
struct func {
  const char *name;
  fn_t f;
  work_t work;
  int in;   /* IN_*: which state vectors are the inputs */
  int nmat; /* n x n outputs, first: 0 to MAX_MAT */
  int nvec; /* vector outputs after them: 0 or 1 */
  const char *out[MAX_MAT + 1]; /* output names, for the dump keys of outputs 2.. */
};

static const struct func FUNCS[] = {
    {"M", M, M_work, IN_Q, 1, 0, {"M"}},
    {"nle", nle, nle_work, IN_QV, 0, 1, {"nle"}},
    {"M_nle", M_nle, M_nle_work, IN_QV, 1, 1, {"M", "nle"}},
    {"rnea", rnea, rnea_work, IN_QVA, 0, 1, {"tau"}},
    {"aba", aba, aba_work, IN_QVTAU, 0, 1, {"ddq"}},
#if PEERS_WORLD
    {"M_world", M_world, M_world_work, IN_Q, 1, 0, {"M"}},
    {"aba_world", aba_world, aba_world_work, IN_QVTAU, 0, 1, {"ddq"}},
#endif
#if PEERS_DERIVS
    {"rnea_derivs", rnea_derivs, rnea_derivs_work, IN_QVA, 2, 0, {"dtau_dq", "dtau_dv"}},
    {"rnea_jac", rnea_jac, rnea_jac_work, IN_QVA, 2, 0, {"dtau_dq", "dtau_dv"}},
    {"aba_derivs", aba_derivs, aba_derivs_work, IN_QVTAU, 3, 0, {"ddq_dq", "ddq_dv", "Minv"}},
    {"aba_jac", aba_jac, aba_jac_work, IN_QVTAU, 3, 0, {"ddq_dq", "ddq_dv", "Minv"}},
    {"minv", minv, minv_work, IN_Q, 1, 0, {"Minv"}},
#endif
};
#define NFUNCS (sizeof(FUNCS) / sizeof(FUNCS[0]))

/* Column-major dense n x n as JSON rows (without the outer brackets). */
static void dump_matrix(const double *m, int n) {
  for (int r = 0; r < n; ++r) {
    printf("%s[", r ? ", " : "");
    for (int c = 0; c < n; ++c) printf("%s%.17g", c ? ", " : "", m[c * n + r]);
    printf("]");
  }
}

static void dump_vector(const double *x, int n) {
  for (int r = 0; r < n; ++r) printf("%s%.17g", r ? ", " : "", x[r]);
}

int main(int argc, char **argv) {
  if (argc < 5) {
    fprintf(stderr, "usage: %s STATES.txt LABEL MODEL time ROUNDS CALLS ROUND_US | dump\n", argv[0]);
    return 2;
  }
  const char *label = argv[2], *model = argv[3], *mode = argv[4];
  FILE *fp = fopen(argv[1], "r");
  if (!fp) { perror(argv[1]); return 1; }
  int K, n;
  if (fscanf(fp, "%d %d", &K, &n) != 2) return 1;
  double *X = malloc(sizeof(double) * (size_t)K * 4 * n); /* per state: q, v, tau, a */
  for (int i = 0; i < K * 4 * n; ++i)
    if (fscanf(fp, "%lf", &X[i]) != 1) { fprintf(stderr, "short states file\n"); return 1; }
  fclose(fp);

  /* work vectors: the largest any function asks for */
  casadi_int sz_arg = 0, sz_res = 0, sz_iw = 0, sz_w = 0;
  for (size_t i = 0; i < NFUNCS; ++i) {
    casadi_int a, r, iw, w;
    FUNCS[i].work(&a, &r, &iw, &w);
    if (a > sz_arg) sz_arg = a;
    if (r > sz_res) sz_res = r;
    if (iw > sz_iw) sz_iw = iw;
    if (w > sz_w) sz_w = w;
  }
  casadi_int *iw = malloc(sizeof(casadi_int) * (size_t)(sz_iw + 1));
  casadi_real *w = malloc(sizeof(casadi_real) * (size_t)(sz_w + 1));
  /* per state and input pattern, an argument array (sz_arg >= 3 entries) */
  const int stride = (int)sz_arg + 3;
  const casadi_real **args[5];
  for (int p = IN_Q; p <= IN_QVA; ++p) {
    args[p] = calloc((size_t)K * (size_t)stride, sizeof(casadi_real *));
    for (int k = 0; k < K; ++k) {
      const double *s = X + (size_t)k * 4 * n;
      args[p][k * stride + 0] = s;
      if (p >= IN_QV) args[p][k * stride + 1] = s + n;
      if (p == IN_QVTAU) args[p][k * stride + 2] = s + 2 * n;
      if (p == IN_QVA) args[p][k * stride + 2] = s + 3 * n;
    }
  }
  /* res[i]: the i-th output; the matrices first, then the vector */
  casadi_real *res[MAX_MAT + 2] = {0};
  for (int i = 0; i <= MAX_MAT; ++i) res[i] = malloc(sizeof(double) * (size_t)n * n);
  double *out0 = res[0];

  if (!strcmp(mode, "dump")) {
    printf("{\"side\": \"%s\", \"label\": \"%s\", \"model\": \"%s\", \"n\": %d, \"samples\": [\n", PEERS_SIDE, label, model, n);
    for (int k = 0; k < K; ++k) {
      printf("%s{", k ? ",\n" : "");
      for (size_t i = 0; i < NFUNCS; ++i) {
        const struct func *F = &FUNCS[i];
        for (int o = 0; o <= MAX_MAT; ++o) memset(res[o], 0, sizeof(double) * n * n);
        F->f(args[F->in] + k * stride, res, iw, w, 0);
        for (int o = 0; o < F->nmat + F->nvec; ++o) {
          if (o) printf(", \"%s.%s\": [", F->name, F->out[o]);
          else printf("%s\"%s\": [", i ? ", " : "", F->name);
          if (o < F->nmat) dump_matrix(res[o], n);
          else dump_vector(res[o], n);
          printf("]");
        }
      }
      printf("}");
    }
    printf("\n]}\n");
    return 0;
  }
  if (argc < 8) {
    fprintf(stderr, "time needs ROUNDS CALLS ROUND_US\n");
    return 2;
  }
  const int rounds = atoi(argv[5]);
  const long max_calls = atol(argv[6]);
  const double round_us = atof(argv[7]);
  double *ns = malloc(sizeof(double) * (size_t)rounds), *wall = malloc(sizeof(double) * (size_t)rounds);
  for (size_t i = 0; i <= NFUNCS; ++i) {
    /* i == NFUNCS: the trigonometry floor, n x glibc sincos per call, stored like an output */
    const int trig = i == NFUNCS;
    fn_t f = trig ? 0 : FUNCS[i].f;
    const casadi_real **A = args[trig ? IN_Q : FUNCS[i].in];
    const int nn = trig ? 2 * n : (FUNCS[i].nmat ? n * n : n);
    double chk = 0.0;
    int k = 0, e = 0;
#define ONE_CALL()                                                                   \
  do {                                                                               \
    if (trig) {                                                                      \
      const double *q = A[k * stride];                                               \
      for (int j = 0; j < n; ++j) sincos(q[j], &out0[2 * j], &out0[2 * j + 1]);      \
    } else {                                                                         \
      f(A + k * stride, res, iw, w, 0);                                              \
    }                                                                                \
    chk += out0[e];                                                                  \
    if (++k == K) k = 0;                                                             \
    if (++e == nn) e = 0;                                                            \
  } while (0)
    long wc = 0;
    const double t_w = peers_now_ns();
    double el;
    do { ONE_CALL(); ++wc; el = peers_now_ns() - t_w; } while (wc < 2 || el < round_us * 1000.0);
    const long calls = peers_calls_per_round(el / (double)wc, round_us, max_calls);
    for (int r = 0; r < rounds; ++r) {
      const double t0 = peers_now_ns(), c0 = peers_cpu_ns();
      for (long c = 0; c < calls; ++c) ONE_CALL();
      ns[r] = (peers_cpu_ns() - c0) / (double)calls;
      wall[r] = (peers_now_ns() - t0) / (double)calls;
    }
    qsort(ns, (size_t)rounds, sizeof(double), peers_cmp_double);
    qsort(wall, (size_t)rounds, sizeof(double), peers_cmp_double);
    printf("%s,%s,%s,%s,%.2f,%.2f,%ld,%.6e,%.2f\n", PEERS_SIDE, label, model, trig ? "sincos_n" : FUNCS[i].name,
           ns[rounds / 2], ns[0], (long)rounds * calls, chk, wall[rounds / 2]);
    fflush(stdout);
  }
  return 0;
}
