// The shared, read-only model and the per-thread simulation state.
//
// As in MuJoCo's own multi-threading advice: one compiled mjModel shared read-only by
// every thread, and one mjData per thread. Our controllers change per-joint damping from
// phase to phase (dof_damping carries each joint's derivative gain so that the Euler
// integrator treats it implicitly, see assets/characters/human2d.xml), so each worker
// also owns a private copy of the model (mj_copyModel, about a microsecond) whose
// dof_damping the controller writes; SimWorker::reset() restores it from the shared
// model, and the step recorder logs every change so a replay can repeat it. The
// robustness suite (robust/robustness.h) also scales a rollout's timestep and friction on
// that copy; reset() restores them as well.
#pragma once

#include <mujoco/mujoco.h>

#include <memory>
#include <string>

namespace diverse {

class SharedModel {
 public:
  // Compiles MJCF text. `origin` names the text in errors (a file path); `directory` is
  // where relative asset paths in the text resolve (unused by our models). Throws
  // UserError with MuJoCo's message on a compile error.
  static std::shared_ptr<const SharedModel> from_xml(const std::string& xml,
                                                     const std::string& origin);
  // Reads and compiles an MJCF file. Throws UserError if it is missing or invalid.
  static std::shared_ptr<const SharedModel> from_file(const std::string& path);

  ~SharedModel();
  SharedModel(const SharedModel&) = delete;
  SharedModel& operator=(const SharedModel&) = delete;

  const mjModel* get() const { return model_; }
  const std::string& xml() const { return xml_; }
  const std::string& origin() const { return origin_; }


 private:
  SharedModel() = default;
  mjModel* model_ = nullptr;
  std::string xml_;
  std::string origin_;
};

// Per-thread state: a private model copy and its mjData.
class SimWorker {
 public:
  explicit SimWorker(std::shared_ptr<const SharedModel> shared);
  ~SimWorker();
  SimWorker(const SimWorker&) = delete;
  SimWorker& operator=(const SimWorker&) = delete;

  // Restores the private model's writable parameters (dof_damping, geom_friction,
  // opt.timestep) from the shared model and resets mjData to qpos0 with zero velocity,
  // time and warnings.
  void reset();

  const SharedModel& shared() const { return *shared_; }
  const std::shared_ptr<const SharedModel>& shared_ptr() const { return shared_; }
  mjModel* model() { return model_; }
  const mjModel* model() const { return model_; }
  mjData* data() { return data_; }
  const mjData* data() const { return data_; }

 private:
  std::shared_ptr<const SharedModel> shared_;
  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
};

// Lowest and highest world z (m) of geom `g` in the kinematics of `d`: exact for spheres,
// capsules, cylinders, boxes and ellipsoids, the bounding sphere for other types.
void geom_z_extent(const mjModel* m, const mjData* d, int g, double* lo, double* hi);

}  // namespace diverse
