// The motion file (SPEC section 7): one simulated motion, complete enough to look at,
// measure and replay exactly in plain MuJoCo. Written by `diverse simulate` (motion.json)
// and `diverse run` (motions/m<i>.json); read by `diverse replay`, render, gallery and
// export.
//
//   {
//     "format": "diverse.motion", "version": 1,
//     "task": "backflip", "label": "M1",
//     "parameters": {"name": value, ...},          named controller parameters (and the
//                                                  shape scales "shape.*" of a shaped body)
//     "shape": {"scales": {...}, "link_names": [...], "link_lengths": [...]}   shaped bodies
//                                                  only: the scales and the link lengths
//                                                  (m) of the shape distance
//     "constraint": {"total": C, "fell": false, "terms": [{"name", "violation", "penalty"}]},
//     "summary": {peak COM height, feet position at the end, rotation, ...},
//     "strength": 1,                               the strength model it ran at (Task::strength)
//     "effort": E, "positive_work": W,             N^2 m^2 s and J (physics/rollout.h)
//     "phases": [{"name": "start", "begin": 0.0}, ...],   begin times (s), -1 if never;
//                                                  "event": "takeoff", "peak" or "landing"
//                                                  on the phases those events begin
//     "pose_samples": {"link_names", "angle_names", "link_masses",
//                      "samples": [{"phase", "phase_time", "time", "link_com", "angles"}]},
//     "replay": {
//       "model": "../model/m1.xml",   path of the MJCF, relative to this file: the exact
//                                     text the motion ran on (MuJoCo's own writer keeps 6
//                                     digits, which rotated frames and shaped bodies do
//                                     not survive: docs/guide/shapes.md)
//       "timestep": 0.002, "nq": 19, "nu": 16,
//       "qpos0": [...], "qvel0": [...],            initial state
//       "damped_dofs": [...],                      dofs whose dof_damping the controller sets
//       "damping": [{"step": k, "values": [...]}], dof_damping written before step k
//       "ctrl": [[...], ...],                      per step, the ctrl written before mj_step
//       "qpos": [[...], ...]                       per step, qpos after mj_step
//     }
//   }
//
// Replaying: load the model, set qpos0/qvel0, and for every step k apply the damping
// changes of step k, copy ctrl[k] into d->ctrl and call mj_step; qpos must equal qpos[k].
// Doubles are written with the shortest representation that parses back to the same bits.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "physics/rollout.h"
#include "task/evaluate.h"
#include "task/foot_slip.h"

namespace diverse {

struct MotionRecordInfo {
  std::string label;                   // "M0", "M1", ... or "" for a single motion
  std::filesystem::path model_path;    // where the saved model is (or will be) written
};

// Builds the motion file's JSON. `record` is the rollout's replay record.
nlohmann::json motion_record_json(const TaskEvaluator& evaluator, const ParameterSet& parameters,
                                  const Evaluation& evaluation, const StepRecorder& record,
                                  const MotionRecordInfo& info,
                                  const std::filesystem::path& json_path);

// The "replay" object of a motion file for `record`, whose model is (or will be) saved at
// model_path; the path is written relative to the motion file json_path. For motions made
// by other programs than a task (a controller's own rollout, a test fixture), so that
// `diverse replay`, render, gallery and export read them as any other.
nlohmann::json replay_record_json(const StepRecorder& record,
                                  const std::filesystem::path& model_path,
                                  const std::filesystem::path& json_path);

// Simulates `parameters` with recording on, saves the model to info.model_path and the
// motion file to json_path. Returns the evaluation. Parameters holding shape scales
// (holds_shape) run on that shape's scene, whose exact MJCF text is saved; otherwise
// the task's model is saved as MuJoCo writes it.
Evaluation write_motion(const TaskEvaluator& evaluator, const ParameterSet& parameters,
                        const MotionRecordInfo& info, const std::filesystem::path& json_path,
                        StepRecorder* record_out = nullptr);

// Reads the replay part of a motion file. Throws UserError "PATH: replay.FIELD: expected
// ..." when it is missing or malformed. `model_path` receives the resolved model path.
StepRecorder read_replay_record(const nlohmann::json& motion, const std::filesystem::path& json_path,
                                std::filesystem::path* model_path);

// Loads a motion file's model in plain MuJoCo and replays its inputs; returns the
// largest |qpos difference| from the recorded qpos over all steps (infinity if the
// replay blew up). Throws UserError if the file or its model cannot be read.
double replay_motion_file(const std::filesystem::path& json_path, int* steps = nullptr);

// Replays a motion file's inputs on its saved model, as replay_motion_file() does, and
// measures how far its feet slide (task/foot_slip.h); the feet are those of the character
// file `spec` bound to the saved model. Throws UserError as replay_motion_file().
FootSlip motion_file_foot_slip(const std::filesystem::path& json_path, std::shared_ptr<const CharacterSpec> spec,
                               const FootSlipOptions& options = {});

}  // namespace diverse
