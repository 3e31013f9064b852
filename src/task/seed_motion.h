// Finding a task's input motion M0 (paper section 7.1).
//
// Starts from a hand-authored small in-place jump and runs CMA-ES (optimize/cmaes.h) on
// the task's constraint penalty C, as the paper does for each jump. With continuation
// (Jump onto, Jump over), the scene object's height is raised in stages, each stage
// starting from the previous stage's best; intermediate stages stop as soon as a
// candidate meets the stage's task.
//
// Objective: every candidate is simulated at the task's timestep and with it halved, and
// counts as meeting the task only if it does so at both and its feet land (at touch-down
// and at rest) within kTimestepAgreement of the same spot at both (landing d further
// apart adds K_c d^2), so input motions do not hinge
// on integration details. f is the mean C of these rollouts; when all of them meet the
// task, f = -robustness * min(margin, 0.1 m), where margin is the smallest slack inside
// the allowed region (task/constraints.h, constraint_margin) and, for a task with the
// half-timestep check, kTimestepAgreement minus how far apart the two landings are: a
// small reward for slack prefers input motions that land near the middle of their box,
// clear their obstacle with room and land alike at both timesteps, so the diversity
// optimizer starts from a motion with margin.
//
// Robustness (ours): the diversity optimizer starts from M0 and samples around it, so an
// input motion is only useful if some of its neighbourhood also meets the task. With
// SeedOptions::perturbations = P > 0, every candidate of the last stage (the task
// itself) is also simulated at P perturbations x + sigma_r z_k of its normalized
// parameters (reflected into [0, 1] as the optimizer's samples are; the same directions
// z_k for every candidate of a generation, so candidates are ranked on equal terms, and
// fresh ones in every generation, so the search cannot tune a motion to a few fixed
// directions), and the objective is the mean C over the 2 + P rollouts: the expected
// penalty under small parameter changes, each perturbation judged as the diversity
// optimizer will judge it (with the half-timestep check where the task asks for it).
// Choosing the result (with perturbations): each generation's mean is over its own few
// directions, so the candidate with the lowest mean of the whole search is mostly the one
// whose directions happened to be kind (the winner's curse of noisy optimization), and
// it holds no more of its neighbourhood than the others. The last stage therefore ends
// with a selection: the six candidates with the lowest objective that met the task
// at both timesteps, the CMA-ES mean and the stage's starting point are all simulated at
// the same SeedOptions::selection_samples perturbations (drawn for the selection alone,
// not those of measure_robustness(), which stays a measure on directions the search never
// saw), and the result is the one among them that meets the task and whose perturbations
// meet it most often (then by the lowest mean C). A search from a motion that meets the
// task thus never returns one that holds less of the selection's perturbations.
// Intermediate continuation stages go without: they have to get over the raised object,
// which a mean over perturbations discourages (a neighbourhood that lands short of a box
// beats one that partly hits its face).
// measure_robustness() reports the fraction of another set of perturbations that meet
// the task.
//
// The share objective (SeedOptions::objective = kShare, `--objective share`): the mean C
// ranks a region whose perturbations all land a few centimetres outside the box (C of
// tens) above one where half meet the task and half fall (C of 1e5), so a search for a
// robust jump drifts to near misses. With kShare each rollout adds 1 if it misses the task
// plus log(1 + C) / 100 (at most about 0.12), 0 if it meets it: f is the share of the
// rollouts that miss, the misses ranked among themselves by how far they miss.
//
// Pushes (SeedOptions::pushes = K > 0; `--pushes K`): robust controller optimization
// evaluates each candidate over several disturbed rollouts (Wang, Fleet and Hertzmann
// 2010), and what input motions fail most in the robustness suite is its pushes. With
// K > 0 every candidate of the last stage is also simulated K times with the root's
// linear velocity changed once by push_speed, exactly as the suite pushes
// (task/pushes.h): directions in turn (forward, backward; and left, right for a 3D root),
// the ground phase alternating after every round of directions (a jump's take-off phase,
// then its landing; a walk's evaluated steps), the moment drawn uniformly in the phase
// of the candidate's own unperturbed rollout. The moments' fractions are shared by the
// generation's candidates and fresh in every generation, as the perturbation directions
// are; each pushed rollout is judged with the half-timestep check where the task asks for
// it, and adds its term to the objective like a perturbation. A push is a disturbance
// from the world used to rank candidates only: the motion written is never pushed, and
// neither the controller nor a run applies one.
//
// A requirement beyond the task (SeedOptions::requirement; `diverse seed-motion --robust`
// sets it to the robustness suite's small part, robust/robustness.h robust_sample_suite()):
// a candidate of the last stage that meets the task at both timesteps (C = 0) meets it
// only if it also passes the requirement; one that does not gets the requirement's
// penalty added to its C, so it ranks below every candidate that meets the task and is
// never the result written as the task's M0. The requirement is judged only where it
// decides something, on candidates whose C is otherwise 0, so it costs nothing for the
// (many) candidates that miss the task anyway. Intermediate continuation stages go
// without, as they go without perturbations: their tasks are not the task.
//
// Deterministic for a given task seed: CMA-ES draws from seeds derived from it, the
// perturbations likewise, and the generation's samples are evaluated in parallel into
// fixed slots.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "params/parameters.h"
#include "task/constraints.h"
#include "task/task.h"

namespace diverse {

// The landing spots of an input motion at the task's timestep and at half of it differ by
// at most kTimestepAgreement (task/constraints.h, with landing_shift()).

// A requirement of the search beyond the task (see above). `check` is called with a
// candidate's named parameters from the search's threads at once (it must be
// thread-safe) and returns whether the candidate passes and what that cost in rollouts.
struct SeedRequirement {
  struct Verdict {
    bool holds = true;
    long long rollouts = 0;
  };
  std::function<Verdict(const ParameterSet&)> check;  // empty = no requirement
  double penalty = 0;  // added to the C of a candidate that meets the task but fails it (> 0)
  std::string name;    // named in the progress lines ("robust")
  explicit operator bool() const { return static_cast<bool>(check); }
};

enum class SeedObjective { kMeanC, kShare };

struct SeedOptions {
  int threads = 1;
  int generations = 0;  // per stage; 0 = the task's seed.generations
  double sigma = 0;     // initial CMA-ES step (normalized); 0 = the task's seed.sigma
  // Robustness term (see above): perturbations per candidate (0 = off) and their
  // standard deviation in normalized units.
  int perturbations = 0;
  double perturbation_sigma = 0.02;
  // Push term (see "Pushes" above): pushed rollouts per candidate (0 = off) and the change
  // of the root's speed they make (m/s, the robustness suite's 0.3 by default).
  int pushes = 0;
  double push_speed = 0.3;
  // The selection that chooses the result among the last stage's best candidates (see
  // above): its perturbations at perturbation_sigma, with pushes as many pushes as keep
  // the search's ratio of pushes to perturbations (0 = off: the candidate with the
  // lowest objective is the result). Only with perturbations or pushes > 0.
  int selection_samples = 32;
  // How the rollouts of a candidate make its objective (see above).
  SeedObjective objective = SeedObjective::kMeanC;
  // A requirement of the search, not of the task: the root turns at least this much (rad,
  // backwards positive) between take-off and touch-down, else K_c d^2 is added to C for
  // a shortfall of d. 0 = none. Makes a backflip turn in the air rather than on the ground.
  double min_flight_rotation = 0;
  // Continuation stages before this one are skipped: the search starts at stage
  // `first_stage` from the starting parameters (a stage file written by `on_stage`).
  int first_stage = 0;
  // A requirement beyond the task, judged on the last stage's candidates that meet it.
  SeedRequirement requirement;
  // Called after every generation with a one-line progress report.
  std::function<void(const std::string&)> log;
  // Called at the end of every continuation stage (before the last) with the stage's
  // index, its landing distance or object height, and the parameters it hands on (the
  // best that meets the stage's task, or the lowest objective), and their C. A long
  // search that is stopped can go on from there (first_stage).
  std::function<void(int stage, double value, const ParameterSet& parameters, double constraint)> on_stage;
};

struct SeedResult {
  ParameterSet parameters;
  double constraint = 0;  // C of the result on the full task (sum over both timesteps,
                          // plus the requirement's penalty when it fails it)
  double margin = 0;      // constraint_margin of the result (m)
  double robustness = 0;  // fraction of the last stage's fixed perturbations (and pushes)
                          // met (0 if off); with a selection, of the selection's
  // The selection (perturbations > 0 and selection_samples > 0): how many candidates it
  // compared and which it chose ("start", "CMA-ES mean", "generation G"); empty if none ran.
  int selection_candidates = 0;
  std::string selected;
  bool fell = true;
  // With a requirement: the result meets the task at both timesteps but fails the
  // requirement (its C is then the requirement's penalty); and, over the last stage's
  // candidates, how many were judged by it (those that met the task) and how many of
  // them passed.
  bool requirement_failed = false;
  long long requirement_checks = 0;
  long long requirement_held = 0;
  // Rollouts simulated: 2 + perturbations + pushes per candidate, plus the requirement's.
  long long evaluations = 0;
  // The last stage's candidate with the lowest objective, whether or not it meets the task
  // (with perturbations, a robust near miss can rank above a fragile motion that meets
  // it): the place to continue a search from.
  ParameterSet lowest_mean;
  double lowest_mean_f = 0;
  bool lowest_mean_meets = false;
  double seconds = 0;
};

// `start` holds the starting parameters (names and values of the task's controller).
SeedResult seed_motion(const Task& task, const ParameterSet& start, const SeedOptions& options);

// `count` perturbations of the normalized vector x: x + sigma * N(0, I), each coordinate
// reflected into [0, 1] (period 2, as the bounded CMA-ES does). Perturbation k draws from
// derive_seed(seed, {k}) only, so the set does not depend on threads or on `count`.
std::vector<Eigen::VectorXd> perturb(const Eigen::VectorXd& x, double sigma, int count,
                                     std::uint64_t seed);

// How much of a motion's neighbourhood meets the task: C at the task's timestep and with
// it halved, and, for each sigma, how many of `samples` perturbations (perturb() with
// robustness_seed()) meet the task as the diversity optimizer judges it: C = 0 at the
// task's timestep, and with the half-timestep check where the task asks for it.
//
// With `convergence` (a jump task; std::logic_error for a walk), each perturbation and the
// motion itself are also simulated at the task's timestep, half and a quarter of it, and
// the report says how far apart their first touch-downs are: a motion converged in the
// timestep comes down ever nearer one spot as the step shrinks, while one whose spots part
// as far between half and a quarter of the step as between the step and half of it rides
// on dynamics that small differences steer (a chaotic push-off or landing), and no
// timestep will make its neighbourhood hold.
// Where the parting starts: the same rollouts' peak COM heights (set at take-off) are
// compared too.
struct TimestepConvergence {
  int compared = 0;          // rollouts that touched down at all three timesteps
  double half_mean = 0;      // m, mean distance of the touch-downs at the step and half of it
  double half_max = 0;       // m, the largest
  double quarter_mean = 0;   // m, the same at half and a quarter of the step
  double quarter_max = 0;
  double peak_half_mean = 0;     // m, mean difference of the peak COM heights, step and half
  double peak_quarter_mean = 0;  // m, the same, half and a quarter
};
struct RobustnessReport {
  double constraint = 0;       // C at the task's timestep
  double constraint_fine = 0;  // C with the timestep halved
  double landing_shift = 0;    // landing_shift() between the two (m; NaN if either fell)
  struct Level {
    double sigma = 0;  // normalized
    int samples = 0;
    int met = 0;       // perturbations with C = 0
    std::vector<double> constraints;  // C of each perturbation, in perturb()'s order
    TimestepConvergence convergence;  // with `convergence`: over the perturbations
    double fraction() const { return samples > 0 ? static_cast<double>(met) / samples : 0; }
  };
  std::vector<Level> levels;
  // With `convergence`: the motion's first touch-down (x, m) at the step, half and a
  // quarter of it (NaN where it did not touch down), and its C at a quarter of the step.
  std::array<double, 3> touchdown_x{};
  double constraint_quarter = 0;
};
RobustnessReport measure_robustness(const Task& task, const ParameterSet& parameters,
                                    const std::vector<double>& sigmas, int samples, int threads,
                                    bool convergence = false);

// What one rollout with constraint penalty c adds to a candidate's objective (see above):
// c itself (kMeanC), or 0 when it meets the task and 1 + log(1 + c) / 100 when it misses
// (kShare). For x itself, counted at both timesteps, the mean objective adds its summed C
// once and the share objective its term twice.
double objective_term(SeedObjective objective, double c);

// The perturbations of the normalized x on which the selection that ends a search with
// perturbations compares its candidates (options.selection_samples of them at
// options.perturbation_sigma; the same directions for every candidate and every x).
std::vector<Eigen::VectorXd> selection_perturbations(const Task& task, const Eigen::VectorXd& x,
                                                     const SeedOptions& options);

// The seed of measure_robustness()'s perturbations at `sigma`: from the task's seed.seed
// and the value of sigma alone, so a sigma gets the same perturbations whatever other
// sigmas are measured with it, in whatever order.
std::uint64_t robustness_seed(const Task& task, double sigma);

}  // namespace diverse
