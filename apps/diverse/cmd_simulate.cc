// `diverse simulate TASK [--params FILE] --out DIR`: simulates one parameter set of a
// task (by default its input motion M0), prints every constraint term, and writes
// DIR/motion.json with the exact-replay record (src/io/motion_record.h), DIR/model.xml
// (the exact MJCF text the motion ran on), and DIR/filmstrip.png with the
// character at the phase events. A parameter file may also give the body shape as scales
// "shape.NAME" (docs/guide/shapes.md; a scale left out is 1); a motion file of a run with
// varying shape is such a file. `--strength S` simulates the strength model S (every
// joint's PD gains and torque limits times S; model.xml carries the limits).
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "command.h"
#include "options.h"
#include "core/error.h"
#include "finished/run_view.h"
#include "io/motion_record.h"
#include "render/film_strip.h"
#include "render/film_columns.h"
#include "render/view_plan.h"
#include "task/evaluate.h"

namespace diverse::cli {
namespace {

struct SimulateArgs {
  std::string task;
  std::string params;
  std::string out;
  bool no_film = false;
  double strength = 1.0;
};

void run(const SimulateArgs& args) {
  namespace fs = std::filesystem;
  Task task = load_task(resolve_task_path(args.task));
  task.strength = args.strength;
  const TaskEvaluator ev(task);
  const std::string params_path = args.params.empty() ? task.m0 : args.params;
  const ParameterSet params = ev.load_shaped_parameters(params_path);
  const fs::path dir(args.out);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw UserError(args.out + ": cannot create the output directory (" + ec.message() + ")");

  StepRecorder record;
  MotionRecordInfo info;
  info.label = "M0";
  info.model_path = dir / "model.xml";
  const Evaluation e = write_motion(ev, params, info, dir / "motion.json", &record);

  std::printf("task %s, parameters %s\n", task.name.c_str(), params_path.c_str());
  if (holds_shape(params)) {
    std::printf("shape:");
    for (const ParamSpec& spec : ev.shapes().specs())
      std::printf(" %s %.4g", spec.name.c_str() + 6, params.get(spec.name));
    std::printf("\n");
  }
  for (const ConstraintTerm& t : e.report.terms) {
    std::printf("  %-12s violation %-10.4g penalty %.6g\n", t.name.c_str(), t.violation, t.penalty);
  }
  std::printf("C = %.6g%s%s\n", e.constraint, e.fell ? ", fell: " : "",
              e.fell ? e.summary.fall_reason.c_str() : "");
  std::printf("effort %.6g N^2 m^2 s, positive work %.6g J\n", e.stats.effort, e.stats.positive_work);
  if (task.strength != 1.0)
    std::printf("strength %g: every joint's PD gains and torque limits times %g\n", task.strength, task.strength);
  if (e.failed) std::printf("failed: %s\n", e.failure.c_str());
  for (size_t p = 0; p < e.phases.names.size(); ++p) {
    if (e.phases.begin[p] < 0) {
      std::printf("  phase %-7s not reached\n", e.phases.names[p].c_str());
    } else {
      std::printf("  phase %-7s begins at %.3f s\n", e.phases.names[p].c_str(), e.phases.begin[p]);
    }
  }
  const MotionSummary& s = e.summary;
  if (ev.task().walk.enabled) {
    // A walk: every step's length in the heading frame and the largest tilt before it.
    for (size_t i = 0; i < s.walk.steps.size(); ++i) {
      const WalkStep& w = s.walk.steps[i];
      std::printf("  step %2zu %s at %7.3f s: forward %6.3f m, lateral %6.3f m, heading %6.1f deg, tilt %5.1f deg%s\n",
                  i + 1, w.leg == 0 ? "left " : "right", w.time, w.forward, w.lateral, w.heading * 180 / M_PI,
                  w.tilt * 180 / M_PI, static_cast<int>(i) >= ev.task().walk.settle_steps ? "" : "  (settling)");
    }
    std::printf("%zu steps, %d simulation steps, %.3f s\n", s.walk.steps.size(), e.stats.steps, e.stats.time);
  } else {
    std::printf("peak COM %.3f m (standing %.3f m), feet touch down at x %.3f y %.3f z %.3f m and end at x %.3f y %.3f z %.3f m, "
                "rotation %.1f deg (flight %.1f), largest forward pitch %.1f deg, min obstacle distance %.3f m, "
                "%d steps, %.3f s\n",
                s.peak_com_z, s.standing_com_z, s.touchdown_feet_x, s.touchdown_feet_y, s.touchdown_feet_z, s.feet_x, s.feet_y,
                s.feet_z, s.rotation_total * 180 / M_PI, s.rotation_flight * 180 / M_PI,
                s.max_forward_pitch * 180 / M_PI, s.min_clearance, e.stats.steps, e.stats.time);
  }

  if (!args.no_film) {
    const auto model = SharedModel::from_file((dir / "model.xml").string());
    FilmColumns columns = motion_film_columns(e.phases, record);
    std::vector<FilmRow> rows;
    rows.push_back(FilmRow{model->get(), "M0", std::move(columns.frames)});
    RunMotion motion;
    motion.record = record;
    const auto frames = motion.sample(10.0);
    const ViewPlan plan = plan_view(std::vector<PosedModel>{{model->get(), frames}});
    FilmStripOptions film;
    film.title = film_title(task.name, columns.names);
    film.ground_strips = task_ground_strips(task);
    film.camera_direction = plan.direction;
    film.follow = plan.follow;
    write_film_strip((dir / "filmstrip.png").string(), rows, film);
  }
  std::printf("wrote %s\n", (dir / "motion.json").string().c_str());
}

void install(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand("simulate", "Simulate a task's motion and write a replayable record");
  cmd->footer("Example:\n"
              "  diverse simulate backflip --out runs/backflip-m0");
  cmd->add_option("task", args->task, "Task name (tasks/<name>.toml) or task file")->required();
  cmd->add_option("--params", args->params, "Parameter file (default: the task's M0)");
  cmd->add_option("--out", args->out, "Output directory")->required();
  cmd->add_flag("--no-film", args->no_film, "Do not render the film strip");
  cmd->add_option("--strength", args->strength,
                  "Strength model: every joint's PD gains and torque limits times S")
      ->capture_default_str()
      ->check(number_in(kMinStrength, kMaxStrength));
  cmd->callback([args] { run(*args); });
}

const bool registered = register_command(50, install);

}  // namespace
}  // namespace diverse::cli
