#include "task/term_fall.h"

#include <algorithm>

#include "character/character.h"
#include "core/error.h"
#include "core/toml_reader.h"
#include "task/task.h"

namespace diverse {

void read_allow_contact(const TomlReader& r, TaskConstraints& c) {
  if (!r.has("allow_contact")) return;
  c.allow_contact = r.strings("allow_contact", 1);
  c.allow_contact_field = r.field("allow_contact");
}

void read_fall(const TomlReader& r, const Task& task, TaskConstraints& c) {
  (void)task;
  r.only({"penalty", "allow_contact"});
  c.fall_penalty = r.number("penalty", 1e-6, 1e12, c.fall_penalty);
  read_allow_contact(r, c);
}

std::vector<int> allowed_contact_bodies(const mjModel* m, const Character& body, const TaskConstraints& c,
                                        const std::string& task_file) {
  std::vector<int> ids;
  for (const std::string& name : c.allow_contact) {
    if (name == "hands") {
      if (body.hands.empty())
        throw_field_error(task_file, c.allow_contact_field,
                          "expected body names: the character \"" + body.spec->name + "\" has no hands");
      ids.insert(ids.end(), body.hands.begin(), body.hands.end());
      continue;
    }
    const int id = mj_name2id(m, mjOBJ_BODY, name.c_str());
    if (id < 0 || !body.is_link(m, id))
      throw_field_error(task_file, c.allow_contact_field,
                        "expected \"hands\" or the name of a body of the character, got \"" + name + "\"");
    ids.push_back(id);
  }
  return ids;
}

bool touches_outside(const mjModel* m, const mjData* d, const Character& body, const std::vector<int>& allowed) {
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& con = d->contact[i];
    if (con.exclude != 0) continue;
    for (int g : {con.geom1, con.geom2}) {
      const int b = m->geom_bodyid[g];
      if (b == 0 || m->body_rootid[b] != body.root_body) continue;
      if (body.is_foot_geom(m, g, nullptr)) continue;
      if (std::find(allowed.begin(), allowed.end(), b) == allowed.end()) return true;
    }
  }
  return false;
}

}  // namespace diverse
