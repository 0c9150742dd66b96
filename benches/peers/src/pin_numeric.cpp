// Numeric Pinocchio (double) timed like the generated code of the other two sides: same model
// (model_txt.hpp rebuilds pin.buildModelFromUrdf's model), same states, same protocol (timing.h).
//
// Built by run.sh with g++ -O3 -march=native, header-only (label `hdr`): the templates are
// instantiated here for double with -march=native, which is what a C++ user who includes
// Pinocchio gets. (Linking the pin wheel's prebuilt libpinocchio_default.so instead, with
// -DPINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION [-DPINOCCHIO_WITH_COLLISION], compiles and links but
// aborts in crba with boost::bad_get on these models, so it is not offered.)
//
// usage: pin_numeric MODEL.txt STATES.txt LABEL MODEL time ROUNDS CALLS ROUND_US
//        pin_numeric MODEL.txt STATES.txt LABEL MODEL dump
//
// Functions (one call each, data allocated once outside the loop, as a controller would):
//   M          crba(model, data, q) (Convention::LOCAL, the default), then the strictly lower
//              triangle mirrored from the upper (Pinocchio computes the upper triangle only; the
//              other sides return the full symmetric matrix)
//   M_world    the same with Convention::WORLD
//   nle        nonLinearEffects(model, data, q, v)
//   M_nle      crba (LOCAL) + mirror + nonLinearEffects: two calls, as Pinocchio has no combined
//              function for exactly these two
//   rnea       rnea(model, data, q, v, a)
//   aba        aba(model, data, q, v, tau) (Convention::LOCAL, the default)
//   aba_world  aba with Convention::WORLD
//   rnea_derivs  computeRNEADerivatives(model, data, q, v, a): data.dtau_dq, data.dtau_dv
//   aba_derivs computeABADerivatives(model, data, q, v, tau): data.ddq_dq, data.ddq_dv, data.Minv
//              (this algorithm mirrors Minv itself: no mirror here)
//   minv       computeMinverse(model, data, q), then the strictly lower triangle mirrored from
//              the upper (Pinocchio fills the upper triangle only)
// The environment PEERS_DERIVS=0 leaves out the three derivative functions.
#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>

#include "model_txt.hpp"
#include "timing.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

using pinocchio::Convention;
using VectorXd = Eigen::VectorXd;

struct State
{
  VectorXd q, v, tau, a;
};

template<typename Mat>
static void mirror(Mat & m)
{
  m.template triangularView<Eigen::StrictlyLower>() = m.transpose().template triangularView<Eigen::StrictlyLower>();
}

enum Func
{
  F_M,
  F_M_WORLD,
  F_NLE,
  F_M_NLE,
  F_RNEA,
  F_ABA,
  F_ABA_WORLD,
  F_RNEA_DERIVS,
  F_ABA_DERIVS,
  F_MINV,
  F_COUNT
};
static const char * NAMES[F_COUNT] = {"M",    "M_world",     "nle",        "M_nle", "rnea",
                                      "aba",  "aba_world",   "rnea_derivs", "aba_derivs", "minv"};
// The functions whose timed output (the checksum's element) is n x n.
static constexpr bool matrix_out(int f)
{
  return f == F_M || f == F_M_WORLD || f == F_M_NLE || f == F_RNEA_DERIVS || f == F_ABA_DERIVS || f == F_MINV;
}

// Evaluates function f at state s; returns one output element (index e, cycling). A template,
// so that the timing loop of each function is compiled for that function alone (no switch).
template<int f>
static inline double call(const pinocchio::Model & model, pinocchio::Data & data, const State & s, int e, int n)
{
  switch (f)
  {
  case F_M:
    pinocchio::crba(model, data, s.q, Convention::LOCAL);
    mirror(data.M);
    return data.M(e / n, e % n);
  case F_M_WORLD:
    pinocchio::crba(model, data, s.q, Convention::WORLD);
    mirror(data.M);
    return data.M(e / n, e % n);
  case F_NLE:
    pinocchio::nonLinearEffects(model, data, s.q, s.v);
    return data.nle(e);
  case F_M_NLE:
    pinocchio::crba(model, data, s.q, Convention::LOCAL);
    mirror(data.M);
    pinocchio::nonLinearEffects(model, data, s.q, s.v);
    return data.M(e / n, e % n) + data.nle(e % n);
  case F_RNEA:
    pinocchio::rnea(model, data, s.q, s.v, s.a);
    return data.tau(e);
  case F_ABA:
    pinocchio::aba(model, data, s.q, s.v, s.tau, Convention::LOCAL);
    return data.ddq(e);
  case F_ABA_WORLD:
    pinocchio::aba(model, data, s.q, s.v, s.tau, Convention::WORLD);
    return data.ddq(e);
  case F_RNEA_DERIVS:
    pinocchio::computeRNEADerivatives(model, data, s.q, s.v, s.a);
    return data.dtau_dq(e / n, e % n) + data.dtau_dv(e / n, e % n);
  case F_ABA_DERIVS:
    pinocchio::computeABADerivatives(model, data, s.q, s.v, s.tau);
    return data.ddq_dq(e / n, e % n) + data.ddq_dv(e / n, e % n) + data.Minv(e / n, e % n);
  case F_MINV:
    pinocchio::computeMinverse(model, data, s.q);
    mirror(data.Minv);
    return data.Minv(e / n, e % n);
  default:
    return 0.0;
  }
}

typedef double (*call_t)(const pinocchio::Model &, pinocchio::Data &, const State &, int, int);
static const call_t DUMP_CALL[F_COUNT] = {call<0>, call<1>, call<2>, call<3>, call<4>,
                                          call<5>, call<6>, call<7>, call<8>, call<9>};

template<int f>
static void time_func(
  const pinocchio::Model & model, pinocchio::Data & data, const std::vector<State> & S, int n, int rounds,
  long max_calls, double round_us, const char * label, const char * model_name)
{
  const int K = int(S.size());
  const int nn = matrix_out(f) ? n * n : n;
  std::vector<double> ns(rounds), wall(rounds);
  double chk = 0.0;
  int k = 0, e = 0;
  auto one = [&]() {
    chk += call<f>(model, data, S[k], e, n);
    if (++k == K) k = 0;
    if (++e == nn) e = 0;
  };
  long wc = 0;
  const double t_w = peers_now_ns();
  double el;
  do
  {
    one();
    ++wc;
    el = peers_now_ns() - t_w;
  } while (wc < 2 || el < round_us * 1000.0);
  const long calls = peers_calls_per_round(el / double(wc), round_us, max_calls);
  for (int r = 0; r < rounds; ++r)
  {
    const double t0 = peers_now_ns(), c0 = peers_cpu_ns();
    for (long c = 0; c < calls; ++c)
      one();
    ns[r] = (peers_cpu_ns() - c0) / double(calls);
    wall[r] = (peers_now_ns() - t0) / double(calls);
  }
  std::sort(ns.begin(), ns.end());
  std::sort(wall.begin(), wall.end());
  std::printf(
    "pinocchio,%s,%s,%s,%.2f,%.2f,%ld,%.6e,%.2f\n", label, model_name, NAMES[f], ns[rounds / 2], ns[0],
    long(rounds) * calls, chk, wall[rounds / 2]);
  std::fflush(stdout);
}
typedef void (*time_t_)(
  const pinocchio::Model &, pinocchio::Data &, const std::vector<State> &, int, int, long, double, const char *,
  const char *);
static const time_t_ TIME[F_COUNT] = {time_func<0>, time_func<1>, time_func<2>, time_func<3>, time_func<4>,
                                      time_func<5>, time_func<6>, time_func<7>, time_func<8>, time_func<9>};

template<typename Vec>
static void print_vec(const Vec & x)
{
  std::printf("[");
  for (Eigen::Index i = 0; i < x.size(); ++i)
    std::printf("%s%.17g", i ? ", " : "", x(i));
  std::printf("]");
}

// A matrix as JSON rows.
template<typename Mat>
static void print_mat(const Mat & m)
{
  std::printf("[");
  for (Eigen::Index r = 0; r < m.rows(); ++r)
  {
    std::printf("%s", r ? ", " : "");
    print_vec(m.row(r));
  }
  std::printf("]");
}

// The dump of one derivative function: the first output under the function's name, the others
// as "NAME.output" (as M_nle's second output is "M_nle.nle").
static void print_derivs(int f, const pinocchio::Data & data)
{
  if (f == F_RNEA_DERIVS)
  {
    print_mat(data.dtau_dq);
    std::printf(", \"rnea_derivs.dtau_dv\": ");
    print_mat(data.dtau_dv);
  }
  else if (f == F_ABA_DERIVS)
  {
    print_mat(data.ddq_dq);
    std::printf(", \"aba_derivs.ddq_dv\": ");
    print_mat(data.ddq_dv);
    std::printf(", \"aba_derivs.Minv\": ");
    print_mat(data.Minv);
  }
  else
    print_mat(data.Minv);
}

int main(int argc, char ** argv)
{
  if (argc < 6)
  {
    std::fprintf(stderr, "usage: %s MODEL.txt STATES.txt LABEL MODEL time ROUNDS CALLS ROUND_US | dump\n", argv[0]);
    return 2;
  }
  std::string mname;
  const pinocchio::Model model = load_model_txt(argv[1], mname);
  pinocchio::Data data(model);
  const char *label = argv[3], *model_name = argv[4], *mode = argv[5];
  std::ifstream in(argv[2]);
  int K = 0, n = 0;
  in >> K >> n;
  if (!in || n != model.nv)
  {
    std::fprintf(stderr, "%s: states for n = %d, model has nv = %d\n", argv[2], n, (int)model.nv);
    return 1;
  }
  std::vector<State> S(K);
  for (auto & s : S)
  {
    for (VectorXd * x : {&s.q, &s.v, &s.tau, &s.a})
    {
      x->resize(n);
      for (int i = 0; i < n; ++i)
        in >> (*x)(i);
    }
  }
  if (!in)
  {
    std::fprintf(stderr, "short states file\n");
    return 1;
  }

  const char * derivs_env = std::getenv("PEERS_DERIVS");
  const int f_count = derivs_env && std::string(derivs_env) == "0" ? F_RNEA_DERIVS : F_COUNT;
  if (!std::strcmp(mode, "dump"))
  {
    std::printf(
      "{\"side\": \"pinocchio\", \"label\": \"%s\", \"model\": \"%s\", \"n\": %d, \"samples\": [\n", label,
      model_name, n);
    for (int k = 0; k < K; ++k)
    {
      std::printf("%s{", k ? ",\n" : "");
      for (int f = 0; f < f_count; ++f)
      {
        DUMP_CALL[f](model, data, S[k], 0, n);
        std::printf("%s\"%s\": ", f ? ", " : "", NAMES[f]);
        if (f == F_RNEA_DERIVS || f == F_ABA_DERIVS || f == F_MINV)
          print_derivs(f, data);
        else if (f == F_M || f == F_M_WORLD || f == F_M_NLE)
        {
          print_mat(data.M);
          if (f == F_M_NLE)
          {
            std::printf(", \"M_nle.nle\": ");
            print_vec(data.nle);
          }
        }
        else if (f == F_NLE)
          print_vec(data.nle);
        else if (f == F_RNEA)
          print_vec(data.tau);
        else
          print_vec(data.ddq);
      }
      std::printf("}");
    }
    std::printf("\n]}\n");
    return 0;
  }
  if (argc < 9)
  {
    std::fprintf(stderr, "time needs ROUNDS CALLS ROUND_US\n");
    return 2;
  }
  const int rounds = std::atoi(argv[6]);
  const long max_calls = std::atol(argv[7]);
  const double round_us = std::atof(argv[8]);
  for (int fi = 0; fi < f_count; ++fi)
    TIME[fi](model, data, S, n, rounds, max_calls, round_us, label, model_name);
  return 0;
}
