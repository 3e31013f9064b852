#include "run/checkpoint.h"

#include <stdexcept>
#include <string>

#include "core/error.h"
#include "distribute/cluster.h"
#include "io/files.h"

namespace diverse {
namespace fs = std::filesystem;

namespace {
constexpr const char* kCheckpointFormat = "diverse.run_checkpoint";
}  // namespace

nlohmann::json vary_json(bool vary_shape) {
  return vary_shape ? nlohmann::json{"control", "shape"} : nlohmann::json{"control"};
}

nlohmann::json run_checkpoint_json(double wall_seconds, bool vary_shape,
                                   const DiversityOptimizer& optimizer) {
  return {{"format", kCheckpointFormat},
          {"wall_seconds", wall_seconds},
          {"vary", vary_json(vary_shape)},
          {"optimizer", optimizer.checkpoint()}};
}

nlohmann::json read_run_checkpoint(const fs::path& file, bool vary_shape, double* wall_seconds) {
  const nlohmann::json checkpoint = read_json(file);
  const std::string where = file.string();
  if (!checkpoint.is_object() || !checkpoint.contains("format") ||
      checkpoint["format"] != kCheckpointFormat || !checkpoint.contains("optimizer"))
    throw UserError(where + ": format: expected a checkpoint written by `diverse run`");
  if (checkpoint.contains("vary") && checkpoint["vary"] != vary_json(vary_shape))
    throw UserError(where + ": vary: " + checkpoint["vary"].dump() + " does not match run.json's " +
                    vary_json(vary_shape).dump());
  double wall = 0.0;
  if (checkpoint.contains("wall_seconds")) {
    const nlohmann::json& w = checkpoint["wall_seconds"];
    if (!w.is_number() || !(w.get<double>() >= 0.0))
      throw_field_error(where, "wall_seconds", "expected a number >= 0");
    wall = w.get<double>();
  }
  if (wall_seconds != nullptr) *wall_seconds = wall;
  return checkpoint["optimizer"];
}

std::unique_ptr<DiversityOptimizer> restore_optimizer(const DiversityProblem& problem,
                                                      const nlohmann::json& state, ThreadPool& pool,
                                                      const fs::path& file, BatchEvaluator* batch) {
  const std::string where = file.string();
  try {
    return std::make_unique<DiversityOptimizer>(
        DiversityOptimizer::from_checkpoint(problem, state, pool, batch));
  } catch (const ClusterError&) {
    throw;  // a rank of the run failed, not the file
  } catch (const UserError& e) {
    throw UserError(where + ": " + e.what());
  } catch (const nlohmann::json::exception& e) {
    throw UserError(where + ": corrupt checkpoint (" + std::string(e.what()) + ")");
  } catch (const std::invalid_argument& e) {
    throw UserError(where + ": corrupt checkpoint (" + std::string(e.what()) + ")");
  } catch (const std::logic_error& e) {
    throw UserError(where + ": does not reproduce on this machine (" + std::string(e.what()) + ")");
  }
}

}  // namespace diverse
