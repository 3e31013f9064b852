// Containment of MuJoCo's process-global error and warning handlers.
//
// MuJoCo reports fatal errors through mju_user_error (the default prints and exits the
// process) and warnings through mju_user_warning (the default writes MUJOCO_LOG.TXT).
// Both hooks are process-global, so they are installed once, here, for every thread:
//
//  - warnings are ignored by the handler: MuJoCo also counts each one in the per-data
//    d->warning[] statistics, which the rollout loop checks after every step, so a warning
//    in one thread never affects another thread's rollout;
//  - an error raised inside guarded_step() (e.g. the mjData stack overflowing after a
//    blow-up) long-jumps back into guarded_step() on the same thread, which reports it as
//    an unstable step. Between setjmp and the jump only MuJoCo's C frames run, so no C++
//    destructor is skipped. An error raised anywhere else aborts with the message.
//
// See the MuJoCo 2.2.2 reference ("Error and memory" and "Multi-threading").
#pragma once

#include <mujoco/mujoco.h>

#include <string>

namespace diverse {

// Installs the handlers (idempotent, thread-safe).
void install_mujoco_handlers();

// One mj_step1 (positions, velocities, contacts of the current state). Returns false
// and fills `error` if MuJoCo raised an error; `d` must then be reset before reuse.
bool guarded_step1(const mjModel* m, mjData* d, std::string* error);
// One mj_step2 (actuation, constraint forces, integration). Same contract.
bool guarded_step2(const mjModel* m, mjData* d, std::string* error);
// mj_step with the same contract.
bool guarded_step(const mjModel* m, mjData* d, std::string* error);

// True when `d` has a warning (bad qpos/qvel/qacc/ctrl, full contact or constraint
// buffers, singular inertia) or a non-finite qpos, qvel or qacc; names it in `why`.
bool simulation_unstable(const mjModel* m, const mjData* d, std::string* why);

}  // namespace diverse
