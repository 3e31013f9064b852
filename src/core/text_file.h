// Reading a file a user named, with one-line errors.
//
// read_text_file() is how every reader of user files (task, character, parameter, model,
// motion, run and checkpoint files) gets their text: a path that does not exist, a
// directory, a device or pipe (which could block or never end), an unreadable file or
// one larger than kMaxInputFileBytes is a UserError "PATH: cannot read the WHAT file
// (REASON)", never a stream exception, a hang or an exhausted memory.
#pragma once

#include <cstddef>
#include <string>

namespace diverse {

// Larger than any file diverse writes (a 6 s motion file is about 3 MB).
constexpr std::size_t kMaxInputFileBytes = std::size_t{256} << 20;

// The whole file; `what` names the kind of file in the message ("task", "parameter", ...;
// "" for "PATH: cannot read (REASON)").
std::string read_text_file(const std::string& path, const std::string& what);

}  // namespace diverse
