/* CasADi-style entry points (casadi_gen.h) on kanegen's C output (kg.h, from
 * `kanegen generate MODEL --lang c --name Kg`): one call of the kanegen function each, outputs
 * written where CasADi writes them (M is symmetric, so its column-major layout is the row-major
 * one). Compiled as CasADi's casadi_gen.c is: alone, with the same gcc and flags, no LTO. */
#include "casadi_gen.h"
#include "kg.h"

typedef double (*kg_matrix)[KG_N];

#define KG_WORK(name)                                                                           \
  int name##_work(casadi_int *sz_arg, casadi_int *sz_res, casadi_int *sz_iw, casadi_int *sz_w) { \
    *sz_arg = 3;                                                                                \
    *sz_res = 2;                                                                                \
    *sz_iw = 0;                                                                                 \
    *sz_w = 0;                                                                                  \
    return 0;                                                                                   \
  }
KG_WORK(M)
KG_WORK(nle)
KG_WORK(M_nle)
KG_WORK(rnea)
KG_WORK(aba)

int M(const casadi_real **arg, casadi_real **res, casadi_int *iw, casadi_real *w, int mem) {
  (void)iw, (void)w, (void)mem;
  kg_mass_matrix(arg[0], (kg_matrix)res[0]);
  return 0;
}

int nle(const casadi_real **arg, casadi_real **res, casadi_int *iw, casadi_real *w, int mem) {
  (void)iw, (void)w, (void)mem;
  kg_nonlinear_effects(arg[0], arg[1], res[0]);
  return 0;
}

int M_nle(const casadi_real **arg, casadi_real **res, casadi_int *iw, casadi_real *w, int mem) {
  (void)iw, (void)w, (void)mem;
  kg_mass_matrix_and_nonlinear_effects(arg[0], arg[1], (kg_matrix)res[0], res[1]);
  return 0;
}

int rnea(const casadi_real **arg, casadi_real **res, casadi_int *iw, casadi_real *w, int mem) {
  (void)iw, (void)w, (void)mem;
  kg_inverse_dynamics(arg[0], arg[1], arg[2], res[0]);
  return 0;
}

int aba(const casadi_real **arg, casadi_real **res, casadi_int *iw, casadi_real *w, int mem) {
  (void)iw, (void)w, (void)mem;
  kg_forward_dynamics(arg[0], arg[1], arg[2], res[0]);
  return 0;
}
