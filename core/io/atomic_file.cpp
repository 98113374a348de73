#include "core/io/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "core/error.h"

namespace femto {

void write_atomically(const std::string& path,
                      const std::function<void(const std::string& tmp_path)>& write) {
  const std::string tmp = path + ".tmp." + std::to_string(static_cast<long>(::getpid()));
  try {
    write(tmp);
  } catch (...) {
    std::remove(tmp.c_str());  // best effort: the writer may not have created it at all
    throw;
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;  // capture before remove() can overwrite it
    std::remove(tmp.c_str());
    throw RuntimeError("cannot write '" + path + "': rename from '" + tmp +
                       "' failed: " + std::strerror(err));
  }
}

void write_text_atomically(const std::string& path, const std::string& text) {
  write_atomically(path, [&](const std::string& tmp) {
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw RuntimeError("cannot write '" + path + "': " + std::strerror(errno));
    const bool wrote = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    const int err = errno;
    // fclose flushes, so it is where a full disk usually shows up.
    if (std::fclose(f) != 0 || !wrote)
      throw RuntimeError("cannot write '" + path + "': " + std::strerror(wrote ? errno : err));
  });
}

}  // namespace femto
