#include "task/rollout_terms.h"

#include "task/term_fall.h"

namespace diverse {

RolloutTerms::RolloutTerms(const Task& task, const mjModel* m, const Character& body)
    : body_(body), allowed_(allowed_contact_bodies(m, body, task.constraints, task.file)) {
  for (const auto& term : task.constraints.terms) {
    if (auto observer = term->observer(m, body)) observers_.push_back(std::move(observer));
  }
}

void RolloutTerms::observe(const mjModel* m, const mjData* d, MotionSummary& s) {
  for (const auto& o : observers_) o->observe(m, d, s);
}

void RolloutTerms::stepped(const mjModel* m, const mjData* d) {
  for (const auto& o : observers_) o->stepped(m, d);
}

void RolloutTerms::finish(MotionSummary& s) {
  for (const auto& o : observers_) o->finish(s);
}

bool RolloutTerms::contact_is_fall(const mjModel* m, const mjData* d) const {
  return allowed_.empty() || touches_outside(m, d, body_, allowed_);
}

}  // namespace diverse
