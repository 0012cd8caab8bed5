#include "io/AtomicFile.h"

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <system_error>

namespace tp {

namespace fs = std::filesystem;

namespace {

std::string errnoText(int err, const char* fallback) {
  return err != 0 ? std::string(std::strerror(err)) : std::string(fallback);
}

// A hidden sibling name unlikely to collide with anything, including another writer of the same
// target in this or another process.
fs::path temporarySibling(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  static const unsigned long long seed = std::random_device{}();
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::mt19937_64 rng(seed + counter.fetch_add(1));
    char suffix[17];
    std::snprintf(suffix, sizeof suffix, "%016llx", static_cast<unsigned long long>(rng()));
    std::string name = target.filename().string();
    name.insert(name.begin(), '.');
    name.append(".tmp-").append(suffix);
    fs::path p = dir / name;
    std::error_code ec;
    if (!fs::exists(p, ec)) return p;
  }
  throw std::runtime_error("cannot write '" + target.string() +
                           "': no free temporary file name in its directory");
}

}  // namespace

void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  if (path.empty()) throw std::runtime_error("cannot write a file with an empty name");
  fs::path target(path);
  std::error_code ec;
  // Replace the file a symbolic link points to, not the link.
  if (fs::is_symlink(target, ec)) {
    const fs::path resolved = fs::weakly_canonical(target, ec);
    if (!ec) target = resolved;
  }
  if (fs::is_directory(target, ec))
    throw std::runtime_error("cannot write '" + path + "': it is a directory");

  const fs::path tmp = temporarySibling(target);
  auto fail = [&](const std::string& reason) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    return std::runtime_error("cannot write '" + path + "': " + reason);
  };

  errno = 0;
  std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
  if (!out) {
    const int err = errno;
    throw fail("cannot create temporary file '" + tmp.string() +
               "': " + errnoText(err, "unknown error"));
  }
  try {
    write(out);
  } catch (...) {
    out.close();
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw;
  }
  errno = 0;
  out.flush();
  if (!out) throw fail("writing failed: " + errnoText(errno, "stream error"));
  out.close();
  if (out.fail()) throw fail("closing failed: " + errnoText(errno, "stream error"));

  // Keep the permissions of the file being replaced (a new file gets the default ones).
  if (fs::exists(target, ec)) {
    const auto perms = fs::status(target, ec).permissions();
    if (!ec) fs::permissions(tmp, perms, ec);
  }
  fs::rename(tmp, target, ec);
  if (ec) throw fail("cannot rename temporary file into place: " + ec.message());
}

void writeFileAtomically(const std::string& path, std::string_view contents) {
  writeFileAtomically(path, [&](std::ostream& os) {
    os.write(contents.data(), static_cast<std::streamsize>(contents.size()));
  });
}

}  // namespace tp
