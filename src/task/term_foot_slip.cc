#include "task/term_foot_slip.h"

#include <algorithm>
#include <cmath>

#include "core/toml_reader.h"
#include "task/constraints.h"
#include "task/foot_slip.h"
#include "task/task.h"

namespace diverse {
namespace {

class FootSlipObserver : public TermObserver {
 public:
  FootSlipObserver(const mjModel* m, const Character& body) : meter_(m, foot_geom_sides(m, body)) {}
  void stepped(const mjModel* m, const mjData* d) override { meter_.after_step(m, d); }
  void finish(MotionSummary& s) override { s.foot_slip = meter_.finish().largest(); }

 private:
  FootSlipMeter meter_;
};

}  // namespace

void read_foot_slip(const TomlReader& r, const Task& task, TaskConstraints& c) {
  (void)task;
  r.only({"per_stance", "weight"});
  auto t = std::make_shared<FootSlipConstraint>(r.path());
  t->per_stance = r.number("per_stance", 0, 1);
  t->weight = term_weight(r, c);
  c.terms.push_back(std::move(t));
}

double FootSlipConstraint::excess(const MotionSummary& motion) const {
  return std::max(0.0, motion.foot_slip - per_stance);
}

void FootSlipConstraint::penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const {
  (void)task;
  const double d = excess(motion);
  report.add("foot_slip", d, weight * d * d);
}

double FootSlipConstraint::margin(const Task& task, const MotionSummary& motion) const {
  (void)task;
  if (!(per_stance > 0)) return INFINITY;
  return 0.1 * (1 - motion.foot_slip / per_stance);
}

std::unique_ptr<TermObserver> FootSlipConstraint::observer(const mjModel* m, const Character& body) const {
  return std::make_unique<FootSlipObserver>(m, body);
}

}  // namespace diverse
