#include "physics/model.h"

#include <algorithm>
#include <cmath>

#include <cstring>
#include <fstream>
#include <memory>
#include <mutex>
#include <sstream>

#include "core/error.h"
#include "core/text_file.h"
#include "physics/mujoco_guard.h"

namespace diverse {
namespace {

// mj_loadXML keeps process-global parser state.
std::mutex& loader_mutex() {
  static std::mutex mutex;
  return mutex;
}

// Compiles `xml` through a virtual file system (heap-allocated: mjVFS is large).
// Caller holds the loader lock.
mjModel* compile_locked(const std::string& xml, std::string* error) {
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* name = "diverse_model.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(xml.size())) != 0) {
    *error = "cannot allocate the model text in MuJoCo's virtual file system";
    return nullptr;
  }
  const int index = mj_findFileVFS(vfs.get(), name);
  std::memcpy(vfs->filedata[index], xml.data(), xml.size());
  char message[1000] = "";
  mjModel* model = mj_loadXML(name, vfs.get(), message, sizeof(message));
  mj_deleteVFS(vfs.get());
  if (model == nullptr) *error = message;
  return model;
}

}  // namespace

std::shared_ptr<const SharedModel> SharedModel::from_xml(const std::string& xml,
                                                         const std::string& origin) {
  install_mujoco_handlers();
  std::string error;
  mjModel* model = nullptr;
  {
    std::lock_guard<std::mutex> lock(loader_mutex());
    model = compile_locked(xml, &error);
  }
  if (model == nullptr) {
    for (char& c : error) {
      if (c == '\n') c = ' ';
    }
    throw UserError(origin + ": MuJoCo cannot compile the model: " + error);
  }
  std::shared_ptr<SharedModel> shared(new SharedModel());
  shared->model_ = model;
  shared->xml_ = xml;
  shared->origin_ = origin;
  return shared;
}

std::shared_ptr<const SharedModel> SharedModel::from_file(const std::string& path) {
  return from_xml(read_text_file(path, "model"), path);
}

SharedModel::~SharedModel() {
  if (model_ != nullptr) mj_deleteModel(model_);
}

SimWorker::SimWorker(std::shared_ptr<const SharedModel> shared) : shared_(std::move(shared)) {
  model_ = mj_copyModel(nullptr, shared_->get());
  data_ = mj_makeData(model_);
}

SimWorker::~SimWorker() {
  if (data_ != nullptr) mj_deleteData(data_);
  if (model_ != nullptr) mj_deleteModel(model_);
}

void SimWorker::reset() {
  const mjModel* src = shared_->get();
  std::memcpy(model_->dof_damping, src->dof_damping, sizeof(mjtNum) * src->nv);
  std::memcpy(model_->geom_friction, src->geom_friction, sizeof(mjtNum) * 3 * src->ngeom);
  model_->opt.timestep = src->opt.timestep;
  mj_resetData(model_, data_);
}

void geom_z_extent(const mjModel* m, const mjData* d, int g, double* lo, double* hi) {
  const double* p = d->geom_xpos + 3 * g;
  const double* R = d->geom_xmat + 9 * g;
  const double* s = m->geom_size + 3 * g;
  double half = 0;
  switch (m->geom_type[g]) {
    case mjGEOM_SPHERE: half = s[0]; break;
    case mjGEOM_CAPSULE: half = std::fabs(R[8]) * s[1] + s[0]; break;
    case mjGEOM_CYLINDER: half = std::fabs(R[8]) * s[1] + s[0] * std::sqrt(std::max(0.0, 1 - R[8] * R[8])); break;
    case mjGEOM_BOX: half = std::fabs(R[6]) * s[0] + std::fabs(R[7]) * s[1] + std::fabs(R[8]) * s[2]; break;
    case mjGEOM_ELLIPSOID:
      half = std::sqrt(R[6] * R[6] * s[0] * s[0] + R[7] * R[7] * s[1] * s[1] + R[8] * R[8] * s[2] * s[2]);
      break;
    default: half = m->geom_rbound[g]; break;
  }
  *lo = p[2] - half;
  *hi = p[2] + half;
}

}  // namespace diverse
