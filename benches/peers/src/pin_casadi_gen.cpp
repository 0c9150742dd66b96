// Pinocchio 4.1.0 algorithms traced on casadi::SX, then CasADi's CodeGenerator -> C.
//
// This is what `import pinocchio.casadi as cpin; cpin.crba(cmodel, cdata, cq)` does in
// Python (the pin PyPI wheel lacks that module, but ships the templated C++ headers it
// wraps): the model is cast to ModelTpl<casadi::SX>, the algorithm runs once on symbolic
// inputs, and the resulting SX expressions become casadi::Function objects.
//
// Adapted for kanegen's benches/peers/ from the shared harness (peers/casadi/src/): the model
// loader moved to model_txt.hpp (trees: each joint names its parent), `rnea` (inverse dynamics)
// added, the WORLD-convention functions optional.
//
// usage: pin_casadi_gen MODEL.txt OUTDIR [VARIANT ...]
//   MODEL.txt: written by tools/prepare.py from pin.buildModelFromUrdf (see there).
//   environment PEERS_WORLD=0 leaves out M_world and aba_world (default: generated).
//   VARIANT (default: plain cse simp cse_noheader) selects how the casadi::Function is built:
//     plain*: Function(name, in, out)                      (no options)
//     cse*:   Function(name, in, out, {"cse": true})       (CasADi's common subexpression elimination)
//     simp*:  plain.transform({"combine_terms": true, "empty_inputs": false})
//             (CasADi 3.8's simplify pass: cse + ref_count + const_folding + combine_terms)
//     a name ending in _noheader is generated with {"with_header": false} (all others: true).
// For each variant V it writes OUTDIR/V/casadi_gen.c (+ casadi_gen.h) holding the C functions
//   M(q)          crba (Convention::LOCAL, Pinocchio's default), upper triangle mirrored
//   nle(q,v)      nonLinearEffects (gravity 0: C(q,v) v)
//   M_nle(q,v)    both outputs from one function (shared subexpressions merged only with cse)
//   rnea(q,v,a)   rnea: inverse dynamics tau = M a + nle
//   aba(q,v,tau)  aba (Convention::LOCAL, default)
//   M_world(q)    crba with Convention::WORLD, mirrored
//   aba_world     aba with Convention::WORLD
//   rnea_derivs(q,v,a)  computeRNEADerivatives on SX: dtau_dq, dtau_dv (row i = tau_i, column j =
//                 input j)
//   rnea_jac(q,v,a)     SX::jacobian of the traced rnea w.r.t. q and v (the same two matrices)
//   aba_derivs(q,v,tau) computeABADerivatives on SX: ddq_dq, ddq_dv, Minv (Pinocchio mirrors
//                 Minv itself there)
//   aba_jac(q,v,tau)    SX::jacobian of the traced aba w.r.t. q, v and tau (the last is M^-1)
//   minv(q)       computeMinverse on SX, upper triangle mirrored (Pinocchio fills only that)
// (the PEERS_DERIVS=0 environment leaves the five derivative functions out).
// and OUTDIR/V/counts.json with CasADi's instruction counts per function.
#include <pinocchio/autodiff/casadi.hpp>  // must come first

#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/algorithm/rnea.hpp>

#include <casadi/casadi.hpp>
#include <casadi/config.h>

#include "model_txt.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <vector>

using SX = casadi::SX;
using Model = pinocchio::Model;
using ADModel = pinocchio::ModelTpl<SX>;
using ADData = pinocchio::DataTpl<SX>;

template<typename Mat>
static SX to_sx(const Mat & m)
{
  SX out;
  pinocchio::casadi::copy(m, out);
  return SX::densify(out);
}

template<typename Mat>
static void symmetrize(Mat & M)
{
  for (Eigen::Index i = 0; i < M.rows(); ++i)
    for (Eigen::Index j = 0; j < i; ++j)
      M(i, j) = M(j, i);
}

struct Spec
{
  std::string name;
  std::vector<SX> in;
  std::vector<std::string> in_names;
  std::vector<SX> out;
  std::vector<std::string> out_names;
};

// The derivative functions: Pinocchio's derivative algorithms run on SX, and CasADi's own
// jacobians of the traced rnea and aba (dense, row i = output i, column j = input j).
static void add_derivative_specs(
  const ADModel & am, ADData & ad, const ADModel::ConfigVectorType & q_ad, const ADModel::TangentVectorType & v_ad,
  const ADModel::TangentVectorType & tau_ad, const ADModel::TangentVectorType & a_ad, const SX & q, const SX & v,
  const SX & tau, const SX & a, const SX & tau_id, const SX & ddq, std::vector<Spec> & specs)
{
  pinocchio::computeRNEADerivatives(am, ad, q_ad, v_ad, a_ad);
  SX dtau_dq = to_sx(ad.dtau_dq), dtau_dv = to_sx(ad.dtau_dv);

  pinocchio::computeABADerivatives(am, ad, q_ad, v_ad, tau_ad);
  SX ddq_dq = to_sx(ad.ddq_dq), ddq_dv = to_sx(ad.ddq_dv), Minv_aba = to_sx(ad.Minv);

  pinocchio::computeMinverse(am, ad, q_ad);
  ADData::MatrixXs Minv_ad = ad.Minv;
  symmetrize(Minv_ad);
  SX Minv = to_sx(Minv_ad);

  const std::vector<std::string> d_rnea = {"dtau_dq", "dtau_dv"}, d_aba = {"ddq_dq", "ddq_dv", "Minv"};
  specs.push_back({"rnea_derivs", {q, v, a}, {"q", "v", "a"}, {dtau_dq, dtau_dv}, d_rnea});
  specs.push_back({"rnea_jac", {q, v, a}, {"q", "v", "a"},
                   {SX::densify(SX::jacobian(tau_id, q)), SX::densify(SX::jacobian(tau_id, v))}, d_rnea});
  specs.push_back({"aba_derivs", {q, v, tau}, {"q", "v", "tau"}, {ddq_dq, ddq_dv, Minv_aba}, d_aba});
  specs.push_back({"aba_jac", {q, v, tau}, {"q", "v", "tau"},
                   {SX::densify(SX::jacobian(ddq, q)), SX::densify(SX::jacobian(ddq, v)),
                    SX::densify(SX::jacobian(ddq, tau))},
                   d_aba});
  specs.push_back({"minv", {q}, {"q"}, {Minv}, {"Minv"}});
}

static std::string count_json(const casadi::Function & f)
{
  std::map<std::string, long> c;
  const char * names[] = {"mul", "add", "sub", "neg", "div", "inv", "sq", "twice", "sin", "cos",
                          "sqrt", "const", "input", "output", "assign", "other"};
  for (auto n : names) c[n] = 0;
  for (casadi_int k = 0; k < f.n_instructions(); ++k)
  {
    switch (f.instruction_id(k))
    {
    case casadi::OP_MUL: c["mul"]++; break;
    case casadi::OP_ADD: c["add"]++; break;
    case casadi::OP_SUB: c["sub"]++; break;
    case casadi::OP_NEG: c["neg"]++; break;
    case casadi::OP_DIV: c["div"]++; break;
    case casadi::OP_INV: c["inv"]++; break;
    case casadi::OP_SQ: c["sq"]++; break;
    case casadi::OP_TWICE: c["twice"]++; break;
    case casadi::OP_SIN: c["sin"]++; break;
    case casadi::OP_COS: c["cos"]++; break;
    case casadi::OP_SQRT: c["sqrt"]++; break;
    case casadi::OP_CONST: c["const"]++; break;
    case casadi::OP_INPUT: c["input"]++; break;
    case casadi::OP_OUTPUT: c["output"]++; break;
    case casadi::OP_ASSIGN: c["assign"]++; break;
    default: c["other"]++; break;
    }
  }
  std::ostringstream o;
  o << "{\"n_instructions\": " << f.n_instructions() << ", \"n_nodes\": " << f.n_nodes()
    << ", \"sz_w\": " << f.sz_w() << ", \"sz_iw\": " << f.sz_iw();
  for (auto & kv : c) o << ", \"" << kv.first << "\": " << kv.second;
  // mul-equivalents: sq = x*x; add-equivalents: sub, twice (x+x)
  o << ", \"mul_total\": " << c["mul"] + c["sq"] << ", \"add_total\": " << c["add"] + c["sub"] + c["twice"]
    << "}";
  return o.str();
}

int main(int argc, char ** argv)
{
  if (argc < 3)
  {
    std::cerr << "usage: " << argv[0] << " MODEL.txt OUTDIR [VARIANT ...]\n";
    return 2;
  }
  std::string name;
  Model model = load_model_txt(argv[1], name);
  const std::string outdir = argv[2];
  const int n = model.nv;

  ADModel am = model.cast<SX>();
  ADData ad(am);
  SX q = SX::sym("q", n), v = SX::sym("v", n), tau = SX::sym("tau", n), a = SX::sym("a", n);
  ADModel::ConfigVectorType q_ad(n);
  ADModel::TangentVectorType v_ad(n), tau_ad(n), a_ad(n);
  pinocchio::casadi::copy(q, q_ad);
  pinocchio::casadi::copy(v, v_ad);
  pinocchio::casadi::copy(tau, tau_ad);
  pinocchio::casadi::copy(a, a_ad);
  const char * world_env = std::getenv("PEERS_WORLD");
  const bool world = !(world_env && std::string(world_env) == "0");

  // Each algorithm call recomputes its own forward kinematics from q, as in Pinocchio.
  pinocchio::crba(am, ad, q_ad, pinocchio::Convention::LOCAL);
  ADData::MatrixXs M_ad = ad.M;
  symmetrize(M_ad);
  SX M = to_sx(M_ad);

  SX Mw;
  if (world)
  {
    pinocchio::crba(am, ad, q_ad, pinocchio::Convention::WORLD);
    ADData::MatrixXs Mw_ad = ad.M;
    symmetrize(Mw_ad);
    Mw = to_sx(Mw_ad);
  }

  pinocchio::nonLinearEffects(am, ad, q_ad, v_ad);
  SX nle = to_sx(ad.nle);

  pinocchio::aba(am, ad, q_ad, v_ad, tau_ad, pinocchio::Convention::LOCAL);
  SX ddq = to_sx(ad.ddq);

  pinocchio::rnea(am, ad, q_ad, v_ad, a_ad);
  SX tau_id = to_sx(ad.tau);

  SX ddqw;
  if (world)
  {
    pinocchio::aba(am, ad, q_ad, v_ad, tau_ad, pinocchio::Convention::WORLD);
    ddqw = to_sx(ad.ddq);
  }

  std::vector<Spec> specs = {
    {"M", {q}, {"q"}, {M}, {"M"}},
    {"nle", {q, v}, {"q", "v"}, {nle}, {"nle"}},
    {"M_nle", {q, v}, {"q", "v"}, {M, nle}, {"M", "nle"}},
    {"rnea", {q, v, a}, {"q", "v", "a"}, {tau_id}, {"tau"}},
    {"aba", {q, v, tau}, {"q", "v", "tau"}, {ddq}, {"ddq"}},
  };
  if (world)
  {
    specs.push_back({"M_world", {q}, {"q"}, {Mw}, {"M"}});
    specs.push_back({"aba_world", {q, v, tau}, {"q", "v", "tau"}, {ddqw}, {"ddq"}});
  }
  const char * derivs_env = std::getenv("PEERS_DERIVS");
  if (!(derivs_env && std::string(derivs_env) == "0"))
    add_derivative_specs(am, ad, q_ad, v_ad, tau_ad, a_ad, q, v, tau, a, tau_id, ddq, specs);

  std::vector<std::string> variants = {"plain", "cse", "simp", "cse_noheader"};
  if (argc > 3)
    variants.assign(argv + 3, argv + argc);
  auto starts = [](const std::string & s, const char * p) { return s.rfind(p, 0) == 0; };
  auto ends = [](const std::string & s, const std::string & e) {
    return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0;
  };
  for (const auto & var : variants)
  {
    const std::string dir = outdir + "/" + var;
    mkdir(outdir.c_str(), 0755);
    mkdir(dir.c_str(), 0755);
    casadi::Dict gopts;
    gopts["with_header"] = !ends(var, "_noheader");
    casadi::CodeGenerator gen("casadi_gen.c", gopts);
    std::ostringstream cj;
    cj << "{\"model\": \"" << name << "\", \"n\": " << n << ", \"variant\": \"" << var
       << "\", \"casadi\": \"" << CASADI_VERSION_STRING << "\", \"functions\": {";
    bool first = true;
    for (const auto & s : specs)
    {
      casadi::Function f;
      if (starts(var, "plain"))
        f = casadi::Function(s.name, s.in, s.out, s.in_names, s.out_names);
      else if (starts(var, "cse"))
        f = casadi::Function(s.name, s.in, s.out, s.in_names, s.out_names, casadi::Dict{{"cse", true}});
      else if (starts(var, "simp"))
      {
        casadi::Function f0(s.name, s.in, s.out, s.in_names, s.out_names);
        f = f0.transform(casadi::Dict{{"combine_terms", true}, {"empty_inputs", false}});
      }
      else
        throw std::runtime_error("unknown variant " + var);
      gen.add(f);
      cj << (first ? "" : ", ") << "\"" << s.name << "\": " << count_json(f);
      first = false;
      std::cout << name << " " << var << " " << s.name << ": n_instructions " << f.n_instructions()
                << ", n_nodes " << f.n_nodes() << "\n";
    }
    cj << "}}\n";
    const auto t_gen = std::chrono::steady_clock::now();
    gen.generate(dir + "/");
    const double gen_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_gen).count();
    std::cout << name << " " << var << ": C written in " << gen_s << " s\n";
    std::ofstream(dir + "/counts.json") << cj.str();
  }
  return 0;
}
