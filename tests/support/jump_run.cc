#include "support/jump_run.h"

#include <algorithm>
#include <vector>

#include "io/files.h"
#include "io/motion_record.h"
#include "params/parameters.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse::test_support {
namespace fs = std::filesystem;

std::string jump_high_task_file() { return std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_high.toml"; }

void write_jump_run(const fs::path& dir) {
  const std::string task_file = jump_high_task_file();
  fs::remove_all(dir);
  fs::create_directories(dir / "model");
  fs::create_directories(dir / "motions");
  const TaskEvaluator evaluator(load_task(task_file));
  const ParameterSet m0 = evaluator.load_parameters(evaluator.task().m0);
  Eigen::VectorXd x1 = m0.normalized();
  for (Eigen::Index k = 0; k < x1.size(); ++k)
    x1[k] = std::clamp(x1[k] + (k % 2 == 0 ? 0.06 : -0.06), 0.0, 1.0);
  ParameterSet m1 = m0, half = m0;
  m1.set_normalized(x1);
  half.set_normalized(0.5 * (m0.normalized() + x1));

  nlohmann::json motions = nlohmann::json::array();
  int i = 0;
  for (const ParameterSet* p : std::vector<const ParameterSet*>{&m0, &m1}) {
    const std::string stem = i == 0 ? "m0" : "m1";
    const Evaluation e = write_motion(evaluator, *p, {i == 0 ? "M0" : "M1", dir / "model" / (stem + ".xml")},
                                      dir / "motions" / (stem + ".json"));
    motions.push_back({{"index", i}, {"label", i == 0 ? "M0" : "M1"}, {"constraint", e.constraint},
                       {"dmin", 1.5}, {"fell", e.fell}, {"failed", e.failed},
                       {"file", "motions/" + stem + ".json"}});
    ++i;
  }
  write_json_atomic(dir / "run.json", {{"format", "diverse.run"},
                                       {"task_file", task_file},
                                       {"task_text", read_file(task_file)},
                                       {"metric", "md"}});
  write_json_atomic(dir / "summary.json",
                    {{"format", "diverse.summary"}, {"task", "jump_high"}, {"metric", "md"},
                     {"N", 1}, {"generations", 2}, {"motions", motions},
                     {"distances", {{"objective", "md"}, {"md", {{0.0, 1.5}, {1.5, 0.0}}}}}});
  nlohmann::json points = nlohmann::json::array();
  int g = 0;
  for (const ParameterSet* p : std::vector<const ParameterSet*>{&m0, &half, &m1})
    points.push_back({{"generation", g}, {"step", g}, {"parameters", p->to_json()}}), ++g;
  write_json_atomic(dir / "paths" / "m1.json", {{"variation", 1}, {"metric", "md"}, {"points", points}});
}

}  // namespace diverse::test_support
