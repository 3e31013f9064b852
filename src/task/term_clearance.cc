#include "task/term_clearance.h"

#include <algorithm>

#include "core/error.h"
#include "core/toml_reader.h"
#include "task/constraints.h"
#include "task/task.h"
#include "task/term_on_box.h"

namespace diverse {
namespace {

class ClearanceObserver : public TermObserver {
 public:
  explicit ClearanceObserver(int geom) : geom_(geom) {}
  // Contacts in the obstacle's margin gap included.
  void observe(const mjModel* m, const mjData* d, MotionSummary& s) override {
    (void)m;
    if (geom_ < 0) return;
    for (int i = 0; i < d->ncon; ++i) {
      const mjContact& c = d->contact[i];
      if (c.geom1 == geom_ || c.geom2 == geom_) s.min_clearance = std::min(s.min_clearance, c.dist);
    }
  }

 private:
  int geom_;
};

}  // namespace

void read_clearance(const TomlReader& r, const Task& task, TaskConstraints& c) {
  r.only({"object", "min_clearance", "weight"});
  auto t = std::make_shared<ClearanceConstraint>(r.path());
  t->object = r.string("object");
  require_object(r, task, "object", t->object, "obstacle");
  t->min_clearance = r.number("min_clearance", 0, 1);
  t->weight = term_weight(r, c);
  c.terms.push_back(std::move(t));
}

void ClearanceConstraint::penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const {
  (void)task;
  const double d = std::max(0.0, min_clearance - motion.min_clearance);
  report.add("clearance", d, weight * d * d);
}

double ClearanceConstraint::margin(const Task& task, const MotionSummary& motion) const {
  (void)task;
  return motion.min_clearance - min_clearance;
}

bool ClearanceConstraint::broken(const Task& task, const MotionSummary& so_far, Moment moment) const {
  (void)task;
  return moment == Moment::kStep && so_far.min_clearance < min_clearance;
}

std::unique_ptr<TermObserver> ClearanceConstraint::observer(const mjModel* m, const Character& body) const {
  (void)body;
  return std::make_unique<ClearanceObserver>(mj_name2id(m, mjOBJ_GEOM, object.c_str()));
}

void ClearanceConstraint::check(const Task& task) const {
  const TaskSimulation& s = task.simulation;
  if (!(min_clearance < s.clearance_range))
    throw_field_error(task.file, field() + ".min_clearance",
                      "expected less than simulation.clearance_range (" + num(s.clearance_range) +
                          " m, the distance up to which proximity is seen), got " + num(min_clearance));
}

}  // namespace diverse
