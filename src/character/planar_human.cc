#include "character/planar_human.h"

#include <cmath>

#include "core/error.h"

namespace diverse {
namespace {

constexpr const char* kTypeNames[kNumJointTypes] = {
    "hip", "knee", "ankle", "waist_lower", "waist_upper",
    "shoulder", "elbow", "wrist", "neck", "head"};

// The joints of each type, by name in the model.
const std::vector<std::vector<std::string>>& joint_names() {
  static const std::vector<std::vector<std::string>> names = {
      {"hip_l", "hip_r"},     {"knee_l", "knee_r"},         {"ankle_l", "ankle_r"},
      {"waist_lower"},        {"waist_upper"},              {"shoulder_l", "shoulder_r"},
      {"elbow_l", "elbow_r"}, {"wrist_l", "wrist_r"},       {"neck"},
      {"head"}};
  return names;
}

int require(const mjModel* m, int type, const std::string& name, const std::string& origin,
            const char* what) {
  const int id = mj_name2id(m, type, name.c_str());
  if (id < 0) throw UserError(origin + ": " + what + " '" + name + "': expected it in the model");
  return id;
}

}  // namespace

const char* joint_type_name(int type) {
  return (type >= 0 && type < kNumJointTypes) ? kTypeNames[type] : "?";
}

PlanarHuman::PlanarHuman(const mjModel* m, const std::string& origin) {
  const int rx = require(m, mjOBJ_JOINT, "rootx", origin, "root joint");
  const int rz = require(m, mjOBJ_JOINT, "rootz", origin, "root joint");
  const int ry = require(m, mjOBJ_JOINT, "rooty", origin, "root joint");
  root_x_qpos = m->jnt_qposadr[rx];
  root_z_qpos = m->jnt_qposadr[rz];
  root_pitch_qpos = m->jnt_qposadr[ry];
  root_x_dof = m->jnt_dofadr[rx];
  root_z_dof = m->jnt_dofadr[rz];
  root_pitch_dof = m->jnt_dofadr[ry];
  root_body = m->jnt_bodyid[ry];

  for (int type = 0; type < kNumJointTypes; ++type) {
    for (const std::string& name : joint_names()[type]) {
      PlanarJoint j;
      j.name = name;
      j.type = type;
      j.joint = require(m, mjOBJ_JOINT, name, origin, "joint");
      if (m->jnt_type[j.joint] != mjJNT_HINGE) {
        throw UserError(origin + ": joint '" + name + "': expected a hinge");
      }
      j.qpos = m->jnt_qposadr[j.joint];
      j.dof = m->jnt_dofadr[j.joint];
      j.actuator = require(m, mjOBJ_ACTUATOR, "tau_" + name, origin, "actuator");
      if (m->actuator_trntype[j.actuator] != mjTRN_JOINT ||
          m->actuator_trnid[2 * j.actuator] != j.joint || m->actuator_gainprm[10 * j.actuator] != 1 ||
          m->actuator_biastype[j.actuator] != mjBIAS_NONE) {
        throw UserError(origin + ": actuator 'tau_" + name +
                        "': expected a motor (gain 1, no bias) on joint '" + name + "'");
      }
      j.lower = m->jnt_range[2 * j.joint];
      j.upper = m->jnt_range[2 * j.joint + 1];
      if (m->nuser_jnt < 1 || !(m->jnt_user[m->nuser_jnt * j.joint] > 0)) {
        throw UserError(origin + ": joint '" + name +
                        "': expected its torque limit (Nm) > 0 as user value");
      }
      j.torque_limit = m->jnt_user[m->nuser_jnt * j.joint];
      by_type[type].push_back(static_cast<int>(joints.size()));
      joints.push_back(j);
    }
  }

  pelvis = require(m, mjOBJ_BODY, "pelvis", origin, "body");
  abdomen = require(m, mjOBJ_BODY, "abdomen", origin, "body");
  chest = require(m, mjOBJ_BODY, "chest", origin, "body");
  const char* side[2] = {"_l", "_r"};
  for (int s = 0; s < 2; ++s) {
    thigh[s] = require(m, mjOBJ_BODY, std::string("thigh") + side[s], origin, "body");
    shin[s] = require(m, mjOBJ_BODY, std::string("shin") + side[s], origin, "body");
    foot[s] = require(m, mjOBJ_BODY, std::string("foot") + side[s], origin, "body");
    hand[s] = require(m, mjOBJ_BODY, std::string("hand") + side[s], origin, "body");
    foot_geom[s] = require(m, mjOBJ_GEOM, std::string("foot") + side[s], origin, "geom");
  }
  if (root_body != pelvis) throw UserError(origin + ": root joints: expected them in 'pelvis'");
  for (int b = 1; b < m->nbody; ++b) {
    if (m->body_rootid[b] == pelvis) {
      links.push_back(b);
      total_mass += m->body_mass[b];
    }
  }
  // Segment lengths from the child bodies' offsets (z) in their parents.
  thigh_length = std::fabs(m->body_pos[3 * shin[0] + 2]);
  shin_length = std::fabs(m->body_pos[3 * foot[0] + 2]);

  // Chains: walk up the body tree collecting the hinge of each body.
  chain_.resize(joints.size());
  for (size_t i = 0; i < joints.size(); ++i) {
    std::vector<int> path;
    for (int b = m->jnt_bodyid[joints[i].joint]; b != pelvis && b > 0; b = m->body_parentid[b]) {
      for (size_t k = 0; k < joints.size(); ++k) {
        if (m->jnt_bodyid[joints[k].joint] == b) path.push_back(static_cast<int>(k));
      }
    }
    chain_[i] = path;
  }
}

double PlanarHuman::child_pitch(const double* qpos, int joint_index) const {
  double pitch = qpos[root_pitch_qpos];
  for (int k : chain_[joint_index]) pitch += qpos[joints[k].qpos];
  return pitch;
}

}  // namespace diverse

namespace diverse {

double PlanarHuman::child_pitch_rate(const double* qvel, int joint_index) const {
  double rate = qvel[root_pitch_dof];
  for (int k : chain_[joint_index]) rate += qvel[joints[k].dof];
  return rate;
}

}  // namespace diverse
