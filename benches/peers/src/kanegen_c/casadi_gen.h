/* The entry points of CasADi's generated C that src/driver.c calls, for the "kanegen C" side:
 * kanegen_c.c implements them on the header `kanegen generate MODEL --lang c --name Kg` writes
 * (kg.h), so that the same driver times both sides (-DPEERS_WORLD=0 -DPEERS_DERIVS=0: M, nle,
 * M_nle, rnea, aba). */
#ifndef KANEGEN_C_CASADI_GEN_H
#define KANEGEN_C_CASADI_GEN_H
#define casadi_real double
#define casadi_int long long int

#define KG_ENTRY(name)                                                                           \
  int name(const casadi_real **arg, casadi_real **res, casadi_int *iw, casadi_real *w, int mem); \
  int name##_work(casadi_int *sz_arg, casadi_int *sz_res, casadi_int *sz_iw, casadi_int *sz_w);
KG_ENTRY(M)
KG_ENTRY(nle)
KG_ENTRY(M_nle)
KG_ENTRY(rnea)
KG_ENTRY(aba)
#undef KG_ENTRY
#endif
