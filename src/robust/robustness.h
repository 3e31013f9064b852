// The robustness suite (SPEC section 12, "Skills that hold"): a fixed, seeded set of
// perturbed rollouts of a motion, and the share of them that still meets the task.
//
//   RobustnessSuite suite;                       // the defaults below
//   ThreadPool pool(threads);
//   const auto results = run_robustness_suite(evaluator, motions, suite, pool);
//   write_json_atomic(run / "robustness.json", robustness_json(evaluator, suite, results));
//
// A motion is a named parameter set (normalized as the optimizer sees it,
// ParameterSet::normalized()). Its suite has four kinds of perturbed rollouts, after one
// unperturbed rollout that gives the motion's C and its phase times:
//
//   parameters     `parameter_samples` rollouts at x + sigma * N(0, I) in normalized
//                  coordinates (every coordinate, the shape scales too when the motion has
//                  a shape). A coordinate outside [0, 1] is mirrored into it as the
//                  optimizer's CMA-ES does (optimize/cmaes.h: period 2, x -> -x below 0,
//                  x -> 2 - x above 1), so no sample is skipped or clipped.
//   pushes         `push_samples` rollouts with the root's linear velocity changed once by
//                  `push_speed` (EvaluationOptions::push, task/evaluate.h; where and which
//                  way: task/pushes.h): directions
//                  forward (+x, where every character faces at the start), backward,
//                  and for a 3D root left (+y) and right, in turn; a planar root is pushed
//                  forward and backward only, in its plane. The moment is drawn uniformly
//                  in a ground phase of the unperturbed rollout, the phases alternating
//                  after every round of directions: a jump's first phase, from the start
//                  to take-off, then its landing, from touch-down to touch-down plus the
//                  task's settle_time (or the rollout's end if sooner: the motion has not
//                  settled before). A walk's ground phase is its evaluated steps, from the
//                  touch-down of its last settling step to its last touch-down. A motion
//                  without the phase (it never took off, never landed, fell before its
//                  evaluated steps) is pushed in [0, its end). Up to the push a pushed
//                  rollout is the unperturbed one, so every push is applied.
//   friction       one rollout per factor: every contact's friction times the factor
//                  (EvaluationOptions::friction_scale).
//   half_timestep  one rollout at half the task's timestep (EvaluationOptions::
//                  timestep_scale = 0.5), judged on its own C.
//
// A perturbed rollout holds when it meets the task: C == 0, judged as a run judges its
// samples, the task's own half-timestep check included when the task asks for one
// ([constraints] half_timestep: a pushed or friction-scaled rollout is simulated again at
// half the timestep under the same push or friction); the half-timestep rollout itself
// has no further check. The run's bounds on effort and on the distance from M0
// (eval/motion_problem.h) are not the task and are not part of the suite.
//
// Determinism: every random number derives from the suite's seed with derive_seed(seed,
// {motion index, kind, sample}) (core/rng.h), the motion index being i of M_i, so a
// motion gives the same suite alone or with its run, and results are identical for any
// number of threads. Every rollout runs on a worker of its own on the pool.
//
// Cost: about 19 rollouts per motion with the defaults (8 + 8 + 2 + 1), plus the half-
// timestep checks of the rollouts that hold on a task that asks for them, plus one
// unperturbed rollout. docs/guide/robustness.md has the measurements of every task's M0.
//
// The push and the friction are the world's, never a controller's: the optimizer and a
// run never set them (EvaluationOptions defaults to none), and the input-motion search
// pushes its candidates only with `--pushes`, drawn as here (task/pushes.h), to rank them.
#pragma once

#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/thread_pool.h"
#include "params/parameters.h"
#include "task/evaluate.h"

namespace diverse {

struct RobustnessSuite {
  std::uint64_t seed = 1;
  int parameter_samples = 8;   // rollouts at perturbed parameters
  double sigma = 0.02;         // normalized units (a share of each parameter's range)
  int push_samples = 8;        // pushed rollouts: 2 rounds of 4 directions (3D), 4 of 2 (planar)
  double push_speed = 0.3;     // m/s, the change of the root's linear velocity (every character)
  std::vector<double> friction_factors{0.6, 1.5};  // one rollout each
  bool half_timestep = true;   // one rollout at half the timestep
  // Which ground phase the first round of pushes falls in (0: a jump's take-off phase, 1:
  // its landing); the rounds alternate from there.
  int first_push_phase = 0;
  // check_suite(): the share of the perturbed rollouts that must hold.
  double required_share = 1.0;
};

// The small part of the suite a `--robust` run asks of a sample before a variation may
// stand at it (eval/motion_problem.h, MotionBounds::robust): 2 parameter perturbations at
// sigma 0.02, and 2 pushes of 0.3 m/s in the landing (forward and backward; a walk's: in
// its evaluated steps); the half-timestep check is the run's own. The same seeded draws
// for every sample; a sample holds when at least 3 of the 4 do (75 %, the share SPEC 12
// asks of a robust motion under the whole suite).
RobustnessSuite robust_sample_suite();

// Whether one motion holds under `suite`: at least suite.required_share of its perturbed
// rollouts meet the task. They run one after another on the calling thread (each on a
// worker of its own) until the verdict is known. `steps`
// counts every rollout's simulation steps, the unperturbed one that gives the push
// moments and the half-timestep checks included.
struct SuiteVerdict {
  bool holds = true;
  int rollouts = 0;      // perturbed rollouts run
  int half_timestep_checks = 0;  // of them, those checked again at half the timestep
  long long steps = 0;
};
SuiteVerdict check_suite(const TaskEvaluator& evaluator, const ParameterSet& parameters,
                         const RobustnessSuite& suite);

// Ranges of the suite's settings (the command's options, and robustness.json when read).
constexpr int kMaxRobustnessSamples = 1000;   // parameter_samples, push_samples: [1, this]
constexpr double kMaxRobustnessSigma = 0.5;   // sigma in (0, this]
constexpr double kMaxPushSpeed = 10;          // m/s, push_speed in [0, this]

enum class PerturbationKind { kParameters = 0, kPush = 1, kFriction = 2, kHalfTimestep = 3 };
constexpr int kPerturbationKinds = 4;
// "parameters", "pushes", "friction", "half_timestep": the keys of robustness.json.
const char* perturbation_key(PerturbationKind kind);

// One perturbed rollout and its outcome.
struct PerturbedRollout {
  PerturbationKind kind = PerturbationKind::kParameters;
  int sample = 0;              // index within its kind
  double constraint = 0;       // C of the perturbed rollout
  bool holds = false;          // C == 0 and the rollout did not fail
  std::string failure;         // why the rollout failed (blew up), or ""
  std::string fall_reason;     // why it fell, or ""
  // s from the first touch-down to the fall; -1 when it did not fall or fell before landing.
  double fell_after_touchdown = -1;
  // kParameters: |x' - x| (normalized units), and the perturbed parameters (a parameter
  // file's "parameters": `diverse simulate --params` shows the rollout).
  double distance = 0;
  nlohmann::json parameters;
  // kPush: the ground phase ("takeoff" before take-off, "landing" after touch-down,
  // "steps" in a walk's evaluated steps, "motion" for the whole rollout), the direction,
  // the time (s) it was applied and the change of velocity (m/s, world frame).
  std::string phase, direction;
  double push_time = -1;
  std::array<double, 3> dv{0.0, 0.0, 0.0};
  double friction = 1;         // kFriction: the factor
  double timestep_scale = 1;   // kHalfTimestep: 0.5
};

// A motion to test: M_index of a run (index 0 for an input motion).
struct MotionUnderTest {
  std::string label;           // "M0", "M1", ...
  int index = 0;               // seeds derive from it
  ParameterSet parameters;     // named; shape scales too for a motion with a shape
};

struct MotionRobustness {
  std::string label;
  int index = 0;
  double constraint = 0;       // the unperturbed motion's C (judged as the perturbed ones)
  std::vector<PerturbedRollout> rollouts;  // by kind, then sample
  int held(PerturbationKind kind) const;
  int count(PerturbationKind kind) const;
  int held() const;            // over every kind
  int count() const;
};

// Runs the suite on every motion; every rollout of every motion on `pool`.
std::vector<MotionRobustness> run_robustness_suite(const TaskEvaluator& evaluator,
                                                   const std::vector<MotionUnderTest>& motions,
                                                   const RobustnessSuite& suite, ThreadPool& pool);

// robustness.json (docs/guide/robustness.md): the suite's definition, then per motion the
// unperturbed C, per kind the counts and every perturbed rollout with its C.
nlohmann::json robustness_json(const TaskEvaluator& evaluator, const RobustnessSuite& suite,
                               const std::vector<MotionRobustness>& results);
// Both at once: what a run's end can call with its motions M0..MN.
nlohmann::json robustness_json(const TaskEvaluator& evaluator, const std::vector<MotionUnderTest>& motions,
                               const RobustnessSuite& suite, ThreadPool& pool);

// "params 7/8, pushes 6/8, friction 2/2, half-step 1/1, all 16/19 = 84 %" for one motion
// of robustness.json ("motions"[i]). Throws UserError "ORIGIN: FIELD: expected ..." when
// the entry is malformed.
std::string robustness_shares(const nlohmann::json& motion, const std::string& origin);

// Mirrors a normalized coordinate into [0, 1] (period 2), as the optimizer's CMA-ES does.
double mirror_unit(double x);

}  // namespace diverse
