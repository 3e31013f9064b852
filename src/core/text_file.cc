#include "core/text_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/error.h"

namespace diverse {

std::string read_text_file(const std::string& path, const std::string& what) {
  const std::string prefix = path + (what.empty() ? ": cannot read (" : ": cannot read the " + what + " file (");
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw UserError(prefix + std::strerror(errno) + ")");
  if (S_ISDIR(st.st_mode)) throw UserError(prefix + "it is a directory)");
  if (!S_ISREG(st.st_mode)) throw UserError(prefix + "not a regular file)");
  if (static_cast<unsigned long long>(st.st_size) > kMaxInputFileBytes)
    throw UserError(prefix + "larger than " + std::to_string(kMaxInputFileBytes >> 20) + " MB)");
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw UserError(prefix + std::strerror(errno) + ")");
  std::string text;
  text.reserve(static_cast<std::size_t>(st.st_size));
  char buffer[1 << 16];
  while (true) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string why = std::strerror(errno);
      ::close(fd);
      throw UserError(prefix + why + ")");
    }
    if (n == 0) break;
    text.append(buffer, static_cast<std::size_t>(n));
    if (text.size() > kMaxInputFileBytes) {
      ::close(fd);
      throw UserError(prefix + "larger than " + std::to_string(kMaxInputFileBytes >> 20) + " MB)");
    }
  }
  ::close(fd);
  return text;
}

}  // namespace diverse
