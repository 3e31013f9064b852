// A task file a test expects to be refused: loading it throws a UserError whose text
// contains `expected` (the file, the field and what was expected).
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "core/error.h"
#include "task/task.h"

namespace diverse::test_files {

inline void expect_task_refused(const std::string& file, const std::string& expected) {
  try {
    load_task(file);
    ADD_FAILURE() << "expected a UserError for " << file << " (" << expected << ")";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
}

}  // namespace diverse::test_files
