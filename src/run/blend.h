// Blends of a finished run's controllers (`diverse blend RUN`; paper section 9, future
// work): how much of the simplex spanned by the motions a run found still meets the task.
//
// The run's motions M0..MN stand at normalized parameter vectors P_0..P_N (for a run whose
// shape varied, the controller's parameters followed by the shape scales, so a blend
// blends bodies too; eval/motion_problem.h). A blend with weights w (w_i >= 0, sum 1) is
// the controller at sum_i w_i P_i; every coordinate of every P_i lies in [0, 1], so a
// blend does too. Sample k's weights are drawn uniformly on the simplex (flat Dirichlet:
// w_i = e_i / sum e, e_i = -log(1 - u_i) exponential) from its own stream,
// Rng(derive_seed(seed, {k})): the same run, seed and k give the same blend whatever
// the number of samples or threads, and more samples only add blends.
//
// Each blend is simulated with the run's task file exactly as the run simulated its
// samples (finished/run_problem.h): its constraint value C (0 when it meets the task) and
// its distance to each of the run's motions in the run's metric. For comparison, points
// of every variation's optimization path (paths/m<i>.json: where it stood after its
// steps, from M0 to its result; up to `path_points` per variation, evenly spaced) are
// simulated again the same way and their share that meets the task is counted.
//
// RUN/blend/ (replaced as a whole by every `diverse blend`):
//   summary.json        {"format": "diverse.blend", "version": 1, task, metric,
//                        run_fingerprint (finished/run_problem.h), seed,
//                        samples (K), vertices (N + 1), labels ["M0", ...], vary,
//                        feasible (count), feasible_fraction,
//                        feasible_nearest_distance {mean, max} (feasible blends' distance
//                        to the nearest motion of the run: how far they reach beyond it),
//                        motions: [{label, constraint}] (the run's motions simulated again),
//                        paths: {points, feasible, feasible_fraction, variations: [...]},
//                        blends: [{index, label "B<k>", file, weights [N + 1], constraint,
//                        fell, failed, feasible, distances [to M0..MN] (null when the
//                        motion failed or never flew), nearest (motion index)}]}
//                       No timing inside: the file depends only on the run, K and the seed.
//   motions/b<k>.json   k = 1..K, each blend as a motion file (io/motion_record.h) that
//                       replays exactly, on model/b<k>.xml; `diverse gallery` plays them.
#pragma once

#include <Eigen/Dense>

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <span>
#include <vector>

namespace diverse {

struct BlendOptions {
  int samples = 64;          // K, blends simulated
  std::uint64_t seed = 1;    // where the weights come from
  int path_points = 16;      // path points per variation simulated for comparison (0: none)
  int threads = 0;           // 0 = one per core
};

// Sample k's weights on the simplex of `vertices` corners (k = 1..K; see above).
Eigen::VectorXd blend_weights(int vertices, std::uint64_t seed, int k);
// sum_i weights[i] * points[i]. Throws std::invalid_argument on mismatched sizes.
Eigen::VectorXd blend_point(std::span<const Eigen::VectorXd> points, const Eigen::VectorXd& weights);

// Simulates the blends and path points of the finished run in `run_dir`, writes
// RUN/blend/ (above) and returns its summary. Throws UserError on a directory that is not
// a finished run, a task file missing or changed since the run, malformed run files, or
// options out of range (samples in [1, 100000], path_points in [0, 10000]).
nlohmann::json write_blend(const std::filesystem::path& run_dir, const BlendOptions& options = {});

}  // namespace diverse
