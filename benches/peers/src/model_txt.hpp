// Rebuilds the pinocchio::Model that tools/prepare.py exported from pin.buildModelFromUrdf
// (one joint per line: type, parent joint index, name, placement rotation (row-major) and
// translation, axis, mass, centre of mass, inertia about the CoM xx xy xz yy yz zz; 17
// significant digits), so the C++ programs need no URDF parser and no libpinocchio_parsers.
// Used by pin_casadi_gen.cpp (cast to casadi::SX) and pin_numeric.cpp (double).
#pragma once

#include <pinocchio/multibody.hpp>

#include <fstream>
#include <stdexcept>
#include <string>

inline pinocchio::Model load_model_txt(const std::string & path, std::string & name)
{
  std::ifstream in(path);
  if (!in)
    throw std::runtime_error("cannot open " + path);
  std::string key;
  int nj = 0;
  in >> key >> name >> key >> nj;
  pinocchio::Model model;
  for (int k = 0; k < nj; ++k)
  {
    std::string tag, type, jname;
    int parent;
    double R[9], p[3], ax[3], m, c[3], I[6];
    in >> tag >> type >> parent >> jname;
    for (double & x : R) in >> x;
    for (double & x : p) in >> x;
    for (double & x : ax) in >> x;
    in >> m;
    for (double & x : c) in >> x;
    for (double & x : I) in >> x;
    if (!in || tag != "joint")
      throw std::runtime_error("bad joint line in " + path);
    Eigen::Matrix3d Rm;
    Rm << R[0], R[1], R[2], R[3], R[4], R[5], R[6], R[7], R[8];
    pinocchio::SE3 placement(Rm, Eigen::Vector3d(p[0], p[1], p[2]));
    Eigen::Vector3d axis(ax[0], ax[1], ax[2]);
    pinocchio::JointIndex jid;
    if (type == "JointModelRX") jid = model.addJoint(parent, pinocchio::JointModelRX(), placement, jname);
    else if (type == "JointModelRY") jid = model.addJoint(parent, pinocchio::JointModelRY(), placement, jname);
    else if (type == "JointModelRZ") jid = model.addJoint(parent, pinocchio::JointModelRZ(), placement, jname);
    else if (type == "JointModelRevoluteUnaligned")
      jid = model.addJoint(parent, pinocchio::JointModelRevoluteUnaligned(axis), placement, jname);
    else if (type == "JointModelPX") jid = model.addJoint(parent, pinocchio::JointModelPX(), placement, jname);
    else if (type == "JointModelPY") jid = model.addJoint(parent, pinocchio::JointModelPY(), placement, jname);
    else if (type == "JointModelPZ") jid = model.addJoint(parent, pinocchio::JointModelPZ(), placement, jname);
    else if (type == "JointModelPrismaticUnaligned")
      jid = model.addJoint(parent, pinocchio::JointModelPrismaticUnaligned(axis), placement, jname);
    else
      throw std::runtime_error("joint type not handled: " + type);
    // Symmetric3(a, b, c, d, e, f) = (xx, xy, yy, xz, yz, zz)
    pinocchio::Symmetric3 S(I[0], I[1], I[3], I[2], I[4], I[5]);
    model.appendBodyToJoint(jid, pinocchio::Inertia(m, Eigen::Vector3d(c[0], c[1], c[2]), S));
  }
  model.gravity.setZero();
  return model;
}
