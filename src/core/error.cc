#include "core/error.h"

namespace diverse {

void throw_field_error(const std::string& file, const std::string& field,
                       const std::string& expectation) {
  std::string message = file;
  if (!field.empty()) message += ": " + field;
  message += ": " + expectation;
  throw UserError(message);
}

}  // namespace diverse
