// Diversity optimization: finds N variations M_1..M_N of a reference M_0 that maximize
// the diversity objective D (paper eq. 1, see optimize/objective.h), with CMA-ES.
//
// Agrawal, Shen, van de Panne, "Diverse Motions and Character Shapes for Simulated
// Skills", IEEE TVCG 2014, section 3. Three strategies:
//
//   round-robin  (the paper's method, default) N CMA-ES instances, one per variation,
//                all starting at P_0. Variation i gets one CMA generation of lambda
//                samples while the others stay where they stand (see "Where a variation
//                stands" below); each sample is scored by the full D with M_i replaced
//                by the sample; then variation i+1, and so on.
//   progressive  (baseline, paper section 9) variations are added one at a time; only
//                the newest is optimized, against M_0 and the earlier ones, until it stops
//                improving or its share of the generation budget ends; it is then frozen
//                at the best set found in its phase.
//   joint        (baseline) one CMA-ES instance over all N x |P| parameters; a sample is
//                a whole set M_1..M_N.
//   simultaneous N CMA-ES instances as in round-robin, but every variation draws its
//                generation at once: one batch of N x lambda rollouts, as best-sample
//                round-robin's batches (below) hold too. Each sample replaces M_i
//                in the set as it stood when the generation was drawn; each instance is
//                told those scores. Then the variations move one after another (1..N),
//                each to its best sample if that beats it among the others as they now
//                stand (best-sample; ranked as round-robin ranks), or all to their new
//                means, evaluated in one more batch of N (mean). What it gives up against
//                round-robin: variation i's samples do not see the moves variations
//                1..i-1 made in the same generation (docs/results.md compares them).
//
// Generations. One generation costs N x lambda evaluations in every strategy, so budgets
// compare directly:
//   round-robin  one CMA generation of each variation, in order 1..N;
//   progressive  N CMA generations of the newest variation;
//   joint        one CMA generation (lambda samples, each N evaluations) of the joint
//                instance;
//   simultaneous one CMA generation of every variation, in one batch.
// A "step" is one CMA generation of one instance (joint: of the joint instance;
// simultaneous: of all N at once); the log has one record per step, with variation 0
// for joint and simultaneous.
// With VariationPoint::kMean, on top of the sample evaluations, the mean of every instance
// that moved is evaluated again (one evaluation per variation per step): its outcome is
// what the other variations' samples are scored against. `evaluations` counts both. That
// evaluation is batched with the next step's samples, so a step's log record and callback
// come once it is known.
//
// Termination, checked at the end of each generation: the generation limit; stagnation
// (over the last `window` generations the best set's D improved by less than epsilon and,
// under the dominant rule below, its total C did not fall); or every
// CMA instance stopped on its own numerical criteria (condition number, no-effect axis;
// its TolFun / TolX are disabled because D moves under it as the other variations move).
// Progressive: each phase ends on stagnation within the phase or when its share of the
// budget, (max_generations - generations used) / (variations still to add), at least 1,
// is used up; the run ends when the last variation's phase ends.
//
// Constraints. Eq. 1 puts -C(M_i) inside D with a penalty weight the paper chooses "large
// enough to rapidly dominate the diversity objective once constraints are violated", and
// notes that since CMA-ES only ranks samples, the exact weight does not matter once it is
// large enough. Two rules:
//   dominant  (default) the limit of a large enough weight: the constraint decides first.
//             A sample that violates its constraints ranks below every sample that meets
//             them, infeasible samples rank by their C, and feasible ones by D. For
//             round-robin and progressive a sample's C is that of the one motion it
//             changes; for joint, the sum over its N motions. Sets (the best set, the
//             stagnation test) compare the same way: smaller total C first, then D.
//   penalty   eq. 1 literally, -C added to D: C competes with the distance terms at the
//             weight the task gives it, so diversity can buy constraint violation when
//             the metric's scale is large (a mass-weighted distance summed over 20 poses
//             of an 80 kg body easily is); the toy of paper figure 2 uses it.
// D itself (logged, reported) is always eq. 1 as printed.
//
// Where a variation stands. The paper scores each sample against the other variations
// "at their current means". A CMA mean is the weighted average of the generation's best
// samples, and when the region that meets the task is thin (a landing box, a backflip
// that must come round) that average is often outside it even when every sample it
// averages is inside. So by default a variation stands at its best sample:
//   best-sample  (default) after each of its steps, M_i becomes the generation's best
//                sample if that beats M_i as it stands, both ranked as above against the
//                current other variations (an elitist choice on top of CMA-ES, which
//                itself still adapts from all its samples as usual). No extra evaluation.
//   mean         the paper's literal choice: M_i is the CMA mean, evaluated once more.
//
// The result is the best set seen: after every step the current set (P_0 and where every
// variation stands) is scored, and the best one under the rule above is kept.
//
// Confirmation. A problem may return provisional outcomes (optimize/objective.h): samples
// that meet the constraints as far as their own evaluation tells, whose final C needs a
// dearer check (a motion's half-timestep rollout). The check decides something only where
// a variation would stand at the sample, so it is spent there: the best candidate of a
// step is confirmed before the variation moves to it, and if the check fails the sample
// takes its final C and the next best candidate is considered, until the winner is a
// confirmed sample or the incumbent. CMA-ES is told every sample's C as it then stands
// (the unconfirmed ones count as meeting the constraints). Means (mean), the sets of the
// joint strategy, M_0 and a restored checkpoint's sets are confirmed at once. So every set
// scored, kept or returned holds confirmed outcomes only, as if every sample had been
// checked, at the cost of a few checks per generation instead of one per feasible sample.
//
// Batches. A rollout depends on its sample alone and variation v's samples on its own CMA
// instance alone, so best-sample round-robin draws every variation's samples of a
// generation at once and simulates them in one batch of N x lambda; only the scoring runs
// variation by variation, each against the moves of those before it, so the variations
// move exactly as with one batch per variation. Standing at means, a variation's samples
// are scored against the new means before it, which need their own rollouts: one batch of
// lambda per variation, the previous step's mean riding along. Confirmations run
// kConfirmWidth at a time (choose_confirmed): a constant, so that the counts do not depend
// on the threads.
//
// Determinism. CMA instance v (1..N; 0 for joint) draws from derive_seed(seed, {v}); a
// generation's samples are drawn before any is evaluated, evaluated in parallel on the
// thread pool, and written by index, so results are bit-identical for any thread count.
// checkpoint() captures everything at a generation boundary (CMA states, counters,
// strategy state, best set, log and paths); a restored optimizer re-evaluates the
// outcomes of its current and best sets (not counted as evaluations) and then continues
// exactly as the uninterrupted run would.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/thread_pool.h"
#include "optimize/batch_evaluator.h"
#include "optimize/cmaes.h"
#include "optimize/objective.h"

namespace diverse {

enum class DiversityStrategy { kRoundRobin, kProgressive, kJoint, kSimultaneous };
enum class ConstraintRule { kDominant, kPenalty };
enum class VariationPoint { kBestSample, kMean };
// "best-sample", "mean".
const char* to_string(VariationPoint point);
// Parses the names above; throws UserError "WHERE: expected one of best-sample, mean, got
// 'NAME'".
VariationPoint parse_variation_point(const std::string& name, const std::string& where = "--point");
// "dominant", "penalty".
const char* to_string(ConstraintRule rule);
// Parses the names above; throws UserError "WHERE: expected one of dominant, penalty, got
// 'NAME'".
ConstraintRule parse_constraint_rule(const std::string& name,
                                     const std::string& where = "--constraints");
// "round-robin", "progressive", "joint", "simultaneous".
const char* to_string(DiversityStrategy strategy);
// Parses the names above; throws UserError "WHERE: expected one of round-robin,
// progressive, joint, simultaneous, got 'NAME'".
DiversityStrategy parse_strategy(const std::string& name, const std::string& where = "--strategy");

struct DiversityOptions {
  int variations = 4;               // N >= 1, variations besides M_0
  double k = 10.0;                  // K >= 0, weight of the dmin term (paper: 10)
  DiversityStrategy strategy = DiversityStrategy::kRoundRobin;
  ConstraintRule constraints = ConstraintRule::kDominant;  // see the header comment
  VariationPoint point = VariationPoint::kBestSample;      // see the header comment
  int popsize = 16;                 // lambda >= 2, samples per CMA generation (paper: 16)
  double sigma0 = 0.1;              // > 0, initial CMA step size, normalized units
  long long max_generations = 500;  // >= 1, generation limit (paper: 500-1000)
  int window = 50;                  // >= 0, stagnation window in generations; 0 = off
  double epsilon = 1e-6;            // >= 0, least improvement of the best D over window
  std::uint64_t seed = 1;           // run seed; every stream derives from it
};
// Throws std::invalid_argument naming the first field out of range (variations in
// [1, kMaxDiversityVariations], popsize in [2, kMaxDiversityPopsize], the rest as above).
constexpr int kMaxDiversityVariations = 1000;
constexpr int kMaxDiversityPopsize = 100000;
void validate(const DiversityOptions& options);
nlohmann::json to_json(const DiversityOptions& options);
DiversityOptions diversity_options_from_json(const nlohmann::json& j);

// One log record per step (one CMA generation of one instance).
struct DiversityRecord {
  long long generation = 0;    // 1-based generation the step belongs to
  long long step = 0;          // 1-based count of steps over all instances
  int variation = 0;           // variation optimized, 1..N; 0 = all (joint)
  double D = 0.0;              // D of the current set after the step
  double best_D = 0.0;         // D of the best set so far (in this phase for progressive)
  Eigen::VectorXd constraint;  // C(M_i) of the current set, i = 0..(motions present - 1)
  Eigen::VectorXd dmin;        // dmin(M_i) of the current set, same indexing
  long long evaluations = 0;   // evaluations so far, including this step's
  int samples = 0;             // the step's samples (joint: motions of its sample sets)
  int feasible = 0;            // of those, how many met their constraints (C = 0)
  long long confirmations = 0;     // provisional outcomes confirmed so far
  long long simulation_steps = 0;  // the ledger's "total" so far (DiversityProblem::tally)
};
nlohmann::json to_json(const DiversityRecord& record);

// A point of a variation's optimization path: where it stood after a step that moved it
// (a step that leaves it where it was adds no point).
struct PathPoint {
  long long generation = 0;  // 0 for the start at P_0
  long long step = 0;
  Eigen::VectorXd x;         // normalized parameters
};

enum class DiversityStop { kNone, kMaxGenerations, kStagnation, kConverged };
// "none", "max-generations", "stagnation", "converged".
const char* to_string(DiversityStop stop);

struct DiversityResult {
  std::vector<Eigen::VectorXd> parameters;                // P_0..P_N, normalized
  std::vector<std::shared_ptr<const Outcome>> outcomes;   // M_0..M_N
  DiversityScore score;                                   // D, distances, C, dmin
  long long generations = 0;
  long long evaluations = 0;
  DiversityStop stop = DiversityStop::kNone;
};

class DiversityOptimizer {
 public:
  using Callback = std::function<void(const DiversityRecord&)>;

  // Evaluates P_0 once. The problem and pool must outlive the optimizer; the pool's size
  // is the number of workers the problem was prepared for. With `batch` (which must
  // outlive the optimizer too), every evaluation goes through it instead of the pool
  // (optimize/batch_evaluator.h); the pool still scores the samples.
  DiversityOptimizer(const DiversityProblem& problem, const DiversityOptions& options,
                     ThreadPool& pool, BatchEvaluator* batch = nullptr);
  // Restores from checkpoint(). Throws UserError if the checkpoint does not fit the
  // problem (dimension or reference differ) and std::logic_error if re-evaluating the
  // stored sets does not reproduce their recorded D (evaluate() is not deterministic).
  static DiversityOptimizer from_checkpoint(const DiversityProblem& problem,
                                            const nlohmann::json& checkpoint, ThreadPool& pool,
                                            BatchEvaluator* batch = nullptr);

  // Called after every step with its log record (also kept in log()).
  void set_callback(Callback callback) { callback_ = std::move(callback); }

  // Runs one generation unless done; returns !done() afterwards.
  bool step();
  // Runs generations until done.
  void run();

  bool done() const { return stop_ != DiversityStop::kNone; }
  DiversityStop stop_reason() const { return stop_; }
  long long generation() const { return generation_; }
  long long evaluations() const { return evaluations_; }
  // Provisional outcomes confirmed so far (DiversityProblem::confirm), beside evaluations.
  long long confirmations() const { return confirmations_; }
  // What the evaluations cost so far, as the problem tallies it (DiversityProblem::tally).
  const nlohmann::json& ledger() const { return ledger_; }
  const DiversityOptions& options() const { return options_; }

  const std::vector<DiversityRecord>& log() const { return log_; }
  // paths()[v] for v = 1..N (paths()[0] holds P_0 alone).
  const std::vector<std::vector<PathPoint>>& paths() const { return paths_; }
  // The current set (P_0 and where each variation stands) and its score. Progressive:
  // only the motions added so far.
  const std::vector<Eigen::VectorXd>& current_parameters() const { return points_; }
  const DiversityScore& current_score() const { return current_; }

  // The best set so far (see the header comment).
  DiversityResult result() const;

  // The complete state, at a generation boundary: call it between step()s (it throws
  // std::logic_error when called from the callback, in the middle of a generation).
  nlohmann::json checkpoint() const;

 private:
  // How good a set is: its total constraint value (dominant rule; 0 under penalty) and D.
  struct Merit {
    double violation = 0.0;
    double D = 0.0;
  };
  Merit merit(const DiversityScore& score) const;
  // a is strictly better than b: less violation, or as much and a higher D.
  bool better(const Merit& a, const Merit& b) const;
  // Index of the best of several candidates by their C and D; the last one is the
  // incumbent and wins ties.
  std::size_t best_candidate(const std::vector<double>& constraint,
                             const std::vector<double>& D) const;
  // CMA fitness (lower is better) of samples with their C values and D values.
  std::vector<double> fitness(const std::vector<double>& constraint,
                              const std::vector<double>& D) const;

  struct Snapshot {
    std::vector<Eigen::VectorXd> points;
    std::vector<std::shared_ptr<const Outcome>> outcomes;
    DiversityScore score;
  };

  DiversityOptimizer(const DiversityProblem& problem, ThreadPool& pool, BatchEvaluator* batch);
  // Outcomes of xs in index order: through batch_ if set, else on the pool; each tallied
  // in the ledger when `tally` (DiversityProblem::tally).
  std::vector<std::shared_ptr<const Outcome>> evaluate_all(const std::vector<Eigen::VectorXd>& xs,
                                                           bool tally = true);
  // Replaces every provisional outcome of xs by its confirmation (DiversityProblem::confirm),
  // on the pool; counted and tallied when `tally`.
  void confirm_all(const std::vector<Eigen::VectorXd>& xs,
                   std::vector<std::shared_ptr<const Outcome>>& outcomes, bool tally);
  // Confirmations run this many at a time (choose_confirmed); a constant, so that the
  // steps a run counts do not depend on its threads.
  static constexpr std::size_t kConfirmWidth = 2;
  // The candidates choose_confirmed() would confirm, in its order, if each failed: at most
  // `width`, all provisional (C and D as it holds them, the incumbent last).
  std::vector<std::size_t> confirmation_order(const std::vector<std::shared_ptr<const Outcome>>& outcomes,
                                              std::size_t first, std::vector<double> C,
                                              std::vector<double> D, std::size_t width) const;
  // best_candidate() over variation v's candidates outcomes[first..] (scored in C and D,
  // the incumbent last), confirming the winner while it is provisional and choosing again
  // with its final C and D (updated in C, D and outcomes) until the winner is confirmed
  // or is the incumbent.
  std::size_t choose_confirmed(int v, const std::vector<Eigen::VectorXd>& xs,
                               std::vector<std::shared_ptr<const Outcome>>& outcomes,
                               std::size_t first, std::vector<double>& C, std::vector<double>& D);
  CmaesOptions cma_options(int dim, int instance) const;
  int present() const;  // motions in the current set, M_0 included
  void step_variation(int variation);  // one CMA generation of one variation
  // A generation drawn by every CMA instance still running: its samples xs[v] (v = 1..N),
  // all of them in one batch, variation v's from batch[first[v]].
  struct Drawn {
    std::vector<int> active;
    std::vector<std::vector<Eigen::VectorXd>> xs;
    std::vector<Eigen::VectorXd> batch;
    std::vector<std::size_t> first;
  };
  Drawn draw_generation();
  // C and D of the n samples outcomes[first..first + n), each in place of M_v in the
  // current set, computed on the pool.
  void score_against_current(int v, const std::vector<std::shared_ptr<const Outcome>>& outcomes,
                             std::size_t first, std::size_t n, std::vector<double>& C,
                             std::vector<double>& D) const;
  void step_round_robin();             // best-sample round-robin: one batch per generation
  // Scores variation v's samples xs (outcomes, tallied) against the current set, moves
  // M_v to the best if it beats M_v as it stands (confirmed first), tells CMA-ES.
  void move_to_best_sample(int v, const std::vector<Eigen::VectorXd>& xs,
                           std::vector<std::shared_ptr<const Outcome>>& outcomes);
  void step_joint();
  void step_simultaneous();
  void rescore();
  void settle_pending(std::shared_ptr<const Outcome> outcome);
  void finish_step(int variation);
  void end_generation();
  void start_phase();

  const DiversityProblem* problem_;
  ThreadPool* pool_;
  BatchEvaluator* batch_ = nullptr;
  DiversityOptions options_;
  Callback callback_;

  std::vector<Cmaes> cmas_;  // N instances (index v - 1), or one (joint)
  std::vector<Eigen::VectorXd> points_;                  // current set, N + 1 entries
  std::vector<std::shared_ptr<const Outcome>> outcomes_;  // their outcomes
  DiversityScore current_;                               // score of the present motions
  Snapshot best_;
  std::vector<Merit> best_history_;  // best set's merit after each generation (0 = start)

  long long generation_ = 0;
  long long steps_ = 0;
  long long evaluations_ = 0;
  long long confirmations_ = 0;
  nlohmann::json ledger_;
  DiversityStop stop_ = DiversityStop::kNone;
  // Progressive: the variation being optimized, when its phase began, and its budget.
  int active_ = 0;
  long long phase_start_ = 0;
  long long phase_budget_ = 0;
  // Variation whose new mean awaits evaluation (0 = none); always 0 between generations.
  int pending_ = 0;
  // The last step's sample count and how many of them met their constraints, for its
  // log record (with kMean the record is made one evaluation later).
  int step_samples_ = 0, step_feasible_ = 0;
  void count_samples(const std::vector<std::shared_ptr<const Outcome>>& outcomes, std::size_t n);
  bool in_step_ = false;

  std::vector<DiversityRecord> log_;
  std::vector<std::vector<PathPoint>> paths_;
};

}  // namespace diverse
