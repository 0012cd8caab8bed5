#pragma once
// Writing a file so that readers see either the old content or the complete new one: the data go
// to a temporary file in the same directory (same file system, so the final rename is atomic),
// which is flushed, checked and then renamed over the target. On any failure the temporary file
// is removed and the target is left exactly as it was.

#include <functional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace tp {

/// A file that could not be written (the message names it and the reason). The command line
/// exits with status 4 for it, apart from bad input (2).
struct WriteError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Writes `path` atomically with the text produced by `write` (the stream is opened in binary
/// mode, so "\n" stays "\n"). Throws WriteError naming the path and the reason (the
/// system's error text) if the temporary file cannot be created, written, flushed or renamed.
/// An exception thrown by `write` itself is passed on unchanged after the temporary file has been
/// removed. If `path` is a symbolic link, the file it points to is replaced and the link kept.
void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

/// Same, with the complete contents given.
void writeFileAtomically(const std::string& path, std::string_view contents);

/// Several files, all or nothing: each is written to its temporary sibling first and only when
/// every one is complete are they renamed into place; if one cannot be written none is replaced.
void writeFilesAtomically(
    const std::vector<std::pair<std::string, std::function<void(std::ostream&)>>>& files);

/// Throws WriteError naming the path unless it can be written: its folder exists and is
/// writable, and an existing file is not read-only (a read-only result is never replaced).
void checkWritable(const std::string& path);

// Temporary files are removed when the process is stopped by SIGINT, SIGTERM or SIGHUP (unless
// the program handles those signals itself).

}  // namespace tp
