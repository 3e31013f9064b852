// Falls (kind "fall"): the task-wide fall rules, read from a [[constraints]] entry
//
//   kind = "fall"
//   penalty = 100000              # the fall constant (table form: fall_penalty)
//   allow_contact = ["hands"]     # bodies whose contact is not a fall (table form: the same key)
//
// A fall is any contact of a body of the character that is not a foot with the ground or
// an object (besides the COM dropping to the feet, a topple, ...: task/jump_eval.h,
// task/walk_eval.h). `allow_contact` lists bodies that may touch (a handspring's or a
// cartwheel's hands): body names of the character's model, or "hands", the bodies of
// its character file's [hands] table. Every other body that is not a foot still falls.
#pragma once

#include <string>
#include <vector>

#include "task/term.h"

namespace diverse {

void read_fall(const TomlReader& r, const Task& task, TaskConstraints& c);
// Reads `allow_contact` of `r` (an array of body names or "hands") into c.
void read_allow_contact(const TomlReader& r, TaskConstraints& c);

// The body ids of c.allow_contact in model `m` ("hands" for the character's hand
// bodies). Throws UserError "FILE: FIELD.allow_contact: expected ..." for a name that is
// no body of the character, or "hands" for a character without hands.
std::vector<int> allowed_contact_bodies(const mjModel* m, const Character& body, const TaskConstraints& c,
                                        const std::string& task_file);

// True when a body of the character that is neither a foot nor in `allowed` touches the
// ground or an object (a contact in an obstacle's margin gap is near, not touching).
bool touches_outside(const mjModel* m, const mjData* d, const Character& body, const std::vector<int>& allowed);

}  // namespace diverse
