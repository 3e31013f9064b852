// Checks that a task's scene can run and its constraints can be met, before any rollout.
//
// load_task() checks every field on its own (ranges, types, names); check_scene() checks
// what only the fields together, or the compiled scene, can tell. TaskEvaluator's
// constructor calls it, so `diverse run`, `simulate`, `seed-motion` and `bench` all refuse
// such a task at once, with one line "FILE: FIELD: expected ...", instead of spending a
// run on a task nothing can meet, dividing by zero, or running forever:
//
//   gravity      the scene's gravity points down: (0, 0, -g) with g in [0.1, 100] m/s^2
//                (the controllers balance against it and time the flight with it)
//   timestep     the scene's timestep in [1e-5, 0.01] s, and simulation.max_time at most
//                kMaxRolloutSteps steps of it
//   objects      no scene object overlaps the character in its start pose (MuJoCo's
//                contacts at the initial state, more than 1 mm of penetration)
//   constraints  no constraint, alone or with the others, that no body could meet:
//                on_box.margin leaves part of the box's top; the landing window, the top
//                of the on_box object and min_length share some x; an obstacle's
//                min_clearance is below simulation.clearance_range (proximity beyond it
//                is not seen); simulation.max_time leaves room to settle_time after a
//                landing; every constraint's own check (task/term.h, Constraint::check)
//   contacts     constraints.allow_contact names bodies of the character, or "hands" of a
//                character that has hands
#pragma once

#include <mujoco/mujoco.h>

#include "character/character.h"
#include "task/task.h"

namespace diverse {

constexpr double kMaxRolloutSteps = 1e7;

// Throws UserError naming the task file (or the model file) and the field.
void check_scene(const Task& task, const mjModel* m, const Character& body);

}  // namespace diverse
