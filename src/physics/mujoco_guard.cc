#include "physics/mujoco_guard.h"

#include <csetjmp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>

namespace diverse {
namespace {

// Per-thread landing point of an error raised inside a guarded call.
thread_local std::jmp_buf* t_jump = nullptr;
thread_local char t_message[512];

void on_error(const char* message) {
  if (t_jump != nullptr) {
    std::snprintf(t_message, sizeof(t_message), "%s", message);
    std::longjmp(*t_jump, 1);
  }
  std::fprintf(stderr, "diverse: MuJoCo error outside a simulation step: %s\n", message);
  std::abort();
}

// Counted per mjData in d->warning[]; nothing to do globally.
void on_warning(const char*) {}

const char* warning_name(int w) {
  switch (w) {
    case mjWARN_INERTIA: return "singular inertia";
    case mjWARN_CONTACTFULL: return "contact buffer full";
    case mjWARN_CNSTRFULL: return "constraint buffer full";
    case mjWARN_VGEOMFULL: return "visual geom buffer full";
    case mjWARN_BADQPOS: return "bad qpos";
    case mjWARN_BADQVEL: return "bad qvel";
    case mjWARN_BADQACC: return "bad qacc";
    case mjWARN_BADCTRL: return "bad ctrl";
    default: return "warning";
  }
}

// setjmp must live in the frame that stays active while MuJoCo runs; keep this tiny
// and free of C++ objects with destructors.
template <void (*Fn)(const mjModel*, mjData*)>
bool guarded(const mjModel* m, mjData* d, std::string* error) {
  std::jmp_buf buf;
  std::jmp_buf* previous = t_jump;
  if (setjmp(buf) != 0) {
    t_jump = previous;
    if (error != nullptr) *error = t_message;
    return false;
  }
  t_jump = &buf;
  Fn(m, d);
  t_jump = previous;
  return true;
}

}  // namespace

void install_mujoco_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_error = on_error;
    mju_user_warning = on_warning;
  });
}

bool guarded_step1(const mjModel* m, mjData* d, std::string* error) {
  return guarded<mj_step1>(m, d, error);
}
bool guarded_step2(const mjModel* m, mjData* d, std::string* error) {
  return guarded<mj_step2>(m, d, error);
}
bool guarded_step(const mjModel* m, mjData* d, std::string* error) {
  return guarded<mj_step>(m, d, error);
}

bool simulation_unstable(const mjModel* m, const mjData* d, std::string* why) {
  for (int w = 0; w < mjNWARNING; ++w) {
    if (w == mjWARN_VGEOMFULL) continue;  // rendering only
    if (d->warning[w].number > 0) {
      if (why != nullptr) *why = warning_name(w);
      return true;
    }
  }
  for (int i = 0; i < m->nq; ++i) {
    if (!std::isfinite(d->qpos[i])) {
      if (why != nullptr) *why = "non-finite qpos";
      return true;
    }
  }
  for (int i = 0; i < m->nv; ++i) {
    if (!std::isfinite(d->qvel[i]) || !std::isfinite(d->qacc[i])) {
      if (why != nullptr) *why = "non-finite qvel or qacc";
      return true;
    }
  }
  return false;
}

}  // namespace diverse
