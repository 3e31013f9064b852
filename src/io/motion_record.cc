#include "io/motion_record.h"

#include <mujoco/mujoco.h>

#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "core/error.h"
#include "io/files.h"
#include "physics/mujoco_guard.h"

namespace diverse {
namespace fs = std::filesystem;

namespace {

nlohmann::json rows(const std::vector<double>& flat, int width) {
  nlohmann::json out = nlohmann::json::array();
  if (width <= 0) return out;
  for (std::size_t k = 0; k + static_cast<std::size_t>(width) <= flat.size(); k += width)
    out.push_back(std::vector<double>(flat.begin() + static_cast<long>(k),
                                      flat.begin() + static_cast<long>(k + width)));
  return out;
}

nlohmann::json summary_json(const MotionSummary& s) {
  nlohmann::json j = {{"unstable", s.unstable},           {"took_off", s.took_off},
          {"landed", s.landed},               {"settled", s.settled},
          {"fell", s.fell},                   {"fall_reason", s.fall_reason},
          {"peak_com_z", s.peak_com_z},       {"standing_com_z", s.standing_com_z},
          {"feet_x", s.feet_x},
          {"feet_y", s.feet_y},               {"feet_z", s.feet_z},
          {"touchdown_feet_x", s.touchdown_feet_x}, {"touchdown_feet_y", s.touchdown_feet_y},
          {"touchdown_feet_z", s.touchdown_feet_z}, {"rotation_total", s.rotation_total},
          {"max_forward_pitch", s.max_forward_pitch},
          {"rotation_flight", s.rotation_flight}, {"min_clearance", s.min_clearance},
          {"end_time", s.end_time}};
  if (!s.walk.steps.empty()) {
    // A walk's steps (task/walk_task.h): leg 0 left, 1 right; lengths in m in the heading
    // frame at the touch-down; heading and tilt in rad.
    nlohmann::json steps = nlohmann::json::array();
    for (const WalkStep& w : s.walk.steps) {
      steps.push_back({{"leg", w.leg}, {"time", w.time}, {"forward", w.forward}, {"lateral", w.lateral},
                       {"heading", w.heading}, {"tilt", w.tilt}});
    }
    j["walk_steps"] = steps;
    j["walk_relandings"] = s.walk.relandings;
  }
  return j;
}

}  // namespace

nlohmann::json motion_record_json(const TaskEvaluator& evaluator, const ParameterSet& parameters,
                                  const Evaluation& e, const StepRecorder& record,
                                  const MotionRecordInfo& info, const fs::path& json_path) {
  nlohmann::json j;
  j["format"] = "diverse.motion";
  j["version"] = 1;
  j["task"] = evaluator.task().name;
  j["label"] = info.label;
  j["parameters"] = parameters.to_json();
  if (holds_shape(parameters)) {
    const ShapeSpace& shapes = evaluator.shapes();
    const Eigen::VectorXd scales = shapes.scales_from(parameters);
    const Eigen::VectorXd lengths = shapes.link_lengths(scales);
    nlohmann::json named = nlohmann::json::object();
    for (int p = 0; p < shapes.size(); ++p) named[shapes.specs()[static_cast<size_t>(p)].name] = scales[p];
    j["shape"] = {{"scales", named},
                  {"link_names", shapes.link_names()},
                  {"link_lengths", std::vector<double>(lengths.data(), lengths.data() + lengths.size())}};
  }

  nlohmann::json terms = nlohmann::json::array();
  for (const ConstraintTerm& t : e.report.terms)
    terms.push_back({{"name", t.name}, {"violation", t.violation}, {"penalty", t.penalty}});
  j["constraint"] = {{"total", e.constraint}, {"fell", e.fell}, {"failed", e.failed},
                     {"failure", e.failure}, {"terms", terms}};
  j["summary"] = summary_json(e.summary);
  j["strength"] = evaluator.task().strength;
  j["effort"] = e.stats.effort;
  j["positive_work"] = e.stats.positive_work;

  nlohmann::json phases = nlohmann::json::array();
  for (std::size_t p = 0; p < e.phases.names.size(); ++p) {
    nlohmann::json phase = {{"name", e.phases.names[p]}, {"begin", e.phases.begin[p]}};
    // The events of the motion: which phases begin at take-off, the peak and touch-down.
    const int i = static_cast<int>(p);
    if (i == e.phases.rise) phase["event"] = "takeoff";
    if (i == e.phases.fall) phase["event"] = "peak";
    if (i == e.phases.land) phase["event"] = "landing";
    phases.push_back(std::move(phase));
  }
  j["phases"] = phases;

  nlohmann::json samples = nlohmann::json::array();
  for (const PoseSample& s : e.poses) {
    nlohmann::json com = nlohmann::json::array();
    for (Eigen::Index c = 0; c < s.link_com.cols(); ++c)
      com.push_back({s.link_com(0, c), s.link_com(1, c), s.link_com(2, c)});
    samples.push_back({{"phase", s.phase},
                       {"phase_time", s.phase_time},
                       {"time", s.time},
                       {"link_com", com},
                       {"angles", std::vector<double>(s.angles.data(), s.angles.data() + s.angles.size())}});
  }
  const Eigen::VectorXd masses = evaluator.link_masses();
  j["pose_samples"] = {{"link_names", evaluator.link_names()},
                       {"angle_names", evaluator.angle_names()},
                       {"link_masses", std::vector<double>(masses.data(), masses.data() + masses.size())},
                       {"samples", samples}};

  j["replay"] = replay_record_json(record, info.model_path, json_path);
  return j;
}

nlohmann::json replay_record_json(const StepRecorder& record, const fs::path& model_path,
                                  const fs::path& json_path) {
  nlohmann::json damping = nlohmann::json::array();
  for (const auto& change : record.damping)
    damping.push_back({{"step", change.step}, {"values", change.values}});
  const fs::path base = json_path.has_parent_path() ? json_path.parent_path() : fs::path(".");
  return {{"model", model_path.lexically_relative(base).generic_string()},
                 {"timestep", record.timestep},
                 {"nq", record.nq},
                 {"nu", record.nu},
                 {"qpos0", record.qpos0},
                 {"qvel0", record.qvel0},
                 {"damped_dofs", record.damped_dofs},
                 {"damping", damping},
                 {"ctrl", rows(record.ctrl, record.nu)},
                 {"qpos", rows(record.qpos, record.nq)}};
}

Evaluation write_motion(const TaskEvaluator& evaluator, const ParameterSet& parameters,
                        const MotionRecordInfo& info, const fs::path& json_path,
                        StepRecorder* record_out) {
  StepRecorder record;
  EvaluationOptions options;
  options.recorder = &record;
  options.half_timestep_check = true;  // when the task asks for it: as the optimizer saw it
  std::shared_ptr<const SharedModel> model;
  const Evaluation e = evaluator.evaluate_named(parameters, options, &model);
  // The exact MJCF text the model was compiled from: loaded by any MuJoCo program it
  // compiles to the same numbers, so the recorded inputs replay bit for bit. MuJoCo's own
  // writer (mj_saveLastXML) keeps 6 significant digits, which a shaped body or a rotated
  // frame (the bird robot's legs: 7e-5 of drift in 3 s) does not survive.
  write_file_atomic(info.model_path, model->xml());
  write_json_atomic(json_path, motion_record_json(evaluator, parameters, e, record, info, json_path));
  if (record_out) *record_out = std::move(record);
  return e;
}

namespace {

// An integer in [lo, hi] (a float, a bool or a string is not one).
int strict_int(const nlohmann::json& j, int lo, int hi) {
  if (!j.is_number_integer()) throw std::invalid_argument("not an integer");
  const long long v = j.get<long long>();
  if (j.is_number_unsigned() && j.get<unsigned long long>() > static_cast<unsigned long long>(hi))
    throw std::invalid_argument("out of range");
  if (v < lo || v > hi) throw std::invalid_argument("out of range");
  return static_cast<int>(v);
}

}  // namespace

StepRecorder read_replay_record(const nlohmann::json& motion, const fs::path& json_path,
                                fs::path* model_path) {
  const std::string where = json_path.string();
  if (!motion.is_object() || !motion.contains("format") || motion["format"] != "diverse.motion")
    throw UserError(where + ": format: expected \"diverse.motion\" (a motion file written by "
                            "`diverse simulate` or `diverse run`)");
  if (!motion.contains("replay") || !motion["replay"].is_object())
    throw UserError(where + ": replay: expected an object with the exact-replay record");
  const nlohmann::json& r = motion["replay"];
  StepRecorder record;
  std::string field;
  try {
    field = "model";
    const fs::path base = json_path.has_parent_path() ? json_path.parent_path() : fs::path(".");
    if (model_path) *model_path = base / r.at("model").get<std::string>();
    field = "timestep";
    record.timestep = r.at("timestep").get<double>();
    if (!(record.timestep > 0 && record.timestep <= 1)) throw std::invalid_argument("timestep");
    field = "nq";
    record.nq = strict_int(r.at("nq"), 1, 100000);
    field = "nu";
    record.nu = strict_int(r.at("nu"), 0, 100000);
    field = "qpos0";
    record.qpos0 = r.at("qpos0").get<std::vector<double>>();
    field = "qvel0";
    record.qvel0 = r.at("qvel0").get<std::vector<double>>();
    field = "damped_dofs";
    for (const auto& dof : r.at("damped_dofs")) record.damped_dofs.push_back(strict_int(dof, 0, 100000));
    record.ndamp = static_cast<int>(record.damped_dofs.size());
    field = "damping";
    for (const auto& change : r.at("damping")) {
      StepRecorder::DampingChange c;
      c.step = strict_int(change.at("step"), 0, std::numeric_limits<int>::max());
      if (!record.damping.empty() && c.step < record.damping.back().step) throw std::invalid_argument("order");
      c.values = change.at("values").get<std::vector<double>>();
      if (static_cast<int>(c.values.size()) != record.ndamp) throw std::invalid_argument("size");
      record.damping.push_back(std::move(c));
    }
    field = "ctrl";
    for (const auto& row : r.at("ctrl")) {
      const auto v = row.get<std::vector<double>>();
      if (static_cast<int>(v.size()) != record.nu) throw std::invalid_argument("row size");
      record.ctrl.insert(record.ctrl.end(), v.begin(), v.end());
    }
    field = "qpos";
    for (const auto& row : r.at("qpos")) {
      const auto v = row.get<std::vector<double>>();
      if (static_cast<int>(v.size()) != record.nq) throw std::invalid_argument("row size");
      record.qpos.insert(record.qpos.end(), v.begin(), v.end());
    }
  } catch (const std::exception&) {
    throw UserError(where + ": replay." + field + ": missing or malformed");
  }
  if (record.qpos0.size() != static_cast<std::size_t>(record.nq) ||
      record.qvel0.empty() || record.ctrl.size() / std::max(1, record.nu) !=
                                  record.qpos.size() / std::max(1, record.nq))
    throw UserError(where + ": replay: expected qpos0 of nq values and as many qpos rows as ctrl rows");
  return record;
}

namespace {

// A motion file's record and a private copy of its saved model, checked against each other.
using ModelCopy = std::unique_ptr<mjModel, void (*)(mjModel*)>;
ModelCopy load_replay(const fs::path& json_path, StepRecorder* record) {
  const nlohmann::json motion = read_json(json_path);
  fs::path model_path;
  *record = read_replay_record(motion, json_path, &model_path);
  const auto model = SharedModel::from_file(model_path.string());
  // The copy is freed on every path out, the errors included; they read the model before.
  ModelCopy copy(mj_copyModel(nullptr, model->get()), mj_deleteModel);
  const mjModel* m = copy.get();
  if (m->nq != record->nq || m->nu != record->nu || m->nv != static_cast<int>(record->qvel0.size()))
    throw UserError(json_path.string() + ": replay: nq/nu do not match the model " + model_path.string());
  for (int dof : record->damped_dofs) {
    if (dof >= m->nv)
      throw UserError(json_path.string() + ": replay.damped_dofs: expected dof indices below the model's nv (" +
                      std::to_string(m->nv) + "), got " + std::to_string(dof));
  }
  if (std::fabs(m->opt.timestep - record->timestep) > 0)
    throw UserError(json_path.string() + ": replay.timestep: does not match the model's");
  return copy;
}

}  // namespace

double replay_motion_file(const fs::path& json_path, int* steps) {
  StepRecorder record;
  const ModelCopy copy = load_replay(json_path, &record);
  const double diff = replay(copy.get(), record);
  if (steps) *steps = record.steps();
  return diff;
}

FootSlip motion_file_foot_slip(const fs::path& json_path, std::shared_ptr<const CharacterSpec> spec,
                               const FootSlipOptions& options) {
  StepRecorder record;
  const ModelCopy copy = load_replay(json_path, &record);
  const Character body = bind_character(std::move(spec), copy.get(), json_path.string());
  return measure_foot_slip(copy.get(), record, body, options);
}

}  // namespace diverse
