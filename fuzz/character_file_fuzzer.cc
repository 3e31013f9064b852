// libFuzzer target: the character-file reader and its binding to the model.
//
// One input is one character file, placed beside the committed characters (so
// `model = "human2d.xml"` resolves). It is parsed (load_character_file), its model
// compiled and the character bound to it (bind_character), as `diverse character FILE`
// does. Every bad file must end in UserError.
#include <cstdint>
#include <memory>

#include "character/character.h"
#include "core/error.h"
#include "fuzz_support.h"
#include "physics/model.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const diverse::fuzz::Scratch scratch("assets_copy/characters", "assets/characters");
  const std::string path = scratch.write("fuzz.toml", data, size);
  try {
    const auto spec =
        std::make_shared<const diverse::CharacterSpec>(diverse::load_character_file(path));
    const auto model = diverse::SharedModel::from_file(spec->model);
    diverse::bind_character(spec, model->get(), spec->model);
  } catch (const diverse::UserError&) {
  }
  return 0;
}
