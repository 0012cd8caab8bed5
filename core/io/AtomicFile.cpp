#include "io/AtomicFile.h"

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <mutex>
#include <system_error>

#include <signal.h>
#include <unistd.h>

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
  throw WriteError("cannot write '" + target.string() +
                           "': no free temporary file name in its directory");
}

// Temporary files being written, removed by a SIGINT/SIGTERM/SIGHUP handler so that an
// interrupted run leaves no hidden .NAME.tmp-* files behind. Fixed slots of plain chars: the
// handler may only call async-signal-safe functions (unlink, signal, raise).
constexpr int kSlots = 32;
constexpr int kPathMax = 4096;
char pendingPaths[kSlots][kPathMax];
std::atomic<bool> pendingUsed[kSlots];

extern "C" void removePendingAndReraise(int sig) {
  for (int i = 0; i < kSlots; ++i)
    if (pendingUsed[i].load()) ::unlink(pendingPaths[i]);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

void installCleanupHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction old {};
      if (sigaction(sig, nullptr, &old) != 0) continue;
      if (old.sa_handler != SIG_DFL) continue;  // someone else handles it (the application)
      struct sigaction sa {};
      sa.sa_handler = removePendingAndReraise;
      sigemptyset(&sa.sa_mask);
      sigaction(sig, &sa, nullptr);
    }
  });
}

int registerPending(const fs::path& tmp) {
  installCleanupHandlers();
  const std::string s = tmp.string();
  if (s.size() >= kPathMax) return -1;
  static std::mutex mutex;
  std::lock_guard lock(mutex);
  for (int i = 0; i < kSlots; ++i)
    if (!pendingUsed[i].load()) {
      std::memcpy(pendingPaths[i], s.c_str(), s.size() + 1);
      pendingUsed[i].store(true);
      return i;
    }
  return -1;
}

void unregisterPending(int slot) {
  if (slot >= 0) pendingUsed[slot].store(false);
}

// One file written to its temporary sibling, not yet renamed into place.
struct Pending {
  std::string path;  // as given (for messages)
  fs::path target, tmp;
  int slot = -1;
};

fs::path resolveTarget(const std::string& path) {
  if (path.empty()) throw WriteError("cannot write a file with an empty name");
  fs::path target(path);
  std::error_code ec;
  // Replace the file a symbolic link points to, not the link.
  if (fs::is_symlink(target, ec)) {
    const fs::path resolved = fs::weakly_canonical(target, ec);
    if (!ec) target = resolved;
  }
  if (fs::is_directory(target, ec))
    throw WriteError("cannot write '" + path + "': it is a directory");
  return target;
}

Pending writeTemporary(const std::string& path, const std::function<void(std::ostream&)>& write) {
  Pending p;
  p.path = path;
  p.target = resolveTarget(path);
  checkWritable(path);
  p.tmp = temporarySibling(p.target);
  p.slot = registerPending(p.tmp);
  auto fail = [&](const std::string& reason) {
    std::error_code ignored;
    fs::remove(p.tmp, ignored);
    unregisterPending(p.slot);
    return WriteError("cannot write '" + path + "': " + reason);
  };

  errno = 0;
  std::ofstream out(p.tmp, std::ios::binary | std::ios::trunc);
  if (!out) {
    const int err = errno;
    throw fail("cannot create temporary file '" + p.tmp.string() +
               "': " + errnoText(err, "unknown error"));
  }
  try {
    write(out);
  } catch (...) {
    out.close();
    std::error_code ignored;
    fs::remove(p.tmp, ignored);
    unregisterPending(p.slot);
    throw;
  }
  errno = 0;
  out.flush();
  if (!out) throw fail("writing failed: " + errnoText(errno, "stream error"));
  out.close();
  if (out.fail()) throw fail("closing failed: " + errnoText(errno, "stream error"));

  // Keep the permissions of the file being replaced (a new file gets the default ones).
  std::error_code ec;
  if (fs::exists(p.target, ec)) {
    const auto perms = fs::status(p.target, ec).permissions();
    if (!ec) fs::permissions(p.tmp, perms, ec);
  }
  return p;
}

void discard(const Pending& p) {
  std::error_code ignored;
  fs::remove(p.tmp, ignored);
  unregisterPending(p.slot);
}

void commit(const Pending& p) {
  std::error_code ec;
  fs::rename(p.tmp, p.target, ec);
  if (ec) {
    discard(p);
    throw WriteError("cannot write '" + p.path +
                             "': cannot rename temporary file into place: " + ec.message());
  }
  unregisterPending(p.slot);
}

}  // namespace

void checkWritable(const std::string& path) {
  const fs::path target = resolveTarget(path);
  std::error_code ec;
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir, ec))
    throw WriteError("cannot write '" + path + "': the folder '" + dir.string() +
                             "' does not exist");
  // Read-only by its mode bits too: root passes access(), but a file nobody may write is one
  // its owner meant to keep.
  if (fs::exists(target, ec) &&
      (::access(target.c_str(), W_OK) != 0 ||
       (fs::status(target, ec).permissions() &
        (fs::perms::owner_write | fs::perms::group_write | fs::perms::others_write)) ==
           fs::perms::none))
    throw WriteError("cannot write '" + path + "': the file is read-only");
  if (::access(dir.c_str(), W_OK) != 0)
    throw WriteError("cannot write '" + path + "': the folder '" + dir.string() +
                             "' is not writable");
}

void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  commit(writeTemporary(path, write));
}

void writeFilesAtomically(
    const std::vector<std::pair<std::string, std::function<void(std::ostream&)>>>& files) {
  std::vector<Pending> done;
  try {
    for (const auto& [path, write] : files) done.push_back(writeTemporary(path, write));
  } catch (...) {
    for (const auto& p : done) discard(p);
    throw;
  }
  // Every file is complete: only renames are left (same folders, so they do not fail for want
  // of space).
  for (size_t i = 0; i < done.size(); ++i) {
    try {
      commit(done[i]);
    } catch (...) {
      for (size_t j = i + 1; j < done.size(); ++j) discard(done[j]);
      throw;
    }
  }
}

void writeFileAtomically(const std::string& path, std::string_view contents) {
  writeFileAtomically(path, [&](std::ostream& os) {
    os.write(contents.data(), static_cast<std::streamsize>(contents.size()));
  });
}

}  // namespace tp
